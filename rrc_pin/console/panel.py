"""Panel: the console's controls; every event becomes one command posted to the mailbox.

The callbacks are coroutines: viser runs them on its event loop as each message arrives, in
the order the messages came (a synchronous callback would wait in viser's thread pool, where
a STOP queued behind a page's flood and a latch could overtake the STOP after it). They build
a command (checked when made: a NaN, a string or a value beyond its slider's range from a
page is refused there, the page told why and the control put back) and post it; they never
touch the controller. Commands that make the loop build a new resolver or controller
(backend, hand, home, load) pass at most :data:`REBUILDS_PER_SECOND` a second, the others
refused to the page that sent them.

Controls (folder by folder):

- **Command**: hand (robots with several tool frames), frame (hand or base axes), six
  velocity sliders, zero; the deadman (a *hold to move* button whose heartbeats keep it held
  for :attr:`~rrc_pin.console.operator.OperatorSettings.hold_timeout`, and a latch), STOP,
  speed override, drop target (the gizmo), the device's pose (a stream of
  ``x y z qw qx qy qz [clutch]`` values, each a :class:`~rrc_pin.console.commands.Pose`: a
  page's script or a program on the console's websocket, behind the same token, Origin and
  intake as every control; the deadman still gates it and STOP still jumps its queue).
- **Resolution**: singularity strategy (those the arm takes), QP backend (those installed).
- **Trajectory**: record, reverse (seconds), save CSV / NPZ (written on the console's machine
  and offered to the page as a download), load (upload a record: it is replayed from its
  start), home.
- **Keyboard** (commands with hotkeys; the page must have focus outside a text field): I/K
  +-x, J/L +-y, U/O +-z, and with Shift the rotations about the same axes (a jog at half the
  slider's range while a key is held), space STOP. (viser moves the camera with W, A, S, D,
  Q, E and the arrow keys: the jogs keep clear of them.)
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

from rrc_pin.console import commands as cmd
from rrc_pin.console.commands import AXES, FRAMES
from rrc_pin.console.intake import TokenBucket
from rrc_pin.console.loop import ControlLoop
from rrc_pin.console.snapshot import Snapshot
from rrc_pin.errors import InvalidInput, RrcPinError

KEYS: dict[str, tuple[int, int]] = {
    "I": (0, 1), "K": (0, -1), "J": (1, 1), "L": (1, -1), "U": (2, 1), "O": (2, -1),
}  # fmt: skip
"""Hotkey -> (linear axis, sign) of its jog; with Shift, the rotation about that axis."""
HOLD_HZ = 20.0
"""Heartbeats per second of the hold-to-move button."""
REBUILDS_PER_SECOND = 4.0
"""Most backend, hand, home and load commands a second, all pages together (each costs the
loop about a millisecond: a new resolver or controller)."""
REBUILDS = (cmd.Backend, cmd.Hand, cmd.Home, cmd.Load)

Callback = Callable[[Any], Awaitable[None]]


def _now(action: Callable[[], None]) -> Callback:
    """A callback doing ``action`` on viser's event loop, as its message arrives."""

    async def callback(event: Any) -> None:
        action()

    return callback


def _id(handle: Any) -> str | None:
    """A viser element's id as its messages carry it (viser keeps it private), or None."""
    return getattr(getattr(handle, "_impl", None), "uuid", None)


def _jog(axis: int, sign: int) -> Callable[[Any], cmd.Jog]:
    """The command of a jog key."""
    return lambda event: cmd.Jog(axis, sign)


