"""Built-in part materials: linear expansion coefficient near 20 degC and its uncertainty.

The figures are handbook values at room temperature (alloys of one family spread by about
+-1e-6 /K, so that is the standard uncertainty given); a cell file gives its own figures when it
knows the alloy (``part.material: {name, alpha_per_K, u_alpha_per_K}``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field

#: limits of a plausible expansion coefficient (1/K): beyond them the figure is a mistake
#: (11.5 written for 11.5e-6, a unit mixed up); the range spans invar to filled plastics
ALPHA_MIN_PER_K = -1e-5
ALPHA_MAX_PER_K = 3e-4


@dataclass(frozen=True)
class Material:
    """A part material: ``alpha_per_K`` (1/K) and its standard uncertainty ``u_alpha_per_K``."""

    name: str
    alpha_per_K: float  # noqa: N815 (unit suffix)
    u_alpha_per_K: float  # noqa: N815 (unit suffix)


BUILTIN_MATERIALS: dict[str, Material] = {
    m.name: m
    for m in (
        Material("steel", 11.5e-6, 1.0e-6),
        Material("stainless_steel", 16.0e-6, 1.0e-6),
        Material("cast_iron", 10.5e-6, 1.0e-6),
        Material("aluminium", 23.0e-6, 1.0e-6),
        Material("titanium", 8.6e-6, 0.5e-6),
        Material("magnesium", 26.0e-6, 1.0e-6),
    )
}

#: the material assumed when a cell file names none (the built-in frame is steel)
DEFAULT_MATERIAL = "steel"


class MaterialSpec(BaseModel):
    """``part.material`` of a cell file: name, expansion coefficient (1/K) and its standard
    uncertainty (1/K), each checked for a plausible range."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    name: Annotated[str, Field(min_length=1)]
    alpha_per_K: Annotated[float, Field(ge=ALPHA_MIN_PER_K, le=ALPHA_MAX_PER_K)]  # noqa: N815
    u_alpha_per_K: Annotated[float, Field(ge=0, le=1e-4)]  # noqa: N815


def material_field(value: Any) -> Any:
    """``part.material`` before validation: a built-in name becomes its figures; a mapping is
    validated as given (:class:`MaterialSpec`); an unknown name is a ``ValueError``."""
    if isinstance(value, str):
        if value not in BUILTIN_MATERIALS:
            known = ", ".join(sorted(BUILTIN_MATERIALS))
            raise ValueError(f"unknown material (built-in: {known}; or give name, alpha_per_K "
                             "and u_alpha_per_K)")  # fmt: skip
        m = BUILTIN_MATERIALS[value]
        return {"name": m.name, "alpha_per_K": m.alpha_per_K, "u_alpha_per_K": m.u_alpha_per_K}
    return value
