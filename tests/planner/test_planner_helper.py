"""The helper process (planner.helper): the same viewpoints and motion checks with it as
without it, whichever process computed what."""

from __future__ import annotations

import numpy as np
import pytest

from cell.config import load_cell
from planner.edge_check import HELPER_MIN_MOTIONS, BatchEdgeChecker
from planner.helper import MIN_HOLES, Helper
from planner.paths import MotionChecker
from planner.viewpoints import CHUNK, ViewSettings, all_hole_candidates

pytestmark = pytest.mark.skipif(
    not Helper.can_pay(MIN_HOLES), reason="no second core or no fork on this machine"
)


@pytest.fixture(scope="module")
def cell():
    return load_cell(None)


def test_viewpoints_with_a_helper_equal_those_without(cell) -> None:
    arm = cell.build_arm()
    holes = cell.holes_in_cell()
    assert len(holes) > 3 * CHUNK  # several chunks: both processes take some
    s = ViewSettings(cell.tool.standoff_m, 30.0, 0.0, 6, 10.0)
    want = all_hole_candidates(arm, holes, s)
    seen: list[int] = []
    with Helper.start(MIN_HOLES, arm=arm) as helper:
        got = all_hole_candidates(arm, holes, s, helper, seen.append)
    assert seen[-1] == len(holes) and sorted(seen) == seen
    assert len(got) == len(want)
    for (c1, t1), (c2, t2) in zip(got, want, strict=True):
        assert c1.hole_id == c2.hole_id and t1 == t2 and c1.reason == c2.reason
        for name in ("q", "branch", "pose", "poses"):
            assert np.array_equal(getattr(c1, name), getattr(c2, name))


def test_motion_checks_split_with_a_helper_equal_one_process(cell) -> None:
    arm = cell.build_arm()
    checker = MotionChecker(arm, np.radians(3.0), 0.012)
    rng = np.random.default_rng(5)
    m = 2 * HELPER_MIN_MOTIONS + 40
    A = rng.uniform(arm.lower, arm.upper, (m, 6)) * 0.4
    B = np.clip(A + rng.normal(scale=0.3, size=A.shape), arm.lower, arm.upper)
    B[:5] = arm.upper + 0.1  # outside the limits: not free
    alone = BatchEdgeChecker(checker)
    want = alone.free(A, B)
    split = BatchEdgeChecker(checker)
    with Helper.start(MIN_HOLES, arm=arm) as helper:
        got = split.free(A, B, helper)
    assert got.tolist() == want.tolist()
    assert split.checks == alone.checks
    assert 0 < got.sum() < len(got) - 5  # both answers occur


def test_motion_checks_of_a_helper_that_died_are_made_here(cell) -> None:
    import os
    import signal

    arm = cell.build_arm()
    checker = MotionChecker(arm, np.radians(3.0), 0.012)
    rng = np.random.default_rng(8)
    A = rng.uniform(arm.lower, arm.upper, (2 * HELPER_MIN_MOTIONS + 10, 6)) * 0.4
    B = np.clip(A + rng.normal(scale=0.3, size=A.shape), arm.lower, arm.upper)
    alone = BatchEdgeChecker(checker)
    want = alone.free(A, B)
    helper = Helper.start(MIN_HOLES, arm=arm)
    for pid in list(helper.pool._processes):
        os.kill(pid, signal.SIGKILL)
    split = BatchEdgeChecker(checker)
    got = split.free(A, B, helper)
    assert helper.close() == 0.0
    assert got.tolist() == want.tolist() and split.checks == alone.checks
    assert 0 < got.sum() < len(got)


def test_representatives_chosen_with_a_helper_equal_those_without(cell) -> None:
    from planner.representatives import every_representatives
    from planner.timing import JointLimits

    arm = cell.build_arm()
    limits = JointLimits.from_arm(arm)
    home = np.asarray(cell.home_q(), float)
    rng = np.random.default_rng(6)
    cands = [rng.uniform(arm.lower, arm.upper, (m, 6)) for m in (3, 40, 8, 60, 5, 9, 30, 2, 50)]
    want = every_representatives(cands, 8, home, limits)
    with Helper.start(MIN_HOLES, arm=arm) as helper:
        got = every_representatives(cands, 8, home, limits, helper)
    assert [g.tolist() for g in got] == [w.tolist() for w in want]
    assert any(len(w) == 8 for w in want) and any(len(w) < 8 for w in want)


def test_a_helper_that_died_leaves_its_share_to_this_process(cell) -> None:
    import os
    import signal

    arm = cell.build_arm()
    holes = cell.holes_in_cell()[: 2 * CHUNK + 1]
    s = ViewSettings(cell.tool.standoff_m, 60.0, 0.0, 6, 10.0)
    want = all_hole_candidates(arm, holes, s)
    helper = Helper.start(MIN_HOLES, arm=arm)
    for pid in list(helper.pool._processes):
        os.kill(pid, signal.SIGKILL)
    got = all_hole_candidates(arm, holes, s, helper)
    assert helper.close() == 0.0
    assert [np.array_equal(a.q, b.q) for (a, _), (b, _) in zip(got, want, strict=True)] == [
        True
    ] * len(holes)


