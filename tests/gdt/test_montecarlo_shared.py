"""The Monte Carlo draws the survey's marker errors once per run: two stops located by the same
markers share them (their difference does not scatter), while independent draws would."""

from __future__ import annotations

import numpy as np

from cell.gdt.montecarlo import draw_centres
from cell.records.hole_result import HoleResult


def _result(hole_id: str, k: int, cov_markers: np.ndarray, factor: np.ndarray | None):
    extra = {
        "cov_center_part_m2": cov_markers.tolist(),
        "cov_components_part_m2": {"survey_markers": cov_markers.tolist()},
        "R_part_left": np.eye(3).tolist(),
    }
    if factor is not None:
        extra["survey_markers_factor_part"] = factor.tolist()
    return HoleResult(hole_id=hole_id, stop_index=k, status="ok", nominal_part_m=(0.0, 0.0, 0.0),
                      nominal_diameter_m=0.01, tolerance_m=None, center_part_m=(0.1 * k, 0, 0),
                      normal_part=(0.0, 0.0, 1.0), diameter_m=0.01, extra=extra)  # fmt: skip


def test_stops_sharing_markers_share_the_survey_error() -> None:
    rng = np.random.default_rng(3)
    F = rng.normal(0.0, 2e-6, (3, 12))  # both holes see the same markers the same way
    cov = F @ F.T
    shared = draw_centres([_result("a", 0, cov, F), _result("b", 1, cov, F)], 4000, 7)
    alone = draw_centres([_result("a", 0, cov, None), _result("b", 1, cov, None)], 4000, 7)
    for draws in (shared, alone):  # each hole alone scatters by its stated covariance
        c = np.cov((draws["a"][1:] - draws["a"][0]).T)
        assert np.allclose(c, cov, atol=0.1 * np.abs(cov).max())
    d_shared = (shared["a"] - shared["a"][0]) - (shared["b"] - shared["b"][0])
    d_alone = (alone["a"] - alone["a"][0]) - (alone["b"] - alone["b"][0])
    assert np.abs(d_shared[1:]).max() < 1e-15
    assert np.sqrt(np.mean(d_alone[1:] ** 2)) > 1e-6
