"""View: the thread that shows the loop's snapshots, at its own (lower) rate.

It reads the latest :class:`~rrc_pin.console.snapshot.Snapshot` (never waits for the loop),
moves the robot and the arrows at ``rate`` and rewrites the readouts at ``readout_rate``,
inside ``server.atomic()`` so that a page receives each update whole. It adapts: an update
that took longer than a fifth of its period stretches the period, so the view never takes
more than about a fifth of a core from the loop. (Its thread keeps its priority: a thread of
lower priority holding the GIL when the OS sets it aside would hold the loop up with it.) An
error in an update is counted and the view goes on.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from rrc_pin.console.loop import LOOP_NICE, ControlLoop, set_nice
from rrc_pin.console.panel import Panel
from rrc_pin.console.readouts import Reader, joints_html, status_html
from rrc_pin.console.scene import Scene
from rrc_pin.solvers.checks import finite_number

DUTY = 0.2
"""Largest fraction of the time the view spends updating."""


class View:
    """Shows a loop's snapshots on a server's scene and readouts.

    Args:
        server: A ``viser.ViserServer``.
        loop: The control loop.
        scene: Its scene.
        panel: Its panel (synchronised with the loop's stops).
        rate: Scene updates per second, > 0.
        readout_rate: Readout updates per second, > 0.

    Attributes:
        updates: Scene updates made.
        errors: Updates that raised.
        cost: Duration of the last scene update [s].
    """

    def __init__(self, server: Any, loop: ControlLoop, scene: Scene, panel: Panel,
                 rate: float = 20.0, readout_rate: float = 5.0) -> None:  # fmt: skip
        self.server = server
        self.loop = loop
        self.scene = scene
        self.panel = panel
        self.period = 1.0 / finite_number(rate, "view_rate", 0.0, inclusive=False)  # fmt: skip
        self.readout_period = 1.0 / finite_number(readout_rate, "readout_rate", 0.0,
                                                  inclusive=False)  # fmt: skip
        self.reader = Reader(loop.robot)
        self.updates = 0
        self.errors = 0
        self.cost = 0.0
        self.last_error = ""
        self._notice = 0
        self._note = ""
        self._tick = -1
        self._next_readout = 0.0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Start the view's thread (once)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="rrc-pin console view",
                                            daemon=True)  # fmt: skip
            self._thread.start()

    def stop(self, timeout: float = 2.0) -> None:
        """Stop the thread and wait for it (up to ``timeout`` [s])."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)

    def _run(self) -> None:
        set_nice(LOOP_NICE)
        while not self._stop.is_set():
            start = time.perf_counter()
            try:
                self.update()
            except Exception as exc:  # a view must outlive one bad update: count, go on
                self.errors += 1
                self.last_error = f"{type(exc).__name__}: {exc}"
            self.cost = time.perf_counter() - start
            self._stop.wait(max(self.period - self.cost, self.cost * (1 / DUTY - 1)))

    def update(self, force: bool = False) -> None:
        """Show the latest snapshot (if new, or ``force``): scene, then readouts when due."""
        snap = self.loop.snapshot
        now = time.perf_counter()
        readout = force or now >= self._next_readout
        if snap.tick == self._tick and not readout:
            return
        self._tick = snap.tick
        with self.server.atomic():
            if snap.hand != self.scene.hand:
                self.scene.set_hand(snap.hand)
            self.scene.follow(snap.target is None)
            pose = self.scene.update(snap.q)
            readings = self.reader.read(snap, pose)
            self.scene.set_arrows(pose[:3, 3], readings.commanded, readings.achieved)
            self.updates += 1
            if not readout:
                return
            self._next_readout = now + self.readout_period
            self._notify()
            self.panel.sync(snap)
            self.panel.joints.content = joints_html(self.loop.robot, snap.q, readings.qdot)
            stats = self.loop.clock.stats()
            self.panel.status.content = status_html(snap, readings, stats, self.loop.rate,
                                                    self._note, self.loop.scheduling)  # fmt: skip

    def _notify(self) -> None:
        """Show the loop's new notices on every page (and the last in the status)."""
        for notice in tuple(self.loop.notices):  # (a copy: the loop appends to it)
            if notice.id <= self._notice:
                continue
            self._notice = notice.id
            self._note = notice.text
            for client in self.server.get_clients().values():
                client.add_notification(
                    "refused" if notice.level == "error" else "console", notice.text,
                    color="red" if notice.level == "error" else "blue", auto_close_seconds=6.0,
                )  # fmt: skip
