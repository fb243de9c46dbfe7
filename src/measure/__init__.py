"""Stereo hole measurement: calibration, sub-pixel edges, triangulation, circle fit."""
