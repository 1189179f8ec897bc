r"""PoseStream: a device's stream of poses turned into a bounded twist of one hand each tick.

A tracker (a VR controller, motion capture, a master arm) sends a pose of the device at its
own rate (:meth:`PoseStream.push`); the control loop asks a twist at its own
(:meth:`PoseStream.twist`). Between them, per hand:

- **the mapping**: the device's motion since its anchor moves the hand from its anchor, in
  the robot's base axes (``device_axes`` turns the device's world into them, ``scale``
  scales the translation):

  .. math:: p^* = p_h + s\,R_a (p_d - p_{d0}), \qquad
      R^* = R_a (R_d R_{d0}^T) R_a^T\, R_h,

  with :math:`(p_{d0}, R_{d0})` the device's pose and :math:`(p_h, R_h)` the hand's target
  when the stream was anchored (a rotation of the device turns the hand about the same base
  axes, in place);
- **the workspace**: :math:`p^*` clamped into a box of the base frame;
- **outliers**: a sample farther from the previous one than ``jump`` plus what the device
  can move in the time between them (``device_speed``, ``device_rate``) is a lost tracker:
  it is rejected and the stream is ``lost``, the hand holds its target. A sample back
  within ``jump`` of the last accepted one ends it (a glitch); else, after ``settle``
  consistent samples, the stream re-anchors on them (the tracker's frame moved: as a clutch
  release, no step);
- **dropouts**: no sample for longer than ``timeout``: the twist fades to zero with the
  time constant ``decay`` (the hand stops smoothly where it was going); a sample after it is
  judged with the time elapsed, and tracking resumes;
- **the clutch**: while pressed (:meth:`clutch`), the hand holds its target while the
  device moves; on release the device's anchor is its pose then and the hand's is its
  target then, so the target, and the twist, are continuous;
- **the twist**: toward the target, :math:`\nu = k\,[p^* - p;\ \log(R^* R^T)]`, its linear
  part clamped to ``linear_speed`` and its angular part to ``angular_speed`` (each scaled
  along itself), in base axes: the command of ``Controller.step(twist, ref="world_aligned")``
  or of a :class:`~rrc_pin.tasks.FrameTask` (``ref="world_aligned"``).

Following a device moving at speed v, the hand lags by about :math:`1/k` seconds (0.1 s at
k = 10), plus up to one device period of sample hold.

In a controller: ``stream = ctl.stream(frame, options)`` (:meth:`Loop.stream
<rrc_pin.control.loop.Loop.stream>`; a :class:`~rrc_pin.cells.CellController`: a command's
name) makes one anchored at the frame's pose and turns it into the frame's twist at every
``ctl.step()``; the device's thread calls :meth:`PoseStream.push` with times on the
controller's clock (``ctl.t``) and :meth:`PoseStream.clutch` (a stream is locked: push and
twist may run in different threads).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_array, finite_number, integer, real_array, rigid_transform

Array = npt.NDArray[np.float64]

State = Literal["idle", "tracking", "clutched", "lost", "dropout"]
"""What the stream does: ``idle`` (no sample yet), ``tracking``, ``clutched`` (the hand
holds while the device moves), ``lost`` (a jump rejected, waiting for consistent samples),
``dropout`` (no sample for longer than the timeout: the twist fades)."""


@dataclass(frozen=True)
class StreamOptions:
    """How a :class:`PoseStream` maps, bounds and judges a device's poses.

    Attributes:
        gain: k > 0 [1/s]: the fraction of the pose error asked per second.
        linear_speed: Largest linear speed asked of the hand [m/s] > 0.
        angular_speed: Largest angular speed asked [rad/s] > 0.
        jump: A sample farther than this [m] from the previous one, beyond what the device
            can move meanwhile, is a lost tracker's; > 0.
        jump_angle: The same for its rotation [rad] > 0.
        device_speed: How fast the device may move [m/s] > 0 (a hand: about 2).
        device_rate: How fast it may turn [rad/s] > 0.
        timeout: No sample for longer than this [s] > 0 is a dropout.
        decay: Time constant [s] > 0 of the twist's fade in a dropout.
        settle: Consistent samples after a jump before the stream re-anchors, >= 1.
        scale: Device translation to hand translation, > 0 (1: one to one).
        device_axes: Rotation (3, 3) from the device's world axes to the robot's base axes.
        lower: The workspace box's lower corner (3,) [m] in the base frame, or None.
        upper: Its upper corner (3,) [m], or None (no box without both).

    Raises:
        InvalidInput: A field that is not a finite number in its range, named.
    """

    gain: float = 10.0
    linear_speed: float = 0.5
    angular_speed: float = 1.5
    jump: float = 0.05
    jump_angle: float = 0.3
    device_speed: float = 2.0
    device_rate: float = 10.0
    timeout: float = 0.05
    decay: float = 0.05
    settle: int = 5
    scale: float = 1.0
    device_axes: npt.ArrayLike | None = None
    lower: npt.ArrayLike | None = None
    upper: npt.ArrayLike | None = None

    def __post_init__(self) -> None:
        for name in ("gain", "linear_speed", "angular_speed", "jump", "jump_angle",
                     "device_speed", "device_rate", "timeout", "decay", "scale"):  # fmt: skip
            finite_number(getattr(self, name), name, 0.0, inclusive=False)
        integer(self.settle, "settle", 1)
        axes = np.eye(4)
        if self.device_axes is not None:
            axes[:3, :3] = as_array(self.device_axes, "device_axes", (3, 3))
            rigid_transform(axes, "device_axes")
        object.__setattr__(self, "device_axes", axes[:3, :3].copy())
        if (self.lower is None) != (self.upper is None):
            raise InvalidInput("lower", "give both corners of the workspace box, or neither")
        if self.lower is not None:
            lo = _vector3(self.lower, "lower")
            hi = _vector3(self.upper, "upper")
            if (lo > hi).any():
                raise InvalidInput("upper", f"expected upper >= lower, got {hi} < {lo}")
            object.__setattr__(self, "lower", lo)
            object.__setattr__(self, "upper", hi)


class PoseStream:
    """One hand's stream of device poses (module docstring).

    Args:
        hand: The hand's pose (4, 4) in the base frame [m] now: its first anchor.
        options: The stream's options (default :class:`StreamOptions()`).

    Attributes:
        state: What the stream does now (:data:`State`).
        rejected: Samples rejected as jumps so far.
        anchors: Times [s] at which it re-anchored (clutch releases, lost tracker settled).

    Raises:
        InvalidInput: ``hand`` not a rigid transform, ``options`` not StreamOptions.
    """

    def __init__(self, hand: npt.ArrayLike, options: StreamOptions | None = None) -> None:
        if options is not None and not isinstance(options, StreamOptions):
            raise InvalidInput("options", f"expected StreamOptions, got {options!r}")
        self.options = StreamOptions() if options is None else options
        self._target = rigid_transform(hand, "hand").copy()
        self._hand_anchor = self._target.copy()
        self._device_anchor: Array | None = None  # set by the first sample
        self._last: tuple[float, Array] | None = None  # the last sample received
        self._accepted: Array | None = None  # the last sample accepted
        self._last_accepted = -math.inf  # its time
        self._settled = 0
        self._pressed = False
        self.state: State = "idle"
        self.rejected = 0
        self.anchors: list[float] = []
        self._lock = threading.Lock()

    @property
    def target(self) -> Array:
        """The hand's target pose (4, 4) in the base frame now (a copy)."""
        with self._lock:
            out: Array = self._target.copy()
            return out

    def push(self, t: float, device: npt.ArrayLike) -> bool:
        """A device sample: its pose (4, 4) in its own world at time ``t`` [s].

        Returns:
            Whether it was accepted (False: a jump, the stream is then ``lost``).

        Raises:
            InvalidInput: ``t`` not finite or earlier than the last sample's, ``device`` not
                a rigid transform; nothing changes.
        """
        pose = rigid_transform(device, "device").copy()  # kept: a caller may reuse its array
        t = finite_number(t, "t")
        with self._lock:
            if self._last is not None and t < self._last[0]:
                raise InvalidInput("t", f"samples come in time order: {t} < {self._last[0]}")
            back = self.state == "lost" and self._back(pose)  # a glitch over
            jumped = not back and self._last is not None and self._is_jump(self._last, t, pose)
            self._last = (t, pose)
            if self._device_anchor is None:
                self._device_anchor = pose
            if jumped:
                self.rejected += 1
                self._settled = 0
                self.state = "lost"
                return False
            if self.state == "lost" and not back:
                self._settled += 1
                if self._settled < self.options.settle:
                    return True
                self._anchor(t, pose)
            self._accepted, self._last_accepted = pose, t
            if self._pressed:
                self.state = "clutched"
                return True
            self.state = "tracking"
            self._target = self._mapped(pose)
            return True

    def clutch(self, pressed: bool, t: float | None = None) -> None:
        """Press (True) or release (False) the hand's clutch.

        Pressed, the hand holds its target while the device moves; released, the device is
        anchored where it is and the hand where its target is (no step).

        Args:
            pressed: The clutch's state now.
            t: The time [s] recorded in :attr:`anchors` for a release (default the last
                sample's).

        Raises:
            InvalidInput: ``pressed`` not a bool.
        """
        if not isinstance(pressed, bool):
            raise InvalidInput("pressed", f"expected True or False, got {pressed!r}")
        with self._lock:
            was, self._pressed = self._pressed, pressed
            if was and not pressed and self._last is not None:
                self._anchor(self._last[0] if t is None else t, self._last[1])
                self.state = "tracking" if self.state == "clutched" else self.state

    def reset(self, hand: npt.ArrayLike) -> None:
        """Hold the hand where it is: its target and anchor ``hand`` (4, 4), base frame [m].

        The device is anchored at its last sample: the next samples move the hand from
        ``hand`` (no step). A controller calls it when it moved the hand otherwise (reverse,
        a configuration set).

        Raises:
            InvalidInput: ``hand`` not a rigid transform; nothing changes.
        """
        pose = rigid_transform(hand, "hand").copy()
        with self._lock:
            self._target, self._hand_anchor = pose, pose.copy()
            if self._last is not None:
                self._device_anchor = self._last[1]

    def target_for(self, device: npt.ArrayLike) -> Array:
        """The hand's target (4, 4) that a device pose would give now (its anchors, its box).

        Raises:
            InvalidInput: ``device`` not a rigid transform.
        """
        pose = rigid_transform(device, "device")
        with self._lock:
            out: Array = self._target.copy() if self._device_anchor is None else self._mapped(pose)
            return out

    def twist(self, t: float, hand: npt.ArrayLike) -> Array:
        """The twist (6,) [m/s, rad/s] toward the target, in base axes, at time ``t`` [s].

        Args:
            t: The control tick's time [s] (the clock of :meth:`push`).
            hand: The hand's pose (4, 4) in the base frame now.

        Raises:
            InvalidInput: ``t`` not finite, ``hand`` not a rigid transform.
        """
        t = finite_number(t, "t")
        pose = rigid_transform(hand, "hand")
        o = self.options
        with self._lock:
            target = self._target
            gap = t - self._last_accepted
            fade = 1.0
            if self.state == "tracking" and gap > o.timeout:
                self.state = "dropout"
            if self.state == "dropout":
                if gap <= o.timeout:
                    self.state = "tracking"
                else:
                    fade = math.exp(-(gap - o.timeout) / o.decay)
        linear = o.gain * (target[:3, 3] - pose[:3, 3])
        angular = o.gain * pin.log3(target[:3, :3] @ pose[:3, :3].T)
        return fade * np.concatenate([_clamped(linear, o.linear_speed),
                                      _clamped(angular, o.angular_speed)])  # fmt: skip

    def _is_jump(self, last: tuple[float, Array], t: float, pose: Array) -> bool:
        o = self.options
        elapsed = t - last[0]
        moved = float(np.linalg.norm(pose[:3, 3] - last[1][:3, 3]))
        turned = float(np.linalg.norm(pin.log3(pose[:3, :3] @ last[1][:3, :3].T)))
        return moved > o.jump + o.device_speed * elapsed or (
            turned > o.jump_angle + o.device_rate * elapsed)  # fmt: skip

    def _back(self, pose: Array) -> bool:
        """Whether a sample is back within ``jump`` of the last accepted one (a glitch over)."""
        last = self._accepted
        if last is None:
            return False
        o = self.options
        return bool(np.linalg.norm(pose[:3, 3] - last[:3, 3]) <= o.jump and np.linalg.norm(
            pin.log3(pose[:3, :3] @ last[:3, :3].T)) <= o.jump_angle)  # fmt: skip

    def _anchor(self, t: float, device: Array) -> None:
        self._device_anchor = device
        self._hand_anchor = self._target.copy()
        self._settled = 0
        self.anchors.append(t)

    def _mapped(self, device: Array) -> Array:
        """The hand's target for a device pose (module docstring), clamped into the box."""
        o = self.options
        Ra = np.asarray(o.device_axes)
        d0 = self._device_anchor
        out: Array = self._hand_anchor.copy()
        if d0 is None:  # no sample yet: the hand where it is
            return out
        out[:3, 3] += o.scale * (Ra @ (device[:3, 3] - d0[:3, 3]))
        out[:3, :3] = Ra @ device[:3, :3] @ d0[:3, :3].T @ Ra.T @ self._hand_anchor[:3, :3]
        if o.lower is not None:
            out[:3, 3] = np.clip(out[:3, 3], o.lower, o.upper)
        return out


def _clamped(v: Array, limit: float) -> Array:
    """``v`` scaled along itself to norm at most ``limit``."""
    norm = float(np.linalg.norm(v))
    out: Array = v if norm <= limit else v * (limit / norm)
    return out


def _vector3(value: npt.ArrayLike | None, name: str) -> Array:
    x: Array = np.array(real_array(np.nan if value is None else value, name),
                        dtype=np.float64).reshape(-1)  # fmt: skip
    if x.shape != (3,) or not np.isfinite(x).all():
        raise InvalidInput(name, f"expected a finite (3,) vector [m], got {value!r}")
    return x
