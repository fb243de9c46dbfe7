"""Exceptions of :mod:`robots.thermal`, all subclasses of :class:`robots.errors.RobotModelError`."""

from __future__ import annotations

from robots.errors import RobotModelError


class ThermalError(RobotModelError):
    """Base of every error raised by the thermal error model."""


class ThermalSpecError(ThermalError):
    """A thermal model description is inconsistent (sensor map, reference temperatures, terms)."""

    def __init__(self, field: str, value: object, reason: str) -> None:
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"thermal model: {field}: {reason} (value: {value!r})")


class ThermalDataError(ThermalError):
    """Observations or poses cannot be used (bad column, unit, value or unknown target).

    ``source`` names the file (or data set), ``line`` the file line (header = line 1).
    """

    def __init__(
        self, source: str, reason: str, line: int | None = None, column: str | None = None
    ) -> None:
        self.source = source
        self.reason = reason
        self.line = line
        self.column = column
        where = source
        if line is not None:
            where += f", line {line}"
        if column is not None:
            where += f", column {column!r}"
        super().__init__(f"{where}: {reason}")


class UnidentifiableError(ThermalError):
    """The observations determine none of the requested terms; ``refused`` maps term to reason."""

    def __init__(self, reason: str, refused: dict[str, str] | None = None) -> None:
        self.reason = reason
        self.refused = dict(refused or {})
        details = "; ".join(f"{k}: {v}" for k, v in self.refused.items())
        super().__init__(
            f"thermal identification impossible: {reason}" + (f" ({details})" if details else "")
        )


class ThermalModelFileError(ThermalError):
    """A thermal.json file is missing fields or holds invalid values."""

    def __init__(self, path: str, field: str, reason: str) -> None:
        self.path = path
        self.field = field
        self.reason = reason
        super().__init__(f"{path}: {field}: {reason}")
