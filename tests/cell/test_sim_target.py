"""The calibration target: the cell file's section, and the simulated head capturing the plate
at its true pose (the truth's base, D-H, head and target errors) so the detector finds it where
the true geometry puts it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.camera import cell_stereo
from cell.config import builtin_cell_path, load_builtin_cell, load_cell
from cell.errors import ConfigError
from cell.sim.camera import SimCamera
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from measure.target import find_target
from planner.reach import viewpoint


class _Arm:
    """A controller that sits at one joint vector."""

    def __init__(self, q: np.ndarray) -> None:
        self.q = q

    def q_rad(self) -> np.ndarray:
        return self.q


def _cell_with_target(tmp_path: Path, **target) -> Path:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["calibration_target"].update(target)
    for k in [k for k, v in target.items() if v is None]:
        del data["calibration_target"][k]
    p = tmp_path / "cell.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


@pytest.mark.parametrize(
    ("target", "field", "reason"),
    [
        ({"pattern": "charuco"}, "calibration_target.pattern", "ChArUco"),
        ({"pattern": "dots"}, "calibration_target.pattern", "chessboard"),
        ({"pitch_m": 9.0}, "calibration_target.pitch_m", "millimetres"),
        ({"cols": 2}, "calibration_target.cols", "greater than or equal to 3"),
        ({"pitch_m": float("nan")}, "calibration_target.pitch_m", "finite"),
        ({"size": 3}, "calibration_target.size", "unknown key"),
        ({"pose": {"xyz": [0, 0, 0]}}, "calibration_target.pose", "rpy or quat_xyzw"),
        ({"corners_file": "c.csv"}, "calibration_target", "not both"),
        (
            {"corners_file": "c.csv", "flatness_m": None},
            "calibration_target.corners_file",
            "no such file",
        ),
    ],
)
def test_bad_target_sections_are_refused_naming_the_field(
    tmp_path: Path, target: dict, field: str, reason: str
) -> None:
    with pytest.raises(ConfigError) as exc:
        load_cell(_cell_with_target(tmp_path, **target))
    assert field in str(exc.value) and reason in str(exc.value)


def test_corner_file_is_read_and_checked(tmp_path: Path) -> None:
    cell = load_builtin_cell()
    nominal = cell.calibration_target.target_spec().object_points()
    measured = nominal + np.array([0.0, 0.0, 1e-5])
    rows = "\n".join(",".join(f"{v:.9f}" for v in p) for p in measured)
    (tmp_path / "c.csv").write_text("x_m,y_m,z_m\n" + rows + "\n")
    p = _cell_with_target(tmp_path, corners_file="c.csv", flatness_m=None)
    t = load_cell(p).calibration_target
    np.testing.assert_allclose(t.board_points_m(p.parent), measured, atol=1e-9)
    (tmp_path / "c.csv").write_text("x_m,y_m,z_m\n" + rows.replace("0.009", "9.0", 1) + "\n")
    with pytest.raises(ConfigError, match=r"row 3: .* off the nominal grid"):
        load_cell(p)
    (tmp_path / "c.csv").write_text("x,y,z\n" + rows + "\n")
    with pytest.raises(ConfigError, match="header must be x_m,y_m,z_m"):
        load_cell(p)
    (tmp_path / "c.csv").write_text("x_m,y_m,z_m\n" + rows.split("\n", 1)[1] + "\n")
    with pytest.raises(ConfigError, match="53 corners, the board has 54"):
        load_cell(p)


def test_the_built_in_plate_is_an_obstacle() -> None:
    cell = load_builtin_cell()
    names = [s.name for s in cell.obstacle_shapes()]
    assert "calibration_plate" in names and "target_stand_post" in names


def test_the_head_sees_the_plate_where_the_truth_puts_it() -> None:
    cell = load_builtin_cell()
    truth = replace(CellTruth.drawn(2, cell), repeatability_rp_m=0.0)  # no scatter: exact chain
    world = SimWorld(cell, WorldOptions(drift_offset_s=0.0, truth=truth))
    t = cell.calibration_target
    centre, normal = t.centre_and_normal(t.T_cell_target())
    arm = world.arm  # the nominal arm plans the view; the truth moves it
    sols = arm.ik(viewpoint(centre, normal, cell.tool.standoff_m, 0.4)).solutions
    q = next(q for q in sols if not arm.in_collision(q))
    cam = SimCamera(world, _Arm(q), cell_stereo(cell))
    pair = cam.capture()
    assert cam.last_truth.kind == "target"
    spec = t.target_spec()
    g = cam.geometry
    T_left_target = np.linalg.inv(g.T_cell_left(q, 0.0)) @ g.T_cell_target
    X = (T_left_target[:3, :3] @ spec.object_points().T).T + T_left_target[:3, 3]
    T_nominal = np.linalg.inv(arm.fk(q) @ g.T_tcp_left) @ t.T_cell_target()
    X_nominal = (T_nominal[:3, :3] @ spec.object_points().T).T + T_nominal[:3, 3]
    for side, img in (("left", pair.left), ("right", pair.right)):
        det = find_target(img, spec)
        assert det.points is not None, det.reason
        err = np.linalg.norm(det.points - cam.true_stereo.project(X, side), axis=1)
        assert np.max(err) < 0.35  # px: the plate is where the true chain puts it
        off = np.linalg.norm(det.points - cam.stereo.project(X_nominal, side), axis=1)
        assert np.median(off) > 5.0  # px: and not where the nominal cell would
    # the true target is off its nominal pose by the truth's placement error
    np.testing.assert_allclose(g.T_cell_target, t.T_cell_target() @ truth.target_placement_error)


def test_the_plate_is_seen_from_in_front_wherever_it_is_in_the_image() -> None:
    cell = load_builtin_cell()
    world = SimWorld(cell, WorldOptions(truth=CellTruth.zero(0)))
    cam = SimCamera(world, _Arm(cell.home_q()), cell_stereo(cell))
    t = cell.calibration_target
    centre, normal = t.centre_and_normal(t.T_cell_target())
    assert cam._target_distance(viewpoint(centre, normal, 0.25, 1.0)) == pytest.approx(0.25)
    assert cam._target_distance(viewpoint(centre, -normal, 0.25, 0.0)) is None  # from behind
    aside = centre + 0.1 * np.cross(normal, [0.0, 0.0, 1.0]) / np.linalg.norm(normal[:2])
    # off the view axis but in the image (issue 26): seen, behind any hole on the axis
    assert cam._target_distance(viewpoint(aside, normal, 0.25, 0.0)) == float("inf")
    far_aside = centre + 0.6 * np.cross(normal, [0.0, 0.0, 1.0]) / np.linalg.norm(normal[:2])
    assert cam._target_distance(viewpoint(far_aside, normal, 0.25, 0.0)) is None  # out of view
    assert cam._target_distance(viewpoint(centre, normal, 1.5, 0.0)) is None  # too far
