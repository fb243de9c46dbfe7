"""The simulated truth file (cell.sim.truth): draw, load, refusals, and the world applying it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cell.cli import main
from cell.config import load_builtin_cell
from cell.errors import TruthFileError
from cell.sim.truth import DH_ANGLE_RANGE_RAD, DH_LENGTH_RANGE_M, CellTruth
from cell.sim.world import SimWorld, WorldOptions
from robots.dh import fk_dh
from robots.transforms import invert, make_transform, rpy_to_matrix

Q = np.array([0.3, -0.2, 0.4, 0.5, 0.9, -0.7])


@pytest.fixture(scope="module")
def cell():
    return load_builtin_cell()


def test_draw_depends_on_the_seed_only() -> None:
    a, b, c = CellTruth.drawn(5), CellTruth.drawn(5), CellTruth.drawn(6)
    assert a.to_yaml() == b.to_yaml()
    assert a.to_yaml() != c.to_yaml()
    lengths, angles = np.abs(a.dh_errors[:, :2]), np.abs(a.dh_errors[:, 2:])
    assert lengths.min() >= DH_LENGTH_RANGE_M[0] and lengths.max() <= DH_LENGTH_RANGE_M[1]
    assert angles.min() >= DH_ANGLE_RANGE_RAD[0] and angles.max() <= DH_ANGLE_RANGE_RAD[1]
    assert 0.5e-3 <= np.linalg.norm(a.tcp_error[:3, 3]) <= 1.5e-3
    assert 0.5e-3 <= np.linalg.norm(a.base_error[:3, 3]) <= 1.5e-3
    assert 0.15e-3 <= np.linalg.norm(a.part_placement_error[:3, 3]) <= 0.45e-3


def test_written_truth_reads_back(tmp_path: Path) -> None:
    t = CellTruth.drawn(11)
    p = tmp_path / "truth.yaml"
    p.write_text(t.to_yaml())
    u = CellTruth.load(p)
    assert u.seed == 11
    np.testing.assert_allclose(u.dh_errors, t.dh_errors, rtol=0, atol=0)
    for k in ("base_error", "tcp_error", "part_placement_error", "target_placement_error"):
        np.testing.assert_allclose(getattr(u, k), getattr(t, k), atol=1e-15)
    assert u.part_temperature_c == t.part_temperature_c


def test_fields_left_out_are_drawn_from_the_files_seed(tmp_path: Path) -> None:
    p = tmp_path / "truth.yaml"
    p.write_text(
        "seed: 7\ntool:\n  tcp_error: {xyz: [0.001, 0, 0], rpy: [0, 0, 0.01]}\n"
        "robot:\n  dh_errors: [{a_m: 0.0001}, {}, {}, {}, {}, {}]\n"
    )
    u, d = CellTruth.load(p, seed=99), CellTruth.drawn(7)
    np.testing.assert_allclose(
        u.tcp_error, make_transform(rpy_to_matrix([0, 0, 0.01]), [0.001, 0, 0])
    )
    assert u.dh_errors[0, 0] == 0.0001
    np.testing.assert_array_equal(u.dh_errors[1:], d.dh_errors[1:])
    np.testing.assert_array_equal(u.base_error, d.base_error)
    p.write_text("part: {temperature_c: 21.5}\n")
    assert CellTruth.load(p, seed=3).base_error.tolist() == CellTruth.drawn(3).base_error.tolist()


@pytest.mark.parametrize(
    ("text", "field", "reason"),
    [
        ("robot: {dh_error: []}\n", "robot.dh_error", "unknown key"),
        ("part: {temperature_c: .nan}\n", "part.temperature_c", "finite"),
        ("tool: {tcp_error: {xyz: [0, 0, 0.001]}}\n", "tool.tcp_error", "rpy or quat_xyzw"),
        (
            "robot: {base_error: {xyz: [1.0, 0, 0], rpy: [0, 0, 0]}}\n",
            "robot.base_error.xyz",
            "within",
        ),
        ("robot: {dh_errors: [{}, {}]}\n", "robot.dh_errors", "6"),
        (
            "robot: {dh_errors: [{a_m: .inf}, {}, {}, {}, {}, {}]}\n",
            "robot.dh_errors[0].a_m",
            "finite",
        ),
        ("- 1\n", "(top level)", "mapping"),
    ],
)
def test_bad_truth_files_are_refused_naming_the_field(
    tmp_path: Path, text: str, field: str, reason: str
) -> None:
    p = tmp_path / "truth.yaml"
    p.write_text(text)
    with pytest.raises(TruthFileError) as exc:
        CellTruth.load(p)
    msg = str(exc.value)
    assert field in msg and reason in msg and str(p) in msg


def test_cli_refuses_a_bad_truth_in_one_line(tmp_path: Path, capsys) -> None:
    p = tmp_path / "truth.yaml"
    p.write_text("stereo: {calibration_sigma_scale: 1, extra: 2}\n")
    assert main(["sim", "--truth", str(p), "--duration-s", "0.1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "stereo.extra" in err[0] and "unknown key" in err[0]


def test_truth_draw_writes_a_reusable_file(tmp_path: Path, capsys) -> None:
    out = tmp_path / "t.yaml"
    assert main(["truth", "draw", "--seed", "4", "-o", str(out)]) == 0
    assert out.read_text() == CellTruth.drawn(4, load_builtin_cell()).to_yaml()
    np.testing.assert_allclose(
        CellTruth.load(out).tcp_error, CellTruth.drawn(4).tcp_error, atol=1e-15
    )
    assert main(["truth", "draw", "--seed", "4", "-o", str(out)]) == 2  # no overwrite
    assert "exists" in capsys.readouterr().err


def _world(cell, truth: CellTruth) -> SimWorld:
    return SimWorld(cell, WorldOptions(drift_offset_s=0.0, truth=truth))


def test_zero_truth_is_the_nominal_cell(cell) -> None:
    w = _world(cell, CellTruth.zero(0))
    g = w.true_geometry()
    nominal = cell.T_cell_base() @ fk_dh(w.arm.dh, Q) @ cell.T_tool0_tcp()
    np.testing.assert_allclose(w.true_T_cell_tcp(Q, 0.0), nominal, atol=1e-12)
    np.testing.assert_array_equal(g.T_cell_part, cell.T_cell_part())
    nominal_holes = {h.id: h for h in cell.holes_in_cell()}
    for k, h in w.holes.items():  # off nominal by the machining scatter only (15 um sigma)
        assert np.linalg.norm(h.position_m - nominal_holes[k].position_m) < 1e-4
        np.testing.assert_array_equal(h.normal, nominal_holes[k].normal)


def test_world_applies_each_error(cell) -> None:
    zero = CellTruth.zero(0)
    w0 = _world(cell, zero)
    E = make_transform(rpy_to_matrix([0.002, -0.001, 0.004]), [0.001, -0.0005, 0.0008])
    # the head: T_tool0_tcp_true = T_tool0_tcp @ E
    w = _world(cell, replace(zero, tcp_error=E))
    np.testing.assert_allclose(
        w.true_T_cell_tcp(Q, 0.0), w0.true_T_cell_tcp(Q, 0.0) @ E, atol=1e-12
    )
    np.testing.assert_allclose(
        w.true_geometry().T_tool0_camera_left,
        cell.T_tool0_tcp() @ E @ w0.true_geometry().T_tcp_left,
        atol=1e-12,
    )
    # the base: T_cell_base_true = T_cell_base @ E
    w = _world(cell, replace(zero, base_error=E))
    np.testing.assert_allclose(
        w.true_T_cell_tcp(Q, 0.0),
        cell.T_cell_base() @ E @ invert(cell.T_cell_base()) @ w0.true_T_cell_tcp(Q, 0.0),
        atol=1e-12,
    )
    # a joint-1 zero error turns the whole arm about the base z axis
    dh = np.zeros((6, 4))
    dh[0, 3] = 3e-4
    w = _world(cell, replace(zero, dh_errors=dh))
    Rz = make_transform(rpy_to_matrix([0.0, 0.0, 3e-4]))
    np.testing.assert_allclose(
        w.true_geometry().T_base_tool0(Q, 0.0),
        Rz @ w0.true_geometry().T_base_tool0(Q, 0.0),
        atol=1e-12,
    )
    # the part on its fixture: the true holes move with it
    flat = replace(zero, hole_position_sigma_m=0.0, hole_diameter_sigma_m=0.0)
    w = _world(cell, replace(flat, part_placement_error=E))
    T = cell.T_cell_part() @ E
    for h in cell.part.holes[:5]:
        np.testing.assert_allclose(
            w.holes[h.id].position_m, T[:3, :3] @ h.position + T[:3, 3], atol=1e-12
        )
    assert w.truth.seed == w.options.seed == 0


def test_demo_world_takes_the_truth(cell) -> None:
    from cell.demo.demo import DemoOptions, demo_truth, demo_world

    t = CellTruth.drawn(8, cell)
    assert demo_world(cell, DemoOptions(truth=t)).truth is t
    assert demo_truth(cell, DemoOptions(truth=t, part_temperature_c=21.0)).part_temperature_c == 21
    ideal = demo_truth(cell, DemoOptions(realistic=False, seed=4))
    assert ideal.is_geometrically_zero() and ideal.repeatability_rp_m == 0.0
    assert ideal.seed == 4 and ideal.part_temperature_c == 23.0
    drawn = demo_truth(cell, DemoOptions(seed=8))  # no truth file: the realistic draw
    assert np.array_equal(drawn.dh_errors, t.dh_errors) and not drawn.is_geometrically_zero()
    before = demo_truth(cell, DemoOptions(geometry_errors=False))  # the demo before issue 18
    assert before.is_geometrically_zero() and before.calibration_sigma_scale == 1.0
    assert before.repeatability_rp_m > 0
    assert not t.is_geometrically_zero()


def test_demo_refuses_ideal_with_a_truth(tmp_path: Path, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["demo", "--ideal", "--truth", str(tmp_path / "t.yaml"), "--quiet"])
    assert exc.value.code == 2 and "not allowed with" in capsys.readouterr().err


def test_the_documented_truth_file_reads(tmp_path: Path) -> None:
    doc = (Path(__file__).parents[2] / "docs" / "calibration.md").read_text()
    text = doc.split("## The simulated truth", 1)[1].split("```yaml\n", 1)[1].split("```", 1)[0]
    p = tmp_path / "truth.yaml"
    p.write_text(text)
    t = CellTruth.load(p)
    assert t.seed == 3 and t.dh_errors[0, 0] == -2.8e-4 and t.part_temperature_c == 22.5
    np.testing.assert_array_equal(t.dh_errors[1:], CellTruth.drawn(3).dh_errors[1:])


def test_marker_truth_takes_offsets_and_refuses_unknown_ids(cell, tmp_path: Path) -> None:
    """A marker's true position: the seeded draw, or the offset the truth file gives (a part
    marker's offset in the part frame, moving with the part); an unknown id is refused."""
    p = tmp_path / "truth.yaml"
    p.write_text(
        "seed: 3\nreference_markers:\n  position_error_sigma_m: 0.0\n"
        "  errors: {T05: [0.002, 0.0, 0.0]}\n"
    )
    t = CellTruth.load(p, cell)
    w = SimWorld(cell, WorldOptions(truth=replace(t, part_temperature_c=20.0)))
    mt = w.markers
    k = mt.ids.index("T05")
    np.testing.assert_allclose(mt.true[k] - mt.nominal[k], [0.002, 0.0, 0.0], atol=1e-12)
    fixture = [
        i for i in range(len(mt.ids)) if mt.on_fixture[i] and mt.ids[i] not in ("T05", "T09", "T36")
    ]  # a bar's far end sits at the bar's true length
    np.testing.assert_allclose(mt.true[fixture], mt.nominal[fixture], atol=1e-12)
    u = CellTruth.load(p, cell)
    assert u.to_dict()["reference_markers"]["errors"] == {"T05": [0.002, 0.0, 0.0]}
    p.write_text("reference_markers:\n  errors: {NOPE: [0.001, 0, 0]}\n")
    with pytest.raises(TruthFileError, match=r"reference_markers\.errors\.NOPE"):
        CellTruth.load(p, cell)