class Panel:
    """The console's controls for one loop.

    Args:
        server: A ``viser.ViserServer``.
        loop: The control loop (its mailbox, hands, strategies, backends and settings).
        out: Folder for saved records.

    Attributes:
        sliders: The six velocity sliders, [vx, vy, vz, wx, wy, wz].
        joints, status: The readouts' HTML blocks (written by the view).
        errors: Refused page events (bad values) so far.
        stop_button: The STOP button.
    """

    def __init__(self, server: Any, loop: ControlLoop, out: Path) -> None:
        self.server = server
        self.loop = loop
        self.mailbox = loop.mailbox
        self.out = out
        self.errors = 0
        self._stops = loop.operator.stops
        self._rebuilds = TokenBucket(REBUILDS_PER_SECOND, 2, time.monotonic())
        gui = server.gui
        gui.configure_theme(control_width="large", dark_mode=False, show_logo=False)
        self._command_folder(gui, loop)
        with gui.add_folder("Readouts"):
            self.joints = gui.add_html("")
            self.status = gui.add_html("")
        self._resolution_folder(gui, loop)
        self._trajectory_folder(gui)
        self._jog_keys(gui)
        space = gui.add_command("STOP", hotkey="space")
        space.on_trigger(_now(self.stop))
        # Taken as their message arrives (urgent): viser keeps its elements' ids private, and
        # without one of them that control's message goes the way of the others.
        self._urgent = {uuid: how for uuid, how in (
            (_id(self.stop_button), ("GuiUpdateMessage", True, self.stop)),
            (_id(space), ("CommandTriggerMessage", None, self.stop)),
            (_id(self.latch), ("GuiUpdateMessage", False, self._let_go)),
        ) if uuid is not None}  # fmt: skip

    def _command_folder(self, gui: Any, loop: ControlLoop) -> None:
        """The command's controls: the hand, the frame, the sliders, the deadman, STOP, the
        speed override, the target and a device's pose stream.
        """  # noqa: D205
        s = loop.operator.settings
        with gui.add_folder("Command"):
            self.hand = None
            if len(loop.hands) > 1:
                self.hand = gui.add_dropdown("hand", loop.hands, initial_value=loop.hands[0])
                self.hand.on_update(self._guard(lambda e: cmd.Hand(self.hand.value)))  # type: ignore[union-attr]
            self.frame = gui.add_dropdown("frame", FRAMES, initial_value="local",
                                          hint="local: hand axes; world_aligned: base axes")
            self.sliders = [
                gui.add_slider(f"{axis} [{'m/s' if i < 3 else 'rad/s'}]",
                               min=-(s.max_linear if i < 3 else s.max_angular),
                               max=s.max_linear if i < 3 else s.max_angular,
                               step=0.005 if i < 3 else 0.02, initial_value=0.0)
                for i, axis in enumerate(AXES)
            ]  # fmt: skip
            for slider in self.sliders:
                slider.on_update(self._guard(self._velocity, reset=self._reset_sliders))
            self.frame.on_update(self._guard(self._velocity, reset=self._reset_sliders))
            zero = gui.add_button("zero the sliders")
            zero.on_click(_now(self._zero))
            self.hold = gui.add_button("hold to move (deadman)", color="green")
            self.hold.on_hold(self._guard(lambda e: cmd.Hold()), callback_hz=HOLD_HZ)
            self.latch = gui.add_checkbox("deadman latched", False,
                                          hint="move without holding; released when the last "
                                               "page closes and at STOP")  # fmt: skip
            self.latch.on_update(self._guard(lambda e: cmd.Latch(bool(self.latch.value))))
            self.stop_button = gui.add_button("STOP (space)", color="red")
            self.stop_button.on_click(_now(self.stop))
            self.speed = gui.add_slider("speed override [%]", min=0, max=100, step=5,
                                        initial_value=100)  # fmt: skip
            self.speed.on_update(self._guard(lambda e: cmd.Speed(self.speed.value / 100.0),
                                             reset=self._reset_speed))  # fmt: skip
            drop = gui.add_button("drop the target")
            drop.on_click(self._guard(lambda e: cmd.Target(None)))
            self.device = gui.add_text("device pose", "", hint="a device's pose stream: x y z "
                                       "qw qx qy qz [clutch 0/1] in metres, from a page or a "
                                       "program (empty: the stream ends)")  # fmt: skip
            self.device.on_update(self._guard(lambda e: cmd.pose_from_page(self.device.value)))

    def _resolution_folder(self, gui: Any, loop: ControlLoop) -> None:
        """The strategy (an arm's controller) and the QP backend."""
        with gui.add_folder("Resolution", expand_by_default=False):
            self.strategy = None
            if loop.strategies:  # (a cell's controller takes none)
                self.strategy = gui.add_dropdown("strategy", loop.strategies,
                                                 initial_value=loop.snapshot.strategy)  # fmt: skip
                self.strategy.on_update(self._guard(lambda e: cmd.Strategy(cmd.one_of(
                    self.strategy.value, "strategy", loop.strategies))))  # type: ignore[union-attr]
            self.backend = gui.add_dropdown("backend", loop.backends,
                                            initial_value=loop.snapshot.backend)  # fmt: skip
            self.backend.on_update(self._guard(lambda e: cmd.Backend(
                cmd.one_of(self.backend.value, "backend", loop.backends))))

    def _trajectory_folder(self, gui: Any) -> None:
        """Recording, reversing, saving and loading the trajectory, and going home."""
        with gui.add_folder("Trajectory", expand_by_default=False):
            self.record = gui.add_checkbox("record", False)
            self.record.on_update(self._guard(lambda e: cmd.Record(bool(self.record.value))))
            self.seconds = gui.add_number("reverse [s]", 1.0, min=0.01, max=3600.0, step=0.01)
            reverse = gui.add_button("reverse")
            reverse.on_click(self._guard(lambda e: cmd.Reverse(self.seconds.value)))
            for suffix in (".csv", ".npz"):
                button = gui.add_button(f"save {suffix[1:].upper()}")
                button.on_click(self._guard(self._saver(suffix)))
            self.upload = gui.add_upload_button("load a record", mime_type=".csv,.npz")
            self.upload.on_upload(self._guard(self._load))
            home = gui.add_button("home")
            home.on_click(self._guard(lambda e: cmd.Home()))

    def _jog_keys(self, gui: Any) -> None:
        """The keyboard's jog commands (:data:`KEYS`; shift: the rotations)."""
        for key, (axis, sign) in KEYS.items():
            for shift in (False, True):
                which = axis + 3 if shift else axis
                label = f"jog {'+' if sign > 0 else '-'}{AXES[which]}"
                command = gui.add_command(label, hotkey=key,
                                          modifier="shift" if shift else None)  # fmt: skip
                command.on_trigger(self._guard(_jog(which, sign)))

    # -- events -------------------------------------------------------------------------------

    def urgent(self, message: Any) -> Callable[[], None] | None:
        """What to do at once for a page's message that stops or releases the arm, or None.

        Those messages: the STOP button, the space key, the latch unchecked. The guard calls
        it for every message as it arrives, ahead of the page's budget and of viser's dispatch
        (:class:`~rrc_pin.console.guard.Guard`), which never sees the message: the action does
        what the control's callback would.
        """
        how = self._urgent.get(str(getattr(message, "uuid", "")))
        if how is None or type(message).__name__ != how[0]:
            return None
        if how[1] is not None and getattr(message, "updates", None) != {"value": how[1]}:
            return None
        return how[2]

    def _let_go(self) -> None:
        """The latch unchecked on a page: on every page, and to the loop."""
        self._put(self.latch, False)
        self.mailbox.post(cmd.Latch(False))

    def _guard(
        self, make: Callable[[Any], cmd.Command | None], reset: Callable[[], None] | None = None
    ) -> Callback:
        """A callback posting ``make(event)``; a refused value is told to the page instead."""

        async def callback(event: Any) -> None:
            if getattr(event, "client", None) is None:
                return  # a value the server set (viser calls back for those too): no request
            try:
                command = make(event)
                if isinstance(command, REBUILDS) and not self._rebuilds.take(time.monotonic()):
                    raise InvalidInput("command", f"at most {REBUILDS_PER_SECOND:g} backend, hand,"
                                       " home or load commands a second: try again")  # fmt: skip
            except (RrcPinError, TypeError, ValueError, OverflowError) as exc:
                self.errors += 1
                self._tell(event, " ".join(str(exc).split()))
                if reset is not None:
                    reset()
                return
            if command is not None:
                self.mailbox.post(command)

        return callback

    def _velocity(self, event: Any) -> cmd.Velocity:
        s = self.loop.operator.settings
        return cmd.velocity_from_page([h.value for h in self.sliders], self.frame.value,
                                      s.max_linear, s.max_angular)  # fmt: skip

    def _reset_sliders(self) -> None:
        """Put back the sliders and frame the loop has (after a refused value)."""
        twist = self.loop.operator.velocity
        for slider, value in zip(self.sliders, twist, strict=True):
            self._put(slider, float(value))
        self._put(self.frame, self.loop.operator.frame)

    def _reset_speed(self) -> None:
        """Put back the speed override the loop has (after a refused value)."""
        self._put(self.speed, round(100 * self.loop.ctl.speed))

    def _zero(self) -> None:
        for slider in self.sliders:
            self._put(slider, 0.0)
        self.mailbox.post(cmd.Velocity(self.loop.operator.velocity * 0.0,
                                       self.frame.value))  # fmt: skip

    def stop(self) -> None:
        """STOP: post it, and put the sliders at zero and the latch off.

        The stop is counted as seen here: :meth:`sync` releases the controls again only for
        stops the page did not ask for (an operator who latches again right after STOP is not
        unlatched when the loop's count catches up).
        """
        self._stops += 1
        self.mailbox.post(cmd.Stop())
        self._release_controls()

    def _release_controls(self) -> None:
        for slider in self.sliders:
            self._put(slider, 0.0)
        self._put(self.latch, False)

    def _saver(self, suffix: str) -> Callable[[Any], cmd.Save]:
        def make(event: Any) -> cmd.Save:
            stamp = time.strftime("%Y%m%d-%H%M%S")
            path = self.out / f"rrc-pin-{self.loop.robot.name}-{stamp}{suffix}"
            client = event.client

            def reply(written: Path | None, error: str) -> None:
                if client is None:
                    return
                if written is None:
                    client.add_notification("save failed", error, color="red",
                                            auto_close_seconds=8.0)  # fmt: skip
                    return
                client.add_notification("saved", str(written), auto_close_seconds=5.0)
                client.send_file_download(written.name, written.read_bytes())

            return cmd.Save(str(path), reply)

        return make

    def _load(self, event: Any) -> cmd.Load:
        upload = self.upload.value
        name = Path(str(upload.name)).name
        if not name.endswith((".csv", ".npz")):
            raise InvalidInput("load", f"expected a .csv or .npz record, got {name!r}")
        folder = Path(tempfile.mkdtemp(prefix="rrc-pin-console-"))
        path = folder / name
        path.write_bytes(upload.content)
        return cmd.Load(str(path))

    def _tell(self, event: Any, text: str) -> None:
        client = getattr(event, "client", None)
        if client is not None:
            client.add_notification("refused", text, color="red", auto_close_seconds=6.0)

    def _put(self, handle: Any, value: object) -> None:
        """Set a control's value from the server (its callback skips it: no page sent it)."""
        if handle.value != value:
            handle.value = value

    # -- the loop's state back on the controls -------------------------------------------------

    def sync(self, snapshot: Snapshot) -> None:
        """Follow the loop's state: after any stop the sliders read zero and the latch off."""
        if snapshot.stops > self._stops:
            self._stops = snapshot.stops
            self._release_controls()
