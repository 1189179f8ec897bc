r"""Closing a cell's closed chains inside the tick's limits: the correction and its bound.

A grip (two hands on one object) and a foot in support close a kinematic chain. The
resolver keeps their rows, :math:`C\dot q = 0`, at every answer: the chains stay closed to
first order. What opens them is the integration, :math:`q_{k+1} = q_k \oplus u\,\Delta t`.
With :math:`e(q)` a chain's pose error to its goal (the grip, the foot's anchor:
:class:`~rrc_pin.limits.contact_limit.Closure`) and :math:`s(u) = D^2p[u, u]` its second
derivative along the step (the frames' classical accelerations at :math:`\ddot q = 0`,
:func:`second_order`),

.. math::

    e_{k+1} = e_k - C u\,\Delta t - \tfrac12 \Delta t^2\, s(u)
              - \tfrac16 \Delta t^3\, D^3p[u, u, u] + O(\Delta t^4).

Left alone (:math:`u = \dot q`, :math:`C\dot q = 0`) every tick adds its second-order
remainder, and the chain drifts (gsfc_dual's grip 1e-5 m a tick at the commanded speeds).
The correction :math:`\delta` (:func:`close`) takes the measured error and the second order
out within the same step, :math:`C\delta = e_k/\Delta t - \tfrac12 \Delta t\, s(\dot q +
\delta)` (two passes: the second order along the corrected step), inside the tick's limits:

.. math::

    lb - \dot q \le \delta \le ub - \dot q,\qquad |\delta_i| \le \rho_i,\qquad
    G\delta \le \max(h - G\dot q, 0),

the box the resolver's rates leave (its velocity and one-step position bounds, exact in
floating point), the trust region :math:`\rho_i` = :data:`TRUST` times each joint's velocity
limit, and the constraint rows (a collision limit's). It is solved as a damped least squares,
in the resolver's metric (a chain's position rows divided by its reach): the chains' rates
first, then, in their null space, the top level's task rates kept (:math:`A\delta = 0`: the
commanded motion unchanged), each a damped least squares pulled toward itself (damping
:data:`DAMPING` of its rows' mean squared singular value, :func:`_damped`: exact to second
order where the rows are well conditioned, bounded near a singular chain); where that leaves
the box, the
point of the box nearest it in the chains' metric, then the top level's (weight
:data:`KEEP`; :func:`~rrc_pin.solvers.tick.slide_kernels.project`). Zero is always feasible:
the correction never moves a joint beyond its limits.

The bound. What is left after a corrected tick is the third-order remainder. Each derivative
of a point on a chain of revolute joints is a cross product with a unit axis, so with
:math:`\ell` the chain's length (both arms' for a grip)

.. math::

    \|e_{k+1}\| \le \tfrac16 \Big(\Delta t \sum_i |u_i|\Big)^3 \ell

(and without :math:`\ell` for the rotation): 2.7 mm with every joint of gsfc_dual at its
velocity limit at 100 Hz, some 3e-5 m at its commanded speeds; measured at most 5e-6 m and
6e-6 rad (docs/api.md, "Cells"), eight times less per halving of the period.
:class:`ClosureBound` is what a cell states and enforces, 2e-5 m and 2e-5 rad: a tick that
starts with a chain open beyond it stops the cell (``grip_lost`` / ``contact_lost``), never a
jump and never a silent drift.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.limits.contact_limit import Closure
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.tick import kernels
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.problem import Box, Rows
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project

Array = npt.NDArray[np.float64]

DAMPING = 1e-4
r"""The correction's damping, relative to its rows' mean squared singular value: a direction of
singular value :math:`\sigma` keeps :math:`\sigma^2(\sigma^2 + 2\mu)/(\sigma^2 + \mu)^2` of
its correction: all but 1e-8 at the mean, at least three quarters at a hundredth of the
largest."""

KEEP = 1e-2
"""Where the box binds, the weight of the top level's rows against the chains' (the chains
first)."""

PASSES = 2
"""Passes of the correction in a tick (:func:`close`)."""

TRUST = 0.1
"""The trust region: the correction moves each joint by at most this fraction of its velocity
limit [rad/s or m/s]."""


@dataclass(frozen=True)
class ClosureBound:
    """How far a closed chain may be open at the start of a tick (module docstring).

    Attributes:
        position: [m] > 0, each chain's position error.
        rotation: [rad] > 0, each chain's rotation error.

    Raises:
        InvalidInput: A field that is not a finite number > 0, named.
    """

    position: float = 2e-5
    rotation: float = 2e-5

    def __post_init__(self) -> None:
        for name in ("position", "rotation"):
            finite_number(getattr(self, name), name, 0.0, inclusive=False)

    def level(self, error: Array) -> float:
        """The largest error of chains ``error`` (6 k,) relative to the bound (<= 1: held)."""
        e = error.reshape(-1, 6)
        if not e.size:
            return 0.0
        position = float(np.max(np.linalg.norm(e[:, :3], axis=1))) / self.position
        rotation = float(np.max(np.linalg.norm(e[:, 3:], axis=1))) / self.rotation
        return max(position, rotation)


class Chains(NamedTuple):
    """A tick's closed chains: their rows and errors, and the frames they close.

    Attributes:
        closure: The chains' rows, errors and units (contacts first, then grips).
        contacts: Frame indices of the contacts.
        grips: ``(a, b)`` frame indices of the grips.
    """

    closure: Closure
    contacts: tuple[int, ...]
    grips: tuple[tuple[int, int], ...]


def close(
    model: pin.Model, data: pin.Data, q: Array, chains: Chains, qdot: Array, top: Array,
    box: Box, rows: Rows | None, dt: float,
) -> tuple[Array, Array]:  # fmt: skip
    r"""The correction that closes ``chains`` within the step, and their error after it.

    The least squares of the module docstring, in the resolver's metric (each chain's position
    rows divided by its reach): the chains' rates first; among the corrections with those
    rates, the one that keeps the top level's rates; each damped (:data:`DAMPING`); where that
    leaves the box (the resolver's, less its rates, within the trust region) or breaks a row,
    the point of the box nearest it in the chains' metric, then the top level's
    (:func:`rrc_pin.solvers.tick.slide_kernels.project`). :data:`PASSES` passes, each with the
    second order along the step corrected by the last (its cross terms with the correction,
    :math:`\Delta t^2 |\dot q| |\delta|`, were the largest error left after one: 2.1e-5 m and
    2.4e-5 rad against 4.1e-6 m and 5.0e-6 rad after two, gsfc_dual at 100 Hz, 3,000 ticks).

    Args:
        model: The cell's model.
        data: A Data of it (overwritten).
        q: Pinocchio's configuration at the tick's start (model.nq,).
        chains: The chains, measured at ``q`` by the tick's limits.
        qdot: The resolver's rates (nv,), inside ``box`` and ``rows``.
        top: The top level's task rows (m, nv) in their metric, kept where the box allows.
        box: The tick's joint-rate bounds.
        rows: The tick's constraint rows ``G qdot <= h``, or None.
        dt: The step [s].

    Returns:
        The correction (nv,), zero where the projection finds none (``qdot + delta`` inside
        the box), and the chains' error after the step (6 k,), predicted to second order.
    """
    n, closure = qdot.size, chains.closure
    C = closure.C / closure.unit[:, None]  # the resolver's metric: metres per reach
    solve = _Lexicographic(C, top)
    trust = TRUST * box.velocity
    low = np.minimum(np.maximum(box.lb - qdot, -trust), 0.0)  # zero always inside
    high = np.maximum(np.minimum(box.ub - qdot, trust), 0.0)
    G: Array
    h: Array
    if rows is None:
        G, h = np.zeros((0, n)), np.zeros(0)
    else:
        G, h = np.ascontiguousarray(rows.G), np.maximum(rows.h - rows.G @ qdot, 0.0)
    delta: Array = np.zeros(n)
    for _ in range(PASSES):
        second = second_order(model, data, q, qdot + delta, chains.contacts, chains.grips)
        delta = solve((closure.error - 0.5 * dt * dt * second) / (dt * closure.unit))
        if not (kernels.inside(delta, low, high) and kernels.rows_hold(G, delta, h, 0.0)):
            x = np.empty(n)
            M = np.ascontiguousarray(np.vstack([C, KEEP * top]))
            if project(M, DAMPING, delta, low, high, G, h, MARGIN, x) != SOLVED:
                x[:] = 0.0
            kernels.clip_into(x, low, high)
            delta = x
    after = closure.error - (closure.C @ (qdot + delta) + 0.5 * dt * second) * dt
    return delta, after


def second_order(
    model: pin.Model, data: pin.Data, q: Array, qdot: Array, contacts: Sequence[int],
    grips: Sequence[tuple[int, int]],
) -> Array:  # fmt: skip
    r"""Each chain's second derivative along a step of rates ``qdot`` (6 k,), as its error's.

    The step :math:`q \oplus \dot q\,t` (constant rates: a floating base on its screw, as
    ``pinocchio.integrate``) moves a contact frame by :math:`v t + \tfrac12 a t^2`, with
    :math:`(a, \dot\omega)` its classical acceleration at :math:`\ddot q = 0`; a grip's pose
    of b in a, :math:`p_{ab} = R_a^T d` with :math:`d = p_b - p_a`, by
    :math:`\ddot p_{ab} = R_a^T(\ddot d - \dot\omega_a \times d - 2\omega_a \times \dot d
    + \omega_a \times (\omega_a \times d))` and its rotation by
    :math:`R_a^T(\dot\omega_b - \dot\omega_a - \omega_a \times (\omega_b - \omega_a))`.
    Contacts first, then grips, in the rows' axes (world, a's).

    Args:
        model: The cell's model.
        data: A Data of it (overwritten).
        q: Pinocchio's configuration (model.nq,).
        qdot: The step's rates (nv,).
        contacts: Frame indices of the contacts.
        grips: ``(a, b)`` frame indices of the grips.
    """
    pin.forwardKinematics(model, data, q, qdot, np.zeros(model.nv))
    out = []
    for f in contacts:
        a = pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED)
        out.append(np.concatenate([a.linear, a.angular]))
    for fa, fb in grips:
        Ta = pin.updateFramePlacement(model, data, fa)
        Tb = pin.updateFramePlacement(model, data, fb)
        va, vb = (pin.getFrameVelocity(model, data, f, pin.LOCAL_WORLD_ALIGNED) for f in (fa, fb))
        aa, ab = (pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED)
                  for f in (fa, fb))  # fmt: skip
        d, W = Tb.translation - Ta.translation, pin.skew(va.angular)
        linear = (ab.linear - aa.linear - pin.skew(aa.angular) @ d
                  - W @ (2.0 * (vb.linear - va.linear) - W @ d))
        angular = ab.angular - aa.angular - W @ vb.angular
        Rt = Ta.rotation.T
        out.append(np.concatenate([Rt @ linear, Rt @ angular]))
    return np.concatenate(out) if out else np.zeros(0)


class _Lexicographic:
    """The chains' rates ``C delta = r`` first, then, among the corrections with those rates,
    the one that keeps the top level's rates (``top delta`` nearest zero): each a damped least
    squares pulled toward itself (:func:`_damped`, :data:`DAMPING`).

    The second stage moves in ``C``'s null space (the last columns of the QR of its
    transpose), made once for every pass of a tick.
    """  # noqa: D205

    def __init__(self, C: Array, top: Array) -> None:
        m, n = C.shape
        self.C = np.ascontiguousarray(C)
        self.null = Factorization(C).Q[:, m:].T if top.shape[0] and m < n else None
        self.top = top
        self.keep = None if self.null is None else np.ascontiguousarray(top @ self.null.T)

    def __call__(self, r: Array) -> Array:
        delta = _damped(self.C, r)
        if self.keep is None or self.null is None:
            return delta
        out: Array = delta + _damped(self.keep, -(self.top @ delta)) @ self.null
        return out


def _damped(J: Array, b: Array) -> Array:
    r"""The damped least squares of ``J x = b`` pulled toward itself (zero where not definite).

    With :math:`M = J^TJ + \mu I` (:math:`\mu` = :data:`DAMPING` times the mean squared
    singular value :math:`\operatorname{tr}(J^TJ)/m`) and :math:`t = M^{-1}J^Tb`, the
    minimiser of :math:`\|Jx - b\|^2 + \mu\|x - t\|^2`, :math:`t + \mu M^{-1}t`: along a
    right singular vector of singular value :math:`\sigma`,
    :math:`\beta\sigma(\sigma^2 + 2\mu)/(\sigma^2 + \mu)^2` of the exact
    :math:`\beta/\sigma`, bounded through a singularity. One Cholesky factorisation
    (:func:`~rrc_pin.solvers.tick.kernels.cholesky`), two triangular solves.
    """
    m, n = J.shape
    M = J.T @ J
    mu = max(DAMPING * float(M.trace()) / max(m, 1), _TINY)
    M.flat[:: n + 1] += mu
    L, t, out = np.zeros((n, n)), np.empty(n), np.empty(n)
    if not kernels.cholesky(M, 1e-12, L):
        return np.zeros(n)
    kernels.solve_factored(L, J.T @ b, t)
    kernels.solve_factored(L, t, out)
    result: Array = t + mu * out
    return result


_TINY = float(np.finfo(np.float64).tiny)
