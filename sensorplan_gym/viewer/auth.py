"""Access control of the live viewer: a secret token in the URL, as Jupyter does.

The server listens on 127.0.0.1 only, but any local user (and any web page the browser
opens, through DNS rebinding or a cross-site request) can reach a localhost port.  So
``sensorplan view`` draws a random token at launch (48 hex digits from
:mod:`secrets`; or ``--token`` / the ``SENSORPLAN_VIEW_TOKEN`` environment variable),
prints the URL with ``?token=...`` and serves only requests that prove they know it:

* **page requests** (the document, ``/autoload.js``, ``/metadata``) must carry
  ``?token=<token>`` (compared in constant time); others are redirected to a 403 page
  that says where the token is, and no session is created;
* **the websocket** (``/ws``, where the session's document lives) must present the
  session's JWT that the server itself minted for an authorised page request: sessions
  are *signed* with a per-launch random secret key (Bokeh's ``sign_sessions``), and the
  signed JWT carries the page request's arguments, so the token is checked there too.
  Without the secret a client can neither forge a session nor open a websocket.

Why Bokeh's own hooks rather than checking ``curdoc().session_context.request.arguments``
in the app: the app body runs only after Bokeh has created a session, and with unsigned
sessions those request arguments come from a JWT the client can write itself.  The auth
provider refuses before any session exists, and signing makes the JWT unforgeable.

Static files (BokehJS itself) are served without the token: they are public code.
"""

from __future__ import annotations

import hmac
import os
import re
import secrets
import zlib
from typing import Any

from bokeh.server.auth_provider import AuthProvider
from bokeh.server.views.ws import WSHandler
from bokeh.util.token import check_token_signature, get_token_payload
from tornado.web import HTTPError, RequestHandler

__all__ = [
    "FORBIDDEN_PATH",
    "TOKEN_ENV",
    "TokenAuth",
    "new_token",
    "token_from",
    "validate_token",
]

#: Environment variable that gives the token (keeps it out of the process list).
TOKEN_ENV = "SENSORPLAN_VIEW_TOKEN"
#: Where requests without the token are sent (a 403 page).
FORBIDDEN_PATH = "/forbidden"
#: A token: at least 16 characters that need no escaping in a URL.
_TOKEN_RE = re.compile(r"[A-Za-z0-9._~-]{16,}")

FORBIDDEN_HTML = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>sensorplan view: token required</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1 id="token-required">403: this viewer needs its access token</h1>
<p>This <code>sensorplan view</code> server only serves pages whose address carries its
token. Open the address that <code>sensorplan view</code> printed when it started; it ends
in <code>/?token=&hellip;</code>.</p>
</body></html>
"""


def new_token() -> str:
    """A fresh random token: 48 hex digits (192 bits), as Jupyter's."""
    return secrets.token_hex(24)


def validate_token(token: str) -> str:
    """``token`` if it is usable in a URL and long enough; ``ValueError`` otherwise."""
    if not isinstance(token, str) or not _TOKEN_RE.fullmatch(token):
        raise ValueError(
            "the viewer's token must be at least 16 characters from A-Z a-z 0-9 . _ ~ - "
            "(leave it out for a random one)"
        )
    return token


def token_from(arg: str | None) -> str:
    """The token to use: ``arg`` (``--token``), else ``$SENSORPLAN_VIEW_TOKEN``, else a new
    random one; validated."""
    if arg is not None:
        return validate_token(arg)
    env = os.environ.get(TOKEN_ENV)
    if env:
        return validate_token(env)
    return new_token()


def _matches(given: bytes | str | None, token: str) -> bool:
    if given is None:
        return False
    if isinstance(given, str):
        given = given.encode("utf-8", "surrogateescape")
    return hmac.compare_digest(given, token.encode("ascii"))


class ForbiddenHandler(RequestHandler):
    """The page shown to requests without the token: status 403, no session."""

    def get(self, *args: Any, **kwargs: Any) -> None:
        self.set_status(403)
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store")
        self.write(FORBIDDEN_HTML)

    head = get


class TokenAuth(AuthProvider):
    """Bokeh auth provider: page requests need ``?token=``, websockets a JWT signed with
    ``secret_key`` whose page request carried the token (see the module docstring)."""

    def __init__(self, token: str, secret_key: str | bytes) -> None:
        self.token = validate_token(token)
        self.secret_key = secret_key.encode() if isinstance(secret_key, str) else secret_key
        super().__init__()

    # --- AuthProvider interface ------------------------------------------------------
    @property
    def get_user(self):
        return None

    @property
    def get_user_async(self):
        # async: Bokeh then checks in ``prepare``, before a websocket handshake is accepted
        return self._user

    @property
    def login_url(self) -> str:
        return FORBIDDEN_PATH

    @property
    def get_login_url(self):
        return None

    @property
    def login_handler(self):
        return ForbiddenHandler

    @property
    def logout_url(self):
        return None

    @property
    def logout_handler(self):
        return None

    # --- the checks --------------------------------------------------------------------
    def websocket_ok(self, subprotocol_header: str) -> bool:
        """Whether a websocket handshake's ``Sec-WebSocket-Protocol`` header (``bokeh,
        <jwt>``) carries a JWT signed with our secret key for a request that had the
        token."""
        parts = [p.strip() for p in subprotocol_header.split(",")]
        if len(parts) != 2 or parts[0] != "bokeh":
            return False
        jwt = parts[1]
        try:
            if not check_token_signature(jwt, secret_key=self.secret_key, signed=True):
                return False
            args = get_token_payload(jwt).get("arguments") or {}
        except (ValueError, TypeError, KeyError, zlib.error):  # a malformed token
            return False
        given = args.get("token") if isinstance(args, dict) else None
        return isinstance(given, list) and len(given) == 1 and _matches(given[0], self.token)

    async def _user(self, handler: RequestHandler) -> str | None:
        """The "user" of a request: ``"token"`` when it proves it knows the token, else
        ``None`` (page requests: redirected to the 403 page); a websocket handshake
        without it is answered 403 at once."""
        if isinstance(handler, WSHandler):
            if not self.websocket_ok(handler.request.headers.get("Sec-WebSocket-Protocol", "")):
                raise HTTPError(403, reason="sensorplan view: no valid session token")
            return "token"
        given = handler.get_query_arguments("token")
        return "token" if len(given) == 1 and _matches(given[0], self.token) else None
