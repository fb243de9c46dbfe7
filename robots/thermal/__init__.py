"""Temperature error compensation on the D-H model.

- :mod:`~robots.thermal.model`: the model (``ThermalSpec``, ``ThermalModel``), D-H lengths
  growing linearly with their link's temperature, optional joint-offset drift.
- :mod:`~robots.thermal.identify`: identification from reference-target observations
  (Levenberg-Marquardt) with the rank/condition report and refusal of what the data
  cannot determine.
- :mod:`~robots.thermal.compensate`: the measurement transform and the command at one pose.
- :mod:`~robots.thermal.drift`: the drift generator (hidden truth for simulation and tests).
- :mod:`~robots.thermal.observations`: observation sets, cell geometry, simulated observations.
- :mod:`~robots.thermal.plan`: viewing poses of the reference targets (the pose plan).
- :mod:`~robots.thermal.uncertainty`: the prediction covariance at a pose
  (``ThermalModel.predict_covariance(q, temps_degC, point_tcp_m=None) -> (..., 3, 3) m^2``).
- :mod:`~robots.thermal.csvio`, :mod:`~robots.thermal.modelfile`: CSV formats, thermal.json.
"""

from robots.thermal.compensate import (
    CommandOptions,
    CommandResult,
    T_part_camera,
    camera_to_part,
    command,
    compensated_T_base_tcp,
    solve_tcp,
)
from robots.thermal.drift import (
    MATERIAL_EXPANSION_PER_K,
    DriftSettings,
    DriftTruth,
    WarmUp,
    default_settings,
)
from robots.thermal.errors import (
    ThermalDataError,
    ThermalError,
    ThermalModelFileError,
    ThermalSpecError,
    UnidentifiableError,
)
from robots.thermal.identify import (
    IdentifiabilityReport,
    IdentificationResult,
    IdentifyOptions,
    identify,
    plan_report,
    reference_from_cold,
)
from robots.thermal.model import ThermalModel, ThermalSpec
from robots.thermal.observations import CellGeometry, Observations, simulate_observations
from robots.thermal.plan import ViewOptions, ViewPlan, view_plan, view_pose
from robots.thermal.uncertainty import prediction_covariance, term_jacobian

__all__ = [
    "MATERIAL_EXPANSION_PER_K",
    "CellGeometry",
    "CommandOptions",
    "CommandResult",
    "DriftSettings",
    "DriftTruth",
    "IdentifiabilityReport",
    "IdentificationResult",
    "IdentifyOptions",
    "Observations",
    "T_part_camera",
    "ThermalDataError",
    "ThermalError",
    "ThermalModel",
    "ThermalModelFileError",
    "ThermalSpec",
    "ThermalSpecError",
    "UnidentifiableError",
    "ViewOptions",
    "ViewPlan",
    "WarmUp",
    "camera_to_part",
    "command",
    "compensated_T_base_tcp",
    "default_settings",
    "identify",
    "plan_report",
    "prediction_covariance",
    "reference_from_cold",
    "simulate_observations",
    "solve_tcp",
    "term_jacobian",
    "view_plan",
    "view_pose",
]
