"""The try-on: a kimono simulated on a body moved by poses (SPEC §5.1, §5.4)."""

from .motion import placed_at_rest, with_lead_in
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
    "SIMULATION_EDGE_CM",
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
