r"""Closing a cell's closed chains inside the tick's limits: the correction and its bound.

A grip (two hands on one object) and a foot in support close a kinematic chain. The
resolver keeps their rows, :math:`C\dot q = 0`, at every answer: the chains stay closed to
first order. What opens them is the integration, :math:`q_{k+1} = q_k \oplus \dot q\,\Delta t`:
with :math:`e(q)` a chain's pose error (:class:`~rrc_pin.limits.contact_limit.Closure`),

.. math::

    e_{k+1} = e_k - C\dot q\,\Delta t - \tfrac12 \Delta t^2\, D^2\!p[\dot q, \dot q]
              + O(\Delta t^3),

:math:`D^2p[\dot q, \dot q]` the chain's second derivative along the step (with
:math:`\ddot q = 0`: the frames' classical accelerations). Each tick therefore adds
:math:`e_k - C u\,\Delta t` to the error that its rates ``u`` leave, plus the second-order
remainder. The correction (:func:`correction`) takes the error measured at the tick's own
configuration out within the same step: rates :math:`\delta` with :math:`C\delta =
e_k/\Delta t`, so that the error after the step is that step's remainder alone and never
accumulates. It is the least squares

.. math::

    \min_\delta \|C\delta - e_k/\Delta t\|^2 + \|A\delta\|^2 + \mu\|\delta - t\|^2
    \quad\text{s.t.}\quad lb - \dot q \le \delta \le ub - \dot q,\quad
    |\delta_i| \le \rho_i,\quad G\delta \le h - G\dot q,

with A the top level's task rows (the commanded motion kept: the correction moves in their
null space where it can), damped (:math:`\mu` = :data:`DAMPING` times the mean squared
singular value of the rows, pulled toward the damped least squares t: the sliding stage's
projection, :func:`rrc_pin.solvers.tick.slide_kernels.project`), inside the box that is left
of the resolver's (the velocity and one-step position bounds, exact in floating point), the
trust region :math:`\rho_i` = :data:`TRUST` times each joint's velocity limit, and the
constraint rows that are left (a collision limit's). Zero is always feasible: the correction
never moves a joint beyond its limits, and it never opens a chain further
(:math:`\|C\delta - r\|` is at most :math:`\|r\|`).

The bound. With the rates in their box, the remainder of one tick is at most (a chain of
revolute joints; :math:`\ell_j` the length of the chain from joint j to the frame, its
:math:`\partial^2 p/\partial q_i\partial q_j` at most :math:`\ell_{\max(i,j)}`)

.. math::

    \|e_{k+1}\|_p \le \tfrac12 \Delta t^2 \Big(\sum_i |\dot q_i|\Big)^2 \ell, \qquad
    \|e_{k+1}\|_R \le \tfrac12 \Delta t^2 \Big(\sum_i |\dot q_i|\Big)^2

(the rotation's from :math:`\dot\omega = \sum_{i<j} \dot q_i \dot q_j\, z_i \times z_j`),
tens of millimetres for every joint at its velocity limit at 100 Hz, while the rows keep the
chain's own motion rigid: its measured remainder is that of the commanded motion, micrometres
(docs/api.md, "Cells"). :class:`ClosureBound` is the bound a cell states and enforces: a tick
that starts with a chain open beyond it stops the cell (``grip_lost`` / ``contact_lost``),
never a jump and never a silent drift.
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
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.problem import Box, Rows
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project

Array = npt.NDArray[np.float64]

THRESHOLD = Damping().threshold
"""The condition number of the correction's rows beyond which its directions are damped
(the resolver's documented threshold, :class:`~rrc_pin.solvers.tick.damping.Damping`)."""

KEEP = 1e-2
"""Where the box binds, the weight of the top level's rows against the chains' (the chains
first)."""

DAMPING = 1e-6
"""Where the box binds, the weight of the distance to the unbounded correction, relative to
the rows' mean squared singular value (what keeps the projection's metric definite)."""

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
    rows divided by its reach): the chains' rates first, damped past :data:`THRESHOLD`; among
    the corrections with those rates, the one that keeps the top level's rates, damped
    likewise; where that leaves the box (the resolver's, less its rates, within the trust
    region) or breaks a row, the point of the box nearest it in the chains' metric, then the
    top level's (:func:`rrc_pin.solvers.tick.slide_kernels.project`). :data:`PASSES` passes,
    each with the second order along the step corrected by the last (its cross terms with
    the correction, :math:`\Delta t^2 |\dot q| |\delta|`, were the largest error left after
    one: 1.8e-5 m against 3.4e-6 m after two, gsfc_dual at 100 Hz).

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
    if rows is None:
        G, h = np.zeros((0, n)), np.zeros(0)
    else:
        G, h = np.ascontiguousarray(rows.G), np.maximum(rows.h - rows.G @ qdot, 0.0)
    delta = np.zeros(n)
    for _ in range(PASSES):
        second = second_order(model, data, q, qdot + delta, chains.contacts, chains.grips)
        delta = solve((closure.error - 0.5 * dt * dt * second) / (dt * closure.unit), dt)
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
    """The chains' rates ``C delta = r`` first, damped past :data:`THRESHOLD`; then, among the
    corrections with those rates, the one that keeps the top level's rates (``top delta``
    nearest zero), of least norm: one factorisation of each for every pass of a tick.

    The damping is Maciejewski & Klein's smooth onset, the resolver's schedule
    (:func:`rrc_pin.solvers.tick.kernels.damping_lambda_sq`, whole: no scale is sought).
    """  # noqa: D205

    def __init__(self, C: Array, top: Array) -> None:
        self.chains = Factorization(C)
        null = self.chains.null_basis()
        self.null = null if top.shape[0] and null.shape[0] else None
        self.top = top
        self.keep = None if self.null is None else Factorization(top @ null.T)

    def __call__(self, r: Array, dt: float) -> Array:
        delta = _damped(self.chains, r, dt)
        if self.keep is None or self.null is None:
            return delta
        out: Array = delta + _damped(self.keep, -(self.top @ delta), dt) @ self.null
        return out


def _damped(factor: Factorization, b: Array, dt: float) -> Array:
    """The least-norm solution of ``J x = b`` (J ``factor``'s rows), damped past the threshold."""
    US, sigma, _, rank = factor.svd
    lam = np.empty(sigma.size)
    along = np.abs(b @ US) / np.maximum(sigma, _TINY)
    damped = kernels.damping_lambda_sq(sigma, rank, 0.0, along, dt, THRESHOLD, lam)
    return factor.rates(b, lam if damped else None)


_TINY = float(np.finfo(np.float64).tiny)
