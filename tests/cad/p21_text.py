"""A second reading of a STEP file's datums and position tolerances, by regular expression over
its Part 21 text, for the tests (nothing of cell/cad or OpenCascade): the faces a datum or a
tolerance names (through its shape aspects, whichever usage entity carries them), each face's
cylinder axis and radius, a tolerance's zone, modifiers and datum letters. Lengths in mm (the
file's inch or mm). A uniquely named module (test modules import from it)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

_STATEMENT = re.compile(r"#(\d+)\s*=\s*(.*?);\s*(?=#\d+\s*=|ENDSEC)", re.S)
_NUM = r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?"


class P21:
    """The entities of a Part 21 file by id, with their back references."""

    def __init__(self, path: Path) -> None:
        text = path.read_text(encoding="latin-1")
        self.ents = {
            int(m[1]): " ".join(m[2].split())
            for m in _STATEMENT.finditer(text, text.index("DATA;"))
        }
        self.users: dict[int, list[int]] = {}
        for n, body in self.ents.items():
            for r in {int(x) for x in re.findall(r"#(\d+)", body)}:
                self.users.setdefault(r, []).append(n)
        self.mm = 25.4 if "CONVERSION_BASED_UNIT('INCH'" in text else 1.0

    def refs(self, n: int) -> list[int]:
        return [int(x) for x in re.findall(r"#(\d+)", self.ents[n])]

    def aspect_faces(self, aspect: int, seen: set[int] | None = None) -> set[int]:
        """The ADVANCED_FACE ids a shape aspect (or its members) is used on."""
        seen = set() if seen is None else seen
        if aspect in seen:
            return set()
        seen.add(aspect)
        out: set[int] = set()
        for u in self.users.get(aspect, []):
            body, refs = self.ents[u], self.refs(u)
            if "USAGE(" in body and refs[0] == aspect:
                out |= {r for r in refs[2:] if self.ents[r].startswith("ADVANCED_FACE")}
            elif (
                body.startswith("SHAPE_ASPECT_RELATIONSHIP")
                and refs[-2] == aspect
                and not self.ents[refs[-1]].startswith("DATUM(")
            ):
                out |= self.aspect_faces(refs[-1], seen)
        return out

    def datum_faces(self, letter: str) -> set[int]:
        """The faces of the datum features of datum ``letter``."""
        out: set[int] = set()
        for n, body in self.ents.items():
            if body.startswith("DATUM(") and body.endswith(f"'{letter}')"):
                for u in self.users[n]:
                    refs = self.refs(u)
                    if self.ents[u].startswith("SHAPE_ASPECT_RELATIONSHIP") and refs[-1] == n:
                        out |= self.aspect_faces(refs[-2])
        return out

    def _floats(self, n: int) -> list[float]:
        return [float(x) for x in re.findall(_NUM, self.ents[n].split("(", 2)[2])]

    def cylinder(self, face: int) -> tuple[np.ndarray, np.ndarray, float] | None:
        """A cylindrical face's axis point (mm), unit direction and radius (mm)."""
        surf = self.refs(face)[-1]
        body = self.ents[surf]
        if not body.startswith("CYLINDRICAL_SURFACE"):
            return None
        place = self.refs(surf)[0]
        point, direction = self.refs(place)[:2]
        radius = float(body.rsplit(",", 1)[1].rstrip(")"))
        d = np.array(self._floats(direction))
        return np.array(self._floats(point)) * self.mm, d / np.linalg.norm(d), radius * self.mm

    def positions(self) -> list[dict]:
        """Every POSITION_TOLERANCE: name, zone (mm), modifiers, datum letters, faces."""
        out = []
        for body in self.ents.values():
            if "POSITION_TOLERANCE()" not in body:
                continue
            m = re.search(r"GEOMETRIC_TOLERANCE\('(.*?)','.*?',#(\d+),#(\d+)\)", body)
            assert m is not None
            zone = float(re.search(_NUM, self.ents[int(m[2])].split("(", 2)[2])[0]) * self.mm
            system = re.search(r"WITH_DATUM_REFERENCE\(\(#(\d+)\)\)", body)
            letters = []
            for comp in self.refs(int(system[1]))[1:] if system else []:
                datum = self.refs(comp)[-1]
                letters.append(self.ents[datum].rsplit("'", 2)[1])
            mods = re.search(r"WITH_MODIFIERS\(\((.*?)\)\)", body)
            out.append(
                {
                    "name": m[1],
                    "zone_mm": zone,
                    "modifiers": re.findall(r"\.([A-Z_]+)\.", mods[1]) if mods else [],
                    "datums": letters,
                    "faces": self.aspect_faces(int(m[3])),
                }
            )
        return out


def on_axis(point_m, axis: tuple[np.ndarray, np.ndarray, float], tol_m: float = 1e-6) -> bool:
    """Whether a point (m) lies on a cylinder's axis line (mm) within ``tol_m``."""
    p0, d, _ = axis
    v = np.asarray(point_m) * 1e3 - p0
    return float(np.linalg.norm(v - np.dot(v, d) * d)) * 1e-3 <= tol_m
