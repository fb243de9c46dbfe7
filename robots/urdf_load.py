"""Reading an arm's URDF: collision meshes resolved and checked, visuals dropped, joint axes read.

Mesh URIs: ``package://pkg/rest`` is looked up as ``<dir>/pkg/rest`` in each directory of
``package_paths`` (in order), then of ``ROS_PACKAGE_PATH``; ``file://`` and absolute paths are
used as they are; a plain relative path is relative to the URDF's folder. Only ``<collision>``
elements are kept (visual meshes are never opened for planning or checks); a collision mesh
that is missing, not a file, unreadable or of a kind coal cannot load is refused naming the
link and the path. Collision meshes are used as given (coal BVH of the triangles, not convex
hulls: a hull would fill the concave parts of a link, e.g. the fork of an upper arm, and
report contacts that are not there).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from robots.errors import MeshError, UrdfError
from robots.meshes import MESH_SUFFIXES as OBSTACLE_MESH_SUFFIXES
from robots.meshes import mesh_file_problem
from robots.opw import JointLine

Array = np.ndarray

#: mesh file kinds coal's loader (assimp) reads for collision
MESH_SUFFIXES = (*OBSTACLE_MESH_SUFFIXES, ".dae")


@dataclass(frozen=True)
class LoadedUrdf:
    """A URDF as Pinocchio needs it, with what the kinematics derivation reads.

    Attributes:
        path: the URDF file.
        model, collision: Pinocchio's kinematic model and collision geometry.
        joint_names: the six joint names in chain order.
        lines: joint axis lines at q = 0 in ``base_link`` (m).
        T_base_tool0_zero, T_tool0_flange: poses at q = 0 (4x4).
        meshes: resolved collision mesh files, per link.
    """

    path: Path
    model: pin.Model
    collision: pin.GeometryModel
    joint_names: tuple[str, ...]
    lines: list[JointLine]
    T_base_tool0_zero: Array
    T_tool0_flange: Array
    meshes: dict[str, list[Path]]


def search_dirs(package_paths: Sequence[str | Path] = ()) -> list[Path]:
    """Directories searched for ``package://`` URIs: ``package_paths``, then ROS_PACKAGE_PATH."""
    env = [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    return [Path(p) for p in (*package_paths, *env)]


def resolve_mesh(uri: str, urdf_dir: Path, dirs: Sequence[Path]) -> tuple[Path | None, str]:
    """The file a mesh URI names, or ``(None, what was tried)``."""
    if uri.startswith("package://"):
        rest = uri[len("package://") :]
        tried = [d / rest for d in dirs]
        for cand in tried:
            if cand.exists():
                return cand, ""
        where = ", ".join(str(d) for d in dirs) or "none given"
        return None, f"not found in robot.package_paths or ROS_PACKAGE_PATH (searched: {where})"
    path = Path(uri[len("file://") :] if uri.startswith("file://") else uri)
    if not path.is_absolute():
        path = urdf_dir / path
    return (path, "") if path.exists() else (None, f"no such file ({path})")


def _check_mesh(path: Path) -> str:
    return mesh_file_problem(path, MESH_SUFFIXES)


def collision_xml(path: Path, package_paths: Sequence[str | Path] = ()) -> tuple[str, dict]:
    """The URDF text with visuals removed and collision mesh URIs made absolute paths."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as exc:
        raise UrdfError(str(path), f"is not a readable URDF: {exc}") from exc
    dirs = search_dirs(package_paths)
    meshes: dict[str, list[Path]] = {}
    for link in root.iter("link"):
        name = link.get("name", "?")
        for visual in link.findall("visual"):
            link.remove(visual)
        for mesh in link.findall("collision/geometry/mesh"):
            uri = mesh.get("filename", "")
            resolved, why = resolve_mesh(uri, path.parent, dirs)
            if resolved is None:
                raise MeshError(str(path), name, uri, why)
            problem = _check_mesh(resolved)
            if problem:
                raise MeshError(str(path), name, str(resolved), problem)
            mesh.set("filename", str(resolved.resolve()))
            meshes.setdefault(name, []).append(resolved.resolve())
    return ET.tostring(root, encoding="unicode"), meshes


def _unreadable_mesh(path: Path, meshes: dict[str, list[Path]], exc: Exception) -> Exception:
    """The mesh coal cannot load (named with its link), else a URDF error."""
    import coal

    loader = coal.MeshLoader()
    for link, files in meshes.items():
        for f in files:
            try:
                loader.load(str(f), np.ones(3))
            except Exception as mesh_exc:  # coal raises plain exceptions
                return MeshError(str(path), link, str(f), f"cannot be read: {mesh_exc}")
    return UrdfError(str(path), f"cannot be read by Pinocchio: {exc}")


def _chain_checks(path: Path, model: pin.Model) -> tuple[str, ...]:
    names = tuple(model.names)[1:]
    if model.nq != 6 or model.nv != 6 or model.njoints != 7:
        raise UrdfError(
            str(path), f"needs six revolute joints with limits, found {model.nq} ({names})"
        )
    for i in range(1, 7):
        short = model.joints[i].shortname()
        if not short.startswith("JointModelR") or "Unbounded" in short or "RUB" in short:
            raise UrdfError(str(path), f"{names[i - 1]}: is not a revolute joint ({short})")
        if model.parents[i] != i - 1:
            raise UrdfError(str(path), f"{names[i - 1]}: the joints do not form one serial chain")
    for frame in ("tool0",):
        if not model.existFrame(frame):
            raise UrdfError(str(path), f"has no frame {frame!r}")
    return names


def joint_lines(model: pin.Model, names: tuple[str, ...]) -> list[JointLine]:
    """Each joint's axis at q = 0 in the root frame: a point on it (m) and its direction."""
    data = model.createData()
    q0 = pin.neutral(model)
    pin.computeJointJacobians(model, data, q0)
    lines = []
    for i in range(1, 7):
        J = pin.getJointJacobian(model, data, i, pin.ReferenceFrame.WORLD)[:, i - 1]
        lines.append(
            JointLine(
                names[i - 1],
                tuple(data.oMi[i].translation.tolist()),
                tuple(np.asarray(J[3:]).tolist()),
            )
        )
    return lines


def load_urdf(path: str | Path, package_paths: Sequence[str | Path] = ()) -> LoadedUrdf:
    """Read an arm's URDF with its collision meshes (see the module docstring for the rules)."""
    path = Path(path)
    if not path.is_file():
        raise UrdfError(str(path), "no such file")
    xml, meshes = collision_xml(path, package_paths)
    try:
        model = pin.buildModelFromXML(xml)
    except (RuntimeError, ValueError) as exc:
        raise UrdfError(str(path), f"cannot be read by Pinocchio: {exc}") from exc
    names = _chain_checks(path, model)
    try:
        collision = pin.buildGeomFromUrdfString(model, xml, pin.GeometryType.COLLISION)
    except (RuntimeError, ValueError) as exc:
        raise _unreadable_mesh(path, meshes, exc) from exc
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    T_tool0 = data.oMf[model.getFrameId("tool0")].homogeneous
    T_flange = (
        data.oMf[model.getFrameId("flange")].homogeneous if model.existFrame("flange") else T_tool0
    )
    return LoadedUrdf(
        path=path,
        model=model,
        collision=collision,
        joint_names=names,
        lines=joint_lines(model, names),
        T_base_tool0_zero=T_tool0,
        T_tool0_flange=np.linalg.inv(T_tool0) @ T_flange,
        meshes=meshes,
    )
