"""The CSV formats and thermal.json: round trips and clear messages for bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robots.thermal import (
    DriftTruth,
    ThermalDataError,
    ThermalModelFileError,
    ThermalSpec,
    default_settings,
    identify,
    reference_from_cold,
    simulate_observations,
)
from robots.thermal.csvio import read_observations, read_poses, write_observations
from robots.thermal.modelfile import load_model, save_model


@pytest.fixture(scope="module")
def obs(table, cell):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    geometry, plan = cell
    times = np.arange(0.0, 7201.0, 1200.0)
    return simulate_observations(
        truth.T_base_tool0,
        truth.sensor_readings,
        truth.settings.sensor_names,
        geometry,
        plan,
        times,
    )


def _write(tmp_path, text, name="obs.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


HEADER = (
    "time_s,target_id,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,temp_amb_degC,"
    "x_tcp_m,y_tcp_m,z_tcp_m"
)
ROW = "0,R0,0,0.1,0.2,0.3,0.4,0.5,20.0,0.001,0.002,0.003"


def test_observations_round_trip(tmp_path, obs):
    path = tmp_path / "obs.csv"
    write_observations(path, obs)
    back = read_observations(path, known_targets={f"R{i}" for i in range(6)})
    assert back.sensor_names == obs.sensor_names
    assert back.target_ids == obs.target_ids
    for field in ("time_s", "q_rad", "temps_degC", "p_tcp_m"):
        assert np.array_equal(getattr(back, field), getattr(obs, field))
    assert back.lines[0] == 2


def test_kelvin_columns_are_converted(tmp_path):
    path = _write(
        tmp_path,
        HEADER.replace("temp_amb_degC", "temp_amb_K") + "\n" + ROW.replace("20.0", "293.15"),
    )
    assert read_observations(path).temps_degC[0, 0] == pytest.approx(20.0)


@pytest.mark.parametrize(
    ("header", "message"),
    [
        (
            HEADER.replace("x_tcp_m", "x_tcp_mm"),
            "column 'x_tcp_mm': unit 'mm' not accepted: the column must be 'x_tcp_m'",
        ),
        (HEADER.replace("q3_rad", "q3_deg"), "column 'q3_deg': unit 'deg' not accepted"),
        (HEADER.replace("time_s", "time_min"), "must be 'time_s'"),
        (HEADER.replace("temp_amb_degC", "temp_amb_degF"), "temperature unit 'degF' not accepted"),
        (HEADER.replace(",target_id", ",target"), "missing columns ['target_id']"),
        (HEADER.replace(",temp_amb_degC", ",ambient"), "no temperature column"),
    ],
)
def test_header_errors_name_the_column(tmp_path, header, message):
    path = _write(tmp_path, header + "\n" + ROW)
    with pytest.raises(ThermalDataError) as info:
        read_observations(path)
    assert str(path) in str(info.value) and message in str(info.value)


def test_value_and_target_errors_name_the_line(tmp_path):
    bad = ROW.replace("0.002", "abc")
    path = _write(tmp_path, f"{HEADER}\n{ROW}\n{bad}\n")
    with pytest.raises(ThermalDataError, match=r"line 3, column 'y_tcp_m': 'abc' is not a number"):
        read_observations(path)
    path = _write(tmp_path, f"{HEADER}\n{ROW}\n{ROW.replace('R0', 'R9')}\n")
    with pytest.raises(
        ThermalDataError, match=r"line 3, column 'target_id': unknown target id 'R9'"
    ):
        read_observations(path, known_targets={"R0", "R1"})
    with pytest.raises(ThermalDataError, match="no such file"):
        read_observations(tmp_path / "absent.csv")
    with pytest.raises(ThermalDataError, match="no data rows"):
        read_observations(_write(tmp_path, HEADER + "\n"))


def test_identify_names_unknown_targets_of_simulated_data(table, cell, obs):
    geometry, _ = cell
    fewer = type(geometry)(
        geometry.T_cell_base, geometry.T_tool0_tcp, {"R0": geometry.targets_cell_m["R0"]}
    )
    with pytest.raises(ThermalDataError, match="unknown target id 'R1'"):
        identify(obs, fewer, table, ThermalSpec.mapped(obs.sensor_names, (20.0,) * 6))


def test_poses_need_every_model_sensor(tmp_path):
    text = "id,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,temp_j1_degC\np1,0,0,0,0,0,0,25\n"
    path = _write(tmp_path, text, "poses.csv")
    rows = read_poses(path, ("j1",))
    assert rows.temps_degC.tolist() == [[25.0]] and rows.rows[0][0] == "p1"
    with pytest.raises(ThermalDataError, match=r"missing temperature columns \['temp_j2_degC'\]"):
        read_poses(path, ("j1", "j2"))
    partial = read_poses(path, ("j1", "j2"), used=("j1",))
    assert partial.temps_degC[0, 0] == 25.0 and np.isnan(partial.temps_degC[0, 1])


def test_model_file_round_trip_and_errors(tmp_path, table, cell, obs):
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs))
    model = identify(obs, cell[0], table, spec, robot_model="abb_irb2600_20_165").model
    path = tmp_path / "thermal.json"
    save_model(path, model)
    back = load_model(path)
    assert back.coefficients == model.coefficients
    assert back.refused == model.refused
    assert back.spec == model.spec and back.table == model.table
    assert np.allclose(back.T_tool0_tcp, model.T_tool0_tcp, atol=1e-15)
    q = np.array([0.1, 0.2, -0.3, 0.4, 0.5, 0.6])
    temps = np.full(6, 30.0)
    assert np.allclose(back.fk(q, temps), model.fk(q, temps), atol=1e-14)
    doc = json.loads(path.read_text())
    assert (doc["format"], doc["version"]) == ("holecell.thermal", 1)
    legacy = {k: v for k, v in doc.items() if k != "version"} | {"format": "holecell.thermal/1"}
    path.write_text(json.dumps(legacy))  # as written before Dec 2026: still read
    assert load_model(path).coefficients == model.coefficients
    path.write_text(json.dumps(doc | {"version": 2}))
    with pytest.raises(ThermalModelFileError, match="version"):
        load_model(path)
    doc["coefficients"]["k_link2"]["value"] = "hot"
    path.write_text(json.dumps(doc))
    with pytest.raises(ThermalModelFileError, match=r"coefficients\.k_link2"):
        load_model(path)
    del doc["dh"]["a_m"]
    path.write_text(json.dumps(doc))
    with pytest.raises(ThermalModelFileError, match=r"dh.a_m: missing"):
        load_model(path)
    path.write_text("{not json")
    with pytest.raises(ThermalModelFileError, match="not valid JSON"):
        load_model(path)
