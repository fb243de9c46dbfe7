"""Exceptions of the :mod:`planner` package: one base, specific subclasses with payloads."""

from __future__ import annotations

from collections import Counter


class PlanningError(Exception):
    """Base of every error raised by :mod:`planner`. The CLI prints its message, no traceback."""


class OptionsError(PlanningError):
    """An option has a value the planner cannot use. ``field`` names it, ``value`` holds it."""

    def __init__(self, field: str, value: object, message: str) -> None:
        self.field = field
        self.value = value
        super().__init__(f"planner option {field}={value!r}: {message}")


class UnreachableHoleError(PlanningError):
    """Holes have no collision-free configuration (raised in strict mode).

    ``reasons`` maps hole id to the reason, e.g. ``"out of reach"``.
    """

    def __init__(self, reasons: dict[str, str]) -> None:
        self.reasons = dict(reasons)
        listed = "; ".join(f"{hole}: {why}" for hole, why in self.reasons.items())
        super().__init__(f"{len(self.reasons)} hole(s) cannot be inspected: {listed}")


class NoReachableHoleError(PlanningError):
    """Not a single hole of the cell can be inspected; ``reasons`` as in UnreachableHoleError."""

    def __init__(self, reasons: dict[str, str]) -> None:
        self.reasons = dict(reasons)
        super().__init__(
            f"none of the {len(self.reasons)} hole(s) can be inspected "
            "(out of reach or in collision from every viewpoint)"
        )


class StartConfigurationError(PlanningError):
    """The home configuration is outside the joint limits or in collision."""

    def __init__(self, q: object, reason: str) -> None:
        self.q = q
        self.reason = reason
        super().__init__(f"home configuration {q} is unusable: {reason}")


class SegmentPlanningError(PlanningError):
    """No collision-free path was found between two stops within the time budget.

    ``hole_a`` and ``hole_b`` are hole ids, or ``"home"`` for the home configuration.
    """

    #: the two candidate nodes of the motion, set by the planner when it knows them
    #: (declared only: read with ``getattr(exc, "nodes", None)``)
    nodes: tuple[int, int] | None

    def __init__(self, hole_a: str, hole_b: str, reason: str) -> None:
        self.hole_a = hole_a
        self.hole_b = hole_b
        self.reason = reason
        super().__init__(f"no collision-free path from {hole_a} to {hole_b}: {reason}")


class TimingError(PlanningError):
    """ruckig could not time a segment; ``result`` is ruckig's result code as text."""

    def __init__(self, what: str, result: str) -> None:
        self.what = what
        self.result = result
        super().__init__(f"trajectory timing failed for {what}: ruckig returned {result}")


class TourFileError(PlanningError):
    """A tour file is unreadable or malformed; names the file and the field."""

    def __init__(self, path: str, field: str, message: str) -> None:
        self.path = path
        self.field = field
        super().__init__(f"{path}: {field}: {message}")


class TourCellMismatchError(PlanningError):
    """A tour was planned for another cell (or robot) than the one it is about to run on."""

    def __init__(self, field: str, tour_value: object, cell_value: object) -> None:
        self.field = field
        self.tour_value = tour_value
        self.cell_value = cell_value
        super().__init__(
            f"the tour does not belong to this cell: {field} is {tour_value!r} in the tour, "
            f"{cell_value!r} in the cell; plan the tour again for this cell"
        )


class EngineError(PlanningError):
    """The engine that runs independent starts is unusable (e.g. Ray not installed, no cluster
    at the address). ``engine`` names it."""

    def __init__(self, engine: str, reason: str) -> None:
        self.engine = engine
        self.reason = reason
        super().__init__(f"{engine}: {reason}")


class StartsFailedError(PlanningError):
    """Every independent start failed; ``messages`` holds each start's error message."""

    def __init__(self, messages: list[str]) -> None:
        self.messages = list(messages)
        super().__init__(self.messages[0] if self.messages else "no start was run")


class NoCalibrationViewError(PlanningError):
    """No pose of the arm shows the board to both cameras; ``reasons`` counts why not."""

    def __init__(self, board: str, reasons: dict[str, int]) -> None:
        self.board = board
        self.reasons = dict(reasons)
        listed = ", ".join(f"{why} ({n})" for why, n in Counter(reasons).most_common())
        super().__init__(f"{board}: no feasible calibration view: {listed or 'no pose tried'}")
