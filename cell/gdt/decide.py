"""ISO 14253-1 decisions of a characteristic against its specification (cf.
:mod:`cell.uncertainty.decision`, the same rule for the older symmetric tolerance).

With the measured value ``y`` and its expanded uncertainty ``U`` (m):

- a **position** (upper limit ``t``: the zone plus any bonus) is proven conforming when
  ``y + U <= t``, proven nonconforming when ``y - U > t``;
- a **size** (limits ``lower <= e <= upper`` on the deviation ``e`` from nominal) is proven
  conforming when ``lower + U <= e <= upper - U``, nonconforming when ``e < lower - U`` or
  ``e > upper + U``;
- otherwise inconclusive. The ``simple`` rule ignores ``U`` (shared acceptance).

Decision strings (report.json ``characteristics``; QIF PASS / FAIL / INDETERMINATE):
``conformance``, ``nonconformance``, ``inconclusive`` and ``not_evaluated``.
"""

from __future__ import annotations

from cell.uncertainty.decision import CONFORMING, DECISION_RULES, INCONCLUSIVE, NONCONFORMING

CONFORMANCE = "conformance"
NONCONFORMANCE = "nonconformance"
INDETERMINATE = "inconclusive"
NOT_EVALUATED = "not_evaluated"
#: characteristic decision -> the hole decision strings of cell.uncertainty.decision
AS_HOLE_DECISION = {CONFORMANCE: CONFORMING, NONCONFORMANCE: NONCONFORMING,
                    INDETERMINATE: INCONCLUSIVE}  # fmt: skip


def _check(rule: str) -> None:
    if rule not in DECISION_RULES:
        raise ValueError(f"decision rule {rule!r} not in {DECISION_RULES}")


def decide_upper(value_m: float, U_m: float, limit_m: float, rule: str) -> str:
    """The decision on a value with an upper limit (a position against its zone)."""
    _check(rule)
    u = 0.0 if rule == "simple" else U_m
    if value_m + u <= limit_m:
        return CONFORMANCE
    if value_m - u > limit_m:
        return NONCONFORMANCE
    return INDETERMINATE


def decide_interval(deviation_m: float, U_m: float, lower_m: float, upper_m: float,
                    rule: str) -> str:  # fmt: skip
    """The decision on a deviation between two limits (a size against its limits)."""
    _check(rule)
    u = 0.0 if rule == "simple" else U_m
    if lower_m + u <= deviation_m <= upper_m - u:
        return CONFORMANCE
    if deviation_m < lower_m - u or deviation_m > upper_m + u:
        return NONCONFORMANCE
    return INDETERMINATE


def hole_decision(decisions: list[str]) -> str | None:
    """A hole's decision (``conforming`` / ``inconclusive`` / ``nonconforming``) from its
    characteristics; None when one was not evaluated and none is proven nonconforming."""
    if NONCONFORMANCE in decisions:
        return NONCONFORMING
    if NOT_EVALUATED in decisions or not decisions:
        return None
    if all(d == CONFORMANCE for d in decisions):
        return CONFORMING
    return INCONCLUSIVE
