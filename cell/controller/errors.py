"""Errors of controller management, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class ControllerError(CellError):
    """A controller-management step failed; ``step`` names it (upload, loadmod, ...)."""

    def __init__(self, url: str, step: str, reason: str) -> None:
        self.url, self.step, self.reason = url, step, reason
        super().__init__(f"controller {url}: {step}: {reason}")
