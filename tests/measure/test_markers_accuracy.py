"""Centre accuracy and identification over random survey views (slow: the benchmark's small
version; benchmarks/marker_detection.py prints the full table)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from markers_helpers import true_ideal_centre

from measure.markers import DEFAULT_DESIGN, circle_center_bias_px, detect_markers
from measure.synth import RenderOptions, standard_stereo
from measure.synth.marker_scenes import marker_grid_view
from measure.synth.markers import render_markers_pair


@pytest.mark.slow
def test_random_views_centres_and_codes():
    st = standard_stereo()
    errs, found, total = [], 0, 0
    for v in range(8):
        rng = np.random.default_rng([3, v])
        dot = 0.005 if v % 2 else 0.010
        z = float(rng.uniform(0.25, 0.8))
        opts = RenderOptions(blur_sigma_px=float(rng.uniform(0.5, 2.0)))
        ms = marker_grid_view(st, rng, DEFAULT_DESIGN, dot, z, 50.0)
        r = render_markers_pair(st, ms, opts, seed=v)
        for side, img in (("left", r.left), ("right", r.right)):
            K, d = (st.K_left, st.dist_left) if side == "left" else (st.K_right, st.dist_right)
            dets = {m.code: m for m in detect_markers(img, K, d)}
            assert set(dets) <= {m.code for m in ms}  # no false identification
            for m in ms:
                total += 1
                if m.code not in dets:
                    continue
                found += 1
                proj, C, N = true_ideal_centre(st, m, side)
                ideal = cv2.undistortPoints(dets[m.code].center_px.reshape(1, 1, 2), K, d, P=K)
                bias = circle_center_bias_px(K, C, N, 0.5 * m.diameter_m)
                errs.append(np.linalg.norm(ideal.ravel() - bias - proj))
    errs = np.array(errs)
    assert found >= 0.95 * total
    assert np.sqrt(np.mean(errs**2)) < 0.02 and errs.max() < 0.06
