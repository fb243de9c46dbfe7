"""Holes from STEP (cell/cad, docs/cad_import.md) against the scripts that made the parts
(build123d, tests/cad/cad_parts.py): every hole to 1 um and 0.001 deg; the CSV, the cell
file's part.step, the mesh and the refusals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from build123d import Box, Cylinder, Pos, export_step, fillet
from cad_parts import GENERATORS, TrueHole, drill, write_part

from cell.cad.errors import CadError
from cell.cad.part import hole_rows, import_step
from cell.cad.step_read import read_step
from cell.cli import main
from cell.config import builtin_cell_path, load_cell
from cell.config.datums import without_drawing
from cell.config.holes_csv import read_holes_csv, write_holes_csv

POS_TOL_M = 1e-6
ANGLE_TOL_DEG = 1e-3


@pytest.fixture(scope="module")
def parts(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, list[TrueHole]]]:
    folder = tmp_path_factory.mktemp("parts")
    return {name: write_part(name, folder) for name in GENERATORS}


def _match(found, truth: list[TrueHole]) -> None:
    assert len(found) == len(truth)
    pos = np.array([h.entry_m for h in found])
    used = set()
    for t in truth:
        k = int(np.argmin(np.linalg.norm(pos - t.entry_m, axis=1)))
        h = found[k]
        used.add(k)
        assert np.linalg.norm(pos[k] - t.entry_m) <= POS_TOL_M, (h.id, h.entry_m, t.entry_m)
        angle = math.degrees(math.acos(min(1.0, float(np.dot(h.normal, t.normal)))))
        assert angle <= ANGLE_TOL_DEG, (h.id, h.normal, t.normal)
        assert abs(h.diameter_m - t.diameter_m) <= POS_TOL_M
        assert abs(h.depth_m - t.depth_m) <= POS_TOL_M, (h.id, h.depth_m, t.depth_m)
        assert h.through is t.through, h.id
        assert [b.diameter_m for b in h.bores] == pytest.approx(list(t.bores_m), abs=POS_TOL_M)
    assert len(used) == len(truth)


@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_every_hole_as_the_script_cut_it(parts, name: str) -> None:
    path, truth = parts[name]
    _match(import_step(path, mesh=False).scan.holes, truth)


def test_a_counterbore_is_one_hole_measured_at_its_entry_bore(parts) -> None:
    holes = import_step(parts["plate"][0], mesh=False).scan.holes
    stepped = [h for h in holes if len(h.bores) > 1]
    assert len(stepped) == 2
    for h in stepped:
        assert h.diameter_m == h.bores[0].diameter_m > h.bores[1].diameter_m
        assert sum(b.length_m for b in h.bores) == pytest.approx(h.depth_m, abs=1e-9)


def test_the_same_part_in_metres_gives_the_same_holes(parts, tmp_path: Path) -> None:
    path = parts["angled"][0]
    text = path.read_text()
    assert "SI_UNIT(.MILLI.,.METRE.)" in text
    metres = tmp_path / "angled_m.step"
    # the same numbers declared in metres: a part 1000 times larger
    metres.write_text(text.replace("SI_UNIT(.MILLI.,.METRE.)", "SI_UNIT($,.METRE.)"))
    big = import_step(metres, mesh=False).scan.holes
    small = import_step(path, mesh=False).scan.holes
    big_m = np.array([h.entry_m for h in big])
    assert np.allclose(big_m, 1000 * np.array([h.entry_m for h in small]), atol=1e-6)
    assert [h.diameter_m for h in big] == pytest.approx([1000 * h.diameter_m for h in small])


def test_fillets_bosses_and_shafts_are_no_holes(tmp_path: Path) -> None:
    body = Box(80, 60, 10)
    body = fillet(body.edges().filter_by(lambda e: abs(e.tangent_at(0).Z) > 0.9), radius=5)
    body = body + Pos(20, 0, 10) * Cylinder(8, 10)  # a boss
    body = body - drill((-20, 0, 5), (0, 0, 1), 6.0, 12)
    path = tmp_path / "boss.step"
    export_step(body, str(path))
    scan = import_step(path, mesh=False).scan
    assert [h.diameter_m for h in scan.holes] == pytest.approx([0.006])
    assert scan.left_out["external cylinders (bosses, shafts)"] >= 5


def test_a_step_that_does_not_parse_is_one_line_naming_file_and_entity(
    parts, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = parts["plate"][0].read_text()
    head, sep, tail = text.partition("#20 = ")
    broken = tmp_path / "broken.step"
    broken.write_text(head + sep + "CARTESIAN_POINT('',(0.,0.,0.);\n" + tail.split(";", 1)[1])
    with pytest.raises(CadError) as err:
        read_step(broken)
    message = str(err.value)
    assert "\n" not in message
    assert str(broken) in message and "entity #20 CARTESIAN_POINT" in message
    assert main(["import-step", str(broken), "-o", str(tmp_path / "h.csv")]) == 2
    out = capsys.readouterr()
    assert out.err.count("\n") == 1 and "#20" in out.err
    assert not (tmp_path / "h.csv").exists()


def test_cli_writes_a_holes_csv_the_cell_file_reads(parts, tmp_path: Path) -> None:
    path, truth = parts["weldment"]
    out = tmp_path / "holes.csv"
    stl = tmp_path / "part.stl"
    assert main(["import-step", str(path), "-o", str(out), "--mesh", str(stl)]) == 0
    rows = read_holes_csv(out)
    _match_rows(rows, truth)
    import trimesh

    mesh = trimesh.load(stl)
    assert mesh.is_watertight and len(mesh.faces) > 100


def _match_rows(rows: list[dict[str, object]], truth: list[TrueHole]) -> None:
    pos = np.array([r["position"] for r in rows])
    for t in truth:
        k = int(np.argmin(np.linalg.norm(pos - t.entry_m, axis=1)))
        assert np.linalg.norm(pos[k] - t.entry_m) <= POS_TOL_M
        assert np.dot(rows[k]["normal"], t.normal) == pytest.approx(1.0, abs=1e-9)


def test_csv_round_trip_in_every_unit(parts, tmp_path: Path) -> None:
    part = import_step(parts["tube"][0], mesh=False)
    for unit in ("m", "mm", "um"):
        out = write_holes_csv(tmp_path / f"h_{unit}.csv", hole_rows(part), unit)
        _match_rows(read_holes_csv(out), parts["tube"][1])


def test_part_step_in_the_cell_file_adds_holes_and_the_mesh(parts, tmp_path: Path) -> None:
    data = without_drawing(yaml.safe_load(builtin_cell_path().read_text()))
    data["part"]["holes"] = []
    path, truth = parts["plate"]
    (tmp_path / "plate.step").write_bytes(path.read_bytes())
    data["part"]["step"] = {"path": "plate.step", "deflection_m": 1e-4}
    cell_path = tmp_path / "cell.yaml"
    cell_path.write_text(yaml.safe_dump(data))
    cfg = load_cell(cell_path)
    rows = [{"position": h.position, "normal": h.normal} for h in cfg.part.holes]
    _match_rows(rows, truth)
    mesh = next(s for s in cfg.obstacle_shapes() if s.name == "part_step")
    assert mesh.mesh is not None and len(mesh.mesh.faces) > 100
    # the mesh holds the part, in metres
    assert np.ptp(mesh.mesh.vertices, axis=0) == pytest.approx([0.12, 0.08, 0.012], abs=1e-9)


@pytest.mark.parametrize("deflection_m", [1e-3, 1e-4])
def test_the_mesh_is_within_its_deflection(tmp_path: Path, deflection_m: float) -> None:
    """The tessellated tube (holes and all) against OpenCascade's exact volume and area: a
    mesh within ``deflection_m`` of the surface differs in volume by less than deflection x
    area, and closes (watertight)."""
    import trimesh
    from cad_parts import tube

    part, _ = tube()
    path = tmp_path / "tube.step"
    export_step(part, str(path))
    mesh = import_step(path, deflection_m=deflection_m).mesh
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces)
    tm.merge_vertices()
    assert tm.is_watertight
    exact_volume_m3, area_m2 = part.volume * 1e-9, part.area * 1e-6
    assert abs(tm.volume - exact_volume_m3) <= deflection_m * area_m2


@pytest.mark.parametrize("direct", [True, False])
def test_two_half_walls_on_opposite_x_directions_are_one_bore(direct: bool) -> None:
    """A hole wall written as two faces u 0..pi each, on cylinders whose x directions are half
    a turn apart (as NIST CTC-03, FTC-07 and FTC-09 in AP242 have them), goes all the way
    round: one full bore (each face's u is measured about the axis from one reference)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_CylindricalSurface
    from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt
    from OCP.TopoDS import TopoDS_Compound

    from cell.cad.axes import chains
    from cell.cad.cylinders import axial_faces, covered_angle, face_map

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for x in (1.0, -1.0):
        ax3 = gp_Ax3(gp_Pnt(5, 7, 0), gp_Dir(0, 0, 1), gp_Dir(x, 0, 0))
        if not direct:
            ax3.YReverse()  # a left-handed frame: u turns the other way
        face = BRepBuilderAPI_MakeFace(Geom_CylindricalSurface(ax3, 3.0), 0, math.pi, 0, 10, 1e-7)
        builder.Add(compound, face.Face().Reversed() if direct else face.Face())
    faces = axial_faces(face_map(compound))
    assert len(faces) == 2 and all(f.internal for f in faces)
    assert covered_angle([f.u_range for f in faces]) == pytest.approx(2 * math.pi)
    found, partial = chains(faces)
    assert len(found) == 1 and partial == [] and found[0].bores[0].full
