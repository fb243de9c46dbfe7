"""The six-hole cell of the referencing tests (the built-in cell cut to the holes near the pivot,
their markers, the table's markers and the two scale bars), as cell-file text."""

from __future__ import annotations

import numpy as np
import yaml

from cell.config import builtin_cell_path, parse_cell
from cell.referencing.layout import suggest_markers
from cell.referencing.survey.plan import survey_views
from cell.referencing.synthetic import observe

HOLES = ("PVL", "FRL", "PUL", "FSL", "PPL", "PMB")


def small_cell_text(bars: bool = True) -> str:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["part"]["holes"] = [h for h in data["part"]["holes"] if h["id"] in HOLES]
    data["part"].pop("datums", None)
    for h in data["part"]["holes"]:
        h.pop("tolerances", None)
    data.pop("reference_markers", None)
    data.pop("scale_bars", None)
    cell = parse_cell(yaml.safe_dump(data), "small.yaml", builtin_cell_path())
    data["reference_markers"] = suggest_markers(cell)
    if bars:
        bar = {"length_m": 1.4, "U_m": 5e-6}
        data["scale_bars"] = [
            {"from": "T01", "to": "T09", **bar},
            {"from": "T28", "to": "T36", **bar},
        ]
    return yaml.safe_dump(data)


def survey_observations(cell, stereo, truth, seed: int = 0, sigma_px: float = 0.05):
    """The survey's views of ``cell`` through the nominal head, each from its planned pose."""
    rng = np.random.default_rng(seed)
    return [
        observe(truth, stereo, T, vid, sigma_px, rng, T) for vid, T in survey_views(cell, stereo)
    ]
