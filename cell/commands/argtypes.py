"""Argument types of the ``holecell`` subcommands: numbers checked when the command line is
parsed, so a bad value is refused by argparse with the option named, never as a traceback."""

from __future__ import annotations

import argparse
import math
from pathlib import Path


def non_negative_int(text: str) -> int:
    """An integer >= 0."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative (give 0 or more)")
    return value


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    value = _finite(text)
    if value < 0.0:
        raise argparse.ArgumentTypeError(f"{value} is negative (give 0 or more)")
    return value


def positive_float(text: str) -> float:
    """A finite number > 0."""
    value = _finite(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(f"{value} is not positive")
    return value


def part_temperature_c(text: str) -> float:
    """A part temperature in degC within the plausible range (ISO 1 correction input)."""
    from cell.uncertainty.part_temperature import RANGE_C

    value = _finite(text)
    if not RANGE_C[0] <= value <= RANGE_C[1]:
        raise argparse.ArgumentTypeError(
            f"{value} degC is outside [{RANGE_C[0]:g}, {RANGE_C[1]:g}] degC (kelvin or Fahrenheit?)"
        )
    return value


def temperature_u_K(text: str) -> float:
    """A temperature's standard uncertainty in K, in (0, 10]."""
    value = positive_float(text)
    if value > 10.0:
        raise argparse.ArgumentTypeError(f"{value} K is more than 10 K")
    return value


def probability(text: str) -> float:
    """A number in [0, 1]."""
    value = _finite(text)
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"{value} is not a probability in [0, 1]")
    return value


def positive_int(text: str) -> int:
    """An integer >= 1."""
    value = non_negative_int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not positive (give 1 or more)")
    return value


def output_file(text: str) -> Path:
    """A file to write: not a directory, in a folder that exists (checked before any work, so
    a mistake costs nothing and leaves nothing half-written)."""
    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a directory; give a file name")
    if not path.parent.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: folder {path.parent} does not exist")
    return path


def hole_diameter_m(text: str) -> float:
    """A hole diameter (m): positive, and not so large that it must be millimetres."""
    from cell.config.plausible import MAX_DIAMETER_M

    value = positive_float(text)
    if value > MAX_DIAMETER_M:
        raise argparse.ArgumentTypeError(
            f"{value:g} m: metres expected, this looks like millimetres ({value / 1e3:g} m?)"
        )
    return value
