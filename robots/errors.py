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