def _cost_table_and_nodes(cell, n: int):
    from planner.costs import CostTable
    from planner.timing import JointLimits

    arm = cell.build_arm()
    lim = JointLimits.from_arm(arm)
    table = CostTable(lim.velocity, lim.acceleration, lim.jerk, lim.upper - lim.lower)
    q = np.random.default_rng(7).uniform(arm.lower, arm.upper, (n, 6))
    return arm, table, q


def test_cost_matrix_built_with_a_helper_equals_one_process(cell) -> None:
    from planner.shared_costs import SHARED_MIN_NODES, split_row, symmetric_costs

    n = SHARED_MIN_NODES + 77  # a last block shorter than the others
    arm, table, q = _cost_table_and_nodes(cell, n)
    want = table.matrix64(q)
    assert 0 < split_row(n) < n
    with Helper.start(MIN_HOLES, arm=arm) as helper:
        got, held = symmetric_costs(table, q, helper)
    assert held and got.dtype == np.float64 and np.array_equal(got, want)
    got[3, 5] = 9.0  # a writable array, as the sequencer learns costs into it
    assert got[3, 5] == 9.0
    import pickle

    copy = pickle.loads(pickle.dumps(got))  # a start's own copy (planner.shared.unpack)
    copy[3, 5] = 1.0
    assert np.array_equal(copy[:3], got[:3]) and got[3, 5] == 9.0


def test_a_dead_helper_leaves_the_whole_cost_matrix_to_this_process(cell) -> None:
    import os
    import signal

    from planner.shared_costs import SHARED_MIN_NODES, symmetric_costs

    arm, table, q = _cost_table_and_nodes(cell, SHARED_MIN_NODES)
    helper = Helper.start(MIN_HOLES, arm=arm)
    for pid in list(helper.pool._processes):
        os.kill(pid, signal.SIGKILL)
    got, held = symmetric_costs(table, q, helper)
    helper.close()
    assert not held
    assert np.array_equal(got, table.matrix64(q))


def test_split_row_halves_the_upper_triangle() -> None:
    from planner.costs import SYMMETRIC_BLOCK
    from planner.shared_costs import split_row

    for n in (1024, 2049, 4001):
        r0 = split_row(n)
        assert r0 % SYMMETRIC_BLOCK == 0
        first = sum((n - i) for i in range(r0))  # upper-triangle entries of rows < r0
        assert abs(first / (n * (n + 1) / 2) - 0.5) < 0.1


def test_neighbour_lists_made_half_in_the_helper_equal_one_process(cell) -> None:
    from planner.roadmap import neighbour_pairs
    from planner.shared_costs import SHARED_MIN_NODES, symmetric_costs

    n = SHARED_MIN_NODES + 300
    arm, table, q = _cost_table_and_nodes(cell, n)
    owner = np.concatenate([[-1], np.arange(n - 1) // 7])  # home, then holes of 7 nodes
    with Helper.start(MIN_HOLES, arm=arm) as helper:
        G, held = symmetric_costs(table, q, helper)
        assert held
        far = n - 3  # a later write here (a learned cost) is seen by the helper too
        G[far, 2] = G[2, far] = 0.0
        got = neighbour_pairs(G, owner, 5, helper)
    want = neighbour_pairs(G, owner, 5)
    assert np.array_equal(got, want)
    assert [2, far] in want.tolist()


def test_detours_with_dijkstra_shared_with_the_helper_equal_one_process(cell) -> None:
    """Every other source's Dijkstra in the helper: the same costs and detour paths as one
    process (ties of equal weights included), and a dead helper leaves its share here."""
    import os
    import signal

    from planner.roadmap import HELPER_MIN_SOURCES, Roadmap, detour_costs

    rng = np.random.default_rng(8)
    n = 3 * HELPER_MIN_SOURCES
    X = rng.random((n, 2))
    G = np.round(np.sqrt(((X[:, None] - X[None]) ** 2).sum(-1)) * 20) / 20  # ties
    pairs = {(int(a), int(b)) for a, b in rng.integers(0, n, (8 * n, 2)) if a < b}
    free = {p: bool(rng.random() < 0.7) and min(p) > 2 for p in sorted(pairs)}  # 0-2: cut off
    blocked = [q for (a, b), f in free.items() if not f for q in ((a, b), (b, a))]
    assert len({a for a, _ in blocked}) >= HELPER_MIN_SOURCES
    alone = Roadmap(free=dict(free))
    want = detour_costs(alone, G, blocked)
    for kill in (False, True):
        rm = Roadmap(free=dict(free))
        helper = Helper.start(MIN_HOLES)
        assert helper is not None
        if kill:
            for pid in list(helper.pool._processes):
                os.kill(pid, signal.SIGKILL)
        got = detour_costs(rm, G, blocked, helper)
        helper.close()
        assert got == want and rm.detours == alone.detours
    assert any(np.isfinite(c) and c > G[a, b] for (a, b), c in want.items())  # real detours
    assert len(alone.detours) < len(blocked)  # and motions without one (the estimate)
