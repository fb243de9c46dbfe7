"""Keeping a run's thermal state in its store, so a resumed run continues with it: the reference
observations (one row each, as measured) and every thermal model the run uses (``thermal.json``
text, :mod:`robots.thermal.modelfile`), each hole naming the model it was compensated with."""

from __future__ import annotations

import json

from cell.review.store import Store
from cell.run.thermal_update import Row
from robots.thermal.model import ThermalModel
from robots.thermal.modelfile import model_from_dict, model_to_dict


def model_text(model: ThermalModel) -> str:
    """The model as ``thermal.json`` text (NaN uncertainties as null, like the file)."""
    return json.dumps(model_to_dict(model), sort_keys=True).replace("NaN", "null")


def remember_model(store: Store, model: ThermalModel, source: str) -> int:
    """Store ``model`` unless it is the one stored last; returns its id in the store."""
    text = model_text(model)
    latest = store.latest_model()
    if latest is not None and latest[2] == text:
        return latest[0]
    return store.record_model(source, text)


def stored_model(store: Store) -> tuple[int, ThermalModel] | None:
    """The model the run used last, or None."""
    latest = store.latest_model()
    if latest is None:
        return None
    model_id, source, text = latest
    return model_id, model_from_dict(json.loads(text), f"{store.path} (thermal model {model_id}, "
                                                       f"{source})")  # fmt: skip


def stored_rows(store: Store) -> list[Row]:
    """The reference observations stored so far, as :class:`cell.run.thermal_update.ThermalUpdate`
    rows."""
    return list(store.reference_observations())
