"""The survey's figures on the terminal."""

from __future__ import annotations

import numpy as np


def print_survey(done) -> None:
    """Print a :class:`cell.referencing.survey.run.SurveyRun`'s figures."""
    r, cap = done.result, done.captures
    sigma = r.sigma_m()
    print(f"survey: {len(r.marker_ids)} markers from {r.n_views} views "
          f"({r.n_observations} observations), {r.rms_px:.3f} px RMS, variance factor "
          f"{r.variance_factor:.2f}; gauge: {r.gauge}")  # fmt: skip
    print(f"  marker sigma: median {1e6 * float(np.median(np.linalg.norm(sigma, axis=1))):.1f} "
          f"um, largest {1e6 * float(np.linalg.norm(sigma, axis=1).max()):.1f} um; scale "
          f"{r.scale_sigma_ppm:.1f} ppm ({r.scale_source})")  # fmt: skip
    post = r.sigma_px * float(np.sqrt(max(r.variance_factor, 0.0)))
    print(f"  centre noise: {post:.4f} px a posteriori (stated {r.sigma_px:g} px); weighed and "
          f"stated at {r.sigma_effective_px:.4f} px (floor {r.sigma_floor_px:g} px)")  # fmt: skip
    for w in r.warnings:
        print(f"  warning: {w}")
    if r.dropped_views:
        print(f"  {len(r.dropped_views)} views left out (too few markers, or on one line)")
    print(f"robot time {cap.robot_time_s:.1f} s on the controller clock (planned "
          f"{done.tour.tour.cycle_time_s:.1f} s); capture {cap.wall_s['capture_s']:.1f} s, "
          f"detection {cap.wall_s['detect_s']:.1f} s, adjustment {done.solve_s:.1f} s")  # fmt: skip
