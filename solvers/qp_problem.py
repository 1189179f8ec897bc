r"""The resolved-rate QP, built apart from any backend.

Every problem is in one standard form that OSQP and qpsolvers both take:

.. math::

    \min_x \tfrac12 x^T P x + q^T x \quad \text{s.t.} \quad
    lo \le G x \le hi, \quad lb \le x \le ub

and the joint rates are :math:`\dot q = x` (no G) or :math:`\dot q = G x + \dot q_0`, in
which case the joint-rate bounds are the rows of G. Three builders, all from the
factorisation of the weighted Jacobian (:data:`solvers.task_factor.Task`: its SVD
:math:`\tilde J = U\Sigma V^T`, :math:`V = [V_r\ V_n]` (row space, null space), or, away
from singularities, :math:`C = (\tilde J\tilde J^T)^{-1}\tilde J`, which gives the same
terms without the SVD):

- :func:`tracking_problem`: weighted least-squares tracking with adaptive damping and a
  secondary objective acting in the null space only (it cannot change the task velocity
  while no bound is active). :math:`x = \dot q`.
- :func:`direction_problem`: :math:`\dot q = u\,w + V_n z` with :math:`w` the damped
  least-squares rates (times a cap): the task velocity is :math:`u` times the damped one,
  whatever z, and u in [0, 1] is maximised: the hand slows down along the command instead of
  veering. :math:`x = (z, u)`.
- :func:`priority_problem`: the strict second level: :math:`\dot q = V_rV_r^T\dot q_1 + V_n z`
  keeps the primary's task velocity exactly; z serves the secondary objective. :math:`x = z`.

Parametrising the null space instead of writing :math:`J\dot q = \dots` as equality rows
keeps the problems small and well conditioned at any distance from a singularity (no
rank-deficient equality block). Joint bounds come from :mod:`solvers.joint_bounds`, which
never returns ``lb > ub``. The resolver builds a problem only when it needs a backend:
:func:`tracking_free` and :func:`direction_terms` give what its shortcuts check first,
:func:`direction_step` solves a direction problem with at most one null-space direction
exactly, and :mod:`solvers.active_set` the tracking problem on a guessed active set.
"""

from __future__ import annotations

import math
from operator import le, neg
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.dls import TaskSVD
from solvers.errors import InputError
from solvers.joint_bounds import VelocityBounds
from solvers.plane_lp import plane_lp
from solvers.task_factor import Task, TaskInverse

Array = npt.NDArray[np.float64]

DIRECTION_REGULARISATION = 0.1
r"""Weight :math:`\epsilon` of :math:`\|z\|^2/R^2` (null-space motion) in the direction problem."""


class QPProblem(NamedTuple):
    r"""A QP: :math:`\min \frac12 x^TPx + q^Tx` s.t. :math:`lo \le Gx \le hi,\ lb \le x \le ub`.

    Attributes:
        P: Symmetric positive definite cost matrix (nx, nx).
        q: Cost vector (nx,).
        G: Constraint rows (n, nx) giving the joint rates ``G x + offset``, or None when the
            joint rates are x itself.
        lo: Lower bounds of ``G x`` (n,) (joint-rate bounds minus offset), or None.
        hi: Upper bounds of ``G x`` (n,), or None.
        lb: Lower box bounds (nx,); -inf allowed.
        ub: Upper box bounds (nx,); +inf allowed.
        offset: Joint rates at x = 0 (n,), or None for zero.
        x_free: Minimiser of the problem without its joint-rate bounds (the box on the scale
            u kept): when it satisfies them, it is the solution (no backend needed).
        n: Number of joints.
        kind: ``"tracking"``, ``"direction"`` or ``"priority"``.
        scale_factor: Direction problem: the scale is ``s = x[-1] * scale_factor``; else 0.
    """

    P: Array
    q: Array
    G: Array | None
    lo: Array | None
    hi: Array | None
    lb: Array
    ub: Array
    offset: Array | None
    x_free: Array
    n: int
    kind: Literal["tracking", "direction", "priority"]
    scale_factor: float = 0.0

    def rates(self, x: Array) -> Array:
        """Joint rates (n,) of a solution ``x`` (nx,)."""
        if self.G is None:
            return x
        return self.G @ x if self.offset is None else self.G @ x + self.offset

    def scale(self, x: Array) -> float:
        """The scale ``s`` of a solution ``x`` (1.0 for problems without one)."""
        if self.kind != "direction":
            return 1.0
        return float(x[-1] * self.scale_factor)

    def free_in_box(self) -> bool:
        """True when :attr:`x_free` satisfies every bound: then it is the solution."""
        x = self.x_free
        if self.G is None:
            return bool((x >= self.lb).all() and (x <= self.ub).all())
        g = self.G @ x
        return bool((g >= self.lo).all() and (g <= self.hi).all())


