"""``holecell thermal identify`` and ``holecell thermal predict`` end to end."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import yaml

from cell import cli
from robots.thermal import DriftTruth, default_settings, simulate_observations
from robots.thermal.csvio import write_observations
from robots.transforms import matrix_to_pose

WARM_S = 4000.0


@pytest.fixture(autouse=True)
def only_thermal_command(monkeypatch):
    """Test this subcommand alone, whatever other subcommands are registered."""
    monkeypatch.setattr(cli, "COMMAND_MODULES", ("thermal_cmd",))


@pytest.fixture(scope="module")
def truth(table):
    return DriftTruth(table, default_settings(per_joint_noise_K=0.0))


@pytest.fixture()
def files(tmp_path, cell, truth, T_cell_base, T_tool0_tcp):
    geometry, plan = cell

    def pose(T):
        p = matrix_to_pose(T)
        return {"xyz": p["xyz"], "quat_xyzw": p["quat_xyzw"]}

    doc = {
        "name": "thermal-test",
        "robot": {
            "model": "abb_irb2600_20_165",
            "base": pose(T_cell_base),
            "home": [0.0, 0.0, 0.0, 0.0, 0.5, 0.0],
        },
        "tool": {"tool0_to_tcp": pose(T_tool0_tcp), "standoff_m": 0.3},
        "part": {},
        "reference_targets": [
            {"id": tid, "position": [float(v) for v in p], "normal": [0, 0, 1], "diameter": 0.01}
            for tid, p in geometry.targets_cell_m.items()
        ],
    }
    cell_path = tmp_path / "cell.yaml"
    cell_path.write_text(yaml.safe_dump(doc))
    obs = simulate_observations(
        truth.T_base_tool0,
        truth.sensor_readings,
        truth.settings.sensor_names,
        geometry,
        plan,
        np.arange(0.0, 7201.0, 900.0),
    )
    obs_path = tmp_path / "obs.csv"
    write_observations(obs_path, obs)
    return {"cell": cell_path, "obs": obs_path, "out": tmp_path / "thermal.json", "dir": tmp_path}


def _identify(files, capsys):
    rc = cli.main(
        [
            "thermal",
            "identify",
            str(files["obs"]),
            "--cell",
            str(files["cell"]),
            "-o",
            str(files["out"]),
        ]
    )
    return rc, capsys.readouterr()


def test_identify_prints_coefficients_and_writes_the_model(files, capsys, truth):
    rc, out = _identify(files, capsys)
    assert rc == 0, out.err
    assert "k_link2" in out.out and "1-sigma" in out.out and "fit residual RMS" in out.out
    assert "refused k_link5: link 5 has no D-H length" in out.out
    doc = json.loads(files["out"].read_text())
    assert doc["coefficients"]["k_link4"]["value"] == pytest.approx(23e-6, abs=1e-11)
    assert doc["sensors"]["names"] == ["j1", "j2", "j3", "j4", "j5", "j6"]


def test_predict_gives_the_drifted_tcp(files, capsys, truth, T_cell_base, T_tool0_tcp):
    assert _identify(files, capsys)[0] == 0
    q = np.array([[0.1, 0.2, -0.3, 0.4, 0.9, 0.6], [-0.5, 0.4, 0.1, -0.2, 1.1, 0.0]])
    temps = truth.sensor_readings(np.array([WARM_S, WARM_S]))
    poses = files["dir"] / "poses.csv"
    with poses.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(
            ["id", *[f"q{i}_rad" for i in range(1, 7)], *[f"temp_j{i}_degC" for i in range(1, 7)]]
        )
        for k in range(2):
            w.writerow([f"p{k}", *q[k], *temps[k]])
    out_csv = files["dir"] / "pred.csv"
    rc = cli.main(
        ["thermal", "predict", str(files["out"]), str(poses), "-o", str(out_csv), "--command"]
    )
    assert rc == 0, capsys.readouterr().err
    rows = list(csv.DictReader(out_csv.open()))
    assert [r["id"] for r in rows] == ["p0", "p1"]
    for k, row in enumerate(rows):
        p = np.array([float(row[c]) for c in ("tcp_x_cell_m", "tcp_y_cell_m", "tcp_z_cell_m")])
        p_true = (T_cell_base @ truth.T_base_tool0(q[k], WARM_S) @ T_tool0_tcp)[:3, 3]
        assert np.allclose(p, p_true, atol=1e-9)
        assert float(row["drift_m"]) > 1e-4
        assert row["command_status"] == "converged"
        q_cmd = np.array([float(row[f"q{i}_cmd_rad"]) for i in range(1, 7)])
        assert np.max(np.abs(q_cmd - q[k])) > 1e-7


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: t.replace(",R3,", ",R99,", 1), "unknown target id 'R99'"),
        (lambda t: t.replace("x_tcp_m", "x_tcp_mm", 1), "unit 'mm' not accepted"),
        (lambda t: t.replace("q1_rad,", "", 1), "missing columns ['q1_rad']"),
    ],
)
def test_bad_observations_give_one_line_and_keep_the_old_model(files, capsys, edit, message):
    files["out"].write_text("previous model")
    files["obs"].write_text(edit(files["obs"].read_text()))
    rc, out = _identify(files, capsys)
    assert rc == 2
    assert message in out.err and "Traceback" not in out.err
    assert len(out.err.strip().splitlines()) == 1
    assert files["out"].read_text() == "previous model"


def test_missing_files_are_reported(files, capsys):
    rc = cli.main(["thermal", "predict", str(files["dir"] / "nope.json"), str(files["obs"])])
    err = capsys.readouterr().err
    assert rc == 2 and "nope.json: file: no such file" in err
    rc = cli.main(
        ["thermal", "identify", str(files["obs"]), "--cell", "missing.yaml", "-o", "x.json"]
    )
    assert rc == 2 and "missing.yaml" in capsys.readouterr().err


def test_simulate_identify_predict_on_the_builtin_cell(tmp_path, capsys):
    obs, model, poses = tmp_path / "obs.csv", tmp_path / "thermal.json", tmp_path / "poses.csv"
    rc = cli.main(["thermal", "simulate", "--cell", "motorcycle_frame", "-o", str(obs)])
    assert rc == 0, capsys.readouterr().err
    assert "observations" in capsys.readouterr().out
    rc = cli.main(["thermal", "identify", str(obs), "--cell", "motorcycle_frame", "-o", str(model)])
    out = capsys.readouterr().out
    assert rc == 0 and "k_link4" in out
    doc = json.loads(model.read_text())
    assert doc["coefficients"]["k_link4"]["value"] == pytest.approx(23e-6, abs=3e-6)
    assert doc["fit"]["residual_rms_m"] < 7e-6
    header = [f"q{i}_rad" for i in range(1, 7)] + [f"temp_j{i}_degC" for i in range(1, 7)]
    poses.write_text(",".join(header) + "\n" + ",".join(["0.2"] * 6 + ["30"] * 6) + "\n")
    rc = cli.main(["thermal", "predict", str(model), str(poses)])
    rows = list(csv.DictReader(capsys.readouterr().out.splitlines()))
    assert rc == 0 and len(rows) == 1
    assert 1e-4 < float(rows[0]["drift_m"]) < 1e-3


def test_simulate_refuses_bad_settings(tmp_path, capsys):
    rc = cli.main(
        [
            "thermal",
            "simulate",
            "--cell",
            "motorcycle_frame",
            "-o",
            str(tmp_path / "o.csv"),
            "--every-s",
            "0",
        ]
    )
    assert rc == 2 and "positive duration" in capsys.readouterr().err
