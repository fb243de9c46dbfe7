"""The simulated head as two GigE Vision cameras: two in-process ``Aravis.GvFakeCamera``s
(default 127.0.0.1 and 127.0.0.2) serving the rendered pairs over real GVCP/GVSP.

Each fake camera's fill callback (set through ctypes: PyGObject frees a callback it is given
at once) takes the image of its camera from the pair of the same trigger number: the first
camera of a trigger to fill renders the pair (:class:`cell.sim.camera.SimCamera`), the other
takes it. Faults (:class:`GigeFaults`) are injected in the right camera, at chosen stops of
the controller or chosen trigger numbers: the frame dropped on the wire, sent incomplete, or
replaced by its previous frame (id, timestamp and image: a frame of another trigger).

Run it only inside a private network namespace (docs/real_cell.md): a fake camera also
listens for discovery broadcasts.
"""

from __future__ import annotations

import ctypes
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cell.camera import CameraError, StereoPair
from cell.camera.aravis import FILL_PATTERN, aravis, clib, gpointer

log = logging.getLogger(__name__)

#: registers of Aravis's fake camera (arvfakecamera.h) and GigE Vision's heartbeat timeout
REG_SENSOR_WIDTH, REG_SENSOR_HEIGHT, REG_WIDTH, REG_HEIGHT = 0x11C, 0x118, 0x100, 0x104
REG_HEARTBEAT_TIMEOUT = 0x938
REG_TRIGGER_SOURCE, REG_TRIGGER_SOFTWARE = 0x304, 0x30C  # source 0: Line0, 1: Software
#: a fake camera answers no GVCP while it renders a pair in its fill callback: it keeps its
#: client this long without a heartbeat (ms; GigE Vision's default is 3000)
HEARTBEAT_TIMEOUT_MS = 60_000
#: how often a fake camera looks for a software trigger (Hz); Aravis's default is 25
TRIGGER_POLL_HZ = 200.0
#: pairs kept for a camera that has not filled its side yet (one camera grabbed alone)
MAX_PENDING = 4
FAULT_KINDS = ("drop", "incomplete", "mismatch")


@dataclass(frozen=True)
class GigeFaults:
    """Faults of the right camera: ``{kind: keys}`` with kind ``drop`` (the frame lost on the
    wire), ``incomplete`` (half its packets lost, never resent) or ``mismatch`` (the previous
    frame sent again); keys are the controller's stop indices (``by="stop"``: every trigger
    while the arm stands at that stop) or 0-based trigger numbers (``by="trigger"``)."""

    at: dict[str, frozenset[int]] = field(default_factory=dict)
    by: str = "stop"

    def __post_init__(self) -> None:
        bad = set(self.at) - set(FAULT_KINDS)
        if bad or self.by not in ("stop", "trigger"):
            raise ValueError(f"GigeFaults: kinds {sorted(bad)} / by {self.by!r} unknown")

    def kind(self, key: int) -> str | None:
        """The fault at ``key``, or None."""
        return next((k for k, keys in self.at.items() if key in keys), None)


class _Pairs:
    """The pair of each trigger number, rendered once for both cameras."""

    def __init__(self, render: Callable[[], StereoPair], key: Callable[[int], int],
                 faults: GigeFaults) -> None:  # fmt: skip
        self.render, self.key, self.faults = render, key, faults
        self.lock = threading.Lock()
        self.filled = [0, 0]
        self.pending: dict[int, tuple[StereoPair, str | None, int]] = {}
        self.errors: list[str] = []

    def take(self, side: int) -> tuple[np.ndarray | None, str | None]:
        """The image of camera ``side`` (0 left, 1 right) for its next trigger and the fault
        to apply to it (right camera only)."""
        with self.lock:
            k = self.filled[side]
            self.filled[side] += 1
            if k not in self.pending:
                try:
                    pair = self.render()
                except (CameraError, ValueError) as exc:
                    self.errors.append(str(exc))
                    log.error("simulated head: render failed: %s", exc)
                    return None, None
                self.pending[k] = (pair, self.faults.kind(self.key(k)), 0)
                while len(self.pending) > MAX_PENDING:
                    del self.pending[min(self.pending)]
            pair, fault, used = self.pending[k]
            if used:
                del self.pending[k]
            else:
                self.pending[k] = (pair, fault, 1)
        return (pair.left, None) if side == 0 else (pair.right, fault)