def tracking_problem(
    task: Task,
    xw: Array,
    bounds: VelocityBounds,
    secondary: Array | None = None,
    secondary_weight: float = 1e-2,
) -> QPProblem:
    r"""Weighted least-squares tracking with damping and a null-space secondary objective.

    .. math::

        \tfrac12\|\tilde J\dot q - \tilde x\|^2 + \tfrac12\lambda^2\|\dot q\|^2
        + \tfrac12\mu\|V_n^T(\dot q - z)\|^2,
        \quad \tilde J = L^T J,\ \tilde x = L^T\dot x,\ W = LL^T,

    with z the secondary joint rates (0 when none: the minimum-norm solution). With no bound
    active the solution is the damped least-squares rates plus
    :math:`\mu/(\mu + \lambda^2) V_nV_n^T z`: the secondary objective leaves the task
    velocity unchanged.

    Args:
        task: The weighted Jacobian factorised with its damping
            (:func:`solvers.task_factor.factor_task` or :func:`solvers.dls.task_svd`).
        xw: Weighted task velocity :math:`L^T\dot x` (m,).
        bounds: Joint-rate bounds.
        secondary: Desired joint rates z (n,) [rad/s], or None.
        secondary_weight: :math:`\mu` > 0 (also keeps P definite along the null space).

    Returns:
        The ``"tracking"`` :class:`QPProblem` (x = qdot).

    Raises:
        InputError: ``secondary_weight`` not > 0.
    """
    if not secondary_weight > 0.0:
        raise InputError("secondary_weight", f"expected a number > 0, got {secondary_weight!r}")
    free = tracking_free(task, xw, secondary, secondary_weight)
    return tracking_problem_from(task, free, bounds)


class TrackingFree(NamedTuple):
    """The box-free minimiser of :func:`tracking_problem` and what builds P and q from it.

    Attributes:
        x: Minimiser (n,) without the bounds: inside them, it is the solution.
        xw: Weighted task velocity (m,).
        secondary: Secondary joint rates (n,), or None.
        mu: Secondary weight.
        d: SVD only: eigenvalues (n,) of P in the singular basis V (else None).
        g: SVD only: components (n,) of -q in the singular basis V (else None).
    """

    x: Array
    xw: Array
    secondary: Array | None
    mu: float
    d: Array | None = None
    g: Array | None = None


def tracking_free(
    task: Task, xw: Array, secondary: Array | None = None, secondary_weight: float = 1e-2
) -> TrackingFree:
    r"""The box-free minimiser of :func:`tracking_problem`, without building P and q.

    The resolver checks it against the bounds first; only when it leaves them are P and q
    built (:func:`tracking_problem_from`). With the inverse factorisation (no damping, full
    row rank) it is :math:`\tilde J^T A^{-1}\tilde x + N N^T z`.
    """
    mu = secondary_weight
    if isinstance(task, TaskInverse):
        x = task.dls(xw)
        if secondary is not None:
            x = x + task.null_project(secondary)
        return TrackingFree(x, xw, secondary, mu)
    d, g = _tracking_terms(task, xw, secondary, mu)
    return TrackingFree(np.dot(task.Vt.T, g / d), xw, secondary, mu, d, g)


