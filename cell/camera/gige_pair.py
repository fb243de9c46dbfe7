"""Do two frames belong to the same trigger? The checks of one GigE Vision stereo pair.

A frame carries the camera's frame (block) id, the camera's timestamp and the host's receive
time. A pair is accepted when, for each camera, its buffer is complete, it was received after
the trigger was sent, and its frame id follows the last accepted one by exactly one (the
camera fired once for this trigger, and no frame of another trigger is in between); and when
the two cameras agree in time: their timestamps within ``bound_ns`` of each other when they
share a clock (IEEE 1588), and always their intervals since the last accepted pair within
``bound_ns`` of each other (clocks that run free count at the same rate). After a failed
attempt a camera may have fired without its frame arriving, so the retry accepts any newer
frame id and the checks start afresh from the accepted pair.
"""

from __future__ import annotations

from dataclasses import dataclass

#: GigE Vision 1.x block ids count 1..65535 (0 is never used)
BLOCK_ID_MODULUS = 65536


@dataclass(frozen=True)
class FrameInfo:
    """One received frame: ``status`` is Aravis's buffer status name (``SUCCESS``, ``TIMEOUT``,
    ``MISSING_PACKETS``, ...); times in ns (camera clock; host realtime clock)."""

    frame_id: int
    timestamp_ns: int
    system_timestamp_ns: int
    status: str = "SUCCESS"


def next_block_id(frame_id: int) -> int:
    """The block id after ``frame_id`` (16-bit, 0 skipped; a 64-bit id just counts on)."""
    if frame_id == BLOCK_ID_MODULUS - 1:
        return 1
    return frame_id + 1


def _newer(frame_id: int, last: int) -> bool:
    """``frame_id`` came after ``last`` (16-bit ids wrap: newer within half the range)."""
    if last < BLOCK_ID_MODULUS and frame_id < BLOCK_ID_MODULUS:
        return 0 < (frame_id - last) % (BLOCK_ID_MODULUS - 1) < BLOCK_ID_MODULUS // 2
    return frame_id > last


class PairChecker:
    """Accepts or refuses stereo pairs (see module doc); ``shared_clock``: the two cameras'
    timestamps are on one clock (IEEE 1588) and are compared directly."""

    def __init__(self, bound_ns: int, shared_clock: bool = False) -> None:
        self.bound_ns = bound_ns
        self.shared_clock = shared_clock
        self.last: tuple[FrameInfo, FrameInfo] | None = None
        self.resync = True  # the next pair starts the frame id sequence afresh

    def refuse(self, left: FrameInfo, right: FrameInfo, trigger_ns: int) -> str | None:
        """Why the pair (``left``, ``right``) of the trigger sent at ``trigger_ns`` (host
        realtime) is not one trigger's pair, or None: accepted (and remembered)."""
        for side, f in (("left", left), ("right", right)):
            if f.status != "SUCCESS":
                return f"{side} frame {f.frame_id} incomplete ({f.status})"
            if f.system_timestamp_ns < trigger_ns:
                return (f"{side} frame {f.frame_id} arrived "
                        f"{(trigger_ns - f.system_timestamp_ns) / 1e6:.1f} ms before the "
                        "trigger: a stale frame")  # fmt: skip
        why = self._ids(left, right) or self._times(left, right)
        if why is None:
            self.last, self.resync = (left, right), False
        return why

    def _ids(self, left: FrameInfo, right: FrameInfo) -> str | None:
        if self.last is None:
            return None
        for side, f, prev in (("left", left, self.last[0]), ("right", right, self.last[1])):
            if self.resync:
                if not _newer(f.frame_id, prev.frame_id):
                    return (f"{side} frame id {f.frame_id} is not newer than the last "
                            f"accepted {prev.frame_id}: a frame of an earlier trigger")  # fmt: skip
            elif f.frame_id != next_block_id(prev.frame_id):
                return (f"{side} frame id {f.frame_id} where {next_block_id(prev.frame_id)} "
                        f"was due (left {left.frame_id}, right {right.frame_id}): the "
                        f"{side} camera missed or added a trigger")  # fmt: skip
        return None

    def _times(self, left: FrameInfo, right: FrameInfo) -> str | None:
        gap = abs(left.timestamp_ns - right.timestamp_ns)
        if self.shared_clock and gap > self.bound_ns:
            return (f"camera timestamps {gap / 1e6:.1f} ms apart (bound "
                    f"{self.bound_ns / 1e6:g} ms): frames of different triggers")  # fmt: skip
        if self.last is not None:
            dl = left.timestamp_ns - self.last[0].timestamp_ns
            dr = right.timestamp_ns - self.last[1].timestamp_ns
            if abs(dl - dr) > self.bound_ns:
                return (f"the cameras' intervals since the last pair differ by "
                        f"{abs(dl - dr) / 1e6:.1f} ms (left {dl / 1e6:.1f} ms, right "
                        f"{dr / 1e6:.1f} ms, bound {self.bound_ns / 1e6:g} ms): frames "
                        "of different triggers")  # fmt: skip
        return None

    def failed(self) -> None:
        """An attempt failed: the next pair may follow any number of lost frames."""
        self.resync = True
