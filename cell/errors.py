"""Exceptions of the ``cell`` package: one base, specific subclasses with payloads."""

from __future__ import annotations


class CellError(Exception):
    """Base of every error raised by :mod:`cell`. The CLI prints its message, no traceback.

    Every subclass pickles with its message and payload whatever its ``__init__`` takes (an
    error raised in a worker process reaches the caller as raised)."""

    def __reduce__(self) -> tuple:
        return (_rebuilt, (type(self), self.args, dict(self.__dict__)))


def _rebuilt(cls: type[CellError], args: tuple, state: dict) -> CellError:
    """A :class:`CellError` of ``cls`` with ``args`` and attributes ``state``, without calling
    its ``__init__``."""
    error = cls.__new__(cls)
    Exception.__init__(error, *args)
    error.__dict__.update(state)
    return error


#: the value of a :class:`ConfigError` problem that has none to show (a YAML syntax error)
NO_VALUE: object = type("NoValue", (), {"__repr__": lambda self: "NO_VALUE"})()


class ConfigError(CellError):
    """A cell file is invalid. ``problems`` lists ``(field path, value, message)``; one line
    each, without the value when it is :data:`NO_VALUE`."""

    def __init__(self, path: str, problems: list[tuple[str, object, str]]) -> None:
        self.path = path
        self.problems = problems
        lines = [
            f"{path}: {field}: {msg}" + ("" if value is NO_VALUE else f" (value: {value!r})")
            for field, value, msg in problems
        ]
        super().__init__("\n".join(lines) if lines else f"{path}: invalid cell file")


class TruthFileError(ConfigError):
    """A simulated-truth file (``truth.yaml``) is invalid; same payload as :class:`ConfigError`."""


class TourMismatchError(CellError):
    """A tour does not belong to the cell (or robot) it is run with."""

    def __init__(self, tour: str, field: str, tour_value: object, cell_value: object) -> None:
        self.tour, self.field = tour, field
        super().__init__(
            f"{tour}: {field} is {tour_value!r} but the cell has {cell_value!r}: "
            "plan the tour for this cell (holecell plan CELL -o tour.json)"
        )
