"""A stereo head of two GigE Vision cameras (``gige://IP_LEFT,IP_RIGHT``) through Aravis.

Each capture flushes what is still waiting in either stream, triggers both cameras (two GVCP
software triggers, or one hardware pulse on the cameras' input line sent by ``fire``), waits
for one frame from each, and accepts the pair only when both are complete and belong to this
trigger (:class:`cell.camera.gige_pair.PairChecker`). A dropped, late, incomplete or
mismatched pair is retried once; then the capture raises :class:`PairError` with both reasons,
so no image is ever paired with another stop's pose.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

from cell.camera.backend import StereoPair
from cell.camera.errors import CameraError, PairError
from cell.camera.gige_device import Frame, GigeDevice
from cell.camera.gige_pair import PairChecker
from cell.camera.gige_url import GigeOptions, parse_gige_url
from measure import StereoCalibration

log = logging.getLogger(__name__)

#: attempts per capture: the first and one retry
ATTEMPTS = 2


class GigeStereo:
    """A :class:`cell.camera.CameraBackend` of two GigE Vision cameras.

    ``fire``: sends the hardware trigger pulse (a ``line*`` trigger; e.g. a controller's
    digital output); without it a line-triggered head waits for a pulse sent elsewhere.
    """

    def __init__(
        self,
        url: str,
        stereo: StereoCalibration,
        fire: Callable[[], None] | None = None,
    ) -> None:
        self.url, self.stereo, self.fire = url, stereo, fire
        self.options: GigeOptions = parse_gige_url(url)
        self.left = GigeDevice(self.options.left_ip, self.options)
        try:
            self.right = GigeDevice(self.options.right_ip, self.options)
        except CameraError:
            self.left.close()
            raise
        shared = self.left.shared_clock and self.right.shared_clock
        self.checker = PairChecker(self.options.pair_bound_ns, shared)
        self.captures = 0
        self.retries = 0
        self._trigger_s = 0.0
        self.left.start()
        self.right.start()

    def capture(self) -> StereoPair:
        """Trigger both cameras and return one trigger's pair (retried once)."""
        self.captures += 1
        reasons: list[str] = []
        for attempt in range(ATTEMPTS):
            pair, why = self._attempt()
            if pair is not None:
                return pair
            reasons.append(why)
            self.checker.failed()
            if attempt + 1 < ATTEMPTS:
                self.retries += 1
                log.warning("%s: capture %d: %s; retrying", self.url, self.captures, why)
                self._wait_before_retry()
        raise PairError(self.url, f"capture {self.captures}: {reasons[0]}; retried: "
                                  f"{reasons[-1]}")  # fmt: skip

    def _wait_before_retry(self) -> None:
        """Trigger the retry at least twice the pair bound after the failed trigger, so that
        a late frame of the failed attempt cannot pass the timestamp check as the retry's."""
        due = self._trigger_s + 2 * self.options.pair_bound_ns / 1e9
        time.sleep(max(0.0, due - time.monotonic()))

    def _attempt(self) -> tuple[StereoPair | None, str]:
        for dev in (self.left, self.right):
            for info in dev.flush():
                log.info("%s: discarded frame %d received before the trigger", dev.source,
                         info.frame_id)  # fmt: skip
        trigger_ns = time.time_ns() // 1000 * 1000  # the streams stamp in whole us
        self._trigger_s = time.monotonic()
        self._trigger()
        deadline = time.monotonic() + self.options.timeout_ms / 1e3
        frames: list[Frame] = []
        for side, dev in (("left", self.left), ("right", self.right)):
            f = dev.next_frame(deadline)
            if f is None:
                return None, (f"{side} frame dropped or late (none within "
                              f"{self.options.timeout_ms:g} ms of the trigger)")  # fmt: skip
            frames.append(f)
        left, right = frames
        why = self.checker.refuse(left.info, right.info, trigger_ns)
        if why is not None:
            return None, why
        assert left.image is not None and right.image is not None
        if left.image.shape != right.image.shape:
            return None, f"image sizes differ: left {left.image.shape}, right {right.image.shape}"
        return StereoPair(left.image, right.image), ""

    def _trigger(self) -> None:
        if self.options.trigger == "software":
            self.left.trigger()
            self.right.trigger()
        elif self.fire is not None:
            self.fire()

    def close(self) -> None:
        """Stop both cameras and release them."""
        for dev in (getattr(self, "left", None), getattr(self, "right", None)):
            if dev is not None:
                dev.close()
