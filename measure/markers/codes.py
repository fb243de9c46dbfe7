"""The code books of the two marker kinds.

Ring codes: ``bits``-bit words read around the dot, identified whatever the marker's rotation
(a code is the set of its cyclic rotations). The book is chosen greedily in increasing order
of the smallest rotation: a word joins when every rotation of it differs from every rotation
of every word already chosen in at least ``min_distance`` bits, and it has at least two ones
and two zeros (an all-black or all-white ring says nothing). With 20 bits and distance 3 that
gives 1221 codes; a read is accepted only when it matches a code exactly, so one or two
misread bits are refused, never mistaken for another marker.

AprilTag codes: OpenCV's ``DICT_APRILTAG_36h11`` (587 codes, minimum distance 11).
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np


def _rotations(word: int, bits: int) -> list[int]:
    mask = (1 << bits) - 1
    return [((word << k) | (word >> (bits - k))) & mask for k in range(bits)]


@lru_cache(maxsize=8)
def ring_codes(bits: int, min_distance: int) -> tuple[int, ...]:
    """The ring code book: code number ``i`` is the word ``ring_codes(...)[i]`` (bit ``k`` of
    the word is the ring sector ``k``, 1 = white)."""
    n = 1 << bits
    words = np.arange(n, dtype=np.int64)
    canonical = np.ones(n, dtype=bool)
    for k in range(1, bits):
        rot = ((words << k) | (words >> (bits - k))) & (n - 1)
        canonical &= words <= rot
    ones = np.zeros(n, dtype=np.int64)
    for k in range(bits):
        ones += (words >> k) & 1
    canonical &= (ones >= 2) & (ones <= bits - 2)
    # every word within distance < min_distance of a chosen word's rotation is taken
    flips = [0]
    for _ in range(min_distance - 1):
        flips = sorted({f | (1 << b) for f in flips for b in range(bits)} | set(flips))
    flip_arr = np.array(flips, dtype=np.int64)
    taken = np.zeros(n, dtype=bool)
    chosen: list[int] = []
    for w in np.flatnonzero(canonical):
        if taken[w]:
            continue
        chosen.append(int(w))
        for r in _rotations(int(w), bits):
            taken[r ^ flip_arr] = True
    return tuple(chosen)


@lru_cache(maxsize=8)
def ring_lookup(bits: int, min_distance: int) -> dict[int, int]:
    """Every rotation of every ring code → its code number."""
    table: dict[int, int] = {}
    for i, w in enumerate(ring_codes(bits, min_distance)):
        for r in _rotations(w, bits):
            table[r] = i
    return table


def ring_bits(code: int, bits: int, min_distance: int) -> np.ndarray:
    """The sectors of ring code ``code`` ((bits,) uint8, sector ``k`` = bit ``k``)."""
    w = ring_codes(bits, min_distance)[code]
    return np.array([(w >> k) & 1 for k in range(bits)], dtype=np.uint8)


@lru_cache(maxsize=1)
def apriltag_dictionary() -> cv2.aruco.Dictionary:
    """OpenCV's AprilTag 36h11 dictionary."""
    return cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)


def apriltag_cells(code: int) -> np.ndarray:
    """The 8 × 8 cells of tag ``code`` (1 = white) including its black border; row 0 is the
    tag's top row (as OpenCV draws it)."""
    img = cv2.aruco.generateImageMarker(apriltag_dictionary(), int(code), 8, borderBits=1)
    return (img > 127).astype(np.uint8)


def apriltag_count() -> int:
    """Number of codes of AprilTag 36h11."""
    return int(apriltag_dictionary().bytesList.shape[0])
