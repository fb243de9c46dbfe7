"""Errors of the RAPID interpreter: refused at load time (syntax, names, types), raised at run
time (an ``ERRNO`` the module's ``ERROR`` handlers see) and a program stopped by an error."""

from __future__ import annotations

from cell.errors import CellError


class RapidError(CellError):
    """Base of the interpreter's errors (a :class:`cell.errors.CellError`: the CLI prints it as
    one line); ``line`` is the module line (1-based, 0: none)."""

    def __init__(self, text: str, line: int = 0, source: str = "") -> None:
        self.text, self.line, self.source = text, line, source
        super().__init__(text)

    def __str__(self) -> str:
        where = f"{self.source}:" if self.source else ""
        where += f"{self.line}: " if self.line else (" " if where else "")
        if where and not self.line and self.source:
            where = f"{self.source}: "
        return f"{where}{self.text}" if self.line or self.source else self.text


class RapidLoadError(RapidError):
    """The module is refused before it runs (what RobotWare reports when loading it)."""


class RapidRunError(RapidError):
    """A recoverable run-time error: ``errno`` is the value of ``ERRNO`` in a handler and
    ``name`` its predefined constant (``ERR_OUTOFBND``, ``ERR_DEV_MAXTIME``...)."""

    def __init__(self, name: str, text: str, line: int = 0, errno: int | None = None) -> None:
        from cell.rapid.interp.consts import ERRNOS

        self.name = name
        self.errno = ERRNOS[name] if errno is None else errno
        super().__init__(f"{name}: {text}", line)


class RapidStopped(RapidError):  # noqa: N818 (RAPID: "execution stopped")
    """Program execution stopped: an error no handler took, or a routine without RETURN."""
