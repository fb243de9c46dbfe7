"""``holecell measure --pairs``: folder and list-file pairing, bad pairs reported in their row."""

from __future__ import annotations

import csv
import json

import cv2
import numpy as np
import pytest
from measure_helpers import render, small_stereo

from cell.cli import main
from cell.commands.measure_batch import collect_pairs


@pytest.fixture(scope="module")
def pair_images():
    return [render(0.008, 10.0, 31), render(0.008, 5.0, 32)]


def _stereo(tmp_path):
    path = tmp_path / "stereo.json"
    small_stereo().save(path)
    return str(path)


def test_folder_batch_reports_bad_pairs_in_their_rows(tmp_path, capsys, pair_images):
    d = tmp_path / "pairs"
    d.mkdir()
    for k, r in enumerate(pair_images, start=1):
        cv2.imwrite(str(d / f"H0{k}_left.png"), r.left)
        cv2.imwrite(str(d / f"H0{k}_right.png"), r.right)
    cv2.imwrite(str(d / "H03_left.png"), np.zeros_like(pair_images[0].left))  # black
    cv2.imwrite(str(d / "H03_right.png"), pair_images[0].right)
    cv2.imwrite(str(d / "H04_left.png"), pair_images[0].left)  # no right image
    (d / "notes.txt").write_text("not an image")
    out = tmp_path / "rows.csv"
    args = ["measure", "--pairs", str(d), "--stereo", _stereo(tmp_path), "-o", str(out)]
    assert main([*args, "--diameter", "0.008"]) == 1  # ran, but two pairs failed
    cap = capsys.readouterr()
    assert "4 pairs: 2 measured, 2 failed" in cap.out and "pairs [" in cap.err
    rows = list(csv.DictReader(out.open()))
    assert [r["id"] for r in rows] == ["H01", "H02", "H03", "H04"]
    assert [r["status"] for r in rows] == ["ok", "ok", "error", "error"]
    assert "black" in rows[2]["reason"] and rows[3]["reason"] == "no right image"
    for r, truth in zip(rows[:2], pair_images, strict=True):
        assert abs(float(r["diameter_m"]) - 0.008) < 6e-6
        c = np.array([float(r[f"center_{a}_m"]) for a in "xyz"])
        assert np.linalg.norm(c - truth.truth.center_m) < 15e-6


def test_list_file_and_json_output(tmp_path, capsys, pair_images):
    r = pair_images[0]
    (tmp_path / "img").mkdir()
    cv2.imwrite(str(tmp_path / "img" / "a L.png"), r.left)
    cv2.imwrite(str(tmp_path / "img" / "a R.png"), r.right)
    listing = tmp_path / "pairs.txt"
    listing.write_text(
        "# left right id\n"
        '"img/a L.png" "img/a R.png" first   # quoted: names with spaces\n'
        "\n"
        "img/missing.png img/a_R.png\n"
        "just-one-field\n"
    )
    out = tmp_path / "rows.json"
    args = ["measure", "--pairs", str(listing), "--stereo", _stereo(tmp_path), "-o", str(out)]
    assert main(args) == 1
    capsys.readouterr()
    doc = json.loads(out.read_text())
    assert doc["format"] == "holecell.measure_batch" and doc["version"] == 1
    first, missing, bad = doc["pairs"]
    assert first["id"] == "first" and first["status"] == "ok" and "center_m" in first
    assert missing["status"] == "error" and "missing.png" in missing["reason"]
    assert "line 5" in bad["reason"] and "LEFT RIGHT [ID]" in bad["reason"]


def test_pairing_rules(tmp_path, capsys):
    d = tmp_path / "a"
    (d / "left").mkdir(parents=True)
    (d / "right").mkdir()
    for side in ("left", "right"):
        (d / side / "0001.png").write_bytes(b"")
    (d / "left" / "0002.png").write_bytes(b"")
    got = {e.pair_id: e.problem for e in collect_pairs(str(d))}
    assert got == {"0001": "", "0002": "no right image"}
    flat = tmp_path / "b"
    flat.mkdir()
    names = ("left01.jpg", "right01.jpg", "H7-Left.PNG", "H7-Right.png", "x.png")
    names += ("raw_left1.png", "raw_right1.png", "a_bright2.png", "c_leftover.png")
    for name in names:
        (flat / name).write_bytes(b"")
    got = {e.pair_id: (e.left.name, e.right.name) for e in collect_pairs(str(flat))}
    assert got == {
        "01": ("left01.jpg", "right01.jpg"),
        "H7": ("H7-Left.PNG", "H7-Right.png"),
        "raw_1": ("raw_left1.png", "raw_right1.png"),
    }
    st = _stereo(tmp_path)
    assert main(["measure", "--pairs", str(tmp_path / "none"), "--stereo", st]) == 2
    assert "no such folder or list file" in capsys.readouterr().err


def test_rows_file_of_another_kind_is_refused_before_measuring(tmp_path, capsys):
    d = tmp_path / "pairs"
    d.mkdir()
    args = ["measure", "--pairs", str(d), "--stereo", _stereo(tmp_path)]
    assert main([*args, "-o", str(tmp_path / "rows.txt")]) == 2
    err = capsys.readouterr().err
    assert "rows.txt" in err and ".csv or .json" in err
    assert not (tmp_path / "rows.txt").exists()
