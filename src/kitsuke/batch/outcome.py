"""What a batch job gives back, and what a kind of job must provide to be run by a batch runner.

The runners (`kitsuke.batch.runners`) know nothing of dressing: they run any `JobKind`. `DressKind`
(`kitsuke.batch.jobs`) is the one `kitsuke batch dress` runs; another kind (kimono E calibration) plugs in the same
way: say which shared inputs a job needs, how the driver reads one, how a worker warms up, and how it runs one job.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from typing import Any, Protocol, TypeVar

#: A job's status. ok: done, every quality target met. out_of_target: done (outputs written), some target missed.
#: refused: bad input (what a single command exits 2 for). failed: no usable result (exit 1: the computation
#: failed, an internal error, the job timed out or its worker died).
OK, OUT_OF_TARGET, REFUSED, FAILED = "ok", "out_of_target", "refused", "failed"
STATUSES = (OK, OUT_OF_TARGET, REFUSED, FAILED)
#: Statuses whose job produced its outputs.
DONE = (OK, OUT_OF_TARGET)

T = TypeVar("T")
#: derived(input_name, factory) -> factory(inputs[input_name]), computed once per worker per shared input (a
#: body's collider: built once, used by every job on that body the worker runs).
Derived = Callable[[str, Callable[[Any], T]], T]


@dataclass
class Outcome:
    """One job's result, as a worker sends it back.

    status : one of STATUSES. reason : one line: why refused or failed, or the targets missed ("" when ok).
    seconds : the job's wall time on its worker (queueing and warm-up not included). measures : quality measures
    and counts for the summary (numbers or short texts). files : output file name -> bytes, written by the
    driver into OUTDIR/<job id>/ (so workers on other machines need no shared disk). worker : "host:pid".
    """

    status: str
    reason: str = ""
    seconds: float = 0.0
    measures: dict[str, Any] = field(default_factory=dict)
    files: dict[str, bytes] = field(default_factory=dict)
    worker: str = ""


class JobKind(Protocol):
    """A kind of batch job. Instances are sent to the workers (pickled): keep them small and stateless."""

    name: str

    def inputs(self, job: Any) -> dict[str, Hashable]:
        """Driver: the shared inputs `job` needs, name -> key. Jobs with equal keys share one loaded input, read
        once by the driver and sent to each worker once."""
        ...

    def load(self, key: Hashable) -> Any:
        """Driver: read one shared input (InputError refuses every job that needs it)."""
        ...

    def warm(self) -> None:
        """Worker, once before its first job: compile or load what every job needs (numba kernels)."""
        ...

    def run(self, job: Any, inputs: dict[str, Any], derived: Derived) -> Outcome:
        """Worker: run `job` on its loaded inputs. Returns its Outcome; may raise (the runner records the
        exception as failed)."""
        ...

    def timeout_s(self, job: Any) -> float | None:
        """The job's own time limit in seconds, or None for the batch's."""
        ...
