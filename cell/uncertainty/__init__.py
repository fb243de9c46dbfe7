"""The uncertainty budget of a hole (GUM), the part-temperature correction (ISO 1) and the
decision rule (ISO 14253-1).

- :mod:`~cell.uncertainty.materials`: built-in part materials and their expansion coefficients.
- :mod:`~cell.uncertainty.repeatability`: the arm's pose repeatability (ISO 9283 RP) and the
  standard uncertainty it stands for.
- :mod:`~cell.uncertainty.part_temperature`: the part's temperature state and the correction
  of positions and diameters to 20 degC.
- :mod:`~cell.uncertainty.calibration`: the stereo calibration's contribution, propagated
  through triangulation and the circle fit (Jacobian; Monte Carlo as the check).
- :mod:`~cell.uncertainty.thermal`: the thermal model's prediction covariance at a stop.
- :mod:`~cell.uncertainty.budget`: the budget of one hole (components, combined, expanded).
- :mod:`~cell.uncertainty.decision`: conformance proven / nonconformance proven / inconclusive.
"""
