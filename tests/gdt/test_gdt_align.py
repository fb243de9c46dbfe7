"""Alignments recover a known placement of the part on its fixture (synthetic placements)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cell.config.datums import Datum
from cell.gdt.align import best_fit_frame, datum_frame, minimax
from robots.transforms import kabsch

# a plate in the x-z plane at y = 0.167 (normal +y) and two holes off it, like the frame's
PLATE = {
    "P1": [0.0, 0.167, 0.0], "P2": [-0.055, 0.167, -0.09], "P3": [0.045, 0.167, 0.13],
    "P4": [-0.02, 0.167, -0.1], "P5": [0.06, 0.167, -0.06],
}  # fmt: skip
OTHERS = {"H1": [0.66, 0.03, 0.3], "H2": [0.4, 0.11, 0.4], "H3": [-0.5, 0.1, 0.29]}
NOMINAL = {k: np.array(v) for k, v in {**PLATE, **OTHERS}.items()}
NORMALS = {k: np.array([0.0, 1.0, 0.0]) for k in NOMINAL}


def _placement(xyz_m: list[float], rotvec_rad: list[float]) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rotvec_rad).as_matrix()
    T[:3, 3] = xyz_m
    return T


def _measured(T: np.ndarray, noise_m: float = 0.0, n: int = 1, seed: int = 0) -> dict:
    rng = np.random.default_rng(seed)
    return {
        k: (T[:3, :3] @ v + T[:3, 3])[None] + rng.normal(0, noise_m, (n, 3))
        for k, v in NOMINAL.items()
    }


def _placement_of(datums: list[Datum], measured: dict) -> np.ndarray:
    nom = {k: v[None] for k, v in NOMINAL.items()}
    act = datum_frame(datums, measured, NOMINAL, NORMALS)
    nominal = datum_frame(datums, nom, NOMINAL, NORMALS)
    return act.matrix() @ np.linalg.inv(nominal.matrix())


A = Datum(label="A", plane={"holes": ["P1", "P2", "P3", "P4", "P5"]})
B = Datum(label="B", hole="P1")
C = Datum(label="C", hole="H1")
PAT = Datum(label="D", pattern=["P2", "P3", "P4", "P5"])
RPS_POINTS = [{"hole": "P1", "axes": ["x", "y", "z"]}, {"hole": "H1", "axes": ["y", "z"]},
              {"hole": "H3", "axes": ["y"]}]  # fmt: skip
RPS = Datum(label="R", rps=RPS_POINTS)
T_OFF = _placement([0.0015, -0.0007, 0.0009], [0.001, -0.004, 0.007])  # 1.9 mm, 0.47 deg


@pytest.mark.parametrize("datums", [[A, B, C], [A, PAT], [RPS],
                                    [Datum(label="P", pattern=list(NOMINAL))]])  # fmt: skip
def test_datum_frames_recover_the_placement(datums: list[Datum]) -> None:
    got = _placement_of(datums, _measured(T_OFF))
    assert np.allclose(got[:3, 3], T_OFF[:3, 3], atol=1e-9)
    assert np.allclose(got[:3, :3], T_OFF[:3, :3], atol=1e-9)


def test_datum_frame_axes_follow_the_datums() -> None:
    f = datum_frame([A, B, C], {k: v[None] for k, v in NOMINAL.items()}, NOMINAL, NORMALS)
    assert np.allclose(f.R[0][:, 2], [0, 1, 0])  # z: the plate's normal
    assert np.allclose(f.t[0], NOMINAL["P1"])  # origin: B on A
    x = NOMINAL["H1"] - NOMINAL["P1"]
    x[1] = 0.0
    assert np.allclose(f.R[0][:, 0], x / np.linalg.norm(x))  # x: towards C in A
    assert f.residuals_m["A"][0] == pytest.approx(0.0, abs=1e-12)


def test_plane_residual_is_the_rms_distance() -> None:
    meas = _measured(np.eye(4))
    meas["P3"] = meas["P3"] + [0, 1e-4, 0]
    f = datum_frame([A, B, C], meas, NOMINAL, NORMALS)
    assert 1e-5 < f.residuals_m["A"][0] < 1e-4


def test_best_fits_recover_the_placement_and_minimax_lowers_the_worst_residual() -> None:
    P = np.stack(list(NOMINAL.values()))
    Q = np.stack([m[0] for m in _measured(T_OFF).values()])[None]
    for fit in (kabsch, minimax):
        R, t, res = fit(P, Q)
        assert np.allclose(R[0], T_OFF[:3, :3], atol=1e-7) and res[0] < 1e-7
        assert np.allclose(t[0], T_OFF[:3, 3], atol=1e-7)
    noisy = np.stack([m[0] for m in _measured(T_OFF, 2e-5, seed=3).values()])[None]
    R, t, worst = minimax(P, noisy)
    R2, t2, _ = kabsch(P, noisy)
    worst_ls = np.max(np.linalg.norm(noisy[0] - P @ R2[0].T - t2[0], axis=1))
    assert worst[0] < worst_ls


def test_frames_vectorise_over_draws() -> None:
    meas = _measured(T_OFF, 1e-5, n=200, seed=1)
    f = best_fit_frame(list(NOMINAL), meas, NOMINAL, "least_squares")
    assert f.R.shape == (200, 3, 3) and f.t.shape == (200, 3)
    assert np.std(f.t[:, 0]) < 2e-5 and abs(np.mean(f.t[:, 0]) - T_OFF[0, 3]) < 5e-6
