"""The compiled GTSP kernels: bit for bit the numpy code they replace above 60 holes; the
neighbour moves of large tours; the Dijkstra rows reused by the roadmap's detour costs."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from planner.lns import NEAR_ABOVE, GtspLns, LnsSettings, layered_nodes, near_holes
from planner.lns_kernel import improve_path, insert, layered
from planner.lns_near import improve_path_near, insert_near
from planner.local_search import improve_order
from planner.roadmap import Roadmap, detour_costs

MOVES = 10_000  # improve_order's default bound


def _instance(holes: int, seed: int, ties: bool = False):
    """Random symmetric costs (s) of home + 1-7 nodes per hole; ``ties``: rounded to 0.05 s."""
    rng = np.random.default_rng(seed)
    k = rng.integers(1, 8, size=holes)
    X = rng.random((1 + int(k.sum()), 3))
    G = np.sqrt(((X[:, None] - X[None]) ** 2).sum(-1))
    if ties:
        G = np.round(G * 20) / 20
    off = np.cumsum([1, *k])
    groups = [np.arange(off[h], off[h] + k[h]) for h in range(holes)]
    gnodes = np.concatenate(groups).astype(np.int64)
    goff = np.cumsum([0, *k]).astype(np.int64)
    return G, groups, gnodes, goff, rng


@pytest.mark.parametrize("seed", range(6))
def test_kernels_equal_the_numpy_reference_bit_for_bit(seed: int) -> None:
    G, groups, gnodes, goff, rng = _instance(int(8 + 7 * seed), seed, ties=seed % 2 == 0)
    order = rng.permutation(len(groups))
    nodes, cost = layered(G, order.astype(np.int64), gnodes, goff)
    ref_nodes, ref_cost = layered_nodes(G, [groups[h] for h in order])
    assert nodes.tolist() == ref_nodes and cost == ref_cost
    path = np.array([0, *nodes, 0], dtype=np.int64)
    perm = improve_path(G, path, MOVES)
    assert perm.tolist() == improve_order(G[np.ix_(path, path)])
    keep, removed = order[: len(order) // 2], order[len(order) // 2 :]
    o, v = insert(
        G, keep.astype(np.int64), nodes[: len(keep)], removed.astype(np.int64), gnodes, goff
    )
    numpy = GtspLns(G, groups, 0, compiled=False)
    ref = numpy._insert(keep.tolist(), nodes[: len(keep)].tolist(), removed.tolist())
    assert (o.tolist(), v.tolist()) == ref


@pytest.mark.parametrize("seed", range(4))
def test_layered_equals_the_reference_for_groups_of_consecutive_and_scattered_nodes(
    seed: int,
) -> None:
    """Holes whose nodes are consecutive ids (read as one slice of a row) and holes with
    nodes added later (scattered ids, as :meth:`GtspSequencer.add_nodes` makes): the same
    nodes and cost as the numpy reference, ties included."""
    G, groups, _gnodes, _goff, rng = _instance(30, seed, ties=seed % 2 == 0)
    extra = rng.choice(len(groups), size=8, replace=False)
    N = G.shape[0]
    X = rng.random((N + len(extra), 3))
    D = np.sqrt(((X[:, None] - X[None]) ** 2).sum(-1))
    G = np.round(D * 20) / 20 if seed % 2 == 0 else D  # rounded: ties
    groups = [g.copy() for g in groups]
    for i, h in enumerate(extra):
        groups[h] = np.append(groups[h], N + i)  # a later node: not next to the others
    gnodes = np.concatenate(groups).astype(np.int64)
    goff = np.cumsum([0, *[len(g) for g in groups]]).astype(np.int64)
    for _ in range(5):
        order = rng.permutation(len(groups))
        nodes, cost = layered(G, order.astype(np.int64), gnodes, goff)
        ref_nodes, ref_cost = layered_nodes(G, [groups[h] for h in order])
        assert nodes.tolist() == ref_nodes and cost == ref_cost


@pytest.mark.parametrize("seed", range(3))
def test_the_compiled_search_finds_the_numpy_search_s_tour(seed: int) -> None:
    G, groups, *_ = _instance(40, seed, ties=seed == 0)
    settings = LnsSettings(max_iterations=120, patience=50, time_limit_s=600)
    a = GtspLns(G, groups, seed, compiled=True).run(settings)
    b = GtspLns(G, groups, seed, compiled=False).run(settings)
    assert (a.nodes, a.cost_s, a.iterations) == (b.nodes, b.cost_s, b.iterations)


def test_near_holes_are_the_nearest_by_the_least_node_to_node_cost() -> None:
    G, groups, *_ = _instance(30, 7)
    near = near_holes(G, groups, 5)
    for h, row in enumerate(near):
        d = np.array(
            [G[np.ix_(groups[h], g)].min() if x != h else np.inf for x, g in enumerate(groups)]
        )
        assert set(row.tolist()) == set(np.argsort(d, kind="stable")[:5].tolist())
        assert h not in row.tolist()


def test_neighbour_moves_keep_a_valid_tour_and_never_make_it_longer() -> None:
    G, groups, gnodes, goff, rng = _instance(60, 3)
    near = near_holes(G, groups, 8)
    for _ in range(5):
        order = rng.permutation(len(groups)).astype(np.int64)
        nodes, _cost = layered(G, order, gnodes, goff)
        path = np.array([0, *nodes, 0], dtype=np.int64)
        perm = improve_path_near(G, path, order, near, MOVES)
        assert (
            perm[0] == 0
            and perm[-1] == len(path) - 1
            and sorted(perm.tolist()) == list(range(len(path)))
        )
        after = path[perm]
        assert G[after[:-1], after[1:]].sum() <= G[path[:-1], path[1:]].sum() + 1e-12
        keep, removed = order[:40], order[40:]
        o, v = insert_near(G, keep, nodes[:40], removed, gnodes, goff, near)
        assert sorted(o.tolist()) == list(range(len(groups)))
        assert all(v[i] in groups[o[i]] for i in range(len(o)))


def _clustered(holes: int, seed: int):
    """Costs (s) like a hole's configurations: each hole's nodes near its own centre."""
    rng = np.random.default_rng(seed)
    centres = rng.random((holes, 3))
    k = rng.integers(1, 8, size=holes)
    X = np.vstack(
        [
            [0.5, 0.5, 0.5],
            *[c + rng.normal(0, 0.03, (n, 3)) for c, n in zip(centres, k, strict=True)],
        ]
    )
    G = np.sqrt(((X[:, None] - X[None]) ** 2).sum(-1))
    off = np.cumsum([1, *k])
    return G, [np.arange(off[h], off[h] + k[h]) for h in range(holes)]


def test_the_search_on_a_large_tour_uses_neighbour_moves_and_stays_near_the_full_scan() -> None:
    G, groups = _clustered(NEAR_ABOVE + 30, 11)
    settings = LnsSettings(max_iterations=150, patience=60, time_limit_s=600)
    near = GtspLns(G, groups, 0).run(settings)
    assert GtspLns(G, groups, 0).near is not None
    full = GtspLns(G, groups, 0)
    full.near = None  # every move scanned
    scanned = full.run(settings)
    assert sorted(near.order) == list(range(len(groups)))
    assert near.cost_s <= 1.03 * scanned.cost_s


def test_detour_costs_reuse_dijkstra_rows_only_for_the_same_weights() -> None:
    # a line 1-2-3-4 of free motions: 1 -> 4 is blocked and detours through 2 and 3
    G = np.full((5, 5), 10.0)
    rm = Roadmap()
    for u, v in ((1, 2), (2, 3), (3, 4)):
        G[u, v] = G[v, u] = 1.0
        rm.free[(u, v)] = True
    G[1, 4] = G[4, 1] = 2.0
    first = detour_costs(rm, G, [(1, 4)])
    assert first[(1, 4)] == pytest.approx(3.0) and rm.via(1, 4) == [2, 3]
    assert 1 in rm._rows
    G[2, 3] = G[3, 2] = 5.0  # a free motion's cost changed: the cached rows are stale
    again = detour_costs(rm, G, [(1, 4)])
    assert again[(1, 4)] == pytest.approx(7.0)
    assert pickle.loads(pickle.dumps(rm))._rows == {}  # the cache is not shipped to the starts
