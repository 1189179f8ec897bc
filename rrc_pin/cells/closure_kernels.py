r"""The closed chains' correction of one tick, compiled (:mod:`rrc_pin.cells.closure`'s math).

One call, :func:`correction`, makes a tick's whole correction from the tick's kinematics: the
chains' second order along the step (:func:`chain_motion` and :func:`second_order`, from the
world Jacobian's columns instead of a second forward pass), the lexicographic damped least
squares (:func:`lexicographic`, :func:`damped`) and, where that leaves the box or breaks a row,
the projection (:func:`~rrc_pin.solvers.tick.slide_kernels.project_factored`), :data:`PASSES`
times. The factors are made once for every pass (:func:`damped_factor`, :func:`kept`): only the
rates change between passes.

The second order. With :math:`S_c` the world Jacobian's column c (the joint's motion as a
spatial twist at the base origin, Pinocchio's ``computeJointJacobians``) and :math:`u_c` its
rate, a joint j moves its body by :math:`\nu_j = \sum_{c \in j} S_c u_c`, and at
:math:`\ddot q = 0` its column turns with the body it sits on (Featherstone, "Rigid Body
Dynamics Algorithms", eq. 5.20 with no joint bias: revolute, prismatic and free-flyer joints),
so that the spatial velocity and acceleration of the frame's body are

.. math::

    V = \sum_j \nu_j, \qquad A = \sum_j V_{<j} \times \nu_j

(:math:`V_{<j}` the sum over the joints before j on the chain, :math:`\times` the motion
cross product). The frame's origin p then moves at :math:`v_p = v + \omega \times p` with the
classical acceleration :math:`a + \alpha \times p + \omega \times v_p`, the same values as
Pinocchio's ``getFrameClassicalAcceleration`` in ``LOCAL_WORLD_ALIGNED`` after a forward pass
with :math:`\ddot q = 0`.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.linalg import (
    cholesky,
    householder_null,
    householder_vectors,
    normal_equations,
    row_values,
    solve_factored,
)
from rrc_pin.solvers.tick.feasibility import clip_into, inside, rows_hold
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project_factored

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

DAMPING = 1e-4
r"""The correction's damping, relative to its rows' mean squared singular value: a direction of
singular value :math:`\sigma` keeps :math:`\sigma^2(\sigma^2 + 2\mu)/(\sigma^2 + \mu)^2` of
its correction: all but 1e-8 at the mean, at least three quarters at a hundredth of the
largest."""

KEEP = 1e-2
"""Where the box binds, the weight of the top level's rows against the chains' (the chains
first)."""

PASSES = 2
"""Passes of the correction in a tick (:func:`correction`)."""

TRUST = 0.1
"""The trust region: the correction moves each joint by at most this fraction of its velocity
limit [rad/s or m/s]."""

_TINY = float(np.finfo(np.float64).tiny)


@kernel
def _cross(a: Array, b: Array, out: Array) -> None:
    """``out = a x b`` (3,)."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@kernel
def _cross_add(a: Array, i: int, b: Array, j: int, sign: float, out: Array, k: int) -> None:
    """``out[k:k + 3] += sign (a[i:i + 3] x b[j:j + 3])`` (sign 1 or -1: exact)."""
    out[k] += sign * (a[i + 1] * b[j + 2] - a[i + 2] * b[j + 1])
    out[k + 1] += sign * (a[i + 2] * b[j] - a[i] * b[j + 2])
    out[k + 2] += sign * (a[i] * b[j + 1] - a[i + 1] * b[j])


@kernel
def largest(error: Array) -> tuple[float, float]:
    """The largest position [m] and rotation [rad] error of chains ``error`` (6 k,) (0 for none).

    Each chain's lengths summed in numpy's order (``numpy.linalg.norm``'s floats).
    """
    position = rotation = 0.0
    for i in range(error.size // 6):
        e = error[6 * i : 6 * i + 6]
        position = max(position, math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]))
        rotation = max(rotation, math.sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]))
    return position, rotation