def tracking_problem_from(task: Task, free: TrackingFree, bounds: VelocityBounds) -> QPProblem:
    r"""The ``"tracking"`` :class:`QPProblem` from :func:`tracking_free`'s minimiser.

    :math:`P = \tilde J^T\tilde J + \lambda^2 I + \mu N N^T` and
    :math:`q = -\tilde J^T\tilde x - \mu N N^T z`: in the singular basis
    (:class:`~solvers.dls.TaskSVD`) or through :math:`A^{-1}`
    (:class:`~solvers.task_factor.TaskInverse`).
    """
    if isinstance(task, TaskInverse):
        P = task.hessian(free.mu)
        q = np.dot(free.xw, task.J)
        if free.secondary is not None:
            q += free.mu * task.null_project(free.secondary)
        np.negative(q, out=q)
    else:
        V = task.Vt.T
        P = (V * free.d) @ task.Vt
        q = V @ -free.g
    return QPProblem(
        P=P, q=q, G=None, lo=None, hi=None, lb=bounds.lb, ub=bounds.ub, offset=None,
        x_free=free.x, n=task.n, kind="tracking",
    )


def _tracking_terms(
    svd: TaskSVD, xw: Array, secondary: Array | None, mu: float
) -> tuple[Array, Array]:
    """Eigenvalues d of P and components g of -q in the singular basis V."""
    n = svd.n
    k = svd.sigma.size
    r = svd.rank
    lam = svd.lambda_sq
    # d > 0: sigma_i > 0 for i < r, mu > 0 beyond.
    d = np.array(
        [s * s + lam + (mu if i >= r else 0.0) for i, s in enumerate(svd.sigma.tolist())]
        + [lam + mu] * (n - k)
    )
    g = np.zeros(n)
    np.multiply(svd.sigma, np.dot(xw, svd.U), out=g[:k])
    if secondary is not None:
        g[r:] += mu * (svd.Vt[r:] @ secondary)
    return d, g


def direction_problem(
    task: Task,
    qdot_dls: Array,
    bounds: VelocityBounds,
    secondary: Array | None = None,
    secondary_weight: float = 1e-2,
) -> QPProblem:
    r"""Direction-preserving problem: maximise the scale s of the damped task velocity.

    With :math:`w = s_{hi} V_rV_r^T\dot q_{dls}` and :math:`s = u\,s_{hi}`:

    .. math::

        \dot q = u\,w + V_n z \ \Rightarrow\ J\dot q = s\,J\dot q_{dls}, \qquad
        lb \le u\,w + V_n z \le ub, \quad 0 \le u \le 1

    minimising :math:`\frac12(1-u)^2 + (1-u) + \frac{\epsilon}{2R^2}\|z\|^2 +
    \frac{\mu}{2R^2}\|z - V_n^T z_2\|^2` (:math:`R` the radius of the box,
    :math:`\epsilon` = :data:`DIRECTION_REGULARISATION`, :math:`z_2` the secondary rates).
    The slope in u is at least 1 while the null-space terms' marginal costs are of order
    :math:`(\epsilon + \mu)(1 + \|z_2\|/R)`, so s takes precedence. Away from singularities
    the damping is 0 and :math:`J\dot q_{dls} = \dot x` (the commanded direction itself);
    near one the direction is that of the damped (realisable) task velocity, so the
    problem never needs an impossible direction. :math:`s_{hi} \le 1` caps s by the box
    radius so that u is of order one even for absurd commands. Feasible whenever the box
    contains zero (u = 0, z = 0).

    Args:
        task: The weighted Jacobian factorised with its damping.
        qdot_dls: Damped least-squares rates (n,) (``task.dls``).
        bounds: Joint-rate bounds; must contain zero (:attr:`VelocityBounds.contains_zero`).
        secondary: Desired joint rates z (n,), or None.
        secondary_weight: :math:`\mu` in [0, 1).

    Returns:
        The ``"direction"`` :class:`QPProblem`: x = (z, u), nx = n - rank + 1.

    Raises:
        InputError: The bounds exclude zero (a joint must recover: use
            :func:`tracking_problem`), or ``secondary_weight`` outside [0, 1).
    """
    if not bounds.contains_zero:
        raise InputError("bounds", "the direction-preserving problem needs lb <= 0 <= ub")
    if not 0.0 <= secondary_weight < 1.0:
        raise InputError("secondary_weight", f"expected [0, 1), got {secondary_weight!r}")
    terms = direction_terms(task, qdot_dls, bounds, secondary, secondary_weight)
    return direction_problem_from(terms, bounds)


