"""``part.step:`` in the cell file: the part's holes, drawing and collision mesh from its STEP
file (:mod:`cell.cad`, docs/cad_import.md)::

    part:
      step: {path: frame.step, deflection_m: 2.0e-4, pmi: true, mesh: true}

``path`` is relative to the cell file; ``deflection_m`` the mesh's largest distance from the
surface (m); ``pmi`` takes the AP242 datums and tolerances where the cell file gives none;
``mesh`` adds the tessellated part to the part's obstacles. The holes found are appended to
``part.holes`` (ids ``H1``..., an id given twice is refused).

:func:`drawing` turns the PMI into the cell file's ``datums`` and per-hole ``tolerances``,
keeping only datums that make a complete frame and position tolerances whose datums are kept;
what it leaves out joins the PMI's list of what is not modelled.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import Field

from cell.config.datums import frame_problem
from cell.config.pose import _Strict


class StepSpec(_Strict):
    """``part.step``: the STEP file and how it is used (module doc)."""

    path: Annotated[str, Field(min_length=1)]
    deflection_m: Annotated[float, Field(gt=0, le=0.01)] = 2.0e-4
    pmi: bool = True
    mesh: bool = True


def drawing(
    datums: list[dict[str, Any]], tolerances: dict[str, dict[str, Any]]
) -> tuple[list[dict[str, Any]], dict[str, dict[str, Any]], list[str]]:
    """The PMI's datums and per-hole tolerances as a cell file can hold them, and one line
    per PMI left out."""
    left: list[str] = []
    kinds = tuple(next(k for k in ("plane", "hole", "pattern") if k in d) for d in datums)
    problem = frame_problem(kinds) if datums else None
    if problem:
        left.append(f"datums {', '.join(d['label'] for d in datums)}: {problem}")
        datums = []
    kept = {d["label"] for d in datums}
    out: dict[str, dict[str, Any]] = {}
    for hole, tol in tolerances.items():
        tol = dict(tol)
        pos = tol.get("position")
        if pos is not None and not set(pos["datums"]) <= kept:
            left.append(f"{pos['pmi_id']} on {hole}: datums {pos['datums']} make no frame kept")
            del tol["position"]
        if tol:
            out[hole] = tol
    return datums, out, left