@kernel
def chain_motion(
    J: Array, support: npt.NDArray[np.bool_], joint: Ints, P: Array, u: Array, v: Array, a: Array
) -> None:
    """Each frame's velocity and classical acceleration at rates ``u`` and no joint acceleration.

    Args:
        J: The world Jacobian (6, nv) of every joint (Pinocchio's ``data.J`` after
            ``computeJointJacobians``: spatial twists [v; w] at the base origin).
        support: (k, nv) True where column c moves frame i (its chain's joints).
        joint: (nv,) the joint each column belongs to (columns of one joint side by side).
        P: (k, 3) the frames' origins in the base frame [m].
        u: The rates (nv,).
        v: Out: (k, 6) each frame's velocity [m/s, rad/s] in ``local_world_aligned``.
        a: Out: (k, 6) each frame's classical acceleration [m/s^2, rad/s^2], the same axes.
    """
    k, n = support.shape
    V, A, nu = np.empty(6), np.empty(6), np.empty(6)
    for i in range(k):
        V[:] = 0.0
        A[:] = 0.0
        c = 0
        while c < n:
            if not support[i, c]:
                c += 1
                continue
            j = joint[c]
            nu[:] = 0.0
            while c < n and support[i, c] and joint[c] == j:
                for r in range(6):
                    nu[r] += J[r, c] * u[c]
                c += 1
            # A += V x nu: (w x nu_v + v x nu_w, w x nu_w)
            _cross_add(V, 3, nu, 0, 1.0, A, 0)
            _cross_add(V, 0, nu, 3, 1.0, A, 0)
            _cross_add(V, 3, nu, 3, 1.0, A, 3)
            for r in range(6):
                V[r] += nu[r]
        p, vi, ai = P[i], v[i], a[i]
        vi[:] = V
        _cross_add(V, 3, p, 0, 1.0, vi, 0)
        ai[:] = A
        _cross_add(A, 3, p, 0, 1.0, ai, 0)
        _cross_add(V, 3, vi, 0, 1.0, ai, 0)


@kernel
def second_order(
    J: Array, support: npt.NDArray[np.bool_], joint: Ints, poses: Array, contacts: Ints,
    grips: Ints, u: Array, out: Array,
) -> None:  # fmt: skip
    r"""Each chain's second derivative along a step of rates ``u``, as its error's.

    The step :math:`q \oplus u\,t` (constant rates: a floating base on its screw, as
    ``pinocchio.integrate``) moves a contact frame by :math:`v t + \tfrac12 a t^2`: a contact's
    is its frame's classical acceleration (world axes); a grip's (b in a,
    :math:`d = p_b - p_a`) is :math:`R_a^T(\ddot d - \dot\omega_a \times d - \omega_a \times
    (2\dot d - \omega_a \times d))` and :math:`R_a^T(\dot\omega_b - \dot\omega_a - \omega_a
    \times \omega_b)`.

    Args:
        J: The world Jacobian (6, nv) of every joint (:func:`chain_motion`).
        support: (k, nv) the chains' frames' joint rates (:func:`chain_motion`).
        joint: (nv,) the joint of each rate.
        poses: (k, 4, 4) the frames' poses in the base frame [m].
        contacts: The contacts' frames (rows of ``support``).
        grips: (g, 2) each grip's frames a and b (rows of ``support``).
        u: The rates (nv,).
        out: Out: (6 (contacts + grips),), contacts first.
    """
    k = support.shape[0]
    v, a = np.empty((k, 6)), np.empty((k, 6))
    P = np.ascontiguousarray(poses[:, :3, 3])
    chain_motion(J, support, joint, P, u, v, a)
    for i in range(contacts.size):
        out[6 * i : 6 * i + 6] = a[contacts[i]]
    s = 6 * contacts.size
    lin, ang, d, dd, t = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for g in range(grips.shape[0]):
        fa, fb = grips[g, 0], grips[g, 1]
        wa = v[fa, 3:]
        d[:] = P[fb] - P[fa]
        _cross(wa, d, t)
        dd[:] = 2.0 * (v[fb, :3] - v[fa, :3]) - t
        lin[:] = a[fb, :3] - a[fa, :3]
        _cross(a[fa, 3:], d, t)
        lin -= t
        _cross(wa, dd, t)
        lin -= t
        _cross(wa, v[fb, 3:], t)
        ang[:] = a[fb, 3:] - a[fa, 3:] - t
        for r in range(3):
            x = y = 0.0
            for c in range(3):
                x += poses[fa, c, r] * lin[c]
                y += poses[fa, c, r] * ang[c]
            out[s + 6 * g + r] = x
            out[s + 6 * g + 3 + r] = y


