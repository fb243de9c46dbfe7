"""Reading a ring marker's code around its dot.

The dot's ellipse is the image of the marker's circle of radius ½ under (nearly) an affine map,
so the same map scaled to the ring's radii gives the ring's image: the ring is sampled at
``SECTOR_SAMPLES`` points per sector on three radii across it, uniformly in the marker's
angle. The sector boundaries' phase is the one that puts the sector means farthest from the
threshold (halfway between the dot's white and the label's black); a sector reads 1 when its
mean over its middle half is above it. The word is looked up among every rotation of every code
(:func:`measure.markers.codes.ring_lookup`): a read that is not exactly a code is refused.
"""

from __future__ import annotations

import numpy as np

from measure.markers.codes import ring_lookup
from measure.markers.design import MarkerDesign
from measure.markers.edges import bilinear
from measure.markers.ellipse import EllipseFit

SECTOR_SAMPLES = 12
#: a sector's mean must lie this far (fraction of white - black) from the threshold
MIN_SECTOR_MARGIN = 0.2


def ring_samples(img: np.ndarray, dot: EllipseFit, radii: np.ndarray, n: int) -> np.ndarray:
    """Mean over ``radii`` (in dot radii) of the image at ``n`` marker angles ``2πj/n``
    (counter-clockwise seen from the front, from an arbitrary origin)."""
    t = -2.0 * np.pi * np.arange(n) / n  # the image of the front face is mirrored
    radii = np.asarray(radii, dtype=float)
    c, s = np.cos(dot.angle), np.sin(dot.angle)
    x = (radii * dot.a)[:, None] * np.cos(t)  # every radius at once, as EllipseFit.point
    y = (radii * dot.b)[:, None] * np.sin(t)
    samples = bilinear(img, dot.center[0] + (c * x - s * y), dot.center[1] + (s * x + c * y))
    vals = np.zeros(n)
    for row in samples:  # summed radius by radius
        vals += row
    return vals / len(radii)


def read_ring(
    img: np.ndarray, dot: EllipseFit, white: float, black: float, design: MarkerDesign
) -> tuple[int | None, float]:
    """The ring code (or None) and the read's margin (the smallest sector's distance from the
    threshold, fraction of the contrast)."""
    contrast = white - black
    level = 0.5 * (white + black)
    n_bits = design.bits
    S = SECTOR_SAMPLES
    r_in, r_out = 2.0 * design.ring_inner, 2.0 * design.ring_outer
    width = r_out - r_in
    radii = r_in + width * np.array([0.25, 0.5, 0.75])
    vals = ring_samples(img, dot, radii, n_bits * S)
    # the label's black border outside the ring must be dark all round
    border = ring_samples(
        img, dot, np.array([r_out + 0.5 * (2.0 * design.label_radius - r_out)]), 90
    )
    if np.quantile(border, 0.9) > black + 0.3 * contrast:
        return None, 0.0
    mid = np.arange(S // 4, S - S // 4)
    best_score, best_means = -1.0, None
    for phase in range(S):
        idx = (phase + np.arange(n_bits)[:, None] * S + mid[None, :]) % (n_bits * S)
        means = vals[idx].mean(axis=1)
        score = float(np.abs(means - level).sum())
        if score > best_score:
            best_score, best_means = score, means
    assert best_means is not None
    margin = float(np.min(np.abs(best_means - level))) / contrast
    if margin < MIN_SECTOR_MARGIN:
        return None, margin
    word = int(sum(1 << k for k in range(n_bits) if best_means[k] > level))
    code = ring_lookup(design.bits, design.min_distance).get(word)
    return code, margin
