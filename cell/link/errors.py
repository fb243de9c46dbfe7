"""Errors of the controller link, all derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class LinkError(CellError):
    """The link to the controller failed (port cannot be opened, no answer after retries)."""

    def __init__(self, url: str, reason: str) -> None:
        self.url = url
        self.reason = reason
        super().__init__(f"controller link {url}: {reason}")


class PayloadError(CellError):
    """A message payload does not have the layout its type requires."""

    def __init__(self, msg_type: int, reason: str) -> None:
        self.msg_type = msg_type
        self.reason = reason
        super().__init__(f"message type 0x{msg_type:02X}: {reason}")


class RequestRefusedError(CellError):
    """The controller answered a request with a NAK (``code``: :class:`cell.link.messages.Nak`)."""

    def __init__(self, request: str, code: int, text: str) -> None:
        self.request = request
        self.code = code
        self.text = text
        super().__init__(f"controller refused {request}: {text} (NAK code {code})")


class MoveTimeoutError(CellError):
    """The arm did not reach stop ``stop`` within ``timeout_s`` while the link kept answering:
    a motion problem, not a dead link (no reconnect, no reload while the arm may move)."""

    def __init__(self, url: str, stop: int, timeout_s: float, state: str) -> None:
        self.url, self.stop, self.timeout_s, self.state = url, stop, timeout_s, state
        super().__init__(
            f"controller {url}: stop {stop} not reached within {timeout_s:.1f} s (state {state})"
        )


class RunFaultError(CellError):
    """The run stopped on a controller fault; ``state`` and ``fault`` as the controller said."""

    def __init__(self, where: str, state: str, fault: str) -> None:
        self.where, self.state, self.fault = where, state, fault
        super().__init__(
            f"run stopped at {where}: controller {state} ({fault}); every hole measured so far "
            "is stored; clear the fault, then continue with --resume RUN_DIR"
        )
