"""Fault injection settings of the simulated controller."""

from __future__ import annotations

import time
from dataclasses import dataclass

from cell.errors import CellError
from cell.link.frame import FrameDecoder


@dataclass(frozen=True)
class FaultPlan:
    """What the simulator does wrong, seeded.

    Attributes:
        drop: probability that a frame (either direction) is lost.
        corrupt: probability that a frame (either direction) gets a flipped bit.
        delay: probability that an answer is delayed by ``delay_s`` (wall s).
        disconnect_after: the link goes dead after this many requests (None: never) ...
        disconnect_s: ... for this long (wall s); a socket is closed, a pty goes silent ...
        disconnect_frames: ... and a silent pty stays silent until it has swallowed this many
            request frames (the client's ``retries + 1`` attempts: the client then gives up and
            reconnects whatever the machine's load; 0: the clock alone ends the outage).
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
    disconnect_frames: int = 0
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
        if self.disconnect_frames < 0:
            raise CellError("fault plan: disconnect_frames must be >= 0")


class Outage:
    """The dead line of a simulated disconnect: dead for ``disconnect_s`` and, for a silent pty,
    until ``disconnect_frames`` request frames were lost in it.

    Why frames and not only the clock: what arrives on a pty is read whenever the controller
    gets to it. On a loaded machine the client's retries, sent inside the window, were read
    after it had closed and answered, so the client never gave up and never reconnected. The
    frames the outage swallows are counted as they are read, so the client's attempts are lost
    however late they are read. A new socket connection ends the outage (the cable is back)."""

    def __init__(self, plan: FaultPlan) -> None:
        self.plan = plan
        self.until = 0.0
        self._frames_left = 0
        self._decoder = FrameDecoder()

    def start(self) -> None:
        """The line goes dead now."""
        self.until = time.monotonic() + self.plan.disconnect_s
        self._frames_left = self.plan.disconnect_frames
        self._decoder = FrameDecoder()

    def timed_out(self) -> bool:
        """Still inside the wall-clock window (a socket is refused meanwhile)."""
        return time.monotonic() < self.until

    def dead(self) -> bool:
        """Bytes in either direction are lost."""
        return self.timed_out() or self._frames_left > 0

    def swallow(self, data: bytes) -> bool:
        """True when ``data`` (received) is lost to the outage; counts its request frames."""
        if not self.dead():
            return False
        self._frames_left -= len(self._decoder.feed(data))
        return True

    def reconnected(self) -> None:
        """A new socket connection was accepted: the outage is over."""
        self._frames_left = 0
