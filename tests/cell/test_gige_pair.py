"""The pair checks of the GigE Vision head on made-up frame infos (no camera needed)."""

from __future__ import annotations

from cell.camera.gige_pair import FrameInfo, PairChecker, next_block_id

MS = 1_000_000


def _f(frame_id: int, t_ms: float, rx_ms: float | None = None, status: str = "SUCCESS"):
    return FrameInfo(frame_id, int(t_ms * MS), int((rx_ms if rx_ms else t_ms + 5) * MS), status)


def test_block_ids_wrap_past_zero() -> None:
    assert next_block_id(65535) == 1 and next_block_id(7) == 8 and next_block_id(70000) == 70001


def test_consecutive_pairs_are_accepted_across_the_wrap() -> None:
    c = PairChecker(250 * MS)
    assert c.refuse(_f(65534, 1000), _f(12, 1003), 990 * MS) is None
    assert c.refuse(_f(65535, 2000), _f(13, 2002), 1990 * MS) is None
    assert c.refuse(_f(1, 3000), _f(14, 3001), 2990 * MS) is None


def test_a_camera_that_missed_a_trigger_is_refused_then_resynced() -> None:
    c = PairChecker(250 * MS)
    assert c.refuse(_f(10, 1000), _f(20, 1000), 990 * MS) is None
    why = c.refuse(_f(11, 2000), _f(22, 2000), 1990 * MS)
    assert why is not None and "right frame id 22 where 21 was due" in why
    c.failed()
    assert c.refuse(_f(12, 3000), _f(23, 3000), 2990 * MS) is None


def test_a_frame_received_before_the_trigger_is_stale() -> None:
    c = PairChecker(250 * MS)
    why = c.refuse(_f(10, 1000, rx_ms=1000), _f(20, 1000, rx_ms=1200), 1100 * MS)
    assert why is not None and "left frame 10 arrived 100.0 ms before the trigger" in why


def test_incomplete_frames_and_timestamps_apart_are_refused() -> None:
    c = PairChecker(1 * MS, shared_clock=True)
    why = c.refuse(_f(10, 1000), _f(20, 1000, status="MISSING_PACKETS"), 990 * MS)
    assert why == "right frame 20 incomplete (MISSING_PACKETS)"
    why = c.refuse(_f(10, 1000), _f(20, 1005), 990 * MS)
    assert why is not None and "5.0 ms apart" in why
    free = PairChecker(1 * MS)  # clocks running free: their intervals are compared
    assert free.refuse(_f(10, 1000), _f(20, 70000), 990 * MS) is None
    why = free.refuse(_f(11, 2000), _f(21, 70500), 1990 * MS)
    assert why is not None and "differ by 500.0 ms" in why


def test_after_a_failure_an_older_frame_is_refused() -> None:
    c = PairChecker(250 * MS)
    assert c.refuse(_f(10, 1000), _f(20, 1000), 990 * MS) is None
    c.failed()
    why = c.refuse(_f(11, 2000), _f(20, 2000), 1990 * MS)
    assert why is not None and "not newer than the last accepted 20" in why
