"""A generated STEP AP242 part with semantic PMI: the build123d plate of cad_parts.py with
datums, diameter dimensions and geometric tolerances put into an XCAF document and written by
OpenCascade's AP242 writer (``write.step.schema AP242DIS``, GD&T mode), each with the values
and faces the script chose (the truth). A uniquely named module (test modules import from it).

The plate (cad_parts.plate, mm, top face z = 6, every hole entered from it):
- datums: A the top face, B the ⌀6 hole at (-45, -25), C the ⌀8.5 hole at (-45, 25);
- the ⌀10 hole at (0, -25): size 10 +0.1/-0.05, position ⌀0.25 (M) |A|B|C, then a second
  position ⌀0.1 (M) |A|B|C;
- the counterbored hole at (22, 0): size 15 +0.2/0 and position ⌀0.4 |A|B|C on its counterbore
  (the measured bore), size 9 ±0.1 on its through bore;
- the counterbored hole at (45, 25): position ⌀0.4 |A|B|C on its ⌀6.6 bore (not the measured
  ⌀11);
- the blind ⌀5 hole at (0, 25): a position of width 0.3 (no ⌀) |A|B|C;
- the blind ⌀4.2 hole at (45, -25): a position ⌀0.3 |A|B (another frame);
- a flatness 0.05 on the top face.

OpenCascade's writer writes no names: every PMI is ``diameter`` or ``geometric tolerance``.
The writer's schema must be set after a writer exists (its parameters are defined then); set
before, the file is AP214 and writing a datum crashes OpenCascade 8.0 (segmentation fault).
"""

from __future__ import annotations

from pathlib import Path

from cad_parts import plate
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.OCP.collections import Sequence_TDF_Label
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_AsIs
from OCP.TCollection import TCollection_ExtendedString, TCollection_HAsciiString
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.XCAFApp import XCAFApp_Application
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_DatumObject,
    XCAFDimTolObjects_DimensionObject,
    XCAFDimTolObjects_DimensionType_Size_Diameter,
    XCAFDimTolObjects_GeomToleranceMatReqModif_M,
    XCAFDimTolObjects_GeomToleranceObject,
    XCAFDimTolObjects_GeomToleranceType_Flatness,
    XCAFDimTolObjects_GeomToleranceType_Position,
    XCAFDimTolObjects_GeomToleranceTypeValue_Diameter,
)
from OCP.XCAFDoc import (
    XCAFDoc_Datum,
    XCAFDoc_Dimension,
    XCAFDoc_DocumentTool,
    XCAFDoc_GeomTolerance,
)


def _faces(shape, x: float | None, y: float | None, d: float | None) -> list:
    """The cylindrical faces of diameter ``d`` on the vertical axis (x, y), or (``d`` None)
    the planar faces at z = 6 (mm)."""
    out = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face(ex.Current())
        s = BRepAdaptor_Surface(face)
        if d is None and s.GetType() == GeomAbs_Plane:
            if abs(s.Plane().Location().Z() - 6.0) < 1e-9:
                out.append(face)
        elif d is not None and s.GetType() == GeomAbs_Cylinder:
            c = s.Cylinder()
            loc = c.Location()
            if (
                abs(loc.X() - x) < 1e-9
                and abs(loc.Y() - y) < 1e-9
                and abs(2 * c.Radius() - d) < 1e-9
            ):
                out.append(face)
        ex.Next()
    assert out, (x, y, d)
    return out


