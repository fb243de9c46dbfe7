"""The camera's output stage, compiled by Numba: read noise added and the image quantised, in
one pass over the pixels (instead of NumPy's three or four full-frame passes), with the same
float32 arithmetic as before, so the same images bit for bit.

- :func:`quantize_u8`: ``uint8(clip(rint(max(image + noise, 0)), 0, 255))`` over a region,
  as ``img += noise; np.maximum(img, 0, out=img); cv2.convertScaleAbs(img)`` gave it;
- :func:`finish_region`: :func:`measure.synth.render._finish`'s read noise (a bank's noise
  over the frame, fresh noise in the measured window) and quantisation to 8 or 12 bits.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _u8(v: np.float32) -> np.uint8:
    """``cv2.convertScaleAbs`` of a value ``>= 0``: rounded half to even, saturated at 255."""
    return np.uint8(min(np.rint(v), np.float32(255.0)))


@njit(cache=True)
def quantize_u8(src, noise, x0, y0, out) -> None:
    """``out[y0 + i, x0 + j] = u8(max(src[i, j] + noise[y0 + i, x0 + j], 0))`` (float32 sum;
    ``noise`` of shape (0, 0): none) for every pixel of ``src`` ((h, w) float32)."""
    h, w = src.shape
    zero = np.float32(0.0)
    if noise.shape[0] > 0:
        for i in range(h):
            s, n, o = src[i], noise[y0 + i, x0 : x0 + w], out[y0 + i, x0 : x0 + w]
            for j in range(w):
                o[j] = _u8(max(s[j] + n[j], zero))
    else:
        for i in range(h):
            s, o = src[i], out[y0 + i, x0 : x0 + w]
            for j in range(w):
                o[j] = _u8(max(s[j], zero))


@njit(cache=True, inline="always")
def _level(v, full: int):
    """A value (float32, DN) clipped at 0 and quantised: ``uint8`` as OpenCV's
    ``convertScaleAbs`` (``full`` = 255), else ``uint16`` truncating ``v + 0.5`` below ``full``."""
    v = max(v, np.float32(0.0))
    if full == 255:
        return np.uint16(_u8(v))
    return np.uint16(min(v, np.float32(full)) + np.float32(0.5))


@njit(cache=True)
def finish_region(src, scale, read, bank, by0, bx0, flipped, fresh, wx0, wy0, full, out) -> None:
    """The camera output of ``src`` ((H, W) float32, fraction of full scale) into ``out``
    ((H, W) uint8 or uint16): ``dn = src * scale`` (``scale``: the full-scale level, float32),
    plus ``read * b`` (``b``: the frame's unit noise, ``bank[by0 : by0 + H, bx0 : bx0 + W]``,
    its rows reversed when ``flipped``), plus, inside the window whose origin is ``(wx0, wy0)``
    and whose shape is ``fresh``'s, ``read * (fresh - b)``; clipped at 0, rounded half to even
    and saturated at ``full`` (255 or 4095). ``read`` = 0: no noise (``bank`` unused)."""
    h, w = src.shape
    fh, fw = fresh.shape
    noisy = read != 0.0
    for yy in range(h):
        s, o = src[yy], out[yy]
        if noisy:
            b = bank[by0 + (h - 1 - yy if flipped else yy), bx0 : bx0 + w]
            for j in range(w):
                o[j] = _level(s[j] * scale + read * b[j], full)
            if wy0 <= yy < wy0 + fh:  # the window: its own noise
                f = fresh[yy - wy0]
                for j in range(max(wx0, 0), min(wx0 + fw, w)):
                    v = s[j] * scale + read * b[j]
                    o[j] = _level(v + read * (f[j - wx0] - b[j]), full)
        else:
            for j in range(w):
                o[j] = _level(s[j] * scale, full)
