"""Reading a STEP file (AP203, AP214, AP242) into an XCAF document with OpenCascade.

OpenCascade converts every length to millimetres on reading, whatever unit the file
declares; :data:`MM_TO_M` turns them into metres. A file that does not parse is refused in one
line naming the file, the line and the entity (``#20 CARTESIAN_POINT``) the parser stopped
at; the parser's own messages (printed by OpenCascade on the C streams) are caught, not shown.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from OCP.IFSelect import IFSelect_RetDone
from OCP.OCP.collections import Sequence_TDF_Label
from OCP.STEPCAFControl import STEPCAFControl_Reader
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Shape
from OCP.XCAFDoc import XCAFDoc_DocumentTool

from cell.cad.errors import CadError

#: OpenCascade's lengths (mm) to metres
MM_TO_M = 1e-3
_LINE = re.compile(r"Line (\d+):\s*(.*?)\s*$")
_ENTITY = re.compile(r"^\s*(#\d+)\s*=\s*\(?\s*([A-Z0-9_]*)")
_ENT_ID = re.compile(r"Ent\.Id\.(#\d+)")


@dataclass
class StepDocument:
    """A STEP file read: the whole shape (mm), its XCAF document (the PMI), the schema and the
    reader (its model and transfer record: the STEP entities behind the faces)."""

    path: Path
    shape: TopoDS_Shape
    doc: TDocStd_Document
    schema: str
    reader: STEPCAFControl_Reader | None = None


@contextlib.contextmanager
def _captured_c_output() -> Iterator[list[str]]:
    """Catch what C++ code prints on file descriptors 1 and 2 (OpenCascade's messenger); the
    text is in the yielded list after the block."""
    out: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        try:
            os.dup2(tmp.fileno(), 1)
            os.dup2(tmp.fileno(), 2)
            yield out
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            tmp.seek(0)
            text = tmp.read().decode("utf-8", "replace")
            out.extend(re.sub(r"\x1b\[[0-9;]*m", "", text).splitlines())


def _entity_at_line(path: Path, line_no: int) -> str:
    """``#N TYPE`` of the entity whose text holds line ``line_no`` (1-based), or ''."""
    try:
        with path.open(encoding="latin-1") as fh:
            lines = [next(fh, "") for _ in range(line_no)]
    except OSError:
        return ""
    for text in reversed(lines):
        m = _ENTITY.match(text)
        if m:
            return f"{m[1]} {m[2]}".strip()
    return ""


def _parse_failure(path: Path, messages: list[str]) -> CadError:
    """The first parse error among OpenCascade's messages, as a one-line error."""
    for msg in messages:
        m = _LINE.search(msg)
        if m:
            line = int(m[1])
            reason = re.sub(r"^Incorrect syntax:\s*", "", m[2]).rstrip("* ").strip()
            entity = _entity_at_line(path, line)
            where = f"line {line}" + (f", entity {entity}" if entity else "")
            return CadError(path, where, f"STEP syntax error: {reason}")
    for msg in messages:
        m = _ENT_ID.search(msg)
        if m:
            return CadError(path, f"entity {m[1]}", f"STEP error: {msg.strip()}")
    return CadError(path, "file", "not a STEP file OpenCascade can read")


def _check_messages(reader: STEPCAFControl_Reader) -> list[str]:
    """The model's global check failures (syntax errors, unresolved references)."""
    model = reader.ChangeReader().StepModel()
    check = model.GlobalCheck()
    return [check.CFail(i + 1) for i in range(check.NbFails())]


def read_step(path: str | Path) -> StepDocument:
    """Read ``path`` with its PMI (GD&T mode on); :class:`CadError` when it cannot be used."""
    p = Path(path)
    if not p.is_file():
        raise CadError(p, "file", "no such file")
    reader = STEPCAFControl_Reader()
    reader.SetGDTMode(True)
    reader.SetNameMode(True)
    with _captured_c_output() as printed:
        status = reader.ReadFile(str(p))
    if status != IFSelect_RetDone:
        raise _parse_failure(p, printed)
    failures = _check_messages(reader)
    if failures:
        raise _parse_failure(p, failures)
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    with _captured_c_output():
        ok = reader.Transfer(doc)
    shape = _free_shape(doc)
    if not ok or shape is None or not TopExp_Explorer(shape, TopAbs_FACE).More():
        raise CadError(p, "file", "parses, but holds no solid or face (no geometry to import)")
    return StepDocument(p, shape, doc, _schema(p), reader)


def _free_shape(doc: TDocStd_Document) -> TopoDS_Shape | None:
    """The document's top-level shapes as one shape (a compound when several)."""
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    labels = Sequence_TDF_Label()
    tool.GetFreeShapes(labels)
    shapes = [tool.GetShape_s(labels.Value(i + 1)) for i in range(labels.Length())]
    shapes = [s for s in shapes if not s.IsNull()]
    if not shapes:
        return None
    if len(shapes) == 1:
        return shapes[0]
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for s in shapes:
        builder.Add(compound, s)
    return compound


def _schema(path: Path) -> str:
    """The file's schema name from its header (``AP242_MANAGED_MODEL_BASED_3D_...``), or ''."""
    with path.open(encoding="latin-1") as fh:
        head = fh.read(8192)
    m = re.search(r"FILE_SCHEMA\s*\(\s*\(\s*'([^'\s{]+)", head)
    return m[1] if m else ""
