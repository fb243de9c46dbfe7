"""The results store of a run: ``results.sqlite`` in the run directory (SQLite, WAL mode).

Tables: ``meta`` (schema version), ``run`` (one row: cell name, SHA-256, text and path of the
cell file, the tour's and the reference tour's text, port, state, times), ``holes`` (every
planned hole with its stop index and nominal geometry), ``measurements`` (at most one row per
hole: a UNIQUE key makes storing a hole twice impossible), ``events`` (run state changes,
faults, retries, thermal updates), ``reference_observations`` (every measured reference target:
round, controller time, target, joints, readings, target in the TCP frame; one transaction each)
``thermal_models`` (every thermal model the run used, as ``thermal.json`` text, with where
it came from; a hole's result names the model it was compensated with, ``thermal_model_id``)
and, since schema version 3, ``uncertainty`` (per measured hole, every component of its budget:
standard uncertainties of the position deviation and the diameter, m, and the note); ``meta``
keeps the part's temperature state (``part_state``).

A new store is built completely in a temporary file next to it and then renamed into place, so
a failed creation leaves no half-made ``results.sqlite`` behind. Each hole is stored in one
transaction, so a killed process leaves every hole either fully
stored or not at all. Opening checks the schema and the file's integrity first and refuses a
corrupt or foreign file without writing to it.
"""

from __future__ import annotations

import json
import sqlite3
import time
from pathlib import Path
from typing import Any

import numpy as np

from cell.records.hole_result import HoleResult
from cell.review.errors import StoreError
from cell.review.store_file import (
    FILENAME,
    READABLE_VERSIONS,
    SCHEMA_VERSION,
    checked_version,
    connect,
    count_measurements,
    create_file,
    upgrade,
)

__all__ = [
    "FILENAME",
    "READABLE_VERSIONS",
    "SCHEMA_VERSION",
    "Store",
    "StoreError",
    "count_measurements",
]


