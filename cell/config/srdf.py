"""A MoveIt SRDF in the cell file: ``robot.srdf: arm.srdf`` (relative to the cell file).

Two of its elements are used:

- ``<disable_collisions link1= link2= reason=/>``: pairs of the arm's links (or the tool, named
  by the link it hangs on, ``tool0`` / ``flange`` / ``link_6``) never checked against each other,
  added to the pairs the collision model already leaves out (adjacent links, links touching at
  q = 0: :mod:`robots.collision`);
- ``<group_state name= group=>`` with one ``<joint name= value=/>`` per arm joint: named states;
  ``robot.home`` may name one (``home: home``) instead of listing six values (rad).

Everything else in the SRDF (groups, end effectors, virtual joints, passive joints) is read
over, as MoveIt's own configuration would need it, not holecell. A file that is not XML, a
state without a value for every joint, a link or joint the URDF does not have: refused naming
the file and the element.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cell.errors import ConfigError


@dataclass(frozen=True)
class Srdf:
    """What holecell takes from an SRDF: disabled pairs (link, link, reason) and named states
    (name -> joint name -> value, rad)."""

    path: str
    disabled: tuple[tuple[str, str, str], ...]
    states: dict[str, dict[str, float]]

    def state(self, name: str, joint_names: list[str]) -> list[float]:
        """The named state's joint values in ``joint_names``' order (rad)."""
        if name not in self.states:
            known = ", ".join(sorted(self.states)) or "none"
            raise ConfigError(
                self.path, [("robot.home", name, f"no group_state {name!r} (known: {known})")]
            )
        values = self.states[name]
        missing = [j for j in joint_names if j not in values]
        if missing:
            raise ConfigError(
                self.path,
                [(f"group_state {name!r}", sorted(values), f"no value for joints {missing}")],
            )
        return [values[j] for j in joint_names]


def read_srdf(path: str | Path) -> Srdf:
    """Read ``path`` (cached while the file is unchanged)."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(str(p), [("robot.srdf", str(p), "no such file")])
    return _read(str(p), p.stat().st_mtime_ns)


@functools.lru_cache(maxsize=16)
def _read(path: str, stamp: int) -> Srdf:
    del stamp  # part of the cache key only
    try:
        root = etree.parse(path).getroot()
    except (etree.XMLSyntaxError, OSError) as exc:
        raise ConfigError(path, [("robot.srdf", path, f"not an SRDF (XML): {exc}")]) from None
    if root.tag != "robot":
        raise ConfigError(path, [("(root element)", root.tag, "an SRDF's root is <robot>")])
    disabled = []
    for el in root.iter("disable_collisions"):
        a, b = el.get("link1"), el.get("link2")
        if not a or not b:
            raise ConfigError(
                path,
                [
                    (
                        f"line {el.sourceline}: disable_collisions",
                        dict(el.attrib),
                        "needs link1 and link2",
                    )
                ],
            )
        disabled.append((a, b, el.get("reason", "")))
    states: dict[str, dict[str, float]] = {}
    for el in root.iter("group_state"):
        name = el.get("name", "")
        values = {}
        for j in el.iter("joint"):
            try:
                values[j.get("name", "")] = float(j.get("value", ""))
            except ValueError:
                raise ConfigError(
                    path,
                    [
                        (
                            f"line {j.sourceline}: group_state {name!r}",
                            j.get("value"),
                            "not a number",
                        )
                    ],
                ) from None
        states[name] = values
    return Srdf(path, tuple(disabled), states)
