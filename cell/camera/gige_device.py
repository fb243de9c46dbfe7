"""One GigE Vision camera through Aravis, opened by IP address: configured for triggered
single frames, its stream with packet resend, a trigger, and the next frame.

USB3 Vision cameras use the same ``ArvCamera`` interface in Aravis; only the opening differs
(by serial number) and there is no packet size: see docs/real_cell.md for what was tested.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from cell.camera.aravis import aravis, open_gv_device
from cell.camera.errors import CameraError
from cell.camera.gige_pair import FrameInfo
from cell.camera.gige_url import GigeOptions

log = logging.getLogger(__name__)


@dataclass
class Frame:
    """A received frame: its image (None unless complete) and what identifies it."""

    info: FrameInfo
    image: np.ndarray | None


class GigeDevice:
    """One camera of the head (``ip``), configured from ``options``."""

    def __init__(self, ip: str, options: GigeOptions) -> None:
        Aravis = aravis()
        self.ip, self.source = ip, f"gige {ip}"
        self._device = open_gv_device(ip)
        try:
            self.camera = Aravis.Camera.new_with_device(self._device)
            self.serial = self.camera.get_device_serial_number()
            self._configure(options)
            self.stream = self.camera.create_stream(None, None)
            self._configure_stream(options)
            payload = self.camera.get_payload()
            for _ in range(options.n_buffers):
                self.stream.push_buffer(Aravis.Buffer.new_allocate(payload))
        except CameraError:
            self.close()
            raise
        except Exception as exc:  # GLib.Error from a feature the camera refused
            self.close()
            raise CameraError(self.source, f"cannot configure: {exc}") from exc
        self.shared_clock = self._ptp_enabled()
        self._streaming = False

    def _configure(self, o: GigeOptions) -> None:
        Aravis, cam = aravis(), self.camera
        cam.set_pixel_format_from_string(o.pixel_format)
        if o.packet_size is None:
            cam.gv_auto_packet_size()
        else:
            cam.gv_set_packet_size(o.packet_size)
        cam.set_acquisition_mode(Aravis.AcquisitionMode.CONTINUOUS)
        cam.set_trigger("Software" if o.trigger == "software" else o.trigger.capitalize())
        if o.trigger != "software" and cam.is_feature_available("TriggerActivation"):
            cam.set_string("TriggerActivation", "RisingEdge")
        if o.exposure_us is not None:
            cam.set_exposure_time_auto(Aravis.Auto.OFF)
            cam.set_exposure_time(o.exposure_us)
        if o.gain_db is not None:
            cam.set_gain_auto(Aravis.Auto.OFF)
            cam.set_gain(o.gain_db)

    def _configure_stream(self, o: GigeOptions) -> None:
        Aravis = aravis()
        resend = Aravis.GvStreamPacketResend
        self.stream.set_property("packet-resend", resend.ALWAYS if o.resend else resend.NEVER)

    def _ptp_enabled(self) -> bool:
        """Whether the camera's clock is an IEEE 1588 clock (then two cameras' timestamps are
        comparable directly)."""
        for feature in ("PtpEnable", "GevIEEE1588"):
            try:
                if self.camera.is_feature_available(feature):
                    return bool(self.camera.get_boolean(feature))
            except Exception:
                continue
        return False

    @property
    def packet_size(self) -> int:
        """The GVSP packet size in use (bytes)."""
        return int(self.camera.gv_get_packet_size())

    def start(self) -> None:
        """Start acquisition: the camera now waits for triggers."""
        if not self._streaming:
            self.camera.start_acquisition()
            self._streaming = True

    def trigger(self) -> None:
        """Send the software trigger (GVCP write of ``TriggerSoftware``)."""
        try:
            self.camera.software_trigger()
        except Exception as exc:
            raise CameraError(self.source, f"software trigger refused: {exc}") from exc

    def next_frame(self, deadline_s: float) -> Frame | None:
        """The next frame of the stream, waiting until ``deadline_s`` (``time.monotonic``),
        or None: nothing arrived (a dropped or late frame)."""
        wait_us = max(0, int((deadline_s - time.monotonic()) * 1e6))
        buf = self.stream.timeout_pop_buffer(wait_us)
        if buf is None:
            return None
        try:
            return self._frame(buf)
        finally:
            self.stream.push_buffer(buf)

    def _frame(self, buf: Any) -> Frame:
        status = buf.get_status().value_nick.upper().replace("-", "_")
        info = FrameInfo(int(buf.get_frame_id()), int(buf.get_timestamp()),
                         int(buf.get_system_timestamp()), status)  # fmt: skip
        if status != "SUCCESS":
            return Frame(info, None)
        h, w = buf.get_image_height(), buf.get_image_width()
        data = buf.get_image_data()
        bpp = len(data) // max(1, h * w)
        dtype = np.uint8 if bpp == 1 else np.dtype("<u2")
        image = np.frombuffer(data, dtype, count=h * w).reshape(h, w).copy()
        return Frame(info, image)

    def flush(self) -> list[FrameInfo]:
        """Take every frame already waiting (late frames of a failed attempt); their infos."""
        out = []
        while (buf := self.stream.try_pop_buffer()) is not None:
            out.append(self._frame(buf).info)
            self.stream.push_buffer(buf)
        return out

    def close(self) -> None:
        """Stop acquisition and release the camera (before a fake camera serving it stops)."""
        cam = getattr(self, "camera", None)
        if cam is not None and getattr(self, "_streaming", False):
            try:
                cam.stop_acquisition()
            except Exception as exc:  # the camera went away: nothing left to stop
                log.info("%s: stop acquisition: %s", self.source, exc)
        self._streaming = False
        self.stream = self.camera = self._device = None  # type: ignore[assignment]
