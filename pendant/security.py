"""The pendant server's guards (docs/security.md, "The pendant's web server").

* **Token.** One random token per server start (``secrets.token_urlsafe``, 256 bits), as
  Jupyter does: the URL the command prints carries it (``?token=``); the first page load sets
  it as an HttpOnly, SameSite=Strict cookie; every HTTP request and every websocket handshake
  must carry it (query, cookie or ``Authorization: token ...``), compared in constant time;
  only the page's bundle under ``/static/`` (the code pip installs, no data) is served without
  it, so that the page also loads inside VS Code's webview, where a SameSite cookie is not sent.
* **Host and Origin.** The ``Host`` header must name the server's own loopback address (a DNS
  rebinding page has another host name); a websocket handshake must come with the page's own
  ``Origin`` and an HTTP request with an ``Origin`` must name it too (cross-site requests and
  cross-site websocket hijacking are refused).
* **The workspace.** A path the page names is resolved (links followed) and must stay inside
  the workspace root, be a regular file and at most :data:`krl.limits.MAX_WEB_FILE_BYTES`.

:class:`Guard` is a pure ASGI middleware: a refused HTTP request gets 403 (400 for a bad
Host) and a refused websocket handshake is closed before it is accepted (HTTP 403).
"""

from __future__ import annotations

import hmac
import secrets
from http.cookies import SimpleCookie
from pathlib import Path
from urllib.parse import parse_qs

from krl.limits import MAX_WEB_FILE_BYTES

COOKIE = "krl_pendant_token"
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]")


class PathRefused(ValueError):
    """A path outside the workspace, not a regular file, or too large."""


def new_token() -> str:
    return secrets.token_urlsafe(32)


def inside(root: Path, path: str | Path, *, suffixes: tuple[str, ...] | None = None) -> Path:
    """``path`` (absolute, or relative to ``root``) when it is a regular file inside ``root`` of
    at most MAX_WEB_FILE_BYTES (and, with ``suffixes``, has one of them, any case): resolved
    (links followed) to decide, and returned below ``root`` as ``root`` is spelled (the user's
    spelling, links of ``root`` kept: ``root / `` the resolved path relative to the resolved
    root). Raises :class:`PathRefused`."""
    text = str(path)
    if not text or "\0" in text or len(text) > 4096:
        raise PathRefused("not a path")
    real_root = root.resolve()
    p = Path(text)
    if not p.is_absolute():
        p = root / p
    real = p.resolve()
    if not real.is_relative_to(real_root):
        raise PathRefused("outside the workspace")
    p = root / real.relative_to(real_root)
    if not p.is_file():
        raise PathRefused("no such file in the workspace")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise PathRefused(f"not a {'/'.join(suffixes)} file")
    if p.stat().st_size > MAX_WEB_FILE_BYTES:
        raise PathRefused(f"larger than {MAX_WEB_FILE_BYTES} bytes")
    return p


class Guard:
    """ASGI middleware: Host, token and Origin checks in front of ``app``."""

    def __init__(self, app, token: str, port_of) -> None:
        self.app = app
        self.token = token
        self.port_of = port_of          # () -> the port the server listens on

    def allowed_hosts(self) -> set[str]:
        port = self.port_of()
        return {f"{h}:{port}" for h in LOOPBACK_HOSTS}

    def allowed_origins(self) -> set[str]:
        return {f"http://{h}" for h in self.allowed_hosts()}

    def check(self, scope) -> tuple[int, str] | None:
        """(status, reason) when the request is refused, else None."""
        headers = {}
        for k, v in scope.get("headers") or ():
            headers.setdefault(k.decode("latin-1").lower(), v.decode("latin-1"))
        if headers.get("host", "").lower() not in self.allowed_hosts():
            return 400, "unknown host"
        origin = headers.get("origin")
        if scope["type"] == "websocket" and origin is None:
            return 403, "no Origin"
        if origin is not None and origin.lower() not in self.allowed_origins():
            return 403, "cross-origin request"
        if scope["type"] == "http" and scope.get("path", "").startswith("/static/"):
            return None         # the page's bundle: the code pip installs, no data (Host still checked)
        if not self._token_ok(scope, headers):
            return 403, "missing or wrong token"
        return None

    def _token_ok(self, scope, headers: dict) -> bool:
        given = []
        qs = parse_qs(scope.get("query_string", b"").decode("latin-1"))
        given += qs.get("token", [])[:1]
        auth = headers.get("authorization", "")
        if auth.lower().startswith("token "):
            given.append(auth[len("token "):].strip())
        if "cookie" in headers:
            c = SimpleCookie()
            try:
                c.load(headers["cookie"])
            except Exception:  # noqa: BLE001 - a malformed cookie header is no token
                c = SimpleCookie()
            if COOKIE in c:
                given.append(c[COOKIE].value)
        return any(hmac.compare_digest(g.encode(), self.token.encode()) for g in given)

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        refused = self.check(scope)
        if refused is None:
            await self.app(scope, receive, send)
            return
        status, reason = refused
        if scope["type"] == "websocket":
            await receive()                                  # websocket.connect
            await send({"type": "websocket.close", "code": 1008, "reason": reason})
            return
        body = f"refused: {reason}\n".encode()
        await send({"type": "http.response.start", "status": status,
                    "headers": [(b"content-type", b"text/plain; charset=utf-8"),
                                (b"content-length", str(len(body)).encode())]})
        await send({"type": "http.response.body", "body": body})


__all__ = ["COOKIE", "Guard", "PathRefused", "inside", "new_token"]
