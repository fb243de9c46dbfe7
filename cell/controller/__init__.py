"""Managing the robot controller beside the link: deploy the RAPID module and watch the
controller's state over its web services (:class:`ControllerManager`; RWS 1.0 for RobotWare 6
in :mod:`cell.controller.rws1`)."""

from cell.controller.errors import ControllerError
from cell.controller.manager import ControllerManager, ControllerState

__all__ = ["ControllerError", "ControllerManager", "ControllerState"]