class _FakeCamera:
    """One ``Aravis.GvFakeCamera`` at ``ip`` serving images from ``pairs``."""

    def __init__(self, ip: str, side: int, pairs: _Pairs, shape: tuple[int, int]) -> None:
        Aravis, lib = aravis(), clib()
        self.ip, self.side, self.pairs = ip, side, pairs
        self.gv = Aravis.GvFakeCamera.new(ip, f"HOLECELL-{'LR'[side]}")
        if not self.gv.is_running():
            why = ("the fake camera did not start (is the address on a local interface? see "
                   "docs/real_cell.md)")  # fmt: skip
            raise CameraError(f"gige {ip}", why)
        self.fake = self.gv.get_fake_camera()
        self._ptr = gpointer(self.fake)
        h, w = shape
        registers = ((REG_SENSOR_WIDTH, w), (REG_SENSOR_HEIGHT, h), (REG_WIDTH, w),
                     (REG_HEIGHT, h), (REG_HEARTBEAT_TIMEOUT, HEARTBEAT_TIMEOUT_MS))  # fmt: skip
        for reg, value in registers:
            lib.arv_fake_camera_write_register(self._ptr, reg, value)
        self.fake.set_trigger_frequency(TRIGGER_POLL_HZ)
        self.served = 0
        self._last: tuple[int, int, np.ndarray] | None = None  # id, timestamp, image
        self._callback = FILL_PATTERN(self._fill)  # kept: the C side holds only the pointer
        lib.arv_fake_camera_set_fill_pattern(self._ptr, self._callback, None)

    def _fill(self, buf: int, _data: Any, _exp: int, _gain: int, _fmt: int) -> None:
        try:
            self._serve(buf)
        except BaseException as exc:  # ctypes would print it and send the buffer's old image
            log.exception("fake camera %s: %s", self.ip, exc)
            self.gv.set_property("gvsp-lost-ratio", 1.0)

    def _serve(self, buf: int) -> None:
        lib = clib()
        image, fault = self.pairs.take(self.side)
        w, h = lib.arv_buffer_get_image_width(buf), lib.arv_buffer_get_image_height(buf)
        frame_id = int(lib.arv_buffer_get_frame_id(buf))
        stamp = int(lib.arv_buffer_get_timestamp(buf))
        if image is None or image.shape != (h, w) or image.dtype != np.uint8:
            log.error("fake camera %s: cannot serve %s as a %dx%d Mono8 frame", self.ip,
                      None if image is None else image.shape, w, h)  # fmt: skip
            self.gv.set_property("gvsp-lost-ratio", 1.0)  # nothing honest to send
            return
        if fault == "mismatch" and self._last is not None:
            frame_id_sent, stamp_sent, image = self._last
            lib.arv_buffer_set_frame_id(buf, frame_id_sent)
            lib.arv_buffer_set_timestamp(buf, stamp_sent)
        self._last = (frame_id, stamp, image)
        data = lib.arv_buffer_get_data(buf, None)
        ctypes.memmove(data, np.ascontiguousarray(image).ctypes.data, image.nbytes)
        lost = {"drop": 1.0, "incomplete": 0.5}.get(fault or "", 0.0)
        self.gv.set_property("gvsp-lost-ratio", lost)
        self.served += 1

    def line_pulse(self) -> bool:
        """A rising edge on Line0: fire once if the client set ``TriggerSource=Line0`` (the
        fake fires only on its software trigger register, so the edge is that register, the
        source switched for the one frame); False: the camera does not listen to the line."""
        lib, value = clib(), ctypes.c_uint32()
        lib.arv_fake_camera_read_register(self._ptr, REG_TRIGGER_SOURCE, ctypes.byref(value))
        if value.value != 0:
            return False
        lib.arv_fake_camera_write_register(self._ptr, REG_TRIGGER_SOURCE, 1)
        lib.arv_fake_camera_write_register(self._ptr, REG_TRIGGER_SOFTWARE, 1)
        return True

    def line_released(self) -> bool:
        """After :meth:`line_pulse`: the fake took the edge; the source goes back to Line0."""
        lib, value = clib(), ctypes.c_uint32()
        lib.arv_fake_camera_read_register(self._ptr, REG_TRIGGER_SOFTWARE, ctypes.byref(value))
        if value.value != 0:
            return False
        lib.arv_fake_camera_write_register(self._ptr, REG_TRIGGER_SOURCE, 0)
        return True

    def close(self) -> None:
        """Stop serving (the fake's thread ends when the object is freed)."""
        if self.gv is not None:
            clib().arv_fake_camera_set_fill_pattern(self._ptr, FILL_PATTERN(), None)
            self.fake = self.gv = None  # type: ignore[assignment]


