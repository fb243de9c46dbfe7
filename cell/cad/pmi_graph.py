"""The faces of a datum feature that OpenCascade's XCAF document leaves without any, found in
the STEP file's own entity graph.

OpenCascade 8.0 (cadquery-ocp 8.0.1) reads a datum feature's faces from a
``GEOMETRIC_ITEM_SPECIFIC_USAGE`` on the feature only; some exporters (NIST CTC-01 and CTC-03
in AP242) write them as an ``ITEM_IDENTIFIED_REPRESENTATION_USAGE(..., #feature, #rep,
SET_REPRESENTATION_ITEM((#f1, #f2)))``, whose set of items OpenCascade's parser leaves empty,
or put the usage on the ``DATUM`` itself. This module reads that much of
the Part 21 text by hand (entity ids, types and references; no geometry) and follows, for a
datum's letter::

    DATUM(..., 'B') <- SHAPE_ASPECT_RELATIONSHIP(..., #feature, #datum)
    #feature <- GEOMETRIC_ITEM_SPECIFIC_USAGE | ITEM_IDENTIFIED_REPRESENTATION_USAGE -> faces
    #datum <- GEOMETRIC_ITEM_SPECIFIC_USAGE -> faces (NIST CTC-03 in AP242, edition 2)
    #feature -> SHAPE_ASPECT_RELATIONSHIP -> its member shape aspects -> their faces

A feature that is a datum target (``PLACED_DATUM_TARGET_FEATURE``, ``DATUM_TARGET``) has no
faces here: it is counted as a target. The faces found (``ADVANCED_FACE`` entities) are turned
into the shape's faces with OpenCascade's own transfer record
(``XSControl_TransferReader.EntityFromShapeResult``): the reader numbers the model's entities in
the order of the file, which :class:`FaceLocator` checks for each face (its type).

The same reading gives the names of the tolerances with a maximum value (``StepGraph.capped``),
which XCAF drops.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from OCP.StepShape import StepShape_AdvancedFace
from OCP.TopoDS import TopoDS_Shape

_STATEMENT = re.compile(r"#(\d+)\s*=\s*(.*?);\s*(?=#\d+\s*=|ENDSEC)", re.S)
_REF = re.compile(r"#(\d+)")
_TYPE = re.compile(r"([A-Z][A-Z0-9_]*)\s*\(")
_STRING = re.compile(r"'(?:[^']|'')*'")
#: entities whose back references the walk follows
_LINKS = (
    "SHAPE_ASPECT_RELATIONSHIP",
    "GEOMETRIC_ITEM_SPECIFIC_USAGE",
    "ITEM_IDENTIFIED_REPRESENTATION_USAGE",
)
_TARGETS = ("PLACED_DATUM_TARGET_FEATURE", "DATUM_TARGET")


def _top_types(text: str) -> tuple[str, ...]:
    """The entity types of a statement: one, or the parts of a complex entity ``(A() B())``."""
    bare = _STRING.sub("''", text).strip()
    if not bare.startswith("("):
        m = _TYPE.match(bare)
        return (m[1],) if m else ()
    types, depth = [], 0
    for m in re.finditer(r"[A-Z][A-Z0-9_]*\s*\(|\(|\)", bare):
        tok = m[0]
        if tok.endswith("(") and tok != "(":
            if depth == 1:
                types.append(tok[:-1].strip())
            depth += 1
        elif tok == "(":
            depth += 1
        else:
            depth -= 1
    return tuple(types)


def _args(text: str) -> list[str]:
    """The top-level parameters of a simple entity's statement ``TYPE('a,b',#2,(c,d))``."""
    inner = text[text.index("(") + 1 : text.rindex(")")]
    out, depth, start, quoted = [], 0, 0, False
    for i, ch in enumerate(inner):
        if ch == "'":
            quoted = not quoted  # a doubled quote inside a string toggles twice
        elif quoted:
            continue
        elif ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append(inner[start:i])
            start = i + 1
    out.append(inner[start:])
    return [a.strip() for a in out]


@dataclass
class DatumFeatures:
    """What the file attaches a datum letter to: ``faces`` (``ADVANCED_FACE`` ids) and the
    number of datum ``targets``."""

    faces: list[int] = field(default_factory=list)
    targets: int = 0


