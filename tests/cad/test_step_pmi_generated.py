"""AP242 PMI on a generated part (tests/cad/pmi_parts.py): the build123d plate with datums,
positions and sizes written by OpenCascade's AP242 writer, every one checked against the
script: what is kept and, for each one left out, the line that says why."""

from __future__ import annotations

import numpy as np
import pytest
from pmi_parts import write_pmi_plate

from cell.cad.part import import_step
from cell.config.step_part import drawing


@pytest.fixture(scope="module")
def plate_pmi(tmp_path_factory):
    part = import_step(write_pmi_plate(tmp_path_factory.mktemp("pmi")), mesh=False)
    ids = {
        (round(h.entry_m[0] * 1e3, 6), round(h.entry_m[1] * 1e3, 6)): h.id for h in part.scan.holes
    }
    return part, ids, drawing(part.pmi.datums, part.pmi.tolerances)


def test_datums_a_b_c(plate_pmi) -> None:
    part, ids, (datums, _, _) = plate_pmi
    assert [d["label"] for d in datums] == ["A", "B", "C"]
    assert set(datums[0]["plane"]["holes"]) == set(ids.values())  # every hole enters from A
    assert datums[1]["hole"] == ids[(-45, -25)]
    assert datums[2]["hole"] == ids[(-45, 25)]
    assert [d["pmi_id"] for d in datums] == ["datum A", "datum B", "datum C"]
    assert part.pmi.notes == []  # XCAF attached every datum: no entity graph needed


def test_positions_and_sizes_kept(plate_pmi) -> None:
    _, ids, (_, tolerances, _) = plate_pmi
    assert set(tolerances) == {ids[(0, -25)], ids[(22, 0)]}
    hole = tolerances[ids[(0, -25)]]
    assert hole["position"]["zone_diameter_m"] == pytest.approx(0.25e-3, abs=1e-12)
    assert hole["position"]["datums"] == ["A", "B", "C"]
    assert hole["position"]["material_condition"] == "MMC"
    assert np.allclose(
        [hole["size"]["upper_m"], hole["size"]["lower_m"]], [1e-4, -5e-5], atol=1e-12
    )
    cbore = tolerances[ids[(22, 0)]]
    assert cbore["position"]["zone_diameter_m"] == pytest.approx(0.4e-3, abs=1e-12)
    assert cbore["position"]["material_condition"] == "RFS"
    assert np.allclose([cbore["size"]["upper_m"], cbore["size"]["lower_m"]], [2e-4, 0], atol=1e-12)


def test_each_one_left_out_is_listed_with_its_reason(plate_pmi) -> None:
    part, ids, (_, _, left) = plate_pmi
    listed = [*part.pmi.unmodelled, *left]
    expect = [
        f"Position 0.1 mm |A|B|C on {ids[(0, -25)]}: a second position tolerance",
        f"Position 0.4 mm |A|B|C on {ids[(45, 25)]}: on its 6.6 mm bore, the cell measures "
        "the 11 mm entry bore",
        f"Position 0.3 mm |A|B|C on {ids[(0, 25)]} (its zone has no ⌀",
        "Flatness 0.05 mm (not modelled",
        f"diameter 9 mm +0.1/-0.1 on {ids[(22, 0)]}: on its 9 mm bore, the cell measures the "
        "15 mm entry bore",
        f"on {ids[(45, -25)]}: datums A|B not the frame kept (A|B|C)",
    ]
    for text in expect:
        assert sum(text in line for line in listed) == 1, text
    assert len(listed) == len(expect)
