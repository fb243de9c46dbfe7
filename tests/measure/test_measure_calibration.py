"""stereo.json round trip, validation errors, and the head frame."""

from __future__ import annotations

import json

import numpy as np
import pytest

from measure import StereoCalibration, convergence_distance_m, head_frame
from measure.errors import CalibrationError
from measure.synth import standard_stereo


def test_round_trip(tmp_path):
    st = standard_stereo()
    path = tmp_path / "stereo.json"
    st.save(path)
    back = StereoCalibration.load(path)
    assert back.image_size == (2448, 2048)
    for a, b in (
        (st.K_left, back.K_left),
        (st.R, back.R),
        (st.T, back.T),
        (st.dist_right, back.dist_right),
    ):
        np.testing.assert_array_equal(a, b)
    data = json.loads(path.read_text())
    assert set(data) == {"image_size", "left", "right", "R", "T"}
    assert len(data["left"]["dist"]) == 5


def test_standard_head_geometry():
    st = standard_stereo()
    assert st.baseline_m == pytest.approx(0.100, abs=1e-12)
    assert st.K_left[0, 0] == pytest.approx(16e-3 / 3.45e-6)
    assert convergence_distance_m(st) == pytest.approx(0.25, abs=1e-9)
    T = head_frame(st)
    np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12)
    # origin midway between the camera centres, x toward the right camera
    np.testing.assert_allclose(T[:3, 3], 0.5 * st.right_center_in_left, atol=1e-12)
    assert T[:3, 0] @ st.right_center_in_left > 0.099
    # the point at the standoff on head z projects to the image centre of both cameras
    p = T[:3, :3] @ np.array([0, 0, 0.25]) + T[:3, 3]
    for side in ("left", "right"):
        np.testing.assert_allclose(st.project(p, side)[0], [1223.5, 1023.5], atol=1e-6)


@pytest.mark.parametrize(
    ("mutate", "field"),
    [
        (lambda d: d.pop("R"), "R"),
        (lambda d: d["left"].pop("K"), "left.K"),
        (lambda d: d.pop("right"), "right"),
        (lambda d: d.__setitem__("T", [0.1, 0.0]), "T"),
        (lambda d: d.__setitem__("image_size", [2448]), "image_size"),
        (lambda d: d["left"].__setitem__("dist", [0.1, 0.2, 0.3]), "left.dist"),
        (lambda d: d.__setitem__("R", [[1, 0, 0], [0, 1, 0], [0, 0, 2]]), "R"),
        (lambda d: d["right"].__setitem__("K", [[1, 0, 5000], [0, 1, 5], [0, 0, 1]]), "right.K"),
    ],
)
def test_bad_files_name_the_field(tmp_path, mutate, field):
    data = standard_stereo().to_dict()
    mutate(data)
    path = tmp_path / "stereo.json"
    path.write_text(json.dumps(data))
    with pytest.raises(CalibrationError) as exc:
        StereoCalibration.load(path)
    assert exc.value.field == field
    assert str(path) in str(exc.value)


def test_missing_and_invalid_files(tmp_path):
    with pytest.raises(CalibrationError, match="no such file"):
        StereoCalibration.load(tmp_path / "nope.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(CalibrationError, match="not valid JSON"):
        StereoCalibration.load(bad)


def test_image_size_mismatch():
    st = standard_stereo()
    with pytest.raises(CalibrationError, match="2448x2048"):
        st.check_image((512, 640), "left")


def test_uncertainty_block_round_trips_and_bad_values_name_the_field(tmp_path):
    import json

    from measure.calibration import StereoCalibration
    from measure.errors import CalibrationError
    from measure.synth import standard_stereo

    cal = standard_stereo()
    data = cal.to_dict()
    data["uncertainty"] = {
        "left": {"K_std_px": [0.5, 0.5, 0.3, 0.3], "dist_std": [1e-3, 1e-2, 1e-5, 1e-5, 0.05]},
        "right": {"K_std_px": [0.6, 0.6, 0.4, 0.4], "dist_std": [1e-3, 1e-2, 1e-5, 1e-5, 0.05]},
        "rvec_std_rad": [1e-4, 2e-4, 1e-4],
        "T_std_m": [2e-5, 1e-5, 4e-5],
        "rms_px": 0.2,
        "per_view_rms_px": [[0.2, 0.21], [0.19, 0.2]],
    }
    path = tmp_path / "stereo.json"
    path.write_text(json.dumps(data))
    loaded = StereoCalibration.load(path)
    assert loaded.uncertainty is not None
    assert loaded.uncertainty.T_std_m[2] == 4e-5
    loaded.save(tmp_path / "again.json")
    assert json.loads((tmp_path / "again.json").read_text())["uncertainty"] == data["uncertainty"]
    assert StereoCalibration.from_dict(cal.to_dict()).uncertainty is None

    data["uncertainty"]["right"]["K_std_px"] = [0.6, -1, 0.4, 0.4]
    path.write_text(json.dumps(data))
    with pytest.raises(CalibrationError, match=r"uncertainty\.right\.K_std_px"):
        StereoCalibration.load(path)
