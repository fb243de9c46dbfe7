"""A referenced stop does not depend on the arm's prior: the markers' perspective bias is
removed again at the resected pose (rendered markers, the real detector)."""

from __future__ import annotations

import numpy as np

from cell.config.markers import marker_codes
from cell.referencing.detection import detect_pair, observe_detections
from cell.referencing.layout import stop_pose
from cell.referencing.network import MarkerNetwork
from cell.referencing.resection import resect
from cell.run.referenced import locate_stop
from measure.synth.markers import MarkerPatch, render_markers_pair
from robots.transforms import invert, so3_exp


def test_the_located_stop_is_the_same_from_priors_two_millimetres_apart(small_cell, stereo,
                                                                       marker_truth):  # fmt: skip
    mt = marker_truth
    T = stop_pose(small_cell, stereo, "PVL")
    Tl = invert(T)
    p_left, n_left = mt.true @ Tl[:3, :3].T + Tl[:3, 3], mt.normals @ Tl[:3, :3].T
    front = (p_left[:, 2] > 0) & (np.sum(n_left * p_left, axis=1) < 0)
    patches = [MarkerPatch(int(mt.codes[k]), p_left[k], n_left[k], mt.diameters_m[k])
               for k in np.flatnonzero(front)]  # fmt: skip
    pair = render_markers_pair(stereo, patches, seed=4)
    codes = marker_codes(small_cell.reference_markers)
    dets = detect_pair(pair.left, pair.right, stereo, codes)
    n = len(mt.ids)
    net = MarkerNetwork(mt.ids, mt.true, np.eye(3 * n) * 1e-12, mt.normals,
                        0.5 * np.asarray(mt.diameters_m), codes, stereo, "test")  # fmt: skip
    priors = []
    for dx, rot in ((0.0, 0.0), (2e-3, 0.1)):
        P = T.copy()
        P[:3, :3] = so3_exp(np.radians([rot, -rot, rot])) @ T[:3, :3]
        P[:3, 3] += [dx, -dx, dx]
        priors.append(P)
    located = [locate_stop(net, dets, P, "PVL") for P in priors]
    assert all(s.referenced and len(s.resection.used) >= 4 for s in located)
    a, b = (s.resection.T_cell_left for s in located)
    c = np.array([0.0, 0.0, 0.25])  # a hole on the view axis
    assert np.linalg.norm((a[:3, :3] - b[:3, :3]) @ c + a[:3, 3] - b[:3, 3]) < 1e-9
    # a single resection about each prior (the bias removed at the prior) differs by more
    geometry = {m: (mt.true[k], mt.normals[k], 0.5 * mt.diameters_m[k])
                for k, m in enumerate(mt.ids)}  # fmt: skip
    once = [resect(observe_detections(dets, stereo, codes, geometry, "PVL", P), stereo, mt.ids,
                   mt.true, None, 0.05).T_cell_left for P in priors]  # fmt: skip
    a1, b1 = once
    assert np.linalg.norm((a1[:3, :3] - b1[:3, :3]) @ c + a1[:3, 3] - b1[:3, 3]) > 1e-7
