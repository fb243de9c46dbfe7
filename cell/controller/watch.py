"""Watch the controller's state during a run (motors off, emergency stop, execution stopped)
and stop the run cleanly when it can no longer go on, before a link timeout would.

:class:`ControllerWatch` polls the :class:`ControllerManager` in a thread;
:class:`WatchedClient` wraps the link's client so that the run's next request raises
:class:`cell.link.errors.RunFaultError` with the state the controller reported.
"""

from __future__ import annotations

import logging
import threading
from typing import Any

from cell.controller.errors import ControllerError
from cell.controller.manager import ControllerManager, ControllerState
from cell.link.errors import RunFaultError

log = logging.getLogger(__name__)


class ControllerWatch:
    """Polls ``manager.state()`` every ``period_s``; ``problem`` is the first reason the run
    must stop (None while the controller runs), ``last`` the last state read."""

    def __init__(self, manager: ControllerManager, period_s: float = 0.5) -> None:
        self.manager, self.period_s = manager, period_s
        self.problem: str | None = None
        self.last: ControllerState | None = None
        self.unreachable = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="holecell-rws", daemon=True)

    def start(self) -> ControllerWatch:
        """Read the state once (a controller that cannot run is refused at once), then
        watch in the background."""
        self.poll()
        if self.problem is not None:
            raise ControllerError(self.manager.url, "state", self.problem)
        self._thread.start()
        return self

    def poll(self) -> None:
        """Read the state once."""
        try:
            self.last = self.manager.state()
        except ControllerError as exc:  # RWS unreachable: the link decides, not the watch
            self.unreachable += 1
            log.warning("%s", exc)
            return
        if self.problem is None:
            self.problem = self.last.problem()

    def _run(self) -> None:
        while not self._stop.wait(self.period_s) and self.problem is None:
            self.poll()

    def close(self) -> None:
        """Stop watching."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)


#: link requests that move or need the controller running; ``stop``, ``close`` and the
#: statistics pass through so that the run can still stop the arm and close
GUARDED = ("connect", "status", "load_trajectory", "move_to_stop", "wait_in_position",
           "reconnect", "reset")  # fmt: skip


class WatchedClient:
    """A :class:`cell.link.client.ControllerClient` that refuses the guarded requests once
    the watch reports a problem."""

    def __init__(self, client: Any, watch: ControllerWatch) -> None:
        self._client, self.watch = client, watch

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._client, name)
        if name not in GUARDED:
            return attr

        def guarded(*args: Any, **kwargs: Any) -> Any:
            self._check(name)
            return attr(*args, **kwargs)

        return guarded

    def close(self) -> None:
        """Stop watching, log out of RWS and close the link."""
        self.watch.close()
        self.watch.manager.close()
        self._client.close()

    def _check(self, request: str) -> None:
        problem = self.watch.problem
        if problem is not None:
            last = self.watch.last
            state = "unknown" if last is None else (
                f"{last.controller}, execution {last.execution}, mode {last.opmode}")  # fmt: skip
            raise RunFaultError(f"{request} (RWS {self.watch.manager.url})", state, problem)
