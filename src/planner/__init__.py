"""Inspection tour planning: viewpoints, sequencing, collision-free paths, timing."""
