"""A simulated IRC5's Robot Web Services 1.0, enough for ``holecell controller deploy`` and
the run's watch: a standard-library HTTP server on 127.0.0.1 with HTTP digest authentication
(RFC 7616, MD5, ``qop=auth``, as RobotWare 6 asks) and a session cookie.

It keeps the calls in ``calls`` (method, path, action) and the controller's state, and
refuses what a controller refuses: a module loaded that was never uploaded, loadmod or resetpp
without mastership, a start with the motors off or before a program pointer is set.
``on_start(module_path, text)`` is called when RAPID starts (e.g. to run the uploaded module
in the interpreter); ``on_stop()`` when it stops; ``on_signal(NETWORK/UNIT/NAME, value)``
when a digital output is set (e.g. the simulated cameras' trigger line).
"""

from __future__ import annotations

import hashlib
import json
import secrets
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import parse_qs, unquote, urlsplit

REALM = "validusers@robapi.abb"


def _md5(text: str) -> str:
    return hashlib.md5(text.encode()).hexdigest()


def _parse_digest(header: str) -> dict[str, str]:
    out = {}
    for part in header[len("Digest ") :].split(","):
        key, _, value = part.strip().partition("=")
        out[key] = value.strip('"')
    return out


class RwsFake:
    """The server (``url``); ``state`` fields can be changed by a test (e-stop, motors)."""

    def __init__(self, user: str = "Default User", password: str = "robotics",
                 on_start: Callable[[str, str], None] | None = None,
                 on_stop: Callable[[], None] | None = None,
                 on_signal: Callable[[str, int], None] | None = None) -> None:  # fmt: skip
        self.user, self._password = user, password
        self.on_start, self.on_stop, self.on_signal = on_start, on_stop, on_signal
        self.signals: dict[str, int] = {}
        self.calls: list[tuple[str, str, str]] = []
        self.refused: list[str] = []
        self.unauthorized = 0
        self.files: dict[str, bytes] = {}
        self.modules: dict[str, str] = {}  # task -> loaded module path
        self.ctrlstate, self.execution, self.opmode = "motoron", "stopped", "AUTO"
        self.mastership = False
        self.pp_set = False
        self._nonces: set[str] = set()
        self._sessions: set[str] = set()
        self.lock = threading.Lock()
        fake = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:  # quiet
                pass

            def do_GET(self) -> None:
                fake._handle(self, "GET")

            def do_POST(self) -> None:
                fake._handle(self, "POST")

            def do_PUT(self) -> None:
                fake._handle(self, "PUT")

        self._server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self._server.server_address[1]}"
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop serving."""
        self._server.shutdown()
        self._server.server_close()

    def __enter__(self) -> RwsFake:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- authentication -------------------------------------------------------------------
    def _authorized(self, h: BaseHTTPRequestHandler, method: str) -> bool:
        cookie = h.headers.get("Cookie", "")
        if any(f"ABBCX={s}" in cookie for s in self._sessions):
            return True
        auth = h.headers.get("Authorization", "")
        if not auth.startswith("Digest "):
            return False
        d = _parse_digest(auth)
        if d.get("username") != self.user or d.get("nonce") not in self._nonces:
            return False
        if d.get("uri") != h.path:  # the digest covers this request's URI
            return False
        ha1 = _md5(f"{self.user}:{REALM}:{self._password}")
        ha2 = _md5(f"{method}:{d.get('uri', '')}")
        expected = _md5(f"{ha1}:{d['nonce']}:{d.get('nc')}:{d.get('cnonce')}:auth:{ha2}")
        return d.get("qop") == "auth" and secrets.compare_digest(expected, d.get("response", ""))

    def _challenge(self, h: BaseHTTPRequestHandler) -> None:
        nonce = secrets.token_hex(16)
        self._nonces.add(nonce)
        self.unauthorized += 1
        h.send_response(401)
        challenge = f'Digest realm="{REALM}", qop="auth", nonce="{nonce}", algorithm=MD5'
        h.send_header("WWW-Authenticate", challenge)
        h.send_header("Content-Type", "text/html")
        h.send_header("Content-Length", "0")
        h.end_headers()

    # --- requests -------------------------------------------------------------------------
    def _handle(self, h: BaseHTTPRequestHandler, method: str) -> None:
        length = int(h.headers.get("Content-Length") or 0)
        body = h.rfile.read(length) if length else b""
        with self.lock:
            if not self._authorized(h, method):
                self._challenge(h)
                return
            parts = urlsplit(h.path)
            path, query = unquote(parts.path), parse_qs(parts.query)
            action = query.get("action", [""])[0]
            self.calls.append((method, path, action))
            try:
                status, doc = self._route(method, path, action, body)
            except _RefusedError as exc:
                self.refused.append(str(exc))
                status, doc = 400, {"_embedded": {"status": {"code": -1, "msg": str(exc)}}}
        session = secrets.token_hex(8)
        self._sessions.add(session)
        data = b"" if doc is None else json.dumps(doc).encode()
        h.send_response(status)
        h.send_header("Set-Cookie", f"ABBCX={session}; Path=/")
        h.send_header("Content-Type", "application/json")
        h.send_header("Content-Length", str(len(data)))
        h.end_headers()
        h.wfile.write(data)

    def _route(self, method: str, path: str, action: str, body: bytes) -> tuple[int, Any]:
        form = {k: v[0] for k, v in parse_qs(body.decode()).items()}
        if method == "PUT" and path.startswith("/fileservice/"):
            self.files["/" + path[len("/fileservice/") :].lstrip("/")] = body
            return 201, None
        if method == "GET":
            return 200, self._get(path)
        if path == "/rw/mastership":
            self.mastership = action == "request"
            return 204, None
        if path.startswith("/rw/rapid/tasks/") and action == "loadmod":
            return self._loadmod(path.rsplit("/", 1)[1], form)
        if path == "/rw/rapid/execution":
            return self._execution(action)
        if path.startswith("/rw/rapid/tasks/") and action in ("activate", "deactivate"):
            return 204, None
        if path.startswith("/rw/iosystem/signals/") and action == "set":
            name = path[len("/rw/iosystem/signals/") :]
            value = int(form.get("lvalue", "0"))
            self.signals[name] = value
            if self.on_signal is not None:
                self.on_signal(name, value)
            return 204, None
        if path == "/rw/panel/ctrlstate" and action == "setctrlstate":
            self.ctrlstate = form.get("ctrl-state", self.ctrlstate)
            return 204, None
        raise _RefusedError(f"{method} {path}?action={action}: not served by the fake")

    def _get(self, path: str) -> Any:
        def state(*items: dict) -> dict:
            return {"_embedded": {"_state": list(items)}}

        if path == "/ctrl/$RAMDISK":
            return state({"_value": "/hd0a/RAMDISK"})
        if path == "/rw/panel/ctrlstate":
            return state({"ctrlstate": self.ctrlstate})
        if path == "/rw/rapid/execution":
            return state({"ctrlexecstate": self.execution, "cycle": "forever"})
        if path == "/rw/panel/opmode":
            return state({"opmode": self.opmode})
        if path == "/rw/rapid/tasks":
            return state({"name": "T_ROB1", "type": "normal", "taskstate": "linked",
                          "excstate": "ready", "active": "On", "motiontask": "TRUE"})  # fmt: skip
        if path == "/logout":
            return None
        raise _RefusedError(f"GET {path}: not served by the fake")

    def _loadmod(self, task: str, form: dict[str, str]) -> tuple[int, Any]:
        module = form.get("modulepath", "")
        if not self.mastership:
            raise _RefusedError("loadmod without mastership")
        if module not in self.files:
            raise _RefusedError(f"loadmod: no file {module!r} on the controller")
        if self.execution == "running":
            raise _RefusedError("loadmod while RAPID runs")
        self.modules[task] = module
        self.pp_set = False
        return 204, None

    def _execution(self, action: str) -> tuple[int, Any]:
        if action == "resetpp":
            if not self.mastership or "T_ROB1" not in self.modules:
                raise _RefusedError("resetpp without mastership or without a module loaded")
            self.pp_set = True
            return 204, None
        if action == "start":
            if self.ctrlstate != "motoron" or not self.pp_set:
                raise _RefusedError("start with the motors off or no program pointer")
            self.execution = "running"
            if self.on_start is not None:
                path = self.modules["T_ROB1"]
                self.on_start(path, self.files[path].decode())
            return 204, None
        if action == "stop":
            self.execution = "stopped"
            if self.on_stop is not None:
                self.on_stop()
            return 204, None
        raise _RefusedError(f"execution action {action!r}")


class _RefusedError(Exception):
    pass