class Store:
    """A run's results store. Create with :meth:`create`, reopen with :meth:`open`."""

    def __init__(self, path: Path, con: sqlite3.Connection) -> None:
        self.path = path
        self._con = con

    @classmethod
    def create(
        cls,
        run_dir: str | Path,
        *,
        cell_name: str,
        cell_sha256: str,
        cell_text: str,
        cell_path: str,
        tour_text: str,
        reference_text: str,
        robot_model: str,
        port: str,
        holes: list[tuple[str, int, dict[str, Any]]],
    ) -> Store:
        """A new store in ``run_dir`` with the planned ``holes`` (id, stop index, nominal)."""
        path = Path(run_dir) / FILENAME
        if path.exists():
            raise StoreError(path, "a run is stored here already; use --resume or another --out")
        path.parent.mkdir(parents=True, exist_ok=True)
        run_row = (cell_name, cell_sha256, cell_text, cell_path, tour_text, reference_text,
                   robot_model, port, time.time())  # fmt: skip
        create_file(path, run_row, holes)
        return cls(path, connect(path))

    @classmethod
    def open(cls, run_dir: str | Path) -> Store:
        """Reopen the store of ``run_dir``; refuses a missing, corrupt or foreign file."""
        path = Path(run_dir) / FILENAME
        if not Path(run_dir).exists():
            raise StoreError(Path(run_dir), "no such run directory")
        if not Path(run_dir).is_dir():
            raise StoreError(Path(run_dir), "a file, not a run directory")
        if not path.is_file():
            raise StoreError(path, "no results store here (not a run directory)")
        version = checked_version(path)
        store = cls(path, connect(path))
        if version != str(SCHEMA_VERSION):
            upgrade(store._con)
        return store

    def close(self) -> None:
        """Close the database (checkpointing the WAL)."""
        self._con.close()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- run --------------------------------------------------------------------------------
    def run_info(self) -> dict[str, Any]:
        """The run row as a mapping."""
        cur = self._con.execute("SELECT * FROM run WHERE id = 1")
        row = cur.fetchone()
        return dict(zip([c[0] for c in cur.description], row, strict=True))

    def set_state(self, state: str, message: str = "", finished: bool = False) -> None:
        """Record a run state change (and an event for the timeline)."""
        with self._con:
            self._con.execute("UPDATE run SET state = ? WHERE id = 1", (state,))
            if finished:
                self._con.execute("UPDATE run SET finished_at = ? WHERE id = 1", (time.time(),))
            self._insert_event("state", state, message, {})

    def event(self, kind: str, message: str, data: dict[str, Any] | None = None) -> None:
        """Record an event (fault, retry, reconnect, thermal update...)."""
        state = self.run_info()["state"]
        with self._con:
            self._insert_event(kind, state, message, data or {})

    def _insert_event(self, kind: str, state: str, message: str, data: dict[str, Any]) -> None:
        self._con.execute(
            "INSERT INTO events (t_wall, kind, state, message, data_json) VALUES (?, ?, ?, ?, ?)",
            (time.time(), kind, state, message, json.dumps(data)),
        )

    def events(self) -> list[dict[str, Any]]:
        """Every event in order."""
        rows = self._con.execute(
            "SELECT t_wall, kind, state, message, data_json FROM events ORDER BY id"
        ).fetchall()
        return [
            {"t_wall": t, "kind": k, "state": s, "message": msg, "data": json.loads(d)}
            for t, k, s, msg, d in rows
        ]

    # --- holes ------------------------------------------------------------------------------
    def planned(self) -> list[tuple[str, int, dict[str, Any]]]:
        """(hole id, stop index, nominal) of every planned hole, in stop order."""
        rows = self._con.execute(
            "SELECT hole_id, stop_index, nominal_json FROM holes ORDER BY stop_index"
        ).fetchall()
        return [(h, k, json.loads(n)) for h, k, n in rows]

    def stored_ids(self) -> set[str]:
        """Ids of the holes already stored."""
        return {r[0] for r in self._con.execute("SELECT hole_id FROM measurements")}

    def done_ids(self) -> set[str]:
        """Ids of the holes stored with a final result (every status but ``unmeasured``, which
        a resumed run tries again)."""
        rows = self._con.execute("SELECT hole_id FROM measurements WHERE status != 'unmeasured'")
        return {r[0] for r in rows}

    def record_hole(self, result: HoleResult) -> None:
        """Store one hole in one transaction. A hole stored as ``unmeasured`` is replaced by a
        new attempt (the earlier attempt is kept as a ``retry`` event); storing any other hole
        twice raises :class:`StoreError`."""
        row = (result.hole_id, result.stop_index, result.status, json.dumps(result.to_dict()),
               time.time())  # fmt: skip
        try:
            with self._con:
                old = self._con.execute(
                    "SELECT result_json FROM measurements WHERE hole_id = ? AND "
                    "status = 'unmeasured'", (result.hole_id,)
                ).fetchone()  # fmt: skip
                if old is not None:
                    self._insert_event("retry", self.run_info()["state"],
                                       f"hole {result.hole_id}: earlier attempt unmeasured",
                                       json.loads(old[0]))  # fmt: skip
                    self._con.execute("DELETE FROM uncertainty WHERE hole_id = ?",
                                      (result.hole_id,))  # fmt: skip
                    self._con.execute("DELETE FROM measurements WHERE hole_id = ?",
                                      (result.hole_id,))  # fmt: skip
                self._con.execute("INSERT INTO measurements VALUES (?, ?, ?, ?, ?)", row)
                for c in (result.budget or {}).get("components", []):
                    self._con.execute(
                        "INSERT INTO uncertainty VALUES (?, ?, ?, ?, ?)",
                        (result.hole_id, c["name"], c["u_position_m"], c["u_diameter_m"],
                         c["note"]),
                    )  # fmt: skip
        except sqlite3.IntegrityError as exc:
            raise StoreError(
                self.path, f"hole {result.hole_id!r} is already stored or not planned ({exc})"
            ) from exc

    def uncertainty_rows(self) -> list[tuple[str, str, float, float, str]]:
        """Every stored budget component: (hole id, component, u position m, u diameter m,
        note), in stop order."""
        return self._con.execute(
            "SELECT u.hole_id, u.component, u.u_position_m, u.u_diameter_m, u.note FROM "
            "uncertainty u JOIN measurements m USING (hole_id) ORDER BY m.stop_index, u.rowid"
        ).fetchall()

    # --- part temperature -------------------------------------------------------------------
    def set_part_state(self, state: dict[str, Any]) -> None:
        """Store the run's part temperature state (:class:`PartThermalState` as a mapping)."""
        with self._con:
            self._con.execute("INSERT OR REPLACE INTO meta VALUES ('part_state', ?)",
                              (json.dumps(state),))  # fmt: skip

    def part_state(self) -> dict[str, Any] | None:
        """The stored part temperature state, or None."""
        row = self._con.execute("SELECT value FROM meta WHERE key = 'part_state'").fetchone()
        return None if row is None else json.loads(row[0])

    # --- thermal ----------------------------------------------------------------------------
    def set_thermal_reference(self, temps_degC: Any) -> None:
        """Store the run's thermal reference readings (degC, one per sensor)."""
        with self._con:
            self._con.execute("INSERT OR REPLACE INTO meta VALUES ('thermal_reference_degC', ?)",
                              (_floats(temps_degC),))  # fmt: skip

    def thermal_reference(self) -> tuple[float, ...] | None:
        """The run's thermal reference readings (degC), or None if none was taken yet."""
        row = self._con.execute(
            "SELECT value FROM meta WHERE key = 'thermal_reference_degC'"
        ).fetchone()
        return None if row is None else tuple(json.loads(row[0]))

    def record_reference(
        self, round_index: int, t_s: float, target: str, q: Any, temps: Any, p_tcp: Any
    ) -> None:
        """Store one reference-target observation in one transaction (joints rad, readings
        degC, target in the TCP frame m)."""
        with self._con:
            self._con.execute(
                "INSERT INTO reference_observations (round, t_s, target, q_rad_json, "
                "temperatures_c_json, p_tcp_m_json, stored_at) VALUES (?, ?, ?, ?, ?, ?, ?)",
                (int(round_index), float(t_s), target, _floats(q), _floats(temps),
                 _floats(p_tcp), time.time()),
            )  # fmt: skip

    def reference_observations(self) -> list[tuple[float, str, Any, Any, Any, int]]:
        """Every stored observation as ``(t_s, target, q, temps, p_tcp, round)`` (numpy arrays),
        in the order stored."""
        rows = self._con.execute(
            "SELECT t_s, target, q_rad_json, temperatures_c_json, p_tcp_m_json, round "
            "FROM reference_observations ORDER BY id"
        ).fetchall()
        return [(t, tgt, np.array(json.loads(q)), np.array(json.loads(tc)),
                 np.array(json.loads(p)), rnd) for t, tgt, q, tc, p, rnd in rows]  # fmt: skip

    def record_model(self, source: str, model_text: str) -> int:
        """Store a thermal model (``thermal.json`` text) the run uses from now; returns its id."""
        with self._con:
            cur = self._con.execute(
                "INSERT INTO thermal_models (source, model_json, stored_at) VALUES (?, ?, ?)",
                (source, model_text, time.time()),
            )
        return int(cur.lastrowid)

    def latest_model(self) -> tuple[int, str, str] | None:
        """``(id, source, thermal.json text)`` of the model stored last, or None."""
        row = self._con.execute(
            "SELECT id, source, model_json FROM thermal_models ORDER BY id DESC LIMIT 1"
        ).fetchone()
        return None if row is None else (int(row[0]), row[1], row[2])

    def model(self, model_id: int) -> tuple[str, str] | None:
        """``(source, thermal.json text)`` of the stored model ``model_id``, or None."""
        row = self._con.execute(
            "SELECT source, model_json FROM thermal_models WHERE id = ?", (model_id,)
        ).fetchone()
        return None if row is None else (row[0], row[1])

    def results(self) -> list[HoleResult]:
        """Every stored hole, in stop order."""
        rows = self._con.execute(
            "SELECT result_json FROM measurements ORDER BY stop_index"
        ).fetchall()
        out = []
        for (text,) in rows:
            d = json.loads(text)
            for key in ("nominal_part_m", "center_part_m", "normal_part", "q_rad"):
                if d.get(key) is not None:
                    d[key] = tuple(d[key])
            d["temperatures_c"] = tuple(d["temperatures_c"])
            if "passed" not in d:  # stored before the verdict had its own field
                d["passed"] = None if d.get("center_part_m") is None else d["status"] != "fail"
            out.append(HoleResult(**d))
        return out


def _floats(values: Any) -> str:
    return json.dumps([float(v) for v in values])
