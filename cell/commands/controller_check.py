"""Connecting to the cell's controller and checking that it drives the cell file's robot: the
first step of ``holecell run``, ``calibrate cell`` and ``survey``."""

from __future__ import annotations

from typing import Any

from cell.errors import CellError


def connect_checked(client: Any, port: str, robot_model: str) -> None:
    """Connect ``client`` (a :class:`cell.link.client.ControllerClient`) and raise
    :class:`CellError` naming both models when the controller at ``port`` drives another robot
    than the cell file's ``robot_model``."""
    client.connect()
    if client.identity.robot_model != robot_model:
        raise CellError(f"controller at {port} drives {client.identity.robot_model!r}, "
                        f"the cell has {robot_model!r}")  # fmt: skip
