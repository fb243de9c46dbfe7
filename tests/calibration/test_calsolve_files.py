"""cellcal.json: written, read back, refused when malformed (the field named), tied to its
robot, tool and cell, and too old; the calibrated kinematics it gives."""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
import pytest
from calsolve_fixtures import seen_views

from cell.calibration.errors import CalibrationFileError
from cell.calibration.estimate import Provenance, example_truth, simulate, solve_calibration
from cell.calibration.file import (
    calibration_to_dict,
    check_age,
    check_belongs,
    load_calibration,
    save_calibration,
)
from cell.calibration.use import CalibratedKinematics
from robots.calibration import calibrated_table, fk_with_errors

PROV = Provenance("abb_irb1600_10_145", "r" * 16, "t" * 16, "c" * 16, "stereo.json", "s" * 16)


@pytest.fixture(scope="module")
def solved():
    tr = example_truth(4)
    obs = simulate(tr, seen_views(tr, 12, seed=5), 0.1, seed=6)
    return tr, solve_calibration(obs, tr.dh, provenance=PROV).calibration


def test_written_and_read_back(solved, tmp_path: Path) -> None:
    _tr, cal = solved
    path = tmp_path / "cellcal.json"
    save_calibration(cal, path)
    back = load_calibration(path)
    a, b = calibration_to_dict(cal), calibration_to_dict(back)
    assert json.dumps(a, sort_keys=True).count("{") == json.dumps(b, sort_keys=True).count("{")
    assert np.allclose(back.T_tool0_camera.T, cal.T_tool0_camera.T, atol=1e-15)
    assert np.array_equal(back.covariance, cal.covariance)
    assert back.parameter_names == cal.parameter_names and back.provenance == PROV
    assert back.flange_scatter == cal.flange_scatter and "source" in back.flange_scatter
    assert [t.reason for t in back.dh_terms] == [t.reason for t in cal.dh_terms]
    data = json.loads(path.read_text())
    assert data["format"] == "holecell.cellcal" and data["version"] == 1
    assert set(data["T_tool0_camera"]) >= {"xyz", "quat_xyzw", "covariance"}
    assert data["residuals"]["rms_px"]["right"] > 0 and len(data["residuals"]["views"]) == 12
    fixed = [e for e in data["dh"]["errors"] if not e["free"]]
    assert fixed and all(e["reason"] and e["value"] == 0.0 and e["sigma"] == 0.0 for e in fixed)


def _broken(cal, edit) -> dict:
    data = calibration_to_dict(cal)
    edit(data)
    return data


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d["T_tool0_camera"].pop("xyz"), "T_tool0_camera.xyz: missing"),
        (lambda d: d["T_tool0_camera"].update(quat_xyzw=[0, 0, 0, 2]), "T_tool0_camera.quat_xyzw"),
        (lambda d: d.update(version=2), "version"),
        (lambda d: d.update(format="thermal"), "format"),
        (lambda d: d["T_base_target"]["covariance"][0].__setitem__(1, 1.0), "not symmetric"),
        (lambda d: d["dh"]["errors"][3].update(name="d1_m"), "dh.errors[3].name"),
        (lambda d: d["dh"]["errors"][0].update(value="x"), "dh.errors[0].value"),
        (lambda d: d.update(created_utc="yesterday"), "created_utc"),
        (lambda d: d["parameters"].update(covariance=[[1.0]]), "parameters.covariance"),
        (lambda d: d["counts"].pop("dof"), "counts.dof: missing"),
    ],
)
def test_a_malformed_file_is_refused_naming_the_field(solved, tmp_path: Path, edit, field) -> None:
    _tr, cal = solved
    path = tmp_path / "cellcal.json"
    path.write_text(json.dumps(_broken(cal, edit)))
    with pytest.raises(CalibrationFileError, match=field.replace("[", r"\[").replace("]", r"\]")):
        load_calibration(path)


def test_not_json_and_missing_file(tmp_path: Path) -> None:
    (tmp_path / "x.json").write_text("{")
    with pytest.raises(CalibrationFileError, match="not valid JSON"):
        load_calibration(tmp_path / "x.json")
    with pytest.raises(CalibrationFileError, match="no such file"):
        load_calibration(tmp_path / "none.json")


def test_a_file_of_another_tool_or_an_old_one_is_refused(solved) -> None:
    _tr, cal = solved
    check_belongs(cal, PROV)
    other = Provenance(tool_fingerprint="u" * 16)
    with pytest.raises(CalibrationFileError, match=r"tool\.fingerprint: belongs to another tool"):
        check_belongs(cal, other, "cellcal.json")
    made = datetime.strptime(cal.created_utc, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=UTC)
    check_age(cal, 30, now=made + timedelta(days=29))
    with pytest.raises(CalibrationFileError, match="older than the limit of 30 days"):
        check_age(cal, 30, now=made + timedelta(days=31))


def test_the_calibrated_kinematics(solved) -> None:
    tr, cal = solved
    ck = CalibratedKinematics(cal)
    assert ck.dh_table == calibrated_table(tr.dh, cal.delta)
    rng = np.random.default_rng(0)
    Q = rng.uniform(-1, 1, (5, 6))
    assert np.allclose(ck.T_base_tool0(Q), fk_with_errors(tr.dh, cal.delta, Q), atol=1e-14)
    assert np.allclose(ck.T_base_camera(Q), ck.T_base_tool0(Q) @ cal.T_tool0_camera.T)


@pytest.mark.parametrize("frame", ["base", "target"])
def test_the_point_covariance_is_the_spread_of_sampled_calibrations(solved, frame) -> None:
    """Draw the free parameters from their covariance, move a point fixed in the camera:
    its scatter matches ``point_covariance`` (first order: errors are micrometres)."""
    tr, cal = solved
    from cell.calibration.estimate import State, step_state

    ck = CalibratedKinematics(cal)
    q = seen_views(tr, 1, seed=9)[0]
    p_c = np.array([0.01, -0.02, 0.25])
    base = State(cal.T_tool0_camera.T, cal.T_base_target.T, cal.T_left_right.T, cal.delta)
    rng = np.random.default_rng(1)
    draws = rng.multivariate_normal(np.zeros(len(cal.parameter_names)), cal.covariance, 1500)
    pts = []
    for x in draws:
        s = step_state(base, x, cal.parameter_names)
        p_b = (fk_with_errors(tr.dh, s.delta, q) @ s.T_tool0_camera @ np.append(p_c, 1))[:3]
        pts.append(
            p_b if frame == "base" else (np.linalg.inv(s.T_base_target) @ np.append(p_b, 1))[:3]
        )
    emp = np.cov(np.array(pts).T)
    pred = ck.point_covariance(q, p_c, frame=frame)
    assert np.allclose(np.sqrt(np.diag(emp)), np.sqrt(np.diag(pred)), rtol=0.1)
    with pytest.raises(ValueError, match="frame"):
        ck.point_covariance(q, p_c, frame="cell")


def test_a_file_with_the_old_version_key_is_still_read(solved, tmp_path: Path) -> None:
    _tr, cal = solved
    data = calibration_to_dict(cal)
    data["schema_version"] = data.pop("version")  # as written before Dec 2026
    path = tmp_path / "cellcal.json"
    path.write_text(json.dumps(data))
    assert load_calibration(path).parameter_names == cal.parameter_names