@kernel
def damped_factor(J: Array, L: Array) -> float:
    r""":func:`damped`'s factor of rows ``J`` (m, n), and its damping :math:`\mu`.

    The Cholesky factor ``L`` (k, k) of :math:`W = JJ^T + \mu I` where k = m < n (the rows'
    side: the smaller where there are fewer rows than rates), else (k = n) of
    :math:`M = J^TJ + \mu I` (:func:`damped_solve`). ``L``'s upper triangle is left as the
    matrix's (:func:`~rrc_pin.solvers.linalg.cholesky` in place;
    :func:`~rrc_pin.solvers.linalg.solve_factored` does not read it).

    Returns:
        :math:`\mu`, or 0 where the matrix is not definite or the rows are all zero (the
        correction is then zero; ``L`` not set).
    """
    m, n = J.shape
    if L.shape[0] < n:
        normal_equations(J.T, np.zeros(n), np.ones(n), L, np.empty(m))
    else:
        normal_equations(J, np.zeros(m), np.ones(m), L, np.empty(n))
    k = L.shape[0]
    trace = 0.0
    for i in range(k):
        trace += L[i, i]
    if not trace > 0.0:
        return 0.0
    mu = max(DAMPING * trace / max(m, 1), _TINY)
    for i in range(k):
        L[i, i] += mu
    return mu if cholesky(L, 1e-12, L) else 0.0


@kernel
def damped_solve(J: Array, L: Array, mu: float, b: Array, out: Array) -> None:
    r"""``out``: :func:`damped` of ``J x = b`` from :func:`damped_factor`'s ``L`` and ``mu``
    (zero where ``mu`` is 0).

    With :math:`M^{-1}J^T = J^TW^{-1}` (:math:`W = JJ^T + \mu I`), on the rows' side
    :math:`t + \mu M^{-1}t = J^T(s + \mu W^{-1}s)` with :math:`s = W^{-1}b`.
    """  # noqa: D205
    m, n = J.shape
    if mu == 0.0:
        out[:] = 0.0
        return
    k = L.shape[0]
    t, s = np.empty(k), np.empty(k)
    if k < n:  # the rows' side
        solve_factored(L, b, t)
        solve_factored(L, t, s)
        out[:] = 0.0
        for r in range(m):
            c = t[r] + mu * s[r]
            for i in range(n):
                out[i] += J[r, i] * c
        return
    g = np.zeros(n)
    for r in range(m):  # J^T b
        for i in range(n):
            g[i] += J[r, i] * b[r]
    solve_factored(L, g, t)
    solve_factored(L, t, s)
    for i in range(n):
        out[i] = t[i] + mu * s[i]