class StepGraph:
    """The entity ids, types and references of a Part 21 file (no values), in file order."""

    def __init__(self, path: Path) -> None:
        text = path.read_text(encoding="latin-1")
        start = text.find("DATA;")
        self.order: list[int] = []
        self.types: dict[int, tuple[str, ...]] = {}
        self.text: dict[int, str] = {}
        self.back: dict[int, list[int]] = {}
        #: names of the geometric tolerances with a maximum value (``|⌀.045 MAX|``), which
        #: OpenCascade 8.0's XCAF leaves out (its GetMaxValueModifier is 0 for them)
        self.capped: set[str] = set()
        for m in _STATEMENT.finditer(text, max(start, 0)):
            n, body = int(m[1]), m[2]
            self.order.append(n)
            types = _top_types(body)
            self.types[n] = types
            if "GEOMETRIC_TOLERANCE_WITH_MAXIMUM_TOLERANCE" in types:
                name = re.search(r"GEOMETRIC_TOLERANCE\s*\(\s*'((?:[^']|'')*)'", body)
                self.capped.add(name[1] if name else "")
            if any(t in _LINKS or t == "DATUM" for t in types):
                self.text[n] = body
                if any(t in _LINKS for t in types):
                    for r in {int(x) for x in _REF.findall(body)}:
                        self.back.setdefault(r, []).append(n)

    def datums(self, letter: str) -> list[int]:
        """The ids of the ``DATUM`` entities of ``letter``."""
        return [
            n
            for n, t in self.types.items()
            if "DATUM" in t and _args(self.text[n])[-1].strip("'") == letter
        ]

    def _refs(self, n: int) -> list[int]:
        return [int(x) for x in _REF.findall(self.text[n])]

    def features(self, letter: str) -> DatumFeatures:
        """The faces and targets the file gives the datum ``letter`` (module doc)."""
        out = DatumFeatures()
        seen: set[int] = set()
        for datum in self.datums(letter):
            self._usages(datum, out)  # some files attach the datum itself to its faces
            for rel in self.back.get(datum, []):
                if "SHAPE_ASPECT_RELATIONSHIP" in self.types[rel]:
                    relating, related = self._refs(rel)[-2:]
                    if related == datum:
                        self._collect(relating, out, seen)
        return out

    def _usages(self, aspect: int, out: DatumFeatures) -> None:
        """The faces of the usages (GISU, IIRU) whose definition is ``aspect``."""
        for user in self.back.get(aspect, []):
            refs = self._refs(user)
            if any(t.endswith("USAGE") for t in self.types[user]) and refs and refs[0] == aspect:
                faces = [r for r in refs[2:] if "ADVANCED_FACE" in self.types.get(r, ())]
                out.faces.extend(f for f in faces if f not in out.faces)

    def _collect(self, aspect: int, out: DatumFeatures, seen: set[int]) -> None:
        if aspect in seen:
            return
        seen.add(aspect)
        if any(t in _TARGETS for t in self.types.get(aspect, ())):
            out.targets += 1
            return
        for user in self.back.get(aspect, []):
            types = self.types[user]
            refs = self._refs(user)
            if (
                "SHAPE_ASPECT_RELATIONSHIP" in types
                and refs[-2] == aspect
                and "DATUM" not in self.types.get(refs[-1], ())
            ):
                self._collect(refs[-1], out, seen)
        self._usages(aspect, out)


class FaceLocator:
    """``ADVANCED_FACE`` entity ids to the face numbers of a face map, through the reader's
    transfer record (the model numbers entities in file order: checked per entity)."""

    def __init__(self, reader, graph: StepGraph, faces, order: list[int]) -> None:
        self.model = reader.ChangeReader().StepModel()
        self.transfer = reader.ChangeReader().WS().TransferReader()
        self.graph = graph
        self.faces = faces
        self.order = order  # face numbers to try first (the holes' walls)
        self.index = {n: i + 1 for i, n in enumerate(graph.order)}
        self.found: dict[int, int] = {}

    def locate(self, ids: list[int]) -> tuple[list[int], list[int]]:
        """The face numbers of the face entities ``ids``, and the ids not found."""
        wanted = {}
        for n in ids:
            if n in self.found:
                continue
            i = self.index.get(n, 0)
            ent = self.model.Value(i) if 0 < i <= self.model.NbEntities() else None
            if isinstance(ent, StepShape_AdvancedFace):
                wanted[n] = ent
        if wanted:
            self._search(wanted)
        return [self.found[n] for n in ids if n in self.found], [
            n for n in ids if n not in self.found
        ]

    def _search(self, wanted: dict[int, object]) -> None:
        left = dict(wanted)
        first = set(self.order)
        rest = [k for k in range(1, self.faces.Extent() + 1) if k not in first]
        for k in [*self.order, *rest]:
            face: TopoDS_Shape = self.faces.FindKey(k)
            ent = self.transfer.EntityFromShapeResult(face, -1)
            for n, e in list(left.items()):
                if ent is e:
                    self.found[n] = k
                    del left[n]
            if not left:
                return
