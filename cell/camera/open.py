"""Open the stereo head a ``--camera`` URL names: ``tcp://HOST:PORT`` (:class:`NetworkCamera`,
the simulator's camera server) or ``gige://IP_LEFT,IP_RIGHT[?...]`` (:class:`GigeStereo`, two
GigE Vision cameras through Aravis)."""

from __future__ import annotations

from collections.abc import Callable

from cell.camera.backend import CameraBackend
from cell.camera.errors import CameraError
from cell.camera.network import NetworkCamera
from measure import StereoCalibration

SCHEMES = ("tcp://", "gige://")


def check_camera_url(url: str) -> None:
    """Refuse a ``--camera`` URL that cannot name a head, before anything is connected."""
    if url.startswith("gige://"):
        from cell.camera.gige_url import parse_gige_url

        parse_gige_url(url)
    elif not url.startswith("tcp://"):
        raise CameraError(url, f"unknown camera URL: expected {' or '.join(SCHEMES)}...")


def open_camera(
    url: str, stereo: StereoCalibration, fire: Callable[[], None] | None = None
) -> CameraBackend:
    """The head at ``url`` with calibration ``stereo``; ``fire`` sends a hardware trigger
    pulse (a GigE head with ``trigger=line*``)."""
    if url.startswith("tcp://"):
        return NetworkCamera(url, stereo)
    if url.startswith("gige://"):
        from cell.camera.gige import GigeStereo  # Aravis only when asked for

        return GigeStereo(url, stereo, fire)
    raise CameraError(url, f"unknown camera URL: expected {' or '.join(SCHEMES)}...")