class GigeHead:
    """Two fake GigE Vision cameras serving ``render()``'s pairs; ``url`` is what the runner
    opens. ``stop_of``: the controller's current stop (for ``GigeFaults(by="stop")``)."""

    def __init__(
        self,
        render: Callable[[], StereoPair],
        shape: tuple[int, int],
        ips: tuple[str, str] = ("127.0.0.1", "127.0.0.2"),
        faults: GigeFaults | None = None,
        stop_of: Callable[[], int] | None = None,
    ) -> None:
        faults = faults or GigeFaults()
        if faults.by == "stop" and faults.at and stop_of is None:
            raise ValueError("GigeFaults(by='stop') needs stop_of")
        key = (lambda k: k) if faults.by == "trigger" or stop_of is None else (
            lambda k: stop_of())  # fmt: skip
        self.pairs = _Pairs(render, key, faults)
        self.cameras: list[_FakeCamera] = []
        try:
            for side, ip in enumerate(ips):
                self.cameras.append(_FakeCamera(ip, side, self.pairs, shape))
        except BaseException:
            self.close()
            raise
        self.url = f"gige://{ips[0]},{ips[1]}"

    @classmethod
    def for_camera(cls, camera: Any, ips: tuple[str, str] = ("127.0.0.1", "127.0.0.2"),
                   faults: GigeFaults | None = None) -> GigeHead:  # fmt: skip
        """Serve a :class:`cell.sim.camera.SimCamera` (its controller gives the stop). One
        pair is rendered first and not counted: the first render compiles and caches, and a
        fake camera answers nothing while it renders."""
        camera.capture()
        camera.captures -= 1
        w, h = camera.true_stereo.image_size
        ctrl = camera.controller

        def stop_of() -> int:
            return int(ctrl.s.at_stop)

        return cls(camera.capture, (h, w), ips, faults, stop_of)

    def pulse(self, timeout_s: float = 10.0) -> None:
        """The hardware trigger line wired to both cameras' Line0: one rising edge. Returns
        once both cameras took it (or after ``timeout_s``)."""
        fired = [cam for cam in self.cameras if cam.line_pulse()]
        t_end = time.monotonic() + timeout_s
        while fired and time.monotonic() < t_end:
            fired = [cam for cam in fired if not cam.line_released()]
            time.sleep(0.0005)

    def close(self) -> None:
        """Stop both cameras (release the clients' ``ArvCamera``s first: a fake waits up to
        5 s for a client that still holds it)."""
        for cam in self.cameras:
            cam.close()
        self.cameras = []

    def __enter__(self) -> GigeHead:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
