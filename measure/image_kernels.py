"""Compiled loop of the image checks and the search (:mod:`measure.image_input`): a histogram.

``cv2.calcHist`` of an 8-bit image costs about 0.6 ns a pixel; four interleaved
histograms in one compiled pass (no store waits on the same bin twice in a row) take
about two thirds of that, and the search image's two histograms (exposure check,
threshold ladder) are a tenth of the search's time. Compiled on first use and cached
beside this file (``cache=True``); a test checks it against ``cv2.calcHist``.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def histogram_u8(img):
    """Counts of the 256 gray levels of a C-contiguous ``uint8`` array (int64)."""
    f = img.ravel()
    h = np.zeros((4, 256), np.int64)
    n = f.shape[0]
    n4 = n - n % 4
    for i in range(0, n4, 4):
        h[0, f[i]] += 1
        h[1, f[i + 1]] += 1
        h[2, f[i + 2]] += 1
        h[3, f[i + 3]] += 1
    for i in range(n4, n):
        h[0, f[i]] += 1
    return h[0] + h[1] + h[2] + h[3]