class _Writer:
    """An XCAF document with one part and GD&T attached to its faces."""

    def __init__(self, shape) -> None:
        self.doc = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
        XCAFApp_Application.GetApplication_s().InitDocument(self.doc)
        self.shapes = XCAFDoc_DocumentTool.ShapeTool_s(self.doc.Main())
        self.gdt = XCAFDoc_DocumentTool.DimTolTool_s(self.doc.Main())
        self.shape = shape
        self.part = self.shapes.AddShape(shape, False)
        self.datums: dict[str, object] = {}

    def _seq(self, faces) -> Sequence_TDF_Label:
        seq = Sequence_TDF_Label()
        for f in faces:
            seq.Append(self.shapes.AddSubShape(self.part, f))
        return seq

    def datum(self, letter: str, faces) -> None:
        lab = self.gdt.AddDatum()
        obj = XCAFDimTolObjects_DatumObject()
        obj.SetName(TCollection_HAsciiString(letter))
        obj.SetPosition(len(self.datums) + 1)
        _attr(lab, XCAFDoc_Datum).SetObject(obj)
        self.gdt.SetDatum(self._seq(faces), lab)
        self.datums[letter] = lab

    def tolerance(
        self, kind, value_mm: float, faces, datums: str = "", diameter=True, mmc=False
    ) -> None:
        lab = self.gdt.AddGeomTolerance()
        obj = XCAFDimTolObjects_GeomToleranceObject()
        obj.SetType(kind)
        obj.SetValue(value_mm)
        if diameter:
            obj.SetTypeOfValue(XCAFDimTolObjects_GeomToleranceTypeValue_Diameter)
        if mmc:
            obj.SetMaterialRequirementModifier(XCAFDimTolObjects_GeomToleranceMatReqModif_M)
        _attr(lab, XCAFDoc_GeomTolerance).SetObject(obj)
        self.gdt.SetGeomTolerance(self._seq(faces), lab)
        for letter in datums:
            self.gdt.SetDatumToGeomTol(self.datums[letter], lab)

    def diameter(self, value_mm: float, upper_mm: float, lower_mm: float, faces) -> None:
        lab = self.gdt.AddDimension()
        obj = XCAFDimTolObjects_DimensionObject()
        obj.SetType(XCAFDimTolObjects_DimensionType_Size_Diameter)
        obj.SetValue(value_mm)
        obj.SetUpperTolValue(upper_mm)
        obj.SetLowerTolValue(lower_mm)
        _attr(lab, XCAFDoc_Dimension).SetObject(obj)
        self.gdt.SetDimension(self._seq(faces), Sequence_TDF_Label(), lab)

    def write(self, path: Path) -> None:
        writer = STEPCAFControl_Writer()  # defines the writer's static parameters
        assert Interface_Static.SetCVal_s("write.step.schema", "AP242DIS")
        writer.SetDimTolMode(True)
        assert writer.Transfer(self.doc, STEPControl_AsIs)
        assert writer.Write(str(path)) == IFSelect_RetDone
        Interface_Static.SetCVal_s("write.step.schema", "AP214IS")


def _attr(label, cls):
    from OCP.TDF import TDF_AttributeIterator

    it = TDF_AttributeIterator(label)
    while it.More():
        if isinstance(it.Value(), cls):
            return it.Value()
        it.Next()
    raise AssertionError(f"no {cls.__name__} on the label")


def write_pmi_plate(folder: Path) -> Path:
    """The plate with its PMI (module doc) as an AP242 file in ``folder``."""
    part, _ = plate()
    shape = part.wrapped
    w = _Writer(shape)
    top = _faces(shape, None, None, None)
    w.datum("A", top)
    w.datum("B", _faces(shape, -45, -25, 6.0))
    w.datum("C", _faces(shape, -45, 25, 8.5))
    pos = XCAFDimTolObjects_GeomToleranceType_Position
    hole = _faces(shape, 0, -25, 10.0)
    w.diameter(10.0, 0.1, -0.05, hole)
    w.tolerance(pos, 0.25, hole, "ABC", mmc=True)
    w.tolerance(pos, 0.1, hole, "ABC", mmc=True)
    w.diameter(15.0, 0.2, 0.0, _faces(shape, 22, 0, 15.0))
    w.diameter(9.0, 0.1, -0.1, _faces(shape, 22, 0, 9.0))
    w.tolerance(pos, 0.4, _faces(shape, 22, 0, 15.0), "ABC")
    w.tolerance(pos, 0.4, _faces(shape, 45, 25, 6.6), "ABC")
    w.tolerance(pos, 0.3, _faces(shape, 0, 25, 5.0), "ABC", diameter=False)
    w.tolerance(pos, 0.3, _faces(shape, 45, -25, 4.2), "AB")
    flat = XCAFDimTolObjects_GeomToleranceType_Flatness
    w.tolerance(flat, 0.05, top, diameter=False)
    path = folder / "pmi_plate.step"
    w.write(path)
    return path
