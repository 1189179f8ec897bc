r"""JerkLimiter: an optional stage after the resolver bounding each joint's acceleration and jerk.

The resolver answers rates inside the step's box (velocity, position over the step); from
one tick to the next they may jump. This stage follows them with each joint's rate change
per tick bounded,

.. math:: |\dot q_k - \dot q_{k-1}| \le a_{max}\,\Delta t, \qquad
    |\dot q_k - 2\dot q_{k-1} + \dot q_{k-2}| \le j_{max}\,\Delta t^2,

choosing per joint the acceleration that reaches the commanded rate soonest without
overshoot: :math:`a^*` solves :math:`a\,\Delta t + a|a|/(2 j_{max}) = \dot q_{cmd} -
\dot q_{k-1}` (the rate gained this tick plus while the acceleration ramps back to zero),
clipped into the jerk's and the acceleration's intervals (a time-optimal velocity filter,
as Ruckig's velocity interface, sampled).

**The box wins.** Its output is then put inside the resolver's box of the tick (the same
:class:`~rrc_pin.solvers.tick.problem.Box`: velocity and one-step position limits hold
exactly, as they did for the resolver's answer); where that clip changes the rates the
acceleration or jerk bound is broken for safety and the tick says so
(:attr:`Smoothed.clipped`). To make that rare, given the joints' position limits and
positions, a joint is slowed before a limit to a rate from which it can stop in the distance
:math:`d` left (:math:`v^2/(2a_b) + v\,(a_{max}/j_{max} + 2\Delta t) \le d`, :math:`a_b` half
of :math:`a_{max}`): the resolver's box shows a position limit only within one step of it.

**STOP.** :meth:`JerkLimiter.stop` commands zero rates: from rates :math:`v` and
accelerations within the bounds the joints stand still (below 1e-9) within
:meth:`JerkLimiter.stop_time` :math:`= \max|v|/a_{max} + 3 a_{max}/j_{max} + 2\Delta t`.

In a controller: ``Controller(..., smoothing=SmoothingOptions(acceleration, jerk))`` (and
``CellController``) runs the stage after its resolver every tick (:attr:`Loop.smoothing
<rrc_pin.control.loop.Loop.smoothing>`, the tick's report :attr:`Loop.smoothed
<rrc_pin.control.loop.Loop.smoothed>`). By hand: after ``r = resolver.solve(q, ...,
qdot_prev=stage.rates)``, ``out = stage.step(r.qdot, r.problem.box,
robot.dof_positions(q))`` and integrate ``out.qdot``; passing the stage's rates as
``qdot_prev`` keeps the resolver's own acceleration limits (if any) relative to what the
joints do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_vector, finite_number, flag, integer, real_array
from rrc_pin.solvers.smoothing_kernels import braked, jerk_step
from rrc_pin.solvers.tick.problem import Box

if TYPE_CHECKING:
    from rrc_pin.robot import Robot

MAX_JOINTS = 100_000
"""The most joints a limiter takes (``n``): more than any robot has."""

Array = npt.NDArray[np.float64]

STILL = 1e-9
"""[rad/s or m/s] A rate below this stands still (STOP's criterion)."""

BRAKE = 0.5
"""The fraction of a_max the braking before a position limit plans with: the rest is the
filter's reserve to follow its own target down (planned with all of it, the rates trailed
the braking curve and the box won for two ticks in one session of 40)."""


SAME = 1e-6
"""[rad/s or m/s] A rate within this of the resolver's is the resolver's (:attr:`Smoothed.changed`):
the filter's own remainder when it follows a rate that changes by e a tick is about
e^2 / (2 j_max dt^2), 1e-7 for e = 1e-4 at the default bounds."""


class Smoothed(NamedTuple):
    """One tick of the stage.

    Attributes:
        qdot: The rates to integrate (n,) [rad/s or m/s], inside the tick's box.
        acceleration: Their change per tick over dt (n,) [rad/s^2 or m/s^2].
        clipped: Mask (n,) of the joints whose smoothed rate the box moved (their bounds were
            broken for the box's sake).
        changed: Mask (n,) of the joints whose rate differs by more than :data:`SAME` from the
            one the stage was given (the resolver's): where the stage changed the rates.
    """

    qdot: Array
    acceleration: Array
    clipped: npt.NDArray[np.bool_]
    changed: npt.NDArray[np.bool_]


@dataclass(frozen=True)
class SmoothingOptions:
    """The bounds of a controller's jerk stage (``Controller(..., smoothing=...)``).

    Attributes:
        acceleration: a_max > 0 [rad/s^2 or m/s^2], a scalar or one per rate (nv,).
        jerk: j_max > 0 [rad/s^3 or m/s^3], a scalar or one per rate (nv,).

    Raises:
        InvalidInput: A bound that is not finite and > 0 (named); its length is checked
            against the robot's rates when a controller builds its stage.
    """

    acceleration: float | npt.ArrayLike = 20.0
    jerk: float | npt.ArrayLike = 500.0

    def __post_init__(self) -> None:
        for name in ("acceleration", "jerk"):
            value = getattr(self, name)
            _positive(value, name, int(np.size(real_array(value, name))))

    def limiter(self, robot: Robot, dt: float, margin: float = 0.0) -> JerkLimiter:
        """The stage for ``robot``'s rates at period ``dt`` [s], braking ``margin`` [rad or m]
        before its position limits (the resolver's ``JointLimits.margin``).

        Raises:
            InvalidInput: A bound of another length than the robot's rates, naming it.
        """  # noqa: D205
        return JerkLimiter(robot.nv, dt, self.acceleration, self.jerk, lower=robot.dof_lower,
                           upper=robot.dof_upper, margin=margin)  # fmt: skip


class JerkLimiter:
    """Acceleration- and jerk-bounded rates after the resolver (module docstring).

    Args:
        n: Number of joint rates.
        dt: Control period [s] > 0.
        acceleration: a_max > 0 [rad/s^2 or m/s^2], a scalar or (n,).
        jerk: j_max > 0 [rad/s^3 or m/s^3], a scalar or (n,).
        lower: The rates' lower position limits (n,) [rad or m] (``robot.dof_lower``), or
            None: no braking before them.
        upper: Their upper limits (n,) (``robot.dof_upper``), or None.
        margin: The distance [rad or m] the resolver's ``JointLimits`` keeps from them.

    Attributes:
        rates: The last rates given (n,) (zero at first).

    Raises:
        InvalidInput: A bad n, dt, acceleration or jerk, named.
    """

    def __init__(
        self,
        n: int,
        dt: float,
        acceleration: float | npt.ArrayLike,
        jerk: float | npt.ArrayLike,
        *,
        lower: npt.ArrayLike | None = None,
        upper: npt.ArrayLike | None = None,
        margin: float = 0.0,
    ) -> None:
        self.n = n = integer(n, "n", 1, MAX_JOINTS)
        self.dt = finite_number(dt, "dt", 0.0, inclusive=False)
        self.a_max = _positive(acceleration, "acceleration", n)
        self.j_max = _positive(jerk, "jerk", n)
        if (lower is None) != (upper is None):
            raise InvalidInput("lower", "give both position limits, or neither")
        margin = finite_number(margin, "margin", 0.0)
        self._lower = None if lower is None else _limits(lower, "lower", n) + margin
        self._upper = None if upper is None else _limits(upper, "upper", n) - margin
        self._brake: Array = BRAKE * self.a_max
        if not math.isfinite(2.0 * self.dt):
            raise InvalidInput("dt", f"expected a period [s] whose double is finite, got {dt!r}")
        with np.errstate(over="ignore"):
            self._lead: Array = self.a_max / self.j_max + 2.0 * self.dt
        if not np.isfinite(self._lead).all():
            raise InvalidInput("jerk", f"expected acceleration / jerk [s] finite, got "
                                       f"{acceleration!r} / {jerk!r}")  # fmt: skip
        self.rates: Array = np.zeros(n)
        self._acceleration: Array = np.zeros(n)
        self._stopping = False
        self._compile()

    def _compile(self) -> None:
        """Run the kernels of :meth:`step` once now, on the rates and positions it may be
        given (writable, or read-only as a resolution's): compiled (or loaded from numba's
        cache) before a control loop's first tick.
        """  # noqa: D205
        n = self.n
        fixed = np.zeros(n)
        fixed.flags.writeable = False
        for given in (fixed, np.zeros(n)):
            jerk_step(np.zeros(n), np.zeros(n), given, self.dt, self.a_max, self.j_max,
                      np.empty(n))  # fmt: skip
            if self._lower is not None and self._upper is not None:
                for position in (fixed, np.zeros(n)):
                    braked(given, position, self._lower, self._upper, self._brake, self._lead,
                           np.empty(n))  # fmt: skip

    def reset(self, rates: npt.ArrayLike | None = None) -> None:
        """Start again from ``rates`` (n,) at rest in acceleration (default zero); no STOP."""
        self.rates = np.zeros(self.n) if rates is None else as_vector(rates, "rates", self.n)
        self._acceleration = np.zeros(self.n)
        self._stopping = False

    def stop(self, stopping: bool = True) -> None:
        """STOP (zero rates commanded from now on, whatever :meth:`step` is given), or resume."""
        self._stopping = flag(stopping, "stopping")

    def stop_time(self) -> float:
        """[s] Within this time of :meth:`stop` every rate is below :data:`STILL`."""
        return float(np.max(np.abs(self.rates) / self.a_max + 3.0 * self.a_max / self.j_max)
                     + 2.0 * self.dt)  # fmt: skip

    def step(
        self, qdot: npt.ArrayLike, box: Box, position: npt.ArrayLike | None = None
    ) -> Smoothed:
        """The smoothed rates of this tick for the resolver's ``qdot`` (n,) within ``box``.

        Args:
            qdot: The resolver's rates (n,) [rad/s or m/s].
            box: The tick's box (``resolution.problem.box``).
            position: Each rate's position (n,) [rad or m] (``robot.dof_positions(q)``), for
                the braking before the position limits given at construction; or None.

        Raises:
            InvalidInput: ``qdot`` or ``position`` not a finite (n,) vector, ``box`` not a Box
                of n joints; nothing changes.
        """
        command = as_vector(qdot, "qdot", self.n)
        if not isinstance(box, Box) or box.lb.shape != (self.n,):
            raise InvalidInput("box", f"expected the tick's Box of {self.n} joints, got {box!r}")
        where = None if position is None else as_vector(position, "position", self.n)
        v = self.rates
        target = np.zeros(self.n) if self._stopping else self._braked(command, where)
        smoothed = np.empty(self.n)
        jerk_step(v, self._acceleration, target, self.dt, self.a_max, self.j_max, smoothed)
        out = box.clip(smoothed)
        clipped = out != smoothed
        change = (out - v) / self.dt
        self.rates, self._acceleration = out, change
        return Smoothed(out.copy(), change, clipped, np.abs(out - command) > SAME)

    def _braked(self, command: Array, position: Array | None) -> Array:
        """``command`` slowed where a position limit is near (module docstring)."""
        if position is None or self._lower is None or self._upper is None:
            return command
        out: Array = np.empty(self.n)
        braked(command, position, self._lower, self._upper, self._brake, self._lead, out)
        return out


def _limits(value: npt.ArrayLike, name: str, n: int) -> Array:
    x: Array = np.array(real_array(value, name), dtype=np.float64)
    if x.shape != (n,) or np.isnan(x).any():
        raise InvalidInput(name, f"expected ({n},) position limits, got {value!r}")
    return x


def _positive(value: float | npt.ArrayLike, name: str, n: int) -> Array:
    given = real_array(value, name)
    if given.shape not in ((), (1,), (n,)):
        raise InvalidInput(name, f"expected a number > 0 or ({n},) of them, got {value!r}")
    x: Array = np.array(np.broadcast_to(given, (n,)), dtype=np.float64)
    if not np.isfinite(x).all() or (x <= 0.0).any():
        raise InvalidInput(name, f"expected a number > 0 or ({n},) of them, got {value!r}")
    x.flags.writeable = False
    return x
