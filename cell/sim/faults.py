"""Fault injection settings of the simulated controller."""

from __future__ import annotations

from dataclasses import dataclass

from cell.errors import CellError


@dataclass(frozen=True)
class FaultPlan:
    """What the simulator does wrong, seeded.

    Attributes:
        drop: probability that a frame (either direction) is lost.
        corrupt: probability that a frame (either direction) gets a flipped bit.
        delay: probability that an answer is delayed by ``delay_s`` (wall s).
        disconnect_after: the link goes dead after this many requests (None: never) ...
        disconnect_s: ... for this long (wall s); a socket is closed, a pty goes silent.
        estop_at_stop: an emergency stop is latched on arrival at this stop index (None: never).
        missing_holes: ids of holes that are not there (the part has no hole at that spot).
        seed: random seed of the frame faults.
    """

    drop: float = 0.0
    corrupt: float = 0.0
    delay: float = 0.0
    delay_s: float = 0.05
    disconnect_after: int | None = None
    disconnect_s: float = 0.5
    estop_at_stop: int | None = None
    missing_holes: tuple[str, ...] = ()
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("drop", "corrupt", "delay"):
            p = getattr(self, name)
            if not 0.0 <= p < 1.0:
                raise CellError(f"fault plan: {name} = {p!r} must be a probability in [0, 1)")
        if self.delay_s < 0 or self.disconnect_s < 0:
            raise CellError("fault plan: delay_s and disconnect_s must be >= 0 s")
