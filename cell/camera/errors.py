"""Errors of the camera backends, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class CameraError(CellError):
    """A capture failed (camera not reachable, bad image transfer)."""

    def __init__(self, source: str, reason: str) -> None:
        self.source = source
        self.reason = reason
        super().__init__(f"camera {source}: {reason}")


class PairError(CameraError):
    """No stereo pair of one trigger could be had at a stop, after the retry: a frame dropped,
    late or incomplete, or two frames of different triggers. The stop fails with ``reason``;
    the cameras still answer, so the run goes on."""