def direction_problem_from(terms: DirectionTerms, bounds: VelocityBounds) -> QPProblem:
    """The ``"direction"`` :class:`QPProblem` of :func:`direction_terms` (no input checks)."""
    n = terms.w.size
    nz = terms.Vn.shape[0]
    P = np.diag([terms.reg] * nz + [1.0])
    q = np.zeros(nz + 1)
    q[nz] = -2.0
    x_free = np.zeros(nz + 1)
    x_free[nz] = 1.0
    if terms.target is not None:
        q[:nz] = -terms.reg * terms.target
        x_free[:nz] = terms.target
    G = np.empty((n, nz + 1))
    G[:, :nz] = terms.Vn.T
    G[:, nz] = terms.w
    return QPProblem(
        P=P, q=q, G=G, lo=bounds.lb, hi=bounds.ub,
        lb=np.concatenate([np.full(nz, -np.inf), [0.0]]),
        ub=np.concatenate([np.full(nz, np.inf), [1.0]]),
        offset=None, x_free=x_free, n=n, kind="direction", scale_factor=terms.s_hi,
    )


class DirectionTerms(NamedTuple):
    r"""The data of the direction-preserving problem (:func:`direction_problem`).

    Attributes:
        Vn: Orthonormal null-space rows (nz, n).
        w: Joint rates per unit of u (n,), :math:`s_{hi} V_rV_r^T\dot q_{dls}`.
        s_hi: Cap of the scale, in (0, 1].
        reg: Weight of :math:`\frac12\|z\|^2` in the cost, :math:`(\epsilon + \mu)/R^2`.
        target: Minimiser (nz,) of the z terms of the cost, or None for zero.
    """

    Vn: Array
    w: Array
    s_hi: float
    reg: float
    target: Array | None


def direction_terms(
    task: Task,
    qdot_dls: Array,
    bounds: VelocityBounds,
    secondary: Array | None = None,
    secondary_weight: float = 1e-2,
) -> DirectionTerms:
    """The :class:`DirectionTerms` of :func:`direction_problem` (no input checks)."""
    Vn = task.null_basis()
    # with the inverse factorisation the least-squares rates lie in the row space already
    w = qdot_dls if isinstance(task, TaskInverse) else task.row_project(qdot_dls)
    lb, ub = bounds.lists()
    radius = math.hypot(*map(max, map(neg, lb), ub))
    w_norm = math.hypot(*w.tolist())
    s_hi = min(1.0, radius / w_norm) if w_norm > 0.0 else 1.0
    if s_hi != 1.0:
        w = s_hi * w
    R2 = max(radius, 1e-12) ** 2
    reg = (DIRECTION_REGULARISATION + secondary_weight) / R2
    target = None
    if secondary is not None and secondary_weight > 0.0 and Vn.shape[0]:
        # minimiser of eps/2R^2 |z|^2 + mu/2R^2 |z - Vn z_2|^2
        target = (secondary_weight / (DIRECTION_REGULARISATION + secondary_weight)) * (
            Vn @ secondary
        )
    return DirectionTerms(Vn, w, s_hi, reg, target)


