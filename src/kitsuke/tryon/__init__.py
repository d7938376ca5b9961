"""The try-on: a kimono simulated on a body moved by poses (SPEC §5.1, §5.4), and the mirror that draws it over
a video or camera (`TryOn`, `run_tryon`, `kitsuke.tryon.live.run_live`)."""

from .frames import Frame, FrameSource, Latest, open_frames
from .mirror import LIVE_EDGE_CM, MirrorFrame, TryOn, TryOnSettings
from .motion import placed_at_rest, with_lead_in
from .register import Registration, fit_focal, register
from .run import TryOnRun, run_tryon
from .simulate import (
    SIMULATION_EDGE_CM,
    FrameQuality,
    KimonoMotion,
    KimonoSimulator,
    SimulationSettings,
    check_poses,
    cloth_model,
    default_simulation_kimono,
    simulate_kimono,
)

__all__ = [
    "LIVE_EDGE_CM",
    "SIMULATION_EDGE_CM",
    "Frame",
    "FrameSource",
    "Latest",
    "MirrorFrame",
    "Registration",
    "TryOn",
    "TryOnRun",
    "TryOnSettings",
    "fit_focal",
    "open_frames",
    "register",
    "run_tryon",
    "FrameQuality",
    "KimonoMotion",
    "KimonoSimulator",
    "SimulationSettings",
    "check_poses",
    "cloth_model",
    "default_simulation_kimono",
    "placed_at_rest",
    "simulate_kimono",
    "with_lead_in",
]
