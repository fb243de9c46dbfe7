"""ABB arm models: URDF, Pinocchio model, kinematics, collision and thermal error model."""

from robots.errors import RobotModelError

__all__ = ["RobotModelError"]
