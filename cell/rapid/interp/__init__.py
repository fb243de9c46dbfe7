"""A RAPID interpreter for the language of ``cell/rapid/HolecellLink.mod``: a Lark parser
after the RAPID reference manual's syntax, load-time checks of names, types and built-in
arguments, and execution with the controller's semantics (num single, dnum double, 1-based
arrays, ERROR handlers). The module reaches the world through a host
(:mod:`cell.rapid.interp.host`)."""

from cell.rapid.interp.errors import RapidError, RapidLoadError, RapidRunError, RapidStopped
from cell.rapid.interp.program import Program

__all__ = ["Program", "RapidError", "RapidLoadError", "RapidRunError", "RapidStopped"]
