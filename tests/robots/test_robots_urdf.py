"""Any OPW arm from its URDF: derivation, refusals, IK, meshes, limits (URDFs written here)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from urdf_factory import (
    ABB_LIKE,
    KUKA_LIKE,
    ArmSketch,
    write_dae,
    write_obj,
    write_stl,
    write_urdf,
)

from robots import MODELS, Arm, LimitsError, MeshError, NotOpwError, UrdfError, dh_table, fk_dh
from robots.opw import fk_opw
from robots.urdf_writer import URDF_DIR


def _arm(tmp_path: Path, sketch: ArmSketch, name: str = "arm", **kw: object) -> Arm:
    return Arm(write_urdf(tmp_path / f"{name}.urdf", sketch), **kw)


@pytest.mark.parametrize("sketch", [ABB_LIKE, KUKA_LIKE], ids=["abb_like", "kuka_like"])
def test_derived_kinematics_reproduce_the_urdf(tmp_path: Path, sketch: ArmSketch) -> None:
    arm = _arm(tmp_path, sketch)
    assert arm.kinematics.fk_error_m < 1e-12
    rng = np.random.default_rng(3)
    for q in rng.uniform(arm.lower, arm.upper, (50, 6)):
        assert np.abs(fk_opw(arm.opw, q) - arm.fk(q, "tool0")).max() < 1e-9


def test_kuka_like_parameters_and_signs(tmp_path: Path) -> None:
    arm = _arm(tmp_path, KUKA_LIKE)
    p = arm.opw
    assert (p.a1, p.c1, p.c2, p.b) == pytest.approx((0.26, 0.675, 0.68, 0.02), abs=1e-12)
    assert (p.a2, p.c3) == pytest.approx((0.035, 0.67), abs=1e-12)
    assert p.sign == (-1.0, 1.0, 1.0, -1.0, 1.0, -1.0)
    assert arm.joint_names == KUKA_LIKE.names
    # J1 about -z: the D-H rows (frame 0 = base_link) turn joint 1 with joint_sign -1
    assert arm.dh.joint_sign == (-1.0, 1.0, 1.0, 1.0, 1.0, 1.0)
    Q = np.random.default_rng(4).uniform(arm.lower, arm.upper, (50, 6))
    assert max(np.abs(fk_dh(arm.dh, q) - arm.fk(q, "tool0")).max() for q in Q) < 1e-9


@pytest.mark.parametrize("sketch", [ABB_LIKE, KUKA_LIKE], ids=["abb_like", "kuka_like"])
def test_ik_of_a_urdf_arm_returns_the_configuration(tmp_path: Path, sketch: ArmSketch) -> None:
    arm = _arm(tmp_path, sketch)
    rng = np.random.default_rng(8)
    for q in rng.uniform(arm.lower, arm.upper, (60, 6)):
        result = arm.ik(arm.fk(q))
        assert result.ok, result.reason
        assert np.abs(result.solutions - q).max(axis=1).min() < 1e-7
        for sol in result.solutions[:4]:
            assert np.abs(arm.fk(sol) - arm.fk(q)).max() < 1e-9


def _pose_error(q: np.ndarray, arm: Arm, T: np.ndarray) -> np.ndarray:
    Tq = arm.fk(q)
    rot = Rotation.from_matrix(T[:3, :3].T @ Tq[:3, :3]).as_rotvec()
    return np.concatenate([Tq[:3, 3] - T[:3, 3], 0.3 * rot])


def test_every_branch_of_the_kuka_like_arm_found_by_numerical_search(tmp_path: Path) -> None:
    arm = _arm(tmp_path, KUKA_LIKE)
    q = np.array([0.4, -0.6, 0.9, 0.7, -0.8, 0.3])
    T = arm.fk(q)
    analytic = arm.ik(T).solutions
    rng = np.random.default_rng(2)
    found = 0
    for q0 in rng.uniform(arm.lower, arm.upper, (40, 6)):
        res = least_squares(_pose_error, q0, args=(arm, T), bounds=(arm.lower, arm.upper),
                            xtol=1e-15, ftol=1e-15, gtol=1e-15)  # fmt: skip
        if np.linalg.norm(res.fun) < 1e-10:
            found += 1
            assert np.abs(analytic - res.x).max(axis=1).min() < 1e-6
    assert found > 0


def test_shipped_urdf_given_as_a_path_is_the_built_in_model() -> None:
    name = "abb_irb2600_20_165"
    by_path = Arm(str(URDF_DIR / f"{name}.urdf"))
    assert by_path.dh == dh_table(name)
    q = np.array([0.2, 0.1, -0.3, 0.4, 0.6, -0.5])
    assert np.allclose(by_path.ik(by_path.fk(q)).solutions, Arm(name).ik(Arm(name).fk(q)).solutions)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_derived_dh_rows_are_the_documented_abb_table(name: str) -> None:
    spec, table = MODELS[name], dh_table(name)
    h = np.pi / 2
    assert table.a_m == pytest.approx((spec.a1, spec.a2, spec.a3, 0, 0, 0), abs=1e-12)
    assert table.d_m == pytest.approx((spec.d1, 0, 0, spec.d4, 0, spec.d6), abs=1e-12)
    assert table.alpha_rad == pytest.approx((-h, 0, -h, h, -h, 0), abs=1e-12)
    assert table.theta_offset_rad == pytest.approx((0, -h, 0, 0, 0, np.pi), abs=1e-12)


def test_a_dh_table_that_does_not_match_the_urdf_is_refused() -> None:
    with pytest.raises(UrdfError, match="does not match the URDF"):
        Arm("abb_irb2600_20_165", dh=dh_table("abb_irb4600_60_205"))
    assert Arm("abb_irb2600_20_165", dh=dh_table("abb_irb2600_20_165")).dh is not None


@pytest.mark.parametrize(
    ("change", "joint", "words"),
    [
        ({"axes": ((0, 0, 1), (0, 0.6, 0.8), *ABB_LIKE.axes[2:])}, "joint_2", "perpendicular"),
        ({"axes": (*ABB_LIKE.axes[:2], (1, 0, 0), *ABB_LIKE.axes[3:])}, "joint_3", "parallel"),
        (
            {"points": (*ABB_LIKE.points[:4], (0.945, 0, 1.29), ABB_LIKE.points[5])},
            "joint_5",
            "not spherical",
        ),
        ({"points": ((0.05, 0, 0.445), *ABB_LIKE.points[1:])}, "joint_1", "origin"),
        ({"axes": ((0, 1, 0), *ABB_LIKE.axes[1:])}, "joint_1", "base z"),
    ],
    ids=["j2_tilted", "j3_crossed", "wrist_offset", "j1_off_origin", "j1_horizontal"],
)
def test_a_chain_that_is_not_opw_is_refused_naming_the_joint(
    tmp_path: Path, change: dict, joint: str, words: str
) -> None:
    with pytest.raises(NotOpwError, match=words) as info:
        _arm(tmp_path, ABB_LIKE.with_(**change))
    assert info.value.joint == joint


def test_package_uris_resolved_through_package_paths(tmp_path: Path) -> None:
    pkg = tmp_path / "share" / "my_arm_support"
    for i, link in enumerate(ABB_LIKE.links):
        write_stl(pkg / "meshes" / f"{link}.stl", (0.1, 0.1, 0.05 + 0.01 * i))
    sketch = ABB_LIKE.with_(
        mesh_uris={link: f"package://my_arm_support/meshes/{link}.stl" for link in ABB_LIKE.links},
        visual_uris={"link_1": "package://my_arm_support/meshes/not_there.dae"},
    )
    path = write_urdf(tmp_path / "urdf" / "arm.urdf", sketch)
    with pytest.raises(MeshError, match="package://my_arm_support") as info:
        Arm(path)  # no search path: refused naming the first link with a mesh
    assert info.value.link == "base_link"
    arm = Arm(path, package_paths=[tmp_path / "share"])
    assert sum(len(v) for v in arm.loaded.meshes.values()) == 7
    assert {i.body for i in arm.collision.infos} >= set(ABB_LIKE.links)


def test_package_uris_resolved_through_ros_package_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = tmp_path / "ws" / "my_arm_support"
    write_obj(pkg / "m" / "l1.obj", (0.1, 0.1, 0.1))
    sketch = ABB_LIKE.with_(mesh_uris={"link_1": "package://my_arm_support/m/l1.obj"})
    path = write_urdf(tmp_path / "arm.urdf", sketch)
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'elsewhere'}:{tmp_path / 'ws'}")
    assert Arm(path).loaded.meshes["link_1"] == [(pkg / "m" / "l1.obj").resolve()]


def test_relative_mesh_paths_are_relative_to_the_urdf(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    write_stl(tmp_path / "robot" / "meshes" / "l3.stl", (0.2, 0.1, 0.1))
    sketch = ABB_LIKE.with_(mesh_uris={"link_3": "meshes/l3.stl"})
    path = write_urdf(tmp_path / "robot" / "arm.urdf", sketch)
    monkeypatch.chdir(tmp_path)
    assert Arm(path).loaded.meshes["link_3"][0].name == "l3.stl"


def test_missing_or_unreadable_collision_mesh_is_refused_naming_link_and_path(
    tmp_path: Path,
) -> None:
    sketch = ABB_LIKE.with_(mesh_uris={"link_2": "meshes/gone.stl"})
    with pytest.raises(MeshError, match="link_2") as info:
        _arm(tmp_path, sketch)
    assert "gone.stl" in str(info.value)
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "bad.stl").write_text("this is not an STL file\n")
    with pytest.raises(MeshError, match="link_2") as info:
        _arm(tmp_path, ABB_LIKE.with_(mesh_uris={"link_2": "meshes/bad.stl"}), "bad")
    assert "bad.stl" in str(info.value)


def test_mesh_collision_against_an_obstacle(tmp_path: Path) -> None:
    from robots import Shape
    from robots.transforms import make_transform

    write_stl(tmp_path / "m" / "l6.stl", (0.06, 0.3, 0.3))  # a plate on the flange
    arm = _arm(tmp_path, ABB_LIKE.with_(mesh_uris={"link_6": "m/l6.stl"}))
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.3, 0.0])
    link6 = arm.fk(q, "flange") @ make_transform(t=[-0.1, 0.0, 0.0])  # the mesh's frame
    near = link6 @ make_transform(t=[0.0, 0.0, 0.17])  # 1 cm beyond the plate's edge (0.15 m)
    arm.add_obstacles([Shape("sphere", (0.01,), near, "probe")])
    assert not arm.in_collision(q)
    assert arm.clearance(q) == pytest.approx(0.01, abs=1e-6)
    # a mesh is its surface (coal BVH): the probe crossing the face is a contact
    arm.add_obstacles([Shape("sphere", (0.01,), link6 @ make_transform(t=[0, 0, 0.155]), "in")])
    assert arm.in_collision(q) and arm.collision.in_collision_exhaustive(q)
    assert any("link_6" in a or "link_6" in b for a, b in arm.colliding_pairs(q))


@pytest.mark.parametrize("writer", [write_stl, write_obj, write_dae], ids=["stl", "obj", "dae"])
def test_stl_obj_and_dae_meshes_are_the_same_box(tmp_path: Path, writer) -> None:
    from robots import Shape
    from robots.transforms import make_transform

    suffix = {write_stl: "stl", write_obj: "obj", write_dae: "dae"}[writer]
    writer(tmp_path / "m" / f"l6.{suffix}", (0.06, 0.3, 0.3))
    arm = _arm(tmp_path, ABB_LIKE.with_(mesh_uris={"link_6": f"m/l6.{suffix}"}))
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.3, 0.0])
    link6 = arm.fk(q, "flange") @ make_transform(t=[-0.1, 0.0, 0.0])
    arm.add_obstacles([Shape("sphere", (0.01,), link6 @ make_transform(t=[0, 0.2, 0]), "p")])
    assert arm.clearance(q) == pytest.approx(0.2 - 0.15 - 0.01, abs=1e-6)


def test_limits_are_narrowed_never_widened(tmp_path: Path) -> None:
    narrow = [[-1.0, 1.0], [-0.5, 0.8], [-1.0, 0.5], [-3.0, 3.0], [-2.0, 2.0], [-3.0, 3.0]]
    arm = _arm(tmp_path, ABB_LIKE, position_limits=narrow)
    assert arm.lower.tolist() == [r[0] for r in narrow]
    assert arm.urdf_lower.tolist() == [-3.0] * 6
    q = np.array([0.2, 0.1, -0.3, 0.4, 0.6, -0.5])
    sols = arm.ik(arm.fk(q)).solutions
    assert len(sols) and np.all(sols >= arm.lower) and np.all(sols <= arm.upper)
    wide = [list(r) for r in narrow]
    wide[2] = [-3.5, 0.5]
    with pytest.raises(LimitsError, match="widens") as info:
        _arm(tmp_path, ABB_LIKE, position_limits=wide)
    assert info.value.joint == "joint_3"
    with pytest.raises(LimitsError, match="not below"):
        _arm(tmp_path, ABB_LIKE, position_limits=[[0.5, 0.1], *narrow[1:]])


def test_builtin_dh_and_urdf_agree_with_fk_dh() -> None:
    arm = Arm()
    q = np.array([0.3, -0.2, 0.4, 1.0, -0.7, 2.0])
    assert np.abs(fk_dh(arm.dh, q) - arm.fk(q, "tool0")).max() < 1e-12
