"""Errors of the QIF writer and reader (:mod:`cell.review.qif`)."""

from __future__ import annotations

from cell.errors import CellError


class QifError(CellError):
    """A QIF file is invalid or a report cannot be written as QIF. ``path`` names the file (or
    the report), ``problems`` lists the schema's messages as ``line N: message``."""

    def __init__(self, path: str, problems: list[str]) -> None:
        self.path = path
        self.problems = problems
        first = problems[0] if problems else "invalid"
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        super().__init__(f"{path}: {first}{more}")
