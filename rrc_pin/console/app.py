"""Console: the server, the control loop, the scene, the panel and the view, put together.

Threads, from the robot outward:

1. the control loop (:class:`~rrc_pin.console.loop.ControlLoop`; for a cell its
   :class:`~rrc_pin.console.cell_loop.CellLoop`): owns the controller, ticks at ``rate``
   (100 Hz by default; 1000 for 1 kHz, a cell's included), reads the mailbox at every tick;
2. viser's event loop: checks every request and message (:mod:`~rrc_pin.console.guard`),
   receives the pages' messages and runs the panel's callbacks in the order the messages
   came, which only post commands to the mailbox; it asks for the loop's scheduling, a step
   below (a STOP travels through it);
3. the view (:class:`~rrc_pin.console.view.View`): reads the loop's latest snapshot at a lower
   rate and sends the scene and the readouts to the pages.

The loop never waits for a page or for the renderer; a page never touches the controller.
"""

from __future__ import annotations

import gc
import logging
import sys
import threading
from pathlib import Path
from typing import Any

import numpy.typing as npt

from rrc_pin.console.access import Access
from rrc_pin.console.cell_loop import loop_of
from rrc_pin.console.commands import Released, Target
from rrc_pin.console.intake import Intake
from rrc_pin.console.loop import LOOP_NICE, REALTIME_PRIORITY, schedule
from rrc_pin.console.mailbox import Mailbox
from rrc_pin.console.operator import OperatorSettings
from rrc_pin.console.panel import Panel
from rrc_pin.console.scene import Scene
from rrc_pin.console.view import View
from rrc_pin.console.visuals import visuals_of
from rrc_pin.errors import InvalidInput, RrcPinError
from rrc_pin.loading import load
from rrc_pin.robot import Robot

LOG = logging.getLogger("rrc_pin.console")
IO_PRIORITY = REALTIME_PRIORITY - 1
"""Real-time priority of viser's event loop thread under ``realtime`` (below the loop's)."""
SWITCH_INTERVAL = 2e-4
"""The interpreter's thread switch interval [s] while a console runs (default 5e-3): a thread
holding the GIL (the view, a page's callback) gives it up to the waking loop this soon."""


