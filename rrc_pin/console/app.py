"""Console: the server, the control loop, the scene, the panel and the view, put together.

Threads, from the robot outward:

1. the control loop (:class:`~rrc_pin.console.loop.ControlLoop`): owns the controller, ticks
   at ``rate`` (100 Hz by default), reads the mailbox at every tick;
2. viser's event loop and its thread pool: receive the pages' messages and run the panel's
   callbacks, which only post commands to the mailbox;
3. the view (:class:`~rrc_pin.console.view.View`): reads the loop's latest snapshot at a lower
   rate and sends the scene and the readouts to the pages.

The loop never waits for a page or for the renderer; a page never touches the controller.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path
from typing import Any

import numpy.typing as npt

from rrc_pin.console.commands import Released, Target
from rrc_pin.console.loop import ControlLoop
from rrc_pin.console.mailbox import Mailbox
from rrc_pin.console.operator import OperatorSettings
from rrc_pin.console.panel import Panel
from rrc_pin.console.scene import Scene
from rrc_pin.console.view import View
from rrc_pin.console.visuals import visuals_of
from rrc_pin.errors import InvalidInput, RrcPinError
from rrc_pin.loading import load
from rrc_pin.robot import Robot

SWITCH_INTERVAL = 2e-4
"""The interpreter's thread switch interval [s] while a console runs (default 5e-3): a thread
holding the GIL (the view, a page's callback) gives it up to the waking loop this soon."""


class Console:
    """The operator's console of one robot, served on a local port.

    Args:
        robot: The robot, or a name :func:`rrc_pin.load` takes.
        host: Interface to serve on (default loopback only).
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

    Raises:
        InvalidInput: A bad argument, named.
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
    ) -> None:
        self.robot = load(robot) if isinstance(robot, str) else robot
        if not isinstance(self.robot, Robot):
            raise InvalidInput("robot", f"expected a rrc_pin.Robot or a name, got {robot!r}")
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port < 65536:
            raise InvalidInput("port", f"expected a port number 0 to 65535, got {port!r}")
        self.host, self.port, self.view_rate = host, port, view_rate
        self.out = Path(out)
        self.loop = ControlLoop(self.robot, rate=rate, q0=q0, mailbox=Mailbox(),
                                settings=settings, strategy=strategy, backend=backend,
                                realtime=realtime)  # fmt: skip
        self.server: Any = None
        self.scene: Scene | None = None
        self.panel: Panel | None = None
        self.view: View | None = None
        self._switch = sys.getswitchinterval()

    def start(self) -> Console:
        """Serve the page, start the loop and the view; returns the console."""
        import viser

        visuals = visuals_of(self.robot)
        self.server = viser.ViserServer(host=self.host, port=self.port, verbose=False)
        server = self.server
        server.gui.set_panel_label(f"rrc-pin console: {self.robot.name}")
        mailbox = self.loop.mailbox
        limits = self.loop.operator.settings
        self.scene = Scene(server, self.robot, visuals,
                           on_target=lambda pose: mailbox.post(Target(pose)),
                           full=(limits.max_linear, limits.max_angular))  # fmt: skip
        self.panel = Panel(server, self.loop, self.out)
        self.view = View(server, self.loop, self.scene, self.panel, rate=self.view_rate)

        def closed(client: Any) -> None:
            if not server.get_clients():  # the last page went away: let go of the arm
                mailbox.post(Released())

        server.on_client_disconnect(closed)

        self._switch = sys.getswitchinterval()
        sys.setswitchinterval(SWITCH_INTERVAL)
        self.loop.start()
        self.view.update(force=True)
        self.view.start()
        return self

    @property
    def url(self) -> str:
        """The page's address (after :meth:`start`)."""
        if self.server is None:
            raise InvalidInput("console", "not started")
        return f"http://{self.host}:{self.server.get_port()}/"

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
