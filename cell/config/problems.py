"""Validation errors of the cell file as ``(field path, value, message)`` problems, the form
of :class:`cell.errors.ConfigError`; the truth file (``cell/sim/truth_file.py``) names its
fields with the same :func:`field_path`."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pydantic import ValidationError

from cell.errors import NO_VALUE


def field_path(loc: tuple[Any, ...]) -> str:
    """A pydantic error location as the file's field path: ``part.holes[3].normal``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out or "(top level)"


def pydantic_problems(
    exc: ValidationError,
    prefix: tuple[Any, ...] = (),
    shown: Callable[[object], object] = lambda value: value,
) -> list[tuple[str, object, str]]:
    """Every error of ``exc`` as ``(field path, value, message)``; an unknown key says so, a
    missing one is named without the mapping around it. ``prefix``: the location of the
    validated part in the file; ``shown``: how a value appears in the message."""
    problems = []
    for err in exc.errors():
        msg = err["msg"].removeprefix("Value error, ")
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        if err["type"] == "missing":  # pydantic's input is then the mapping around the key
            msg, err["input"] = "a required key is missing", NO_VALUE
        problems.append((field_path((*prefix, *err["loc"])), shown(err.get("input")), msg))
    return problems
