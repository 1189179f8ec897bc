"""Who may open the console: its secret token, and the Host and Origin of every request.

A console serves its page and one websocket per page on one port, in plain HTTP. It makes a
token at each start (:func:`make_token`) unless the user gives one, and prints its address
with it (``http://127.0.0.1:8080/?token=...``). Opening that address stores the token in a
cookie of this port (``HttpOnly``, ``SameSite=Lax``) and redirects to ``/`` (the token leaves
the address bar); the page and its websocket then carry the cookie. :meth:`Access.verdict`
refuses a request unless all of these hold:

- it carries the token: the cookie, or ``token=`` in its query (a program's websocket);
- its Host names this machine (``127.0.0.1``, ``localhost``, ``::1``: a DNS name of another
  site pointed at 127.0.0.1, DNS rebinding, is refused) when the console serves loopback only;
- its Origin, if it has one (a browser sends one with every websocket), is the page's own,
  ``http://`` or ``https://`` and the Host: a page of another site, or of another port of this
  machine, open in the operator's browser, cannot open the websocket.

Serving beyond this machine (:func:`is_loopback` false) needs a token the user chose: a
console never makes one up for the network.
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
import string
from collections.abc import Mapping
from typing import NamedTuple
from urllib.parse import parse_qsl, urlencode, urlsplit

from rrc_pin.errors import InvalidInput

TOKEN_ENV = "RRC_PIN_CONSOLE_TOKEN"
"""The environment variable the command line reads a token from (``--token`` also works, but
a command line is visible to every user of the machine)."""
MIN_TOKEN = 16
"""Fewest characters of a token the user gives."""
TOKEN_CHARACTERS = frozenset(string.ascii_letters + string.digits + "-_.~")
"""What a token may hold: characters that go into an address and a cookie unescaped."""


def make_token() -> str:
    """A new secret token: 32 random bytes, URL-safe base64 (43 characters)."""
    return secrets.token_urlsafe(32)


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an address to serve on) is reachable from this machine only."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:  # a name: it may resolve to anything
        return False


def check_token(token: object) -> str:
    """A token the user gave, checked.

    Raises:
        InvalidInput: Naming ``token``: not a string of at least :data:`MIN_TOKEN` characters
            of :data:`TOKEN_CHARACTERS`.
    """
    if not isinstance(token, str) or len(token) < MIN_TOKEN:
        raise InvalidInput("token", f"expected a secret of at least {MIN_TOKEN} characters")
    if not set(token) <= TOKEN_CHARACTERS:
        raise InvalidInput("token", "expected letters, digits and - _ . ~ only")
    return token


class Verdict(NamedTuple):
    """What to do with one request.

    Attributes:
        refused: Why it is refused (HTTP 403 with this text), or None.
        set_cookie: Whether the response stores the token in the page's cookie.
        location: Where to redirect the page (303) once the cookie is set, or None.
    """

    refused: str | None
    set_cookie: bool = False
    location: str | None = None


class Access:
    """The console's door: its token and the hosts it answers to.

    Args:
        host: The address the console serves on.
        token: The user's token, or None to make one (loopback only).

    Attributes:
        token: The secret.
        chosen: Whether the user gave it.
        loopback: Whether the console serves this machine only.

    Raises:
        InvalidInput: A bad token; or none given for an address beyond this machine.
    """

    def __init__(self, host: str, token: str | None = None) -> None:
        if not isinstance(host, str) or not host:
            raise InvalidInput("host", f"expected an address to serve on, got {host!r}")
        self.loopback = is_loopback(host)
        self.chosen = token is not None
        if token is None and not self.loopback:
            raise InvalidInput(
                "token",
                f"serving on {host!r} lets every machine that reaches it drive the arm: give a "
                f"token of your own ({TOKEN_ENV} or --token, at least {MIN_TOKEN} characters) "
                "to serve beyond this machine",
            )
        self.token = make_token() if token is None else check_token(token)
        self.cookie = "rrc-pin-console"

    def name_cookie(self, port: int) -> None:
        """Name the cookie after the served port (two consoles on one machine: two cookies)."""
        self.cookie = f"rrc-pin-console-{port}"

    def verdict(self, path: str, headers: Mapping[str, list[str]], websocket: bool) -> Verdict:
        """Whether to answer a request, and how.

        Args:
            path: The request's target (path and query).
            headers: Its ``Host``, ``Origin`` and ``Cookie`` headers, each name to every value
                sent (a repeated ``Host`` or ``Origin`` is refused).
            websocket: Whether it asks to open a websocket.
        """
        hosts, origins = headers.get("Host", []), headers.get("Origin", [])
        if len(hosts) != 1 or len(origins) > 1:
            return Verdict("expected one Host header and at most one Origin")
        host = hosts[0]
        try:
            name = urlsplit("//" + host).hostname or ""
        except ValueError:  # a Host that is not one
            name = ""
        if self.loopback and not is_loopback(name):
            return Verdict(f"this console answers to this machine's own names, not {host!r}")
        if origins and origins[0].lower() not in (f"http://{host}".lower(),
                                                  f"https://{host}".lower()):  # fmt: skip
            return Verdict(f"a page of {origins[0]!r} may not use this console")
        query = parse_qsl(urlsplit(path).query, keep_blank_values=True)
        given = [v for k, v in query if k == "token"]
        if given and self._matches(given[-1]):
            if websocket:
                return Verdict(None)
            rest = urlencode([(k, v) for k, v in query if k != "token"])
            return Verdict(None, set_cookie=True, location="/" + (f"?{rest}" if rest else ""))
        if self._matches(_cookie("; ".join(headers.get("Cookie", [])), self.cookie)):
            return Verdict(None)
        return Verdict("this console needs its token: open the address it printed when it "
                       "started (it ends in ?token=...)")  # fmt: skip

    def cookie_header(self) -> str:
        """The ``Set-Cookie`` value that stores the token in the page."""
        return f"{self.cookie}={self.token}; Path=/; HttpOnly; SameSite=Lax"

    def _matches(self, given: str | None) -> bool:
        return given is not None and hmac.compare_digest(given.encode(), self.token.encode())


def _cookie(header: str, name: str) -> str | None:
    """The value of cookie ``name`` in a ``Cookie`` header, or None."""
    for part in header.split(";"):
        key, _, value = part.strip().partition("=")
        if key == name:
            return value
    return None
