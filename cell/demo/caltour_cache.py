"""The demo's calibration tour, planned once per cell and kept in the user's cache folder.

Planning the calibration tour (views, IK, collision checks, the tour) takes 20 s on the
2-core machine and gives the same tour for the same cell, view count, seed and code. So
:func:`cached_caltour` keeps it as JSON under the user's cache folder
(``platformdirs.user_cache_dir("holecell")``, or ``$HOLECELL_CACHE_DIR``), named by a
SHA-256 of what decides it: the cell file's hash (:func:`planner.cell_sha256`), the plan
options, and the source of the code that plans it (``planner``, ``robots``,
``cell/calibration/plan``, this folder), so that a changed planner plans again. A file that
does not read back as a calibration tour is planned over. What happened is returned as a
sentence (the demo prints it); a folder that cannot be written costs the cache, not the run.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from measure.user_cache import cache_dir
from planner.calibration import caltour_from_dict
from planner.cell_identity import cell_sha256
from planner.errors import PlanningError
from planner.tour import write_json

#: the packages (relative to the repository root) whose source decides the plan
_CODE = ("planner", "robots", "cell/calibration/plan", "cell/demo", "cell/config")


def _code_digest(packages: tuple[str, ...] = _CODE) -> str:
    root = Path(__file__).resolve().parents[2]
    h = hashlib.sha256()
    for pkg in packages:
        for f in sorted((root / pkg).rglob("*.py")):
            h.update(str(f.relative_to(root)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def caltour_key(cell: Any, options: Any, views: int, seed: int) -> str:
    """SHA-256 (hex) of the cell, the plan's options, the view count, the seed and the code."""
    what = {
        "cell": cell_sha256(cell),
        "options": repr(options),
        "views": views,
        "seed": seed,
        "code": _code_digest(),
    }
    return hashlib.sha256(json.dumps(what, sort_keys=True).encode()).hexdigest()


def plan_key(what: dict[str, Any], packages: tuple[str, ...] = _CODE) -> str:
    """SHA-256 (hex) of ``what`` (JSON-ready) and of the source of ``packages``."""
    return hashlib.sha256(
        json.dumps({**what, "code": _code_digest(packages)}, sort_keys=True).encode()
    ).hexdigest()


def cached_caltour(
    key: str, plan: Callable[[], dict[str, Any]] | None, folder: Path | None = None
) -> tuple[dict[str, Any], str] | None:
    """The calibration tour (``caltour.json`` mapping) for ``key``: read from the cache, else
    ``plan()`` and stored (``plan`` None: None). Returns it and a sentence saying which."""
    return cached_plan("caltour", key, plan, caltour_from_dict, folder)


def cached_plan(
    name: str,
    key: str,
    plan: Callable[[], dict[str, Any]] | None,
    check: Callable[[dict[str, Any], str], Any],
    folder: Path | None = None,
) -> tuple[dict[str, Any], str] | None:
    """A planned mapping for ``key``, kept as ``<name>-<key>.json``: read from the cache (and
    ``check(data, path)``: raises :class:`PlanningError` or ValueError when it is not one),
    else ``plan()`` and stored (``plan`` None: None, nothing planned). Returns it and a
    sentence saying which."""
    path = (folder or cache_dir()) / f"{name}-{key[:24]}.json"
    if path.is_file():
        try:
            data = json.loads(path.read_text())
            check(data, str(path))
            return data, f"from the cache {path} (planned once per cell; delete it to plan again)"
        except (
            OSError,
            ValueError,
            PlanningError,
        ) as exc:  # unreadable or not a tour: plan it again
            stale = f" (the cached file did not read back: {exc})"
    else:
        stale = ""
    if plan is None:
        return None
    t0 = time.perf_counter()
    data = plan()
    took = time.perf_counter() - t0
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_json(path, data)
        return data, f"planned in {took:.1f} s{stale}, cached in {path}"
    except OSError as exc:
        return data, f"planned in {took:.1f} s{stale} (not cached: {exc})"
