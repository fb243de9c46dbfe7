"""The file of a run's results store (:mod:`cell.review.store`): its schema, its creation
(built completely in a temporary file, then renamed into place), the checks before it is
opened (integrity, schema version; nothing is written to a file refused), the upgrade of an
older schema, and a read-only count of its measurements.
"""

from __future__ import annotations

import json
import os
import sqlite3
from pathlib import Path
from typing import Any

from cell.review.errors import StoreError

SCHEMA_VERSION = 3
#: versions :meth:`Store.open` can read; older ones get the tables added since (nothing removed)
READABLE_VERSIONS = ("1", "2", "3")
FILENAME = "results.sqlite"

_SCHEMA = (
    """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE run (
    id INTEGER PRIMARY KEY CHECK (id = 1),
    cell_name TEXT NOT NULL, cell_sha256 TEXT NOT NULL, cell_text TEXT NOT NULL,
    cell_path TEXT NOT NULL, tour_text TEXT NOT NULL, reference_text TEXT NOT NULL,
    robot_model TEXT NOT NULL, port TEXT NOT NULL,
    state TEXT NOT NULL, started_at REAL NOT NULL, finished_at REAL
);
CREATE TABLE holes (
    hole_id TEXT PRIMARY KEY, stop_index INTEGER NOT NULL UNIQUE,
    nominal_json TEXT NOT NULL
);
CREATE TABLE measurements (
    hole_id TEXT PRIMARY KEY REFERENCES holes(hole_id),
    stop_index INTEGER NOT NULL, status TEXT NOT NULL, result_json TEXT NOT NULL,
    stored_at REAL NOT NULL
);
CREATE TABLE events (
    id INTEGER PRIMARY KEY AUTOINCREMENT, t_wall REAL NOT NULL, kind TEXT NOT NULL,
    state TEXT NOT NULL, message TEXT NOT NULL, data_json TEXT NOT NULL
);
"""
    + """
CREATE TABLE IF NOT EXISTS reference_observations (
    id INTEGER PRIMARY KEY AUTOINCREMENT, round INTEGER NOT NULL, t_s REAL NOT NULL,
    target TEXT NOT NULL, q_rad_json TEXT NOT NULL, temperatures_c_json TEXT NOT NULL,
    p_tcp_m_json TEXT NOT NULL, stored_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS thermal_models (
    id INTEGER PRIMARY KEY AUTOINCREMENT, source TEXT NOT NULL, model_json TEXT NOT NULL,
    stored_at REAL NOT NULL
);
"""
    + """
CREATE TABLE IF NOT EXISTS uncertainty (
    hole_id TEXT NOT NULL REFERENCES measurements(hole_id) ON DELETE CASCADE,
    component TEXT NOT NULL, u_position_m REAL NOT NULL, u_diameter_m REAL NOT NULL,
    note TEXT NOT NULL, PRIMARY KEY (hole_id, component)
);
"""
)
#: the tables added by schema versions 2 and 3
_SCHEMA_V2 = _SCHEMA[_SCHEMA.index("CREATE TABLE IF NOT EXISTS reference_observations") :]


def create_file(
    path: Path, run_row: tuple[Any, ...], holes: list[tuple[str, int, dict[str, Any]]]
) -> None:
    """Create the store ``path`` with its run row and planned holes, all or nothing."""
    tmp = path.with_name(f"{FILENAME}.creating-{os.getpid()}")
    try:
        build_file(tmp, run_row, holes)
        if path.exists():
            raise StoreError(path, "a run was stored here meanwhile; not overwritten")
        os.replace(tmp, path)
    except sqlite3.Error as exc:
        raise StoreError(path, f"cannot create the store ({exc}); nothing was written") from exc
    finally:
        tmp.unlink(missing_ok=True)


def checked_version(path: Path) -> str:
    """The schema version of the existing store ``path`` after its integrity check; raises
    :class:`StoreError` for a corrupt, foreign or unreadable file (which is not modified)."""
    try:
        con = sqlite3.connect(f"file:{path}?mode=rw", uri=True, isolation_level=None)
    except sqlite3.Error as exc:
        raise StoreError(path, f"cannot open the store ({exc}); not modified") from exc
    try:
        check = con.execute("PRAGMA quick_check").fetchone()[0]
        if check != "ok":
            raise StoreError(path, f"the store is corrupt ({check}); it was not modified")
        version = con.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()
        if version is None or version[0] not in READABLE_VERSIONS:
            found = None if version is None else version[0]
            raise StoreError(path, f"schema version {found!r} is not one this holecell "
                                   f"reads {READABLE_VERSIONS}; not modified")  # fmt: skip
    except sqlite3.DatabaseError as exc:
        raise StoreError(path, f"not a readable holecell store ({exc}); not modified") from exc
    finally:
        con.close()
    return version[0]


def upgrade(con: sqlite3.Connection) -> None:
    """Add the tables of the current schema to an older store (nothing is removed); on a
    failure the transaction is rolled back and ``con`` closed."""
    try:
        con.execute("BEGIN")
        for statement in _SCHEMA_V2.split(";"):
            if statement.strip():
                con.execute(statement)
        con.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'",
                    (str(SCHEMA_VERSION),))  # fmt: skip
        con.execute("COMMIT")
    except BaseException:
        con.execute("ROLLBACK")
        con.close()
        raise


def count_measurements(run_dir: Path) -> int:
    """Measurements stored in a run directory, read-only; -1 when there is no readable store.

    Safe to call while another process writes the store (used to watch a run from outside).
    """
    path = Path(run_dir) / FILENAME
    if not path.exists():
        return -1
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            return int(con.execute("SELECT count(*) FROM measurements").fetchone()[0])
        finally:
            con.close()
    except sqlite3.DatabaseError:
        return -1


def build_file(
    tmp: Path, run_row: tuple[Any, ...], holes: list[tuple[str, int, dict[str, Any]]]
) -> None:
    """Write a complete new store into ``tmp`` (a rollback-journal file, closed on return):
    either every table and row is there, or the caller removes the file."""
    tmp.unlink(missing_ok=True)
    con = sqlite3.connect(str(tmp), isolation_level=None)
    try:
        con.execute("BEGIN")
        for statement in _SCHEMA.split(";"):
            if statement.strip():
                con.execute(statement)
        con.execute("INSERT INTO meta VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),))
        con.execute(
            "INSERT INTO run VALUES (1, ?, ?, ?, ?, ?, ?, ?, ?, 'created', ?, NULL)", run_row
        )
        con.executemany(
            "INSERT INTO holes VALUES (?, ?, ?)",
            [(h, k, json.dumps(nom)) for h, k, nom in holes],
        )
        con.execute("COMMIT")
    finally:
        con.close()


def connect(path: Path) -> sqlite3.Connection:
    """A read-write connection to the store ``path``: WAL journal, full sync, foreign keys."""
    con = sqlite3.connect(str(path))
    con.execute("PRAGMA journal_mode=WAL")
    con.execute("PRAGMA synchronous=FULL")
    con.execute("PRAGMA foreign_keys=ON")
    return con
