"""``holecell measure`` on PNG files: JSON, table, and errors without tracebacks."""

from __future__ import annotations

import json

import cv2
import numpy as np
from measure_helpers import render, small_stereo

from cell.cli import main


def _write_pair(tmp_path, r):
    left, right = tmp_path / "left.png", tmp_path / "right.png"
    cv2.imwrite(str(left), r.left)
    cv2.imwrite(str(right), r.right)
    stereo = tmp_path / "stereo.json"
    small_stereo().save(stereo)
    return str(left), str(right), str(stereo)


def test_json_output(tmp_path, capsys):
    r = render(0.008, 10.0, 21)
    left, right, stereo = _write_pair(tmp_path, r)
    assert main(["measure", left, right, "--stereo", stereo, "--diameter", "0.008", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "ok"
    assert abs(out["radius_m"] - 0.004) < 3e-6
    assert np.linalg.norm(np.array(out["center_m"]) - r.truth.center_m) < 12e-6
    for key in ("normal", "rms_m", "n_points", "time_s"):
        assert key in out


def test_table_output_in_mm(tmp_path, capsys):
    r = render(0.008, 0.0, 22)
    left, right, stereo = _write_pair(tmp_path, r)
    assert main(["measure", left, right, "--stereo", stereo]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.startswith("diameter"))
    assert line.endswith("mm") and abs(float(line.split()[1]) - 8.0) < 0.006


def test_sixteen_bit_png(tmp_path, capsys):
    from measure.synth import RenderOptions

    r = render(0.008, 0.0, 23, RenderOptions(bit_depth=12, read_noise_dn=32.0))
    left, right, stereo = _write_pair(tmp_path, r)
    assert main(["measure", left, right, "--stereo", stereo, "--json"]) == 0
    assert abs(json.loads(capsys.readouterr().out)["radius_m"] - 0.004) < 3e-6


def test_errors_are_one_line(tmp_path, capsys):
    r = render(0.008, 0.0, 24)
    left, right, stereo = _write_pair(tmp_path, r)
    black = tmp_path / "black.png"
    cv2.imwrite(str(black), np.zeros_like(r.left))
    assert main(["measure", str(black), right, "--stereo", stereo, "--json"]) == 2
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "error" and "black" in out["reason"]
    assert main(["measure", str(black), right, "--stereo", stereo]) == 2
    err = capsys.readouterr().err
    assert "black" in err and "Traceback" not in err
    assert main(["measure", left, right, "--stereo", str(tmp_path / "missing.json")]) == 2
    assert "no such file" in capsys.readouterr().err
    assert main(["measure", str(tmp_path / "nope.png"), right, "--stereo", stereo]) == 2
    assert "nope.png" in capsys.readouterr().err


def test_table_and_batch_rows_name_the_rim_and_the_suspect_reasons(tmp_path, capsys):
    from cell.commands.measure_batch import CSV_COLUMNS, PairEntry, measure_pairs
    from cell.commands.measure_cmd import _table
    from measure import MeasureOptions, measure_hole

    r = render(0.008, 10.0, 25)
    left, right, stereo = _write_pair(tmp_path, r)
    assert main(["measure", left, right, "--stereo", stereo]) == 0
    lines = capsys.readouterr().out.splitlines()
    rim = next(ln for ln in lines if ln.startswith("rim "))
    assert "dark interior" in rim and "px (left / right)" in rim
    assert "µm)" in next(ln for ln in lines if ln.startswith("rms residual"))
    assert not any(ln.startswith("suspect because") for ln in lines)
    # a fit-RMS limit no real fit meets: the table and the batch row say why it is suspect
    strict = MeasureOptions(suspect_rms_m=1e-9, suspect_rms_px=1e-6)
    m = measure_hole(r.left, r.right, small_stereo(), options=strict)
    assert m.status == "suspect" and m.suspect_reasons
    table = _table(m)
    why = next(ln for ln in table.splitlines() if ln.startswith("suspect because"))
    assert why.endswith(m.suspect_reasons[0]) and "fit RMS" in why
    entry = PairEntry("H1", tmp_path / "left.png", tmp_path / "right.png")
    (row,) = measure_pairs([entry], small_stereo(), None, strict)
    assert {"rms_um", "suspect_reasons", "rim"} <= set(CSV_COLUMNS)
    assert row["status"] == "suspect" and "fit RMS" in row["suspect_reasons"]
    assert abs(row["rms_um"] - row["rms_m"] * 1e6) < 1e-9 and "dark interior" in row["rim"]
    assert row["_result"]["suspect_reasons"] == list(m.suspect_reasons)
