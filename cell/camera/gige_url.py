"""``gige://IP_LEFT,IP_RIGHT[?key=value&...]``: the GigE Vision head's addresses and settings.

Keys (all optional): ``trigger`` (``software``: the cell computer triggers each camera over
GVCP; ``line0``..``line3``: a hardware pulse wired to both cameras' input line, see
docs/real_cell.md), ``packet_size`` (GVSP packet size in bytes, or ``auto`` to let the camera
test it; 9000 needs jumbo frames on the whole path), ``resend`` (``1``/``0``: ask the camera
to resend lost packets), ``timeout_ms`` (wait for both frames after a trigger), ``pair_ms``
(largest gap between the two frames' camera timestamps, or between their intervals since the
last pair), ``exposure_us``, ``gain_db``, ``pixel_format`` (e.g. ``Mono8``).
"""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass
from urllib.parse import parse_qsl, urlsplit

from cell.camera.errors import CameraError

TRIGGERS = ("software", "line0", "line1", "line2", "line3")


@dataclass(frozen=True)
class GigeOptions:
    """How the two cameras of a GigE Vision head are opened and checked (see module doc)."""

    left_ip: str
    right_ip: str
    trigger: str = "software"
    packet_size: int | None = 1500  # bytes; None: negotiated by the camera (auto)
    resend: bool = True
    timeout_ms: float = 3000.0
    pair_ms: float | None = None  # None: 250 ms for a software trigger, 1 ms for a line
    exposure_us: float | None = None
    gain_db: float | None = None
    pixel_format: str = "Mono8"
    n_buffers: int = 4

    @property
    def pair_bound_ns(self) -> int:
        """The timestamp bound of one pair (ns): the given ``pair_ms``, else what the trigger
        allows: two GVCP commands one after the other (software) or one pulse (a line)."""
        ms = self.pair_ms if self.pair_ms is not None else (
            250.0 if self.trigger == "software" else 1.0)  # fmt: skip
        return int(ms * 1e6)


def parse_gige_url(url: str) -> GigeOptions:
    """The options of ``url``, or :class:`CameraError` naming the bad part."""
    parts = urlsplit(url)
    if parts.scheme != "gige":
        raise CameraError(url, "expected gige://IP_LEFT,IP_RIGHT")
    ips = [p.strip() for p in parts.netloc.split(",")]
    if len(ips) != 2:
        raise CameraError(url, "give two camera addresses: gige://IP_LEFT,IP_RIGHT")
    for ip in ips:
        try:
            ipaddress.IPv4Address(ip)
        except ValueError:
            raise CameraError(url, f"{ip!r} is not an IPv4 address (cameras are opened by "
                                   "IP address, never discovered)") from None  # fmt: skip
    if ips[0] == ips[1]:
        raise CameraError(url, "the left and right camera have the same address")
    kw: dict[str, object] = {}
    for key, value in parse_qsl(parts.query, keep_blank_values=True):
        kw[key] = _value(url, key, value)
    return GigeOptions(ips[0], ips[1], **kw)  # type: ignore[arg-type]


def _value(url: str, key: str, value: str) -> object:
    try:
        if key == "trigger":
            if value.lower() not in TRIGGERS:
                raise ValueError(f"one of {', '.join(TRIGGERS)}")
            return value.lower()
        if key == "packet_size":
            if value == "auto":
                return None
            n = int(value)
            if not 576 <= n <= 16384:
                raise ValueError("576..16384 bytes or auto")
            return n
        if key == "resend":
            if value not in ("0", "1"):
                raise ValueError("0 or 1")
            return value == "1"
        if key in ("timeout_ms", "pair_ms", "exposure_us", "gain_db"):
            x = float(value)
            if not x >= 0 or x == float("inf"):
                raise ValueError("a finite number >= 0")
            return x
        if key == "pixel_format":
            if not value.isalnum():
                raise ValueError("a GenICam pixel format name such as Mono8")
            return value
    except ValueError as exc:
        raise CameraError(url, f"{key}={value!r}: {exc}") from None
    raise CameraError(url, f"unknown setting {key!r} (known: trigger, packet_size, resend, "
                           "timeout_ms, pair_ms, exposure_us, gain_db, pixel_format)")  # fmt: skip
