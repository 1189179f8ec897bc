"""What the page may ask of the control loop: one small record per request, checked when made.

The panel turns every widget event into one of these records and posts it to the
:class:`~rrc_pin.console.mailbox.Mailbox`; the loop applies them at the start of a tick. Every
record validates its fields in ``__post_init__`` and raises :class:`~rrc_pin.InvalidInput`
naming the field, so a bad value from the page (NaN, a string, a number out of range) is
refused where it arrives and never reaches the loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_array, as_vector
from rrc_pin.solvers.closed_form.quaternion import matrix_from_quaternion

Array = npt.NDArray[np.float64]
Frame = Literal["local", "world_aligned"]
FRAMES: tuple[Frame, ...] = ("local", "world_aligned")
AXES = ("vx", "vy", "vz", "wx", "wy", "wz")


def bounded(value: object, name: str, lower: float, upper: float) -> float:
    """``value`` as a finite float in ``[lower, upper]``.

    Raises:
        InvalidInput: Naming ``name``: not a real number (booleans and strings refused), not
            finite, or outside the interval.
    """
    real = isinstance(value, (int, float, np.integer, np.floating))
    if isinstance(value, (bool, np.bool_)) or not real:
        raise InvalidInput(name, f"expected a number in [{lower:g}, {upper:g}], got {value!r}")
    out = float(value)  # type: ignore[arg-type]  # a real number, checked above
    if not (math.isfinite(out) and lower <= out <= upper):
        raise InvalidInput(name, f"expected a number in [{lower:g}, {upper:g}], got {out}")
    return out


def one_of(value: object, name: str, choices: tuple[str, ...]) -> str:
    """``value`` if it is one of ``choices``.

    Raises:
        InvalidInput: Naming ``name`` and listing the choices.
    """
    if not isinstance(value, str) or value not in choices:
        raise InvalidInput(name, f"expected one of {', '.join(choices)}, got {value!r}")
    return value


@dataclass(frozen=True)
class Velocity:
    """The sliders' twist: held while the deadman is, until the next one.

    Attributes:
        twist: [v; w] (6,) [m/s, rad/s] of the commanded tool frame, in ``frame``; each
            component within the console's ``max_linear`` / ``max_angular`` (checked by the
            panel, which knows them; here: finite).
        frame: ``"local"`` (hand axes, Barker eq. (20)) or ``"world_aligned"`` (base axes).
    """

    twist: Array
    frame: Frame = "local"

    def __post_init__(self) -> None:
        twist = as_vector(self.twist, "twist", 6).copy()
        twist.flags.writeable = False
        object.__setattr__(self, "twist", twist)
        one_of(self.frame, "frame", FRAMES)


@dataclass(frozen=True)
class Jog:
    """A key press: ``sign`` times the jog speed along one axis, for a short while.

    Attributes:
        axis: Index into [vx, vy, vz, wx, wy, wz], 0 to 5.
        sign: +1 or -1.
    """

    axis: int
    sign: int

    def __post_init__(self) -> None:
        if isinstance(self.axis, bool) or not isinstance(self.axis, int) or not 0 <= self.axis < 6:
            raise InvalidInput("axis", f"expected an axis index 0 to 5, got {self.axis!r}")
        if self.sign not in (-1, 1) or isinstance(self.sign, bool):
            raise InvalidInput("sign", f"expected +1 or -1, got {self.sign!r}")


@dataclass(frozen=True)
class Hold:
    """The deadman button is held (sent repeatedly while it is: a heartbeat)."""


@dataclass(frozen=True)
class Latch:
    """The deadman latched on or off (a checkbox; released when the last page closes).

    Attributes:
        on: Whether motion is enabled without holding the button.
    """

    on: bool

    def __post_init__(self) -> None:
        if not isinstance(self.on, bool):
            raise InvalidInput("on", f"expected True or False, got {self.on!r}")


@dataclass(frozen=True)
class Stop:
    """Stop now: zero twist, deadman released, target and jogs dropped, replay ended."""


@dataclass(frozen=True)
class Speed:
    """The speed override (a teach pendant's percentage).

    Attributes:
        value: In [0, 1].
    """

    value: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", bounded(self.value, "speed", 0.0, 1.0))


@dataclass(frozen=True)
class Strategy:
    """Switch the singularity strategy (a name of ``rrc_pin.control.STRATEGIES``).

    Attributes:
        name: The strategy's name; the loop refuses one the arm cannot take.
    """

    name: str

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInput("strategy", f"expected a strategy name, got {self.name!r}")


@dataclass(frozen=True)
class Backend:
    """Switch the resolver's QP backend (a name of ``installed_backends()``).

    Attributes:
        name: The backend's name; the loop refuses one that is not installed.
    """

    name: str

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInput("backend", f"expected a backend name, got {self.name!r}")


@dataclass(frozen=True)
class Hand:
    """Which tool frame the twist commands (robots with several).

    Attributes:
        frame: A tool frame of the robot; the loop refuses any other.
    """

    frame: str

    def __post_init__(self) -> None:
        if not isinstance(self.frame, str) or not self.frame:
            raise InvalidInput("hand", f"expected a tool frame name, got {self.frame!r}")


@dataclass(frozen=True)
class Target:
    """Servo the hand to a pose (the gizmo), or stop servoing (``pose`` None).

    Attributes:
        pose: (4, 4) rigid transform of the wanted tool pose in the base frame [m], or None.
    """

    pose: Array | None = None

    def __post_init__(self) -> None:
        if self.pose is not None:
            object.__setattr__(self, "pose", _rigid(self.pose))


@dataclass(frozen=True)
class Pose:
    """A device's pose for the commanded hand's stream (a VR controller, a tracker, a master).

    The first sample opens the hand's stream anchored where the hand is
    (``Controller.stream``); each moves the hand's target by the device's motion since, at the
    loop's tick; ``pose`` None ends the stream.

    Attributes:
        pose: The device's pose (4, 4) in its own world [m] (a rigid transform), or None.
        clutch: Whether the device's clutch is pressed: the hand holds while the device moves,
            and is re-anchored on release.
    """

    pose: Array | None = None
    clutch: bool = False

    def __post_init__(self) -> None:
        if self.pose is not None:
            object.__setattr__(self, "pose", _rigid(self.pose))
        if not isinstance(self.clutch, bool):
            raise InvalidInput("clutch", f"expected True or False, got {self.clutch!r}")


def _rigid(value: object) -> Array:
    """``value`` as a read-only rigid transform (4, 4).

    Raises:
        InvalidInput: Naming ``pose``: not a finite (4, 4) rigid transform.
    """
    pose: Array = np.array(as_array(value, "pose", (4, 4)), dtype=np.float64)  # type: ignore[arg-type, unused-ignore]
    R = pose[:3, :3]
    if not (np.allclose(R @ R.T, np.eye(3), atol=1e-6) and np.allclose(pose[3], [0, 0, 0, 1])
            and np.linalg.det(R) > 0.0):  # fmt: skip
        raise InvalidInput("pose", "expected a rigid transform (4, 4)")
    pose.flags.writeable = False
    return pose


@dataclass(frozen=True)
class Record:
    """Start (clear the log and keep every tick) or stop (forget the record) recording.

    Attributes:
        on: Whether to record.
    """

    on: bool

    def __post_init__(self) -> None:
        if not isinstance(self.on, bool):
            raise InvalidInput("on", f"expected True or False, got {self.on!r}")


@dataclass(frozen=True)
class Reverse:
    """Retrace the last ``seconds`` of the record (``Controller.reverse``).

    Attributes:
        seconds: Length [s], > 0; the loop refuses more than is recorded.
    """

    seconds: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "seconds", bounded(self.seconds, "seconds", 1e-9, 3600.0))


@dataclass(frozen=True)
class Save:
    """Write the record to a file (``TrajectoryLog.save``: ``.csv`` or ``.npz``).

    Attributes:
        path: Where, on the console's machine; its suffix picks the format.
        reply: Called from a worker thread with the path written, or None and the error's
            message, so that the page can offer the file or say why not; or None.
    """

    path: str
    reply: Callable[[Path | None, str], None] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.path, str) or not self.path.endswith((".csv", ".npz")):
            raise InvalidInput("path", f"expected a .csv or .npz file name, got {self.path!r}")


@dataclass(frozen=True)
class Load:
    """Read a trajectory (``TrajectoryLog.load``) and replay its commands from its start.

    Attributes:
        path: A ``.csv`` or ``.npz`` file written by ``TrajectoryLog.save``.
    """

    path: str

    def __post_init__(self) -> None:
        if not isinstance(self.path, str) or not self.path.endswith((".csv", ".npz")):
            raise InvalidInput("path", f"expected a .csv or .npz file name, got {self.path!r}")


@dataclass(frozen=True)
class Home:
    """Put the arm back at its start configuration (everything else stopped)."""


@dataclass(frozen=True)
class Released:
    """The last page closed: release the deadman as :class:`Stop` does, but say why."""


Command = (
    Velocity | Jog | Hold | Latch | Stop | Speed | Strategy | Backend | Hand | Target | Pose
    | Record | Reverse | Save | Load | Home | Released
)
"""Every request the loop takes."""


def velocity_from_page(
    values: list[object] | tuple[object, ...], frame: object, max_linear: float,
    max_angular: float,
) -> Velocity:  # fmt: skip
    """A :class:`Velocity` from six slider values, each checked against its range.

    Args:
        values: [vx, vy, vz, wx, wy, wz] as the page sent them [m/s, rad/s].
        frame: ``"local"`` or ``"world_aligned"``.
        max_linear: Largest |v| component [m/s].
        max_angular: Largest |w| component [rad/s].

    Raises:
        InvalidInput: Naming the component (``vx``...) or ``frame``.
    """
    if not isinstance(values, (list, tuple)) or len(values) != 6:
        raise InvalidInput("twist", f"expected six values, got {values!r}")
    twist = [
        bounded(v, AXES[i], -(max_linear if i < 3 else max_angular),
                max_linear if i < 3 else max_angular)
        for i, v in enumerate(values)
    ]  # fmt: skip
    return Velocity(np.array(twist), one_of(frame, "frame", FRAMES))  # type: ignore[arg-type]


def pose_from_page(text: object) -> Pose:
    """A :class:`Pose` from the page's device field: ``"x y z qw qx qy qz [clutch]"``.

    The position [m] and the orientation's unit quaternion (scalar first; one within 1e-3 of
    unit length is normalised: a device's single-precision floats), then 1 or 0 for the
    clutch (default 0); an empty text ends the stream.

    Raises:
        InvalidInput: Naming ``pose`` (not seven or eight numbers, not finite, the clutch not
            0 or 1) or ``quaternion`` (not of unit length).
    """
    if not isinstance(text, str):
        raise InvalidInput("pose", f"expected the device's pose as text, got {text!r}")
    if not text.strip():
        return Pose(None)
    try:
        values = [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise InvalidInput("pose", f"expected numbers: x y z qw qx qy qz [clutch], got {text!r}") \
            from None
    if len(values) not in (7, 8) or not all(math.isfinite(v) for v in values):
        raise InvalidInput("pose", f"expected seven or eight finite numbers, got {text!r}")
    if len(values) == 8 and values[7] not in (0.0, 1.0):
        raise InvalidInput("pose", f"expected the clutch 0 or 1, got {values[7]}")
    quaternion = np.array(values[3:7])
    size = float(np.linalg.norm(quaternion))
    if abs(size - 1.0) > 1e-3:
        raise InvalidInput("quaternion", f"expected a unit quaternion, got |q| = {size:.6g}")
    pose = np.eye(4)
    pose[:3, :3] = matrix_from_quaternion(quaternion)  # (normalised there)
    pose[:3, 3] = values[:3]
    return Pose(pose, len(values) == 8 and values[7] == 1.0)
