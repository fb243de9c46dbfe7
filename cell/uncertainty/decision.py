"""The decision rule of ISO 14253-1: conformance or nonconformance proven, or inconclusive.

For a characteristic with deviation ``e`` (m), expanded uncertainty ``U`` (m) and a symmetric
tolerance ``t`` (m; ``|e| <= t`` conforms):

- **conformance proven** when ``|e| + U <= t`` (the whole uncertainty interval is inside);
- **nonconformance proven** when ``|e| - U > t`` (the whole interval is outside);
- **inconclusive** otherwise.

A hole is proven conforming when every characteristic (position, diameter) is, proven
nonconforming when any is, else inconclusive. The ``simple`` rule ignores ``U`` (shared
acceptance: conforming iff ``|e| <= t``), as the results did before the budget.
"""

from __future__ import annotations

DECISION_RULES = ("iso14253", "simple")
DEFAULT_RULE = "iso14253"
CONFORMING = "conforming"
NONCONFORMING = "nonconforming"
INCONCLUSIVE = "inconclusive"
DECISIONS = (CONFORMING, INCONCLUSIVE, NONCONFORMING)


def decide_one(deviation_m: float, U_m: float, tolerance_m: float, rule: str) -> str:
    """The decision for one characteristic (see module doc)."""
    e = abs(deviation_m)
    if rule == "simple":
        return CONFORMING if e <= tolerance_m else NONCONFORMING
    if rule != "iso14253":
        raise ValueError(f"decision rule {rule!r} not in {DECISION_RULES}")
    if e + U_m <= tolerance_m:
        return CONFORMING
    if e - U_m > tolerance_m:
        return NONCONFORMING
    return INCONCLUSIVE


def decide_hole(decisions: list[str]) -> str:
    """A hole's decision from its characteristics' decisions."""
    if NONCONFORMING in decisions:
        return NONCONFORMING
    if all(d == CONFORMING for d in decisions):
        return CONFORMING
    return INCONCLUSIVE
