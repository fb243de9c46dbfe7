"""The chessboard's colour check blurs only a crop around the squares it reads: the means are
those of the whole image blurred, bit for bit, wherever the squares lie (partly or wholly off
the image too)."""

from __future__ import annotations

import cv2
import numpy as np

from cell.calibration.capture.orient import _cell_box, _cell_means


def test_crop_means_equal_whole_image_means() -> None:
    rng = np.random.default_rng(0)
    img = (rng.random((120, 160)) * 255).astype(np.uint8)
    full = cv2.GaussianBlur(img, (3, 3), 0).astype(float)
    checked = 0
    for _ in range(500):
        grid = np.stack([np.sort(rng.uniform(-15, 175, (2, 3)), axis=1),
                         np.sort(rng.uniform(-15, 135, (2, 3)), axis=0)], axis=-1)  # fmt: skip
        cells = [(0, 0), (0, 1)]
        for (i, j), got in zip(cells, _cell_means(img, grid, cells), strict=True):
            y0, y1, x0, x1 = _cell_box(grid, i, j, img.shape)
            if y1 > y0 and x1 > x0:
                assert got == float(full[y0:y1, x0:x1].mean())
                checked += 1
            else:
                assert np.isnan(got)
    assert checked > 300
