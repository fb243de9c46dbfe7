"""``part.step:`` in the cell file: the part's holes, drawing and collision mesh from its STEP
file (:mod:`cell.cad`, docs/cad_import.md)::

    part:
      step: {path: frame.step, deflection_m: 2.0e-4, pmi: true, mesh: true}

``path`` is relative to the cell file; ``deflection_m`` the mesh's largest distance from the
surface (m); ``pmi`` takes the AP242 datums and tolerances where the cell file gives none;
``mesh`` adds the tessellated part to the part's obstacles. The holes found are appended to
``part.holes`` (ids ``H1``..., an id given twice is refused).

:func:`drawing` turns the PMI into the cell file's ``datums`` and per-hole ``tolerances``,
keeping one complete datum reference frame (the one most position tolerances refer to) and the
position tolerances that refer to it; what it leaves out joins the PMI's list of what is not
modelled.
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


def _frames(datums: list[dict[str, Any]], tolerances: dict[str, dict[str, Any]]) -> list[list[str]]:
    """The frames to try, best first: the position tolerances' datum references, most used
    first, then every datum in the order listed."""
    count: dict[tuple[str, ...], int] = {}
    for tol in tolerances.values():
        pos = tol.get("position")
        if pos is not None:
            key = tuple(pos["datums"])
            count[key] = count.get(key, 0) + 1
    ranked = sorted(count, key=lambda k: -count[k])  # stable: first seen first among equals
    return [list(f) for f in ranked] + [[d["label"] for d in datums]]


def drawing(
    datums: list[dict[str, Any]], tolerances: dict[str, dict[str, Any]]
) -> tuple[list[dict[str, Any]], dict[str, dict[str, Any]], list[str]]:
    """The PMI's datums and per-hole tolerances as a cell file can hold them, and one line
    per PMI left out.

    One datum reference frame is kept (the run's alignment is the frame of the datums in the
    order listed): the frame most position tolerances refer to whose datums make a complete
    frame, else all the datums when they make one. Its datums are kept in its order, with the
    position tolerances that refer to it; other datums and positions are listed."""
    left: list[str] = []
    by_label = {d["label"]: d for d in datums}
    kind = {
        lab: next(k for k in ("plane", "hole", "pattern") if k in d) for lab, d in by_label.items()
    }
    frame: list[str] = []
    for f in _frames(datums, tolerances) if datums else []:
        if f and all(lab in kind for lab in f) and not frame_problem(tuple(kind[x] for x in f)):
            frame = f
            break
    if datums and not frame:
        kinds = tuple(kind[d["label"]] for d in datums)
        left.append(f"datums {', '.join(d['label'] for d in datums)}: {frame_problem(kinds)}")
    for d in datums:
        if frame and d["label"] not in frame:
            left.append(
                f"{d.get('pmi_id') or 'datum ' + d['label']}: not in the frame kept "
                f"({'|'.join(frame)}; a cell file takes one frame from the STEP)"
            )
    out: dict[str, dict[str, Any]] = {}
    for hole, tol in tolerances.items():
        tol = dict(tol)
        pos = tol.get("position")
        if pos is not None and (not frame or pos["datums"] != frame):
            why = f"not the frame kept ({'|'.join(frame)})" if frame else "make no frame kept"
            left.append(f"{pos['pmi_id']} on {hole}: datums {'|'.join(pos['datums'])} {why}")
            del tol["position"]
        if tol:
            out[hole] = tol
    return [by_label[lab] for lab in frame], out, left
