"""The console's door on viser's server: who connects, and what each page may send.

The access check runs at every handshake and the intake on every message, before viser sees
either.

viser (1.1) serves its page and its websocket from one ``websockets.asyncio.server.Server``,
started inside ``ViserServer()``, and offers no hook into the handshake or the messages. The
least private way found, in three steps on viser's event loop:

1. that server is found among the interpreter's objects (``gc``) by its public type,
   its event loop (``ViserServer.get_event_loop()``) and its listening port;
2. its ``process_request``, the handshake hook ``websockets`` documents, becomes
   :meth:`Guard.process_request`, which refuses a request (HTTP 403) unless
   :class:`~rrc_pin.console.access.Access` allows it and passes the rest to viser's own;
   connections that reached viser before (the milliseconds between its start and this step,
   before the console has any control on the page) are dropped;
3. each websocket admitted gets websockets' own message size limit, a small kernel receive
   buffer (:data:`RECEIVE_BUFFER`), and its ``recv``, which viser's reader awaits for every
   message, replaced by :meth:`Guard.admit`'s: a message too big, too deep, too long or not
   viser's protocol closes the connection (1008, the reason said) before viser decodes it;
   the others spend from the connection's budget
   (:class:`~rrc_pin.console.intake.TokenBucket`) and wait when it is empty; a connection
   whose messages have all waited for ``Intake.patience`` is closed (1008). A message that
   stops or releases the arm is taken there, as it arrives, ahead of the budget and of
   viser's dispatch (the ``urgent`` hook: STOP does not wait behind any page's messages,
   its own page's included).

A later viser that serves differently makes :meth:`Guard.install` raise: the console does
not start unguarded.
"""

from __future__ import annotations

import asyncio
import collections
import gc
import http
import inspect
import logging
import math
import socket
import time
import weakref
from collections.abc import Callable
from typing import Any

from websockets.asyncio.server import Server, ServerConnection
from websockets.frames import CloseCode
from websockets.http11 import Request, Response
from websockets.protocol import State

from rrc_pin.console.access import Access
from rrc_pin.console.intake import Intake, TokenBucket, shape_refusal
from rrc_pin.errors import RrcPinError

LOG = logging.getLogger("rrc_pin.console")
FRAME_HEADERS = {"X-Frame-Options": "DENY", "Content-Security-Policy": "frame-ancestors 'none'",
                 "Referrer-Policy": "no-referrer"}  # fmt: skip
"""Headers of every page answered: no other site may frame the console (and click it)."""
RECEIVE_BUFFER = 16384
"""The kernel's receive buffer of a page's socket [bytes] (Linux doubles it: 32 kB): what a
page sent beyond it waits in the page's own socket, and the server parses at most a few
hundred of its messages at once (a flood read 256 kB at a time held the event loop, and a
STOP, for tens of milliseconds; a buffer under 16 kB stalls TCP: uploads crawled at 40 kB/s)."""
URGENT_RATE, URGENT_BURST = 20.0, 5
"""How many urgent messages a second a connection may send ahead of its budget, and at once
(an operator's STOPs, a held space key's repeats: the rest wait like any message)."""
CLOSE_TIMEOUT = 1.0
"""How long [s] a connection closed for what it sent has to answer the close (a flooding page
does not read: then its socket is dropped)."""


class GuardError(RrcPinError):
    """viser serves in a way the guard does not know: the console refuses to start."""