def direction_step(
    terms: DirectionTerms, bounds: VelocityBounds
) -> tuple[Array, float, float]:
    """Exact solution of a direction problem with at most one null-space direction.

    No null space: the rates are u w and the largest feasible u is optimal. One direction:
    the plane LP of :mod:`solvers.plane_lp` (largest u, then z nearest its target). No
    backend and no :class:`QPProblem` are involved; the arithmetic is on Python floats.

    Args:
        terms: The problem's :func:`direction_terms` (``Vn`` with at most one row).
        bounds: Joint-rate bounds containing zero.

    Returns:
        The joint rates (n,) clipped into the bounds, the scale s in [0, 1], and the size
        of the clip (rounding only).

    Raises:
        InputError: More than one null-space direction.
    """
    Vn = terms.Vn
    lb, ub = bounds.lists()
    w = terms.w.tolist()
    if Vn.shape[0] == 0:
        u = largest_scale(w, lb, ub)
        rates = [u * wi for wi in w]
    elif Vn.shape[0] == 1:
        a = Vn[0].tolist()
        target = 0.0 if terms.target is None else float(terms.target[0])
        z, u = plane_lp(a, w, lb, ub, target)
        rates = [z * ai + u * wi for ai, wi in zip(a, w)]  # noqa: B905
    else:
        raise InputError("terms", f"expected at most one null-space direction, got {Vn.shape[0]}")
    clip = 0.0
    if not (all(map(le, lb, rates)) and all(map(le, rates, ub))):  # rounding at a bound
        for i, (low, v, high) in enumerate(zip(lb, rates, ub)):  # noqa: B905
            clipped = min(max(v, low), high)
            clip, rates[i] = max(clip, abs(clipped - v)), clipped
    return np.array(rates), u * terms.s_hi, clip


def largest_scale(qdot: list[float], lb: list[float], ub: list[float]) -> float:
    """Largest s in [0, 1] with ``lb <= s * qdot <= ub`` on the joints whose bounds contain zero.

    A recovering joint (bounds excluding zero) cannot be satisfied by scaling: it is
    ignored here (and clipped by the caller).

    Args:
        qdot: Joint rates (n,), Python floats.
        lb: Lower bounds (n,), Python floats.
        ub: Upper bounds (n,), Python floats.

    Returns:
        The scale s in [0, 1].
    """
    s = 1.0
    for v, lo, hi in zip(qdot, lb, ub, strict=True):
        if v > hi >= 0.0:
            s = min(s, hi / v)
        elif v < lo <= 0.0:
            s = min(s, lo / v)
    return max(0.0, s)


def priority_problem(
    task: Task, qdot_primary: Array, bounds: VelocityBounds, secondary: Array
) -> QPProblem:
    r"""Strict second priority level: the secondary objective in the primary's null space.

    .. math::

        \dot q = V_rV_r^T\dot q_1 + V_n z, \qquad
        \min \tfrac12\|z - V_n^T z_2\|^2 \ (\iff \min \|\dot q - z_2\|^2)
        \quad \text{s.t.} \quad lb \le \dot q \le ub

    :math:`J\dot q = J\dot q_1` for every z: the primary task velocity is kept exactly.
    Feasible whenever ``qdot_primary`` is within the bounds (z = its null-space part).

    Args:
        task: The weighted Jacobian factorised (its SVD is used: ``task.svd()``).
        qdot_primary: Solution of the primary problem (n,), within the bounds.
        bounds: Joint-rate bounds.
        secondary: Desired joint rates :math:`z_2` (n,).

    Returns:
        The ``"priority"`` :class:`QPProblem`: x = z, nx = n - rank (may be 0: nothing to do).
    """
    svd = task.svd()
    Vr = svd.Vt[: svd.rank]
    Vn = svd.Vt[svd.rank :]
    nz = Vn.shape[0]
    offset = Vr.T @ (Vr @ qdot_primary)
    return QPProblem(
        P=np.eye(nz), q=-(Vn @ secondary), G=Vn.T.copy(), lo=bounds.lb - offset,
        hi=bounds.ub - offset, lb=np.full(nz, -np.inf), ub=np.full(nz, np.inf),
        offset=offset, x_free=Vn @ secondary, n=svd.n, kind="priority",
    )
