"""Procedural machined-surface texture and a cached background noise bank.

Both are generated once per process from fixed seeds; each render then picks a random
placement, so images differ between seeds while rendering stays fast.
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np

#: texel size of the surface texture tile (metres) and its side (texels)
TEXEL_M = 25e-6
TILE_TEXELS = 1024


def _periodic_blur(a: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur with wrap-around borders (FFT), so the tile stays periodic."""
    f = np.fft.fftfreq(a.shape[0])
    g = np.exp(-2.0 * (np.pi * sigma) ** 2 * (f[:, None] ** 2 + f[None, :] ** 2))
    return np.real(np.fft.ifft2(np.fft.fft2(a) * g)).astype(np.float32)


@lru_cache(maxsize=1)
def texture_tile() -> np.ndarray:
    """A periodic 1024² float32 albedo tile, mean 1, std 1: milling marks plus mottling."""
    rng = np.random.default_rng(20260101)
    n = TILE_TEXELS
    mottle = _periodic_blur(rng.standard_normal((n, n)), 18.0)
    grain = _periodic_blur(rng.standard_normal((n, n)), 1.5)
    x = np.arange(n, dtype=np.float32)
    # milling marks: periodic in x with an exact number of periods per tile
    marks = np.sin(2.0 * np.pi * 64.0 * x / n)[None, :] * np.ones((n, 1), np.float32)
    tile = mottle / mottle.std() + 0.5 * grain / grain.std() + 0.7 * marks
    tile = (tile - tile.mean()) / tile.std()
    return tile.astype(np.float32)


def sample_texture(tx: np.ndarray, ty: np.ndarray) -> np.ndarray:
    """Texture values (mean 0, std 1) at texel coordinates (float32 arrays, wrapped)."""
    tile = texture_tile()
    shape = tx.shape
    if tx.ndim == 2 and max(shape) < 32767:
        mx, my = tx, ty
    else:  # remap wants 2-D maps under 32767 per side: fold long vectors into rows
        n = tx.size
        cols = 1024
        pad = (-n) % cols
        mx = np.pad(np.ravel(tx), (0, pad)).reshape(-1, cols)
        my = np.pad(np.ravel(ty), (0, pad)).reshape(-1, cols)
    out = cv2.remap(
        tile,
        np.ascontiguousarray(mx, dtype=np.float32),
        np.ascontiguousarray(my, dtype=np.float32),
        cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_WRAP,
    )
    out = out.ravel()[: tx.size]
    return out.reshape(shape)


@lru_cache(maxsize=1)
def _noise_bank() -> np.ndarray:
    rng = np.random.default_rng(7)
    return rng.standard_normal((2048 + 512, 2448 + 512), dtype=np.float32)


def background_noise(shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    """Unit Gaussian noise of ``shape`` for the background (a random view of a cached bank).

    The region a measurement uses is given fresh noise by the renderer; this bank only
    makes the full frame noisy without the cost of drawing 5 million normals per image.
    """
    h, w = shape
    bank = _noise_bank()
    if h + 1 > bank.shape[0] or w + 1 > bank.shape[1]:
        return rng.standard_normal(shape, dtype=np.float32)
    y0 = int(rng.integers(0, bank.shape[0] - h + 1))
    x0 = int(rng.integers(0, bank.shape[1] - w + 1))
    view = bank[y0 : y0 + h, x0 : x0 + w]
    return view[::-1] if rng.random() < 0.5 else view
