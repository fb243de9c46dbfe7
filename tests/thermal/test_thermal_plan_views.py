"""``holecell thermal plan-views``: a valid views.csv, the per-stop prediction, clear refusals."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.cli import main
from cell.commands.thermal_plan_cmd import VIEW_COLUMNS, read_views
from cell.config import builtin_cell_path, load_cell
from cell.config.datums import without_drawing
from planner import Options, plan_tour


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A three-hole copy of the built-in cell and its tour."""
    root = tmp_path_factory.mktemp("plan_views")
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = "small_frame"
    data["part"]["holes"] = data["part"]["holes"][:3]
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    path = root / "small.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    tour = plan_tour(load_cell(path), Options(seed=1))
    return path, tour.save(root / "tour.json")


def _cli(args: list[str], capsys) -> tuple[int, str, str]:
    try:
        code = main(["thermal", "plan-views", *args])
    except SystemExit as exc:  # a command-line mistake (-o in no folder): argparse's exit
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def test_writes_a_valid_views_csv(small, tmp_path, capsys):
    cell_path, tour_path = small
    views = tmp_path / "views.csv"
    code, out, err = _cli(["--cell", str(cell_path), "--tour", str(tour_path), "-o", str(views)],
                          capsys)  # fmt: skip
    assert code == 0, err
    rows = list(csv.DictReader(views.open()))
    assert tuple(rows[0]) == VIEW_COLUMNS and len(rows) == 6  # three per target
    cell = load_cell(cell_path)
    plan = read_views(views, cell)
    arm = cell.build_arm()
    assert all(not arm.in_collision(q) for _, q in plan)
    assert {t for t, _ in plan} <= {t.id for t in cell.reference_targets}
    stops = [line.split()[0] for line in out.splitlines() if line.endswith(" um") and "  " in line]
    tour_ids = [s["hole_id"] for s in __import__("json").loads(tour_path.read_text())["stops"]]
    assert stops[: len(tour_ids)] == tour_ids  # one predicted residual per stop
    assert "old recommended plan" in out and "RMS over the stops" in out


def test_simulate_reads_the_views(small, tmp_path, capsys):
    cell_path, _ = small
    views, obs = tmp_path / "views.csv", tmp_path / "obs.csv"
    assert _cli(["--cell", str(cell_path), "-o", str(views), "--views", "4"], capsys)[0] == 0
    code = main(["thermal", "simulate", "--cell", str(cell_path), "--views", str(views), "-o",
                 str(obs), "--hours", "0.5"])  # fmt: skip
    assert code == 0
    rows = list(csv.DictReader(obs.open()))
    assert len(rows) == 4 * 7
    q0 = np.array([float(rows[0][f"q{i}_rad"]) for i in range(1, 7)])
    assert np.allclose(q0, read_views(views, load_cell(cell_path))[0][1])


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--try-target", "1,2"], "--try-target '1,2'"),
        (["--try-target", "1,nan,0.3"], "X,Y,Z"),
        (["-o", "/nonexistent/dir/views.csv"], "does not exist"),
    ],
)
def test_bad_arguments_are_one_line_errors(small, tmp_path, capsys, extra, needle):
    cell_path, _ = small
    args = ["--cell", str(cell_path), "-o", str(tmp_path / "v.csv"), *extra]
    code, _, err = _cli(args, capsys)
    assert code == 2 and needle in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "v.csv").exists()


def test_tour_of_another_cell_and_no_targets_are_refused(small, tmp_path, capsys):
    cell_path, _ = small
    data = yaml.safe_load(cell_path.read_text())
    data["name"] = "other_frame"
    other = tmp_path / "other.yaml"
    other.write_text(yaml.safe_dump(data, sort_keys=False))
    code, _, err = _cli(["--cell", str(other), "--tour", str(small[1]), "-o",
                         str(tmp_path / "v.csv")], capsys)  # fmt: skip
    assert code == 2 and "other_frame" in err and len(err.strip().splitlines()) == 1
    data["reference_targets"] = []
    other.write_text(yaml.safe_dump(data, sort_keys=False))
    code, _, err = _cli(["--cell", str(other), "-o", str(tmp_path / "v.csv")], capsys)
    assert code == 2 and "reference_targets" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ("view_id,target_id,q1_rad\n0,R1,0\n", "missing column"),
        ("view_id,target_id,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\n0,NOPE,0,0,0,0,1,0\n",
         "line 2: target_id"),
        ("view_id,target_id,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\n0,R1,0,0,0,0,x,0\n",
         "line 2: q5_rad"),
        ("view_id,target_id,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\n0,R1,9,0,0,0,1,0\n",
         "outside the limits"),
    ],
)  # fmt: skip
def test_bad_views_csv_is_refused_naming_line_and_column(small, tmp_path, capsys, body, needle):
    cell_path, _ = small
    views = tmp_path / "views.csv"
    views.write_text(body)
    code = main(["thermal", "simulate", "--cell", str(cell_path), "--views", str(views), "-o",
                 str(tmp_path / "obs.csv")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1


def test_suggested_places_are_on_the_table_and_scored(small):
    from cell.run.target_suggest import suggest_targets, top_face_points

    cell = load_cell(small[0])
    table = next(o for o in cell.environment.obstacles if o.name == "table")
    top_z = table.pose.xyz[2] + table.box.size[2] / 2
    points = top_face_points(cell, spacing_m=0.5)
    assert points and all(abs(p[2] - top_z - 0.001) < 1e-9 for p in points)
    stops = np.array([s["q"] for s in __import__("json").loads(small[1].read_text())["stops"]])
    baseline, scores = suggest_targets(cell, stops, spacing_m=0.5)
    assert np.isfinite(baseline) and scores
    rms = [s.predicted_rms_m for s in scores]
    assert rms == sorted(rms) and any(s.views_of_it > 0 for s in scores)
    assert {s.position_m for s in scores} <= {tuple(float(v) for v in p) for p in points}
