"""Procedural machined-surface texture and a cached background noise bank.

Both are generated once per process from fixed seeds; each render then picks a random
placement, so images differ between seeds while rendering stays fast. The texture tile
covers 205 mm × 205 mm at 50 µm per texel (about one pixel of the standard head at
250 mm), large enough for any view, so lookups never wrap (OpenCV's wrapping remap is
several times slower).
"""

from __future__ import annotations

import inspect
from functools import lru_cache

import cv2
import numpy as np

from measure.synth.disk_cache import cached_array

#: texel size of the surface texture (metres) and the tile side (texels)
TEXEL_M = 50e-6
TILE_TEXELS = 4096
#: plane coordinate (metres) of the tile centre offset applied by renderers
TILE_CENTER_M = 0.5 * TILE_TEXELS * TEXEL_M


@lru_cache(maxsize=1)
def texture_tile() -> np.ndarray:
    """A 4096² float32 albedo tile, mean 0, std 1: milling marks, mottling and grain (drawn
    once per machine, :mod:`measure.synth.disk_cache`; read-only)."""
    return cached_array("texture", inspect.getsource(_draw_texture),
                        (TILE_TEXELS, TILE_TEXELS), _draw_texture)  # fmt: skip


def _draw_texture() -> np.ndarray:
    rng = np.random.default_rng(20260101)
    n = TILE_TEXELS
    coarse = rng.standard_normal((n // 16, n // 16)).astype(np.float32)
    mottle = cv2.resize(coarse, (n, n), interpolation=cv2.INTER_CUBIC)
    grain = rng.integers(0, 256, (n, n), dtype=np.uint8).astype(np.float32)
    grain = cv2.GaussianBlur(grain, (0, 0), 0.8)
    marks = np.sin(2.0 * np.pi * np.arange(n, dtype=np.float32) / 4.0)[None, :]  # 0.2 mm pitch
    tile = mottle * np.float32(1.0 / mottle.std())
    tile += grain * np.float32(0.5 / grain.std())
    tile += np.float32(0.7) * marks
    tile -= tile.mean()
    tile *= np.float32(1.0 / tile.std())
    return tile


def sample_texture(tx: np.ndarray, ty: np.ndarray) -> np.ndarray:
    """Texture values (mean 0, std 1) at texel coordinates (float arrays, clamped)."""
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
        borderMode=cv2.BORDER_REFLECT,
    )
    out = out.ravel()[: tx.size]
    return out.reshape(shape)


#: the noise bank's shape: the standard head's frame and 512 pixels of placements each way
BANK_SHAPE = (2048 + 512, 2448 + 512)


@lru_cache(maxsize=1)
def _noise_bank() -> np.ndarray:
    return cached_array("noise-bank", inspect.getsource(_draw_bank), BANK_SHAPE, _draw_bank)


def _draw_bank() -> np.ndarray:
    return np.random.default_rng(7).standard_normal(BANK_SHAPE, dtype=np.float32)


def background_noise_at(
    shape: tuple[int, int], rng: np.random.Generator
) -> tuple[np.ndarray, int, int, bool]:
    """Where :func:`background_noise` takes its view: ``(bank, y0, x0, flipped)``, the view being
    ``bank[y0 : y0 + h, x0 : x0 + w]``, its rows reversed when ``flipped`` (the same draws
    from ``rng``)."""
    h, w = shape
    bank = _noise_bank()
    if h + 1 > bank.shape[0] or w + 1 > bank.shape[1]:
        return rng.standard_normal(shape, dtype=np.float32), 0, 0, False
    y0 = int(rng.integers(0, bank.shape[0] - h + 1))
    x0 = int(rng.integers(0, bank.shape[1] - w + 1))
    return bank, y0, x0, bool(rng.random() < 0.5)


def background_noise(shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    """Unit Gaussian noise of ``shape`` for the background (a random view of a cached bank).

    The region a measurement uses is given fresh noise by the renderer; this bank only
    makes the full frame noisy without the cost of drawing 5 million normals per image.
    """
    h, w = shape
    bank, y0, x0, flipped = background_noise_at(shape, rng)
    view = bank[y0 : y0 + h, x0 : x0 + w]
    return view[::-1] if flipped else view