@kernel
def damped(J: Array, b: Array, out: Array) -> None:
    r"""``out``: the damped least squares of ``J x = b`` pulled toward itself (zero where not
    definite).

    With :math:`M = J^TJ + \mu I` (:math:`\mu` = :data:`DAMPING` times the mean squared
    singular value :math:`\operatorname{tr}(J^TJ)/m`) and :math:`t = M^{-1}J^Tb`, the
    minimiser of :math:`\|Jx - b\|^2 + \mu\|x - t\|^2`, :math:`t + \mu M^{-1}t`: along a
    right singular vector of singular value :math:`\sigma`,
    :math:`\beta\sigma(\sigma^2 + 2\mu)/(\sigma^2 + \mu)^2` of the exact
    :math:`\beta/\sigma`, bounded through a singularity. One Cholesky factorisation
    (:func:`damped_factor`, once for all right-hand sides: of the smaller of M and
    :math:`JJ^T + \mu I`), two triangular solves (:func:`damped_solve`).
    """  # noqa: D205
    m, n = J.shape
    L = np.empty((min(m, n), min(m, n)))
    damped_solve(J, L, damped_factor(J, L), b, out)


@kernel
def kept(C: Array, top: Array) -> tuple[Array, Array]:
    """A basis of the null space of rows ``C`` (m, n) and the top level's rows in it.

    Returns:
        ``null`` (n - m, n), orthonormal rows from the Householder QR of :math:`C^T`
        (:func:`~rrc_pin.solvers.linalg.householder_null`), and ``keep``, ``top @
        null.T`` (t, n - m); (0, n) and (t, 0) where there is no top level (t = 0) or no
        null space (m >= n).
    """
    m, n = C.shape
    t = top.shape[0]
    if t == 0 or m >= n:
        return np.zeros((0, n)), np.zeros((t, 0))
    k = min(n - 1, m)
    R, V, beta = np.empty((n, m)), np.empty((k, n)), np.empty(k)
    householder_vectors(C.T, R, V, beta)
    null, keep = np.empty((n - m, n)), np.empty((t, n - m))
    householder_null(V, beta, m, null)
    for r in range(t):
        for c in range(n - m):
            s = 0.0
            for i in range(n):
                s += top[r, i] * null[c, i]
            keep[r, c] = s
    return null, keep


@kernel
def lexicographic(
    C: Array, LC: Array, muC: float, top: Array, null: Array, keep: Array, LK: Array,
    muK: float, r: Array, out: Array,
) -> None:  # fmt: skip
    """``out``: the chains' rates ``C x = r`` first, then, among the corrections with those
    rates, the one that keeps the top level's (``top x`` nearest zero), each :func:`damped`.

    Args:
        C: The chains' rows (m, n), in their metric.
        LC: :func:`damped_factor`'s factor of C.
        muC: Its damping (0: not definite).
        top: The top level's rows (t, n) (t = 0: none kept).
        null: (n - m, n) a basis of C's null space (rows), or (0, n): none (:func:`kept`).
        keep: ``top @ null.T`` (t, n - m).
        LK: :func:`damped_factor`'s factor of keep.
        muK: Its damping.
        r: The chains' rates (m,).
        out: Out: (n,).
    """  # noqa: D205
    damped_solve(C, LC, muC, r, out)
    p, n = null.shape
    t = top.shape[0]
    if p == 0 or t == 0:
        return
    b, y = np.empty(t), np.empty(p)
    for i in range(t):
        s = 0.0
        for j in range(n):
            s += top[i, j] * out[j]
        b[i] = -s
    damped_solve(keep, LK, muK, b, y)
    for c in range(p):
        for j in range(n):
            out[j] += y[c] * null[c, j]


