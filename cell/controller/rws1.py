"""The :class:`cell.controller.ControllerManager` of an IRC5 with RobotWare 6: Robot Web
Services 1.0 through ``abb-robot-client`` (digest authentication, a session cookie).

``loadmod`` has no wrapper in the client: it is ``POST rw/rapid/tasks/TASK?action=loadmod``
with ``modulepath`` and ``replace``; loading a module and resetting the program pointer need
mastership, requested and released around them. The password is kept only in the client's
authentication object: never logged, stored or put in a message.
"""

from __future__ import annotations

import functools
import logging
from typing import Any

from cell.controller.errors import ControllerError
from cell.controller.manager import ControllerState

log = logging.getLogger(__name__)


class Rws1Manager:
    """RWS 1.0 at ``url`` (``http://HOST[:PORT]``) as ``user``."""

    def __init__(self, url: str, user: str, password: str, timeout_s: float = 10.0) -> None:
        if not url.startswith(("http://", "https://")):
            raise ControllerError(url, "connect", "expected http://HOST[:PORT]")
        try:
            from abb_robot_client.rws import RWS
        except ImportError as exc:
            raise ControllerError(url, "connect", f"abb-robot-client missing: {exc}") from exc
        self.url = url.rstrip("/")
        self._rws: Any = RWS(self.url, user, password)
        session = self._rws._session  # the client sets no timeout: a dead controller would hang
        session.request = functools.partial(session.request, timeout=timeout_s)

    def _call(self, step: str, fn: Any, *args: Any) -> Any:
        try:
            return fn(*args)
        except Exception as exc:  # requests' and ABBException: the reason, never the password
            text = str(exc)
            if "401" in text:
                text = "authentication refused (user or password wrong)"
            raise ControllerError(self.url, step, text) from None

    def upload(self, name: str, data: bytes) -> str:
        """``PUT fileservice/$RAMDISK/NAME``; the path the controller loads it from."""
        ramdisk = self._call("ramdisk path", self._rws.get_ramdisk_path)
        path = f"{ramdisk.rstrip('/')}/{name}"
        self._call("upload", self._rws.upload_file, path.lstrip("/"), data)
        log.info("uploaded %s (%d bytes)", path, len(data))
        return path

    def _mastership(self, action: str) -> None:
        self._call(f"mastership {action}", self._rws._do_post, f"rw/mastership?action={action}")

    def load_module(self, path: str, task: str) -> None:
        """Load ``path`` into ``task``, replacing a module of the same name."""
        self._mastership("request")
        try:
            self._call("loadmod", self._rws._do_post, f"rw/rapid/tasks/{task}?action=loadmod",
                       {"modulepath": path, "replace": "true"})  # fmt: skip
        finally:
            self._mastership("release")

    def reset_pp(self) -> None:
        """Program pointer to main."""
        self._mastership("request")
        try:
            self._call("reset program pointer", self._rws.resetpp)
        finally:
            self._mastership("release")

    def start(self, task: str) -> None:
        """Start ``task`` (continuous cycle)."""
        self._call("start", self._rws.start, "forever", [task])

    def stop(self) -> None:
        """Stop RAPID execution."""
        self._call("stop", self._rws.stop)

    def state(self) -> ControllerState:
        """Controller state, execution state and operating mode."""
        ctrl = self._call("controller state", self._rws.get_controller_state)
        exe = self._call("execution state", self._rws.get_execution_state)
        mode = self._call("operating mode", self._rws.get_operation_mode)
        return ControllerState(str(ctrl), str(exe.ctrlexecstate), str(mode))

    def pulse(self, signal: str) -> None:
        """``POST rw/iosystem/signals/NETWORK/UNIT/NAME?action=set`` with 1, then 0 (network
        and unit default to ``Local/DRV_1``)."""
        parts = signal.split("/")
        if len(parts) not in (1, 3) or not all(parts):
            raise ControllerError(self.url, "pulse", f"signal {signal!r}: NAME or "
                                                     "NETWORK/UNIT/NAME")  # fmt: skip
        network, unit, name = parts if len(parts) == 3 else ("Local", "DRV_1", parts[0])
        for value in (1, 0):
            self._call(f"set {signal}={value}", self._rws.set_digital_io, name, value, network,
                       unit)  # fmt: skip

    def close(self) -> None:
        """Log out."""
        self._rws.close()
