"""Moving the arm along the loaded trajectory for a run, surviving a dead link: load (and
reload) the trajectory, move to a stop and wait for "in position", reconnect within a budget,
stop the arm safely. A controller fault or a move timeout ends in :class:`RunFaultError`."""

from __future__ import annotations

import logging
import sqlite3
import time
from collections.abc import Callable
from typing import Any, Protocol, TypeVar

from cell.config.tours import stop_rows
from cell.errors import CellError
from cell.link import messages as m
from cell.link.client import ControllerClient
from cell.link.errors import LinkError, MoveTimeoutError, RequestRefusedError, RunFaultError
from planner import Tour

log = logging.getLogger(__name__)
T = TypeVar("T")


class EventLog(Protocol):
    """Where the motion steps record what happened (the run's store)."""

    def event(self, kind: str, text: str) -> None:
        """Record one event of ``kind`` (``"motion"``, ``"link"``, ``"fault"``)."""


class Motion:
    """The motion steps of :class:`cell.run.runner.Runner` (its base): uses ``client``, ``store``
    and ``options`` (``move_timeout_s``, ``reconnect_budget_s``, ``settle_s``)."""

    client: ControllerClient
    store: EventLog
    options: Any
    _loaded: Tour | None = None
    _need_load: bool = False

    # --- motion ----------------------------------------------------------------------------
    def _load(self, tour: Tour) -> None:
        self._loaded, self._need_load = tour, True
        self._call("load trajectory", self._ensure_loaded)

    def _ensure_loaded(self) -> None:
        if self._need_load and self._loaded is not None:
            self.client.load_trajectory(self._loaded.trajectory, stop_rows(self._loaded),
                                        self._loaded.dt)  # fmt: skip
            self._need_load = False

    def _call(self, where: str, fn: Callable[[], T]) -> T:
        """``fn()`` on the link, reconnecting (and reloading) while the link is dead."""
        while True:
            try:
                self._ensure_loaded()
                return fn()
            except LinkError as exc:
                self._recover(exc, where)

    def _move(self, k: int, where: str) -> m.Status:
        """Bring the arm to stop ``k`` of the loaded tour, surviving a dead link."""
        deadline = time.monotonic() + self.options.move_timeout_s

        def go() -> m.Status:
            self.client.move_to_stop(k)
            return self.client.wait_in_position(k, self.options.move_timeout_s)

        while True:
            try:
                st = self._call(where, go)
            except MoveTimeoutError as exc:
                self._safe_stop()
                raise RunFaultError(where, exc.state, "move timed out") from exc
            except RequestRefusedError as exc:
                if exc.code == m.Nak.NOT_LOADED:  # the controller lost the trajectory
                    self.store.event("motion", f"{where}: {exc}; reloading")
                    self._need_load = True
                    continue
                st = self._call(where, self.client.status)
                if st.state in (m.State.ESTOP, m.State.FAULT):
                    raise RunFaultError(where, st.state.name, st.fault.name) from exc
                raise
            if st.state == m.State.IN_POSITION and st.at_stop == k:
                return st
            if st.state in (m.State.ESTOP, m.State.FAULT):
                raise RunFaultError(where, st.state.name, st.fault.name)
            self.store.event("motion", f"{where}: {st.state.name} ({st.fault.name}), moving on")
            if time.monotonic() > deadline:
                raise RunFaultError(where, st.state.name, "move timed out")

    def _recover(self, exc: LinkError, where: str) -> None:
        """Reconnect within the budget (LinkError beyond it); the trajectory is reloaded."""
        self.store.event("link", f"{where}: {exc}; reconnecting")
        self.client.reconnect(self.options.reconnect_budget_s)
        self._need_load = True
        self.store.event("link", f"{where}: link restored")

    def _safe_stop(self) -> None:
        """Ask the controller to stop the arm; a failure is recorded, never raised."""
        try:
            self.client.stop()
        except (CellError, OSError, KeyboardInterrupt) as exc:
            try:
                self.store.event("fault", f"stop request failed: {exc}")
            except (CellError, sqlite3.Error) as err:
                log.error("stop request failed (%s) and could not be recorded: %s", exc, err)

    def _settled_status(self) -> m.Status:
        time.sleep(self.options.settle_s)
        return self._call("status", self.client.status)