class Guard:
    """Access and intake on a started ``viser.ViserServer``.

    Args:
        server: The viser server (started).
        access: Who may connect.
        intake: What each connection may send.
        decodes: A message of viser's protocol decoded (``viser.infra.Message.deserialize``;
            it raises for anything else); called once the message's shape passed.
        urgent: The action of a decoded message that stops or releases the arm, or None
            (:meth:`~rrc_pin.console.panel.Panel.urgent`): taken as the message arrives, ahead
            of its connection's budget (within :data:`URGENT_RATE`) and of viser, which
            never sees it.

    Attributes:
        refused: Requests refused at the handshake.
        last_refused: Why the last one was.
        closed: Connections closed for a message, by reason.
        throttled: Messages that waited for their connection's budget.
        urgents: Messages taken as urgent (STOP, the latch let go).
        faults: Errors on viser's event loop (each also reported as asyncio reports it).
        last_fault: The last one, in a line.
    """

    def __init__(self, server: Any, access: Access, intake: Intake,
                 decodes: Callable[[bytes], object],
                 urgent: Callable[[Any], Callable[[], None] | None] = lambda m: None,
                 ) -> None:  # fmt: skip
        self.server = server
        self.access = access
        self.intake = intake
        self.decodes = decodes
        self.urgent = urgent
        self.refused = 0
        self.last_refused = ""
        self.closed: collections.Counter[str] = collections.Counter()
        self.throttled = 0
        self.urgents = 0
        self.faults = 0
        self.last_fault = ""
        self._pages: weakref.WeakSet[ServerConnection] = weakref.WeakSet()
        self._opens = TokenBucket(1.0, 2 * intake.max_pages, time.monotonic())
        self._viser: Callable[[ServerConnection, Request], Any] = lambda c, r: None

    def install(self, timeout: float = 30.0) -> None:
        """Put the guard in front of viser's handlers (on viser's event loop; waits for it).

        Raises:
            GuardError: No websockets server of viser's on its port.
        """
        loop = self.server.get_event_loop()
        port = self.server.get_port()
        # by type, not isinstance: a weak proxy whose object is gone raises on isinstance
        found = [o for o in gc.get_objects() if issubclass(type(o), Server)
                 and o.get_loop() is loop
                 and any(s.getsockname()[1] == port for s in o.sockets)]  # fmt: skip
        if len(found) != 1:
            raise GuardError(f"no websockets server of viser's on port {port}: the console "
                             "cannot guard this viser, and does not start")
        (ws,) = found
        self.access.name_cookie(port)

        async def put() -> None:
            self._viser = ws.process_request or self._viser
            ws.process_request = self.process_request
            for connection in tuple(getattr(ws, "handlers", ())):  # before the guard: dropped
                connection.transport.abort()
            loop.set_exception_handler(self._fault)

        asyncio.run_coroutine_threadsafe(put(), loop).result(timeout)

    def _fault(self, loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        self.faults += 1
        self.last_fault = f"{context.get('message')}: {context.get('exception')!r}"
        loop.default_exception_handler(context)

    async def process_request(self, connection: ServerConnection,
                              request: Request) -> Response | None:  # fmt: skip
        """The handshake hook of ``websockets``: refuse, redirect, or admit and let viser answer."""
        websocket = "websocket" in (v.lower() for v in request.headers.get_all("Upgrade"))
        headers = {name: request.headers.get_all(name) for name in ("Host", "Origin", "Cookie")}
        verdict = self.access.verdict(request.path, headers, websocket)
        if verdict.refused is not None:
            return self._refuse(connection, http.HTTPStatus.FORBIDDEN, verdict.refused)
        if websocket:
            if sum(c.state is not State.CLOSED for c in self._pages) >= self.intake.max_pages:
                return self._refuse(connection, http.HTTPStatus.SERVICE_UNAVAILABLE,
                                    f"{self.intake.max_pages} pages are open on this console")
            if not self._opens.take(time.monotonic()):
                return self._refuse(connection, http.HTTPStatus.SERVICE_UNAVAILABLE,
                                    "pages open too often on this console: wait a second")
            self.admit(connection)
        if verdict.location is not None:
            response = connection.respond(http.HTTPStatus.SEE_OTHER, "")
            response.headers["Location"] = verdict.location
        else:
            response = self._viser(connection, request)
            if inspect.isawaitable(response):
                response = await response
        if response is not None:
            for name, value in FRAME_HEADERS.items():
                response.headers[name] = value
            if verdict.set_cookie:
                response.headers["Set-Cookie"] = self.access.cookie_header()
        return response

    def _refuse(self, connection: ServerConnection, status: http.HTTPStatus,
                why: str) -> Response:  # fmt: skip
        self.refused += 1
        self.last_refused = why
        return connection.respond(status, why + "\n")

    def admit(self, connection: ServerConnection) -> None:
        """Limit an admitted websocket: message size, shape and rate, before viser reads it."""
        connection.protocol.max_message_size = self.intake.max_bytes  # checked as frames arrive
        sock = connection.transport.get_extra_info("socket")
        if sock is not None:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECEIVE_BUFFER)
        self._pages.add(connection)
        connection.recv = _Reader(self, connection).recv  # type: ignore[method-assign]

    async def close(self, connection: ServerConnection, why: str) -> None:
        """Close a page's connection for what it sent (1008, ``why``); raises as recv does."""
        self.closed[why] += 1
        LOG.warning("closed a page's connection: %s", why)
        connection.close_timeout = CLOSE_TIMEOUT
        await connection.close(CloseCode.POLICY_VIOLATION, why)
        raise connection.protocol.close_exc

    def check(self, data: object) -> tuple[str | None, Any]:
        """A page's message decoded, or why it closes its connection.

        Returns:
            (None, the message) or (the reason, None).
        """
        if not isinstance(data, bytes):
            return "text messages are not this console's protocol", None
        if len(data) > self.intake.max_bytes:
            return f"a message larger than {self.intake.max_bytes} bytes", None
        why = shape_refusal(data, self.intake.max_depth, self.intake.max_items)
        if why is not None:
            return f"a message {why}", None
        try:
            return None, self.decodes(data)
        except Exception as exc:  # whatever viser's decoder raises: not its protocol
            return f"not a message of the page's protocol ({type(exc).__name__})", None


class _Reader:
    """One connection's intake: what viser's reader awaits instead of ``connection.recv``."""

    def __init__(self, guard: Guard, connection: ServerConnection) -> None:
        now = time.monotonic()
        self.guard = guard
        self.connection = connection
        self.receive = connection.recv
        self.budget = TokenBucket(guard.intake.rate, guard.intake.burst, now)
        self.quick = TokenBucket(URGENT_RATE, URGENT_BURST, now)
        self.spent = math.inf  # since when the budget has been spent [s]

    async def recv(self, *args: Any, **kwargs: Any) -> Any:
        """The next message for viser; an urgent one (a STOP) is taken here and not passed."""
        guard, intake = self.guard, self.guard.intake
        while True:
            data = await self.receive(*args, **kwargs)
            now = time.monotonic()
            why, message = guard.check(data)
            act = guard.urgent(message) if why is None else None
            if act is not None and self.quick.take(now):
                guard.urgents += 1
                act()  # ahead of the budget and of viser's dispatch: viser never sees it
                continue
            delay = self.budget.wait(now)
            # spent: every message waits and the budget never refills to half (a late wake-up
            # of this loop refills a little, not that much)
            full = self.budget.level >= intake.burst / 2
            self.spent = math.inf if full else min(self.spent, now)
            if why is None and now - self.spent > intake.patience:
                why = f"more than {intake.rate:g} messages a second for {intake.patience:g} s"
            if why is not None:
                await guard.close(self.connection, why)
            if delay > 0.0:
                guard.throttled += 1
            await asyncio.sleep(delay)  # (0: the other pages' messages get their turn)
            if act is None:
                return data
            guard.urgents += 1
            act()
