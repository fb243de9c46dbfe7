"""Opening the serial line: ``/dev/ttyS0``, ``socket://host:port`` or a pseudo-terminal.

Everything goes through :func:`serial.serial_for_url`, so the client runs unchanged on a real
RS-232 port of the ABB controller, on a serial-over-TCP server and on the simulator's pty.
"""

from __future__ import annotations

import time

import serial

from cell.link.errors import LinkError


def open_port(url: str, baudrate: int = 115200, timeout_s: float = 5.0) -> serial.SerialBase:
    """Open ``url`` (8N1, no flow control, short read timeout), retrying for ``timeout_s`` while
    the other end is not there yet. Raises :class:`LinkError` naming the URL and the reason."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            port = serial.serial_for_url(
                url, baudrate=baudrate, timeout=0.005, write_timeout=2.0, exclusive=None
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            if time.monotonic() >= deadline:
                raise LinkError(url, f"cannot open the port: {exc}") from exc
            time.sleep(0.05)
            continue
        return port


def read_some(port: serial.SerialBase, url: str) -> bytes:
    """Bytes available now (waits at most the port's short timeout). LinkError if the line died."""
    try:
        waiting = port.in_waiting
        return port.read(waiting if waiting > 0 else 1)
    except (serial.SerialException, OSError) as exc:
        raise LinkError(url, f"read failed: {exc}") from exc


def write_all(port: serial.SerialBase, data: bytes, url: str) -> None:
    """Write ``data``; LinkError if the line died."""
    try:
        port.write(data)
        port.flush()
    except (serial.SerialException, OSError) as exc:
        raise LinkError(url, f"write failed: {exc}") from exc
