"""Arm models: URDF, Pinocchio model, OPW kinematics, collision and thermal error model."""

from robots.arm import Arm, LimitScaling, urdf_path
from robots.dh import DHTable, fk_dh
from robots.dh_models import dh_table
from robots.errors import (
    DHFormError,
    JointVectorError,
    LimitsError,
    MeshError,
    NotOpwError,
    RobotModelError,
    ShapeError,
    UnknownModelError,
    UrdfError,
)
from robots.ik import IKResult, solve_ik
from robots.models import DEFAULT_MODEL, JOINT_NAMES, MODELS, ArmSpec
from robots.shapes import Shape

__all__ = [
    "DEFAULT_MODEL",
    "JOINT_NAMES",
    "MODELS",
    "Arm",
    "ArmSpec",
    "DHFormError",
    "DHTable",
    "IKResult",
    "JointVectorError",
    "LimitScaling",
    "LimitsError",
    "MeshError",
    "NotOpwError",
    "RobotModelError",
    "Shape",
    "ShapeError",
    "UnknownModelError",
    "UrdfError",
    "dh_table",
    "fk_dh",
    "solve_ik",
    "urdf_path",
]
