"""Exceptions of the ``robots`` package: one base, specific subclasses with payloads."""

from __future__ import annotations


class RobotModelError(Exception):
    """Base of every error raised by :mod:`robots`."""


class UnknownModelError(RobotModelError):
    """A model name is neither a built-in model nor a readable URDF path."""

    def __init__(self, name: str, known: list[str]) -> None:
        self.name = name
        self.known = known
        super().__init__(
            f"unknown robot model {name!r}: not a built-in model ({', '.join(known)}) "
            "and not a path to a .urdf file"
        )


class UrdfError(RobotModelError):
    """A URDF file could not be used (missing joints, frames or collision elements)."""

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class ShapeError(RobotModelError):
    """A collision shape description is malformed (unknown kind, bad size)."""

    def __init__(self, where: str, reason: str) -> None:
        self.where = where
        self.reason = reason
        super().__init__(f"{where}: {reason}")


class JointVectorError(RobotModelError):
    """A joint vector has the wrong length or holds non-finite values."""

    def __init__(self, q: object, expected: int) -> None:
        self.q = q
        self.expected = expected
        super().__init__(f"joint vector {q!r} must hold {expected} finite values (rad)")


class NotOpwError(RobotModelError):
    """A kinematic chain is not ortho-parallel with a spherical wrist (the OPW family)."""

    def __init__(self, joint: str, prop: str) -> None:
        self.joint = joint
        self.prop = prop
        super().__init__(f"not an ortho-parallel arm with a spherical wrist: {joint}: {prop}")


class LimitsError(RobotModelError):
    """Joint limits asked of an arm widen its URDF's limits or are malformed."""

    def __init__(self, joint: str, reason: str) -> None:
        self.joint = joint
        self.reason = reason
        super().__init__(f"{joint}: {reason}")


class MeshError(RobotModelError):
    """A collision mesh of a URDF link is missing or cannot be read."""

    def __init__(self, urdf: str, link: str, path: str, reason: str) -> None:
        self.urdf = urdf
        self.link = link
        self.path = path
        self.reason = reason
        super().__init__(f"{urdf}: link {link!r}: collision mesh {path}: {reason}")


class DHFormError(RobotModelError):
    """An arm's chain has no D-H table of the form the thermal model uses (frame 0 = base_link)."""

    def __init__(self, joint: str, reason: str) -> None:
        self.joint = joint
        self.reason = reason
        super().__init__(f"{joint}: {reason}")


class MeshFileError(RobotModelError):
    """A mesh file is missing, unreadable or holds no triangles."""

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class DesignError(RobotModelError):
    """A design cannot be chosen from its candidates (too few, or none determines the model)."""
