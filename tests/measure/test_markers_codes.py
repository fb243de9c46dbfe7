"""The marker code books and designs."""

from __future__ import annotations

import numpy as np
import pytest

from measure.markers import APRILTAG_DESIGN, DEFAULT_DESIGN, RING_DESIGN, MarkerDesign
from measure.markers.codes import apriltag_cells, ring_codes, ring_lookup


def _rotations(w, n):
    return [((w << k) | (w >> (n - k))) & ((1 << n) - 1) for k in range(n)]


def test_ring_code_book_is_large_and_codes_differ_in_three_bits_under_any_rotation():
    book = ring_codes(RING_DESIGN.bits, RING_DESIGN.min_distance)
    assert len(book) == RING_DESIGN.n_codes() >= 1000
    rots = np.array([_rotations(w, RING_DESIGN.bits) for w in book[:300]])  # (300, bits)
    first = np.array(book[:300])
    for i, w in enumerate(first):
        dist = np.array([bin(int(x)).count("1") for x in (rots[i + 1 :].ravel() ^ w)])
        assert dist.size == 0 or dist.min() >= 3
    table = ring_lookup(RING_DESIGN.bits, RING_DESIGN.min_distance)
    assert table[_rotations(book[17], RING_DESIGN.bits)[5]] == 17
    assert (1 << RING_DESIGN.bits) - 1 not in table and 0 not in table


def test_designs():
    assert DEFAULT_DESIGN.n_codes() >= 200
    assert APRILTAG_DESIGN.n_codes() == 587
    assert apriltag_cells(3).shape == (8, 8) and apriltag_cells(3)[0].sum() == 0
    assert RING_DESIGN.outer_radius(0.005) == pytest.approx(0.0075)
    assert APRILTAG_DESIGN.outer_radius(0.005) > RING_DESIGN.outer_radius(0.005)
    with pytest.raises(ValueError, match="kind"):
        MarkerDesign(kind="qr")
