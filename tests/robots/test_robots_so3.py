"""The SO(3) helpers of robots.transforms against SciPy and finite differences."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from robots.transforms import skew, so3_exp, so3_left_jacobian, so3_log


def test_skew_is_the_cross_product_batched() -> None:
    rng = np.random.default_rng(0)
    v, u = rng.normal(size=(4, 5, 3)), rng.normal(size=(4, 5, 3))
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", skew(v), u), np.cross(v, u))


def test_exp_and_log_agree_with_scipy_and_invert_each_other() -> None:
    rng = np.random.default_rng(1)
    w = rng.normal(size=(20, 3))
    w[0] = 0.0
    w[1] = [1e-12, 0, 0]
    np.testing.assert_allclose(so3_exp(w), Rotation.from_rotvec(w).as_matrix(), atol=1e-12)
    small = w * (np.pi * 0.99 / np.maximum(np.linalg.norm(w, axis=1), np.pi))[:, None]
    np.testing.assert_allclose(so3_log(so3_exp(small)), small, atol=1e-10)


def test_left_jacobian_by_finite_differences() -> None:
    rng = np.random.default_rng(2)
    for w in (rng.normal(size=3), np.array([1e-10, 0.0, 0.0])):
        J = so3_left_jacobian(w)
        h = 1e-6
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            # exp(w + e) exp(w)^T = exp(J e): its log / h is column k of J
            d = so3_log(so3_exp(w + e) @ so3_exp(w).T) / h
            np.testing.assert_allclose(d, J[:, k], atol=1e-5)
