"""Aravis 0.8 (the open GigE Vision / USB3 Vision library) through PyGObject, and the few C
calls PyGObject cannot make (a buffer's memory, a fake camera's fill callback), through ctypes.

Nothing here discovers devices: Aravis's discovery broadcasts on every interface, so cameras
are opened by IP address only (:func:`open_gv_device`).
"""

from __future__ import annotations

import ctypes
import functools
import socket
from types import ModuleType
from typing import Any

from cell.camera.errors import CameraError

#: what to install when Aravis or PyGObject is missing (Debian 12 package names)
INSTALL_HINT = (
    "Aravis 0.8 with PyGObject is needed: apt-get install aravis-tools gir1.2-aravis-0.8 "
    "libaravis-0.8-0 libgirepository1.0-dev libcairo2-dev, then pip install 'pygobject<3.51' "
    "(make test does both)"
)

#: ``void (*ArvFakeCameraFillPattern)(ArvBuffer*, void*, guint32 exposure_us, guint32 gain,
#: ArvPixelFormat)``
FILL_PATTERN = ctypes.CFUNCTYPE(
    None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint32
)


@functools.cache
def aravis() -> ModuleType:
    """``gi.repository.Aravis`` (0.8), or :class:`CameraError` naming what to install."""
    try:
        import gi

        gi.require_version("Aravis", "0.8")
        from gi.repository import Aravis
    except (ImportError, ValueError) as exc:
        raise CameraError("aravis", f"{exc}. {INSTALL_HINT}") from exc
    return Aravis


@functools.cache
def gio() -> ModuleType:
    """``gi.repository.Gio`` (socket addresses for :func:`open_gv_device`)."""
    aravis()
    from gi.repository import Gio

    return Gio


@functools.cache
def clib() -> ctypes.CDLL:
    """``libaravis-0.8`` with the signatures of the calls used through ctypes."""
    try:
        lib = ctypes.CDLL("libaravis-0.8.so.0")
    except OSError as exc:
        raise CameraError("aravis", f"{exc}. {INSTALL_HINT}") from exc
    vp, u32 = ctypes.c_void_p, ctypes.c_uint32
    lib.arv_buffer_get_data.restype = vp
    lib.arv_buffer_get_data.argtypes = [vp, ctypes.POINTER(ctypes.c_size_t)]
    lib.arv_buffer_get_frame_id.restype = ctypes.c_uint64
    lib.arv_buffer_get_frame_id.argtypes = [vp]
    lib.arv_buffer_set_frame_id.argtypes = [vp, ctypes.c_uint64]
    lib.arv_buffer_get_timestamp.restype = ctypes.c_uint64
    lib.arv_buffer_get_timestamp.argtypes = [vp]
    lib.arv_buffer_set_timestamp.argtypes = [vp, ctypes.c_uint64]
    lib.arv_buffer_get_image_width.restype = ctypes.c_int
    lib.arv_buffer_get_image_width.argtypes = [vp]
    lib.arv_buffer_get_image_height.restype = ctypes.c_int
    lib.arv_buffer_get_image_height.argtypes = [vp]
    lib.arv_fake_camera_set_fill_pattern.argtypes = [vp, FILL_PATTERN, vp]
    lib.arv_fake_camera_write_register.restype = ctypes.c_int
    lib.arv_fake_camera_write_register.argtypes = [vp, u32, u32]
    lib.arv_fake_camera_read_register.restype = ctypes.c_int
    lib.arv_fake_camera_read_register.argtypes = [vp, u32, ctypes.POINTER(u32)]
    return lib


def gpointer(obj: Any) -> int:
    """The C address of a PyGObject object (its ``__gpointer__`` capsule)."""
    get = ctypes.pythonapi.PyCapsule_GetPointer
    get.restype, get.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
    return int(get(obj.__gpointer__, None))


def interface_address(device_ip: str) -> str:
    """The local address the kernel routes to ``device_ip`` from (a UDP ``connect`` sends no
    packet): the interface a GigE Vision device is reached through."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            s.connect((device_ip, 3956))
        except OSError as exc:
            raise CameraError(f"gige {device_ip}", f"no route to the camera: {exc}") from exc
        return str(s.getsockname()[0])


def open_gv_device(device_ip: str) -> Any:
    """An ``ArvGvDevice`` opened directly by IP address (``arv_gv_device_new``): no discovery
    broadcast is ever sent."""
    Aravis, Gio = aravis(), gio()
    try:
        socket.inet_aton(device_ip)
    except OSError as exc:
        raise CameraError(f"gige {device_ip}", "not an IPv4 address") from exc
    local = Gio.InetAddress.new_from_string(interface_address(device_ip))
    remote = Gio.InetAddress.new_from_string(device_ip)
    try:
        return Aravis.GvDevice.new(local, remote)
    except Exception as exc:  # GLib.Error: the device did not answer
        raise CameraError(f"gige {device_ip}", f"cannot open the camera: {exc}") from exc
