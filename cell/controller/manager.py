"""What the cell computer asks of a controller beside the link: the
:class:`ControllerManager` interface (RWS 1.0 in :mod:`cell.controller.rws1`; an RWS 2.0
adapter for OmniCore implements the same) and the :class:`ControllerState` it reports."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol


@dataclass(frozen=True)
class ControllerState:
    """The controller as RWS reports it: ``controller`` (``motoron``, ``motoroff``,
    ``guardstop``, ``emergencystop``, ``emergencystopreset``, ``sysfail``, ``init``),
    ``execution`` (``running`` or ``stopped``) and ``opmode`` (``AUTO``, ``MANR``, ...)."""

    controller: str
    execution: str
    opmode: str

    def problem(self) -> str | None:
        """Why a run cannot go on in this state, or None."""
        if self.controller in ("emergencystop", "emergencystopreset"):
            return f"emergency stop (controller state {self.controller})"
        if self.controller == "guardstop":
            return "guard stop: a safety circuit is open (controller state guardstop)"
        if self.controller != "motoron":
            return f"motors off (controller state {self.controller})"
        if self.execution != "running":
            return f"RAPID execution {self.execution}"
        return None


class ControllerManager(Protocol):
    """A controller's management interface (names the RAPID module's steps)."""

    url: str

    def upload(self, name: str, data: bytes) -> str:
        """Write ``data`` as ``name`` on the controller's RAM disk; returns its path there."""
        ...

    def load_module(self, path: str, task: str) -> None:
        """Load (or replace) the module file ``path`` into RAPID task ``task``."""
        ...

    def reset_pp(self) -> None:
        """Set the program pointer to main."""
        ...

    def start(self, task: str) -> None:
        """Start RAPID execution of ``task``."""
        ...

    def stop(self) -> None:
        """Stop RAPID execution."""
        ...

    def state(self) -> ControllerState:
        """The controller's state now."""
        ...

    def pulse(self, signal: str) -> None:
        """Set the digital output ``signal`` (``NAME`` or ``NETWORK/UNIT/NAME``) to 1, then
        0: e.g. the cameras' trigger line."""
        ...

    def close(self) -> None:
        """End the session."""
        ...