class Console:
    """The operator's console of one robot, served on a local port.

    Args:
        robot: The robot, or a name :func:`rrc_pin.load` takes.
        host: Interface to serve on (default loopback only); any other needs ``token``.
        port: Port; 0 takes a free one (see :attr:`url`).
        rate: Control loop rate [1/s].
        view_rate: Scene updates per second (the readouts 5 per second).
        out: Folder for saved records.
        q0: Start configuration (nq,) [rad or m]; default
            :func:`~rrc_pin.console.loop.start_pose`.
        strategy: Initial singularity strategy's name.
        backend: Initial QP backend's name.
        settings: Limits of the operator's controls.
        realtime: Run the control loop under real-time scheduling where permitted
            (:class:`~rrc_pin.console.loop.ControlLoop`).
        token: The secret every page and websocket must show, at least 16 characters of
            letters, digits and ``-_.~``; None makes one at each start (loopback only).
        intake: What each connection may send (size, shape and rate of its messages).

    Attributes:
        access: Who may connect (:class:`~rrc_pin.console.access.Access`: its ``token``).
        io_scheduling: How viser's event loop thread is scheduled (as the loop's
            ``scheduling``, one real-time priority below it).
        guard: The checks on viser's server once started (:class:`~rrc_pin.console.guard.Guard`).

    Raises:
        InvalidInput: A bad argument, named; no ``token`` for a ``host`` beyond this machine.
        UnknownArm, URDFError: ``robot`` is a name that does not load.
    """

    def __init__(
        self,
        robot: Robot | str,
        *,
        host: str = "127.0.0.1",
        port: int = 8080,
        rate: float = 100.0,
        view_rate: float = 20.0,
        out: str | Path = ".",
        q0: npt.ArrayLike | None = None,
        strategy: str = "resolver",
        backend: str = "daqp",
        settings: OperatorSettings | None = None,
        realtime: bool = False,
        token: str | None = None,
        intake: Intake | None = None,
    ) -> None:
        self.access = Access(host, token)
        if intake is not None and not isinstance(intake, Intake):
            raise InvalidInput("intake", f"expected a console.Intake, got {intake!r}")
        self.intake = intake or Intake()
        self.robot = load(robot) if isinstance(robot, str) else robot
        if not isinstance(self.robot, Robot):
            raise InvalidInput("robot", f"expected a rrc_pin.Robot or a name, got {robot!r}")
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port < 65536:
            raise InvalidInput("port", f"expected a port number 0 to 65535, got {port!r}")
        self.host, self.port, self.view_rate = host, port, view_rate
        self.out = Path(out)
        self.loop = loop_of(self.robot, rate=rate, q0=q0, mailbox=Mailbox(), settings=settings,
                            strategy=strategy, backend=backend, realtime=realtime)  # fmt: skip
        self.server: Any = None
        self.guard: Any = None
        self.io_scheduling = "not started"
        self.scene: Scene | None = None
        self.panel: Panel | None = None
        self.view: View | None = None
        self._switch = sys.getswitchinterval()

    def start(self) -> Console:
        """Serve the page, start the loop and the view; returns the console."""
        import viser
        import viser.infra

        from rrc_pin.console.guard import Guard

        visuals = visuals_of(self.robot)
        self.server = server = viser.ViserServer(host=self.host, port=self.port, verbose=False)
        self.guard = Guard(server, self.access, self.intake, viser.infra.Message.deserialize)
        try:
            self.guard.install()
        except BaseException:
            self.stop()
            raise
        if not self.access.loopback:
            LOG.warning(exposed(self.host, self.server.get_port()))
        server.get_event_loop().call_soon_threadsafe(self._schedule_io)
        server.gui.set_panel_label(f"rrc-pin console: {self.robot.name}")
        mailbox = self.loop.mailbox
        limits = self.loop.operator.settings
        self.scene = Scene(server, self.robot, visuals,
                           on_target=lambda pose: mailbox.post(Target(pose)),
                           full=(limits.max_linear, limits.max_angular))  # fmt: skip
        self.panel = Panel(server, self.loop, self.out)
        self.guard.urgent = self.panel.urgent
        self.view = View(server, self.loop, self.scene, self.panel, rate=self.view_rate)

        async def closed(client: Any) -> None:  # on viser's event loop: at once
            if not server.get_clients():  # the last page went away: let go of the arm
                mailbox.post(Released())

        server.on_client_disconnect(closed)

        self._switch = sys.getswitchinterval()
        sys.setswitchinterval(SWITCH_INTERVAL)
        # what the process holds by now (modules, models, the server) is left out of every
        # later garbage collection: a full one stops every thread, the loop's with them, for
        # as long as it takes to walk them (docs/api.md, "Pauses of the garbage collector")
        gc.freeze()
        self.loop.start()
        self.view.update(force=True)
        self.view.start()
        return self

    def _schedule_io(self) -> None:
        """Schedule viser's event loop thread (it runs there): the loop's way, a step below.

        The thread that reads the pages, and carries STOP, asks for the loop's scheduling one
        real-time priority below it (where the OS allows it): it does not wait for a core
        behind other processes.
        """
        self.io_scheduling = schedule(self.loop.realtime, IO_PRIORITY, LOOP_NICE)[0]

    @property
    def url(self) -> str:
        """The page's address with its token (after :meth:`start`): what the operator opens."""
        if self.server is None:
            raise InvalidInput("console", "not started")
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.server.get_port()}/?token={self.access.token}"

    def stop(self) -> None:
        """Stop the view, the loop and the server."""
        if self.view is not None:
            self.view.stop()
        self.loop.stop()
        if self.server is not None:
            self.server.stop()
            self.server = None
        sys.setswitchinterval(self._switch)

    def serve_forever(self) -> None:
        """Start, print the address, and serve until interrupted (Ctrl-C)."""
        self.start()
        if not self.access.loopback:
            print(f"\n{'!' * 79}\n{exposed(self.host, self.server.get_port())}\n{'!' * 79}\n",
                  file=sys.stderr, flush=True)  # fmt: skip
        print(f"rrc-pin console: {self.robot.name} at {self.url} (loop {self.loop.rate:g} Hz; "
              "Ctrl-C to stop)", flush=True)  # fmt: skip
        try:
            threading.Event().wait()
        except KeyboardInterrupt:
            pass
        finally:
            self.stop()

    def __enter__(self) -> Console:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def exposed(host: str, port: int) -> str:
    """The warning of a console served beyond this machine."""
    return (f"rrc-pin console: serving on {host}, port {port}: every machine that reaches it and "
            "holds the token drives the arm. The traffic (the token included) is plain HTTP, "
            "readable on the network: serve 127.0.0.1 and reach it through an SSH tunnel "
            "where the network is not yours alone.")  # fmt: skip


def console_robot(arm: str | None, cell: str | None) -> Robot:
    """The robot of ``rrc-pin console --arm NAME`` or ``--cell NAME`` (default ``barker6``).

    Raises:
        InvalidInput: Both given, or a cell name that does not load (the message says so).
        UnknownArm, URDFError: An arm name that does not load.
    """
    if arm is not None and cell is not None:
        raise InvalidInput("--cell", "give --arm or --cell, not both")
    if cell is None:
        return load(arm or "barker6")
    try:
        return load(cell)
    except RrcPinError as exc:
        raise InvalidInput(
            "--cell", f"{cell!r} does not load as a cell ({' '.join(str(exc).split())})"
        ) from exc