@kernel
def correction(
    J: Array, support: npt.NDArray[np.bool_], joint: Ints, poses: Array, contacts: Ints,
    grips: Ints, C: Array, error: Array, unit: Array, top: Array, qdot: Array, box: Array,
    G: Array, h: Array, dt: float, delta: Array, after: Array, applied: Array,
) -> None:  # fmt: skip
    r"""The correction that closes the chains within the step, and their error after it.

    :func:`rrc_pin.cells.closure.close` (its docstring: the least squares, the box, the
    passes), on the tick's kinematics. The least squares' factors are made once, for every
    pass (the rows do not change between passes, only their rates).

    Args:
        J: The world Jacobian (6, nv) of every joint (:func:`second_order`).
        support: (k, nv) the chains' frames' joint rates.
        joint: (nv,) the joint of each rate.
        poses: (k, 4, 4) the frames' poses in the base frame [m].
        contacts: The contacts' frames (rows of ``support``).
        grips: (g, 2) each grip's frames a and b.
        C: The chains' rows (6 k, nv).
        error: Their errors (6 k,) [m, rad].
        unit: Their units (6 k,) (the resolver's metric).
        top: The top level's rows (t, nv) in their metric.
        qdot: The resolver's rates (nv,).
        box: (3, nv) the tick's box: its lower and upper bounds and the velocity limits
            (the correction's bounds are the box less the rates, within the trust region
            :data:`TRUST` times the velocity limits, and zero).
        G: The constraint rows ``G qdot <= h`` (p, nv), or (0, nv).
        h: Their bounds (p,) (the correction's room: ``max(h - G qdot, 0)``).
        dt: The step [s].
        delta: Out: the correction (nv,).
        after: Out: the chains' error after the step (6 k,), to second order.
        applied: Out: the rates with the correction, ``qdot + delta`` clipped into the box
            (numpy's ``minimum(maximum(x, lb), ub)``, against the rounding of ``qdot + delta``).
    """
    m, n, t = C.shape[0], qdot.size, top.shape[0]
    Cm = np.empty((m, n))  # the chains' rows in the resolver's metric (metres per reach)
    M = np.empty((m + t, n))  # the projection's rows: the chains', the top level's
    for i in range(m):
        for j in range(n):
            Cm[i, j] = M[i, j] = C[i, j] / unit[i]
    for i in range(t):
        for j in range(n):
            M[m + i, j] = KEEP * top[i, j]
    null, keep = kept(Cm, top)
    k = min(t, keep.shape[1])
    LC, LK = np.empty((min(m, n), min(m, n))), np.empty((k, k))
    muC, muK = damped_factor(Cm, LC), damped_factor(keep, LK)
    low, high, room = np.empty(n), np.empty(n), row_values(G, qdot)
    for i in range(n):  # zero always inside
        trust = TRUST * box[2, i]
        low[i] = min(max(box[0, i] - qdot[i], -trust), 0.0)
        high[i] = max(min(box[1, i] - qdot[i], trust), 0.0)
    for i in range(h.size):
        room[i] = max(h[i] - room[i], 0.0)
    second, r, u, x = np.empty(m), np.empty(m), np.empty(n), np.empty(n)
    LP, muP = np.empty((n, n)), -1.0
    delta[:] = 0.0
    for _ in range(PASSES):
        for i in range(n):
            u[i] = qdot[i] + delta[i]
        second_order(J, support, joint, poses, contacts, grips, u, second)
        for i in range(m):
            r[i] = (error[i] - 0.5 * dt * dt * second[i]) / (dt * unit[i])
        lexicographic(Cm, LC, muC, top, null, keep, LK, muK, r, delta)
        if not (inside(delta, low, high) and rows_hold(G, delta, room, 0.0)):
            if muP < 0.0:  # the projection's metric, factored once where it is first needed
                muP = damped_factor(M, LP)
            if muP == 0.0 or project_factored(LP, delta, low, high, G, room, MARGIN,
                                              x) != SOLVED:  # fmt: skip
                x[:] = 0.0
            clip_into(x, low, high)
            delta[:] = x
    for i in range(m):
        s = 0.0
        for j in range(n):
            s += C[i, j] * (qdot[j] + delta[j])
        after[i] = error[i] - (s + 0.5 * dt * second[i]) * dt
    for j in range(n):
        x = qdot[j] + delta[j]
        x = x if x >= box[0, j] else box[0, j]
        applied[j] = x if x <= box[1, j] else box[1, j]
