r"""The factorisation of a step's task Jacobian, and the damping near singularities.

The SVD, :math:`J = U\Sigma V^T` (J the stacked, row-weighted task Jacobian (m, n)), gives
everything the resolver needs: the rank (singular values above :data:`RANK_TOL` times the
largest), the least-squares rates of least norm :math:`\dot q = V_r\Sigma_r^{-1}U_r^T\dot x`,
their damped version, the null space :math:`V_n` and the row space. Most steps need only the
rates, inside the bounds: :func:`normal_rates` gets them by a Cholesky solve of the normal
equations where these are well conditioned, and the SVD is computed only when a step needs
more (measured: 6.8 us against 9.5 us on a 6 x 7 Jacobian, 6.3 us against 39 us on a 27 x 15
stack, baxter's two hands and a posture).

Damping (:class:`Damping`) is an answer to one problem only: near a singularity the exact
rates of a command grow without bound, so the limits would stop the arm along a direction
it can barely move. It is therefore set from the joint-rate limits and the command's own
rates, never from a fixed singular-value threshold (which mixes metres and radians and
bends ordinary commands far from any singularity):

- for each singular direction :math:`v_i`, :math:`r_i = 1/\max_j |v_{ij}|/\dot q_{max,j}` is
  the largest rate along it within the velocity limits and :math:`c_i = \sigma_i r_i` the
  task speed it then delivers; the direction is weak when :math:`c_i < c_{on} =
  \max_k c_k/\kappa` (``Damping.ratio`` :math:`\kappa`), or when one step along it would
  reach the singularity (below);
- the exact rates are tried first: if they fit the step's bounds the command is met
  exactly, however weak a direction. Otherwise, with :math:`s_e \in [0, 1]` the uniform
  scale that brings them into the bounds, a weak direction gets the squared damping
  (Maciejewski & Klein 1988's smooth onset, here in rate-normalised units)

  .. math::

      \lambda_i^2 = \max\Big(\Big(1 - \big(c_i/c_{on}\big)^2\Big)\big(c_{on}/r_i\big)^2,\
          g_i\,\big(\sigma_1 |u_i^T\dot x|\,\Delta t - \sigma_i^2\big),\ 0\Big)\,(1 - s_e),
      \qquad g_i = \max\Big(1 - \frac{\sigma_i}{\sigma_1 R\,\Delta t},\ 0\Big),

  and its rates become :math:`\sigma_i/(\sigma_i^2 + \lambda_i^2)\,u_i^T\dot x\,v_i`. The
  second term is for the step :math:`\Delta t`: near a singularity :math:`\sigma_i` changes
  by about :math:`\sigma_1` (the arm's size) per radian along :math:`v_i`, so the
  singularity is :math:`\sigma_i/\sigma_1` away, and a step of :math:`\Delta t\,\sigma_i
  |u_i^T\dot x|/(\sigma_i^2 + \lambda_i^2)` along :math:`v_i` stays short of it when
  :math:`\sigma_i^2 + \lambda_i^2 \ge \sigma_1 |u_i^T\dot x| \Delta t`. A step that crosses
  it is undone by the next (a stretched elbow pushed outward: without the term the joints
  flipped between opposite rate limits at every tick). No rates within the bounds reach
  further than :math:`R\Delta t` (R the norm of the largest rates the bounds allow), so the
  term fades out (:math:`g_i`, continuously) where the singularity is further away.

The damping is zero away from singularities (every :math:`c_i \ge c_{on}`, and steps short
of them), zero for commands whose exact rates fit the limits (:math:`s_e = 1`), continuous
in the configuration and in the command.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.linalg.lapack import dgesvd, dposv

from solvers.direction import uniform_scale
from solvers.joint_bounds import excludes_zero, radius
from solvers.resolution import norm
from solvers.validation import finite_number

Array = npt.NDArray[np.float64]

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * sigma_max`` count as zero (null-space directions)."""


NORMAL_RCOND = 1e-3
"""The normal equations are used when the Cholesky factor's smallest diagonal entry is at
least this times its largest: the normal matrix's condition is then about 1e6 (the ratio
squared, an estimate from below), leaving some ten digits; otherwise the SVD answers."""

NORMAL_RESIDUAL = 1e-10
"""Relative residual under which the normal equations' rates of a wide J are accepted (below
:data:`solvers.resolution.EXACT_TOL`, so that accepted rates meet the command)."""


def normal_rates(J: Array, b: Array) -> Array | None:
    r"""The least-squares rates of least norm :math:`J^+ b` (n,) by the normal equations.

    Wide or square J (m <= n): :math:`\dot q = J^T y`, :math:`J J^T y = b`, accepted when
    :math:`J\dot q = b` to :data:`NORMAL_RESIDUAL` relative (a solution in the row space is
    the least-norm one). Tall J (m > n): :math:`J^T J \dot q = J^T b`, the one least-squares
    solution. By LAPACK's Cholesky solve (dposv).

    Args:
        J: Rows (m, n), row-weighted.
        b: Their rates (m,).

    Returns:
        The rates, or None where the normal matrix is not numerically definite or badly
        conditioned (:data:`NORMAL_RCOND`): then the SVD (:class:`JacobianSVD`) answers.
    """
    m, n = J.shape
    wide = m <= n
    G = J @ J.T if wide else J.T @ J
    factor, y, info = dposv(G, b if wide else b @ J)
    if info != 0:
        return None
    diagonal = factor.diagonal().tolist()  # the Cholesky factor's, positive
    if min(diagonal) < NORMAL_RCOND * max(diagonal):
        return None
    if not wide:
        return np.asarray(y, dtype=np.float64)
    x: Array = y @ J
    if norm(J @ x - b) > NORMAL_RESIDUAL * (1.0 + norm(b)):
        return None
    return x


class JacobianSVD:
    r"""Singular value decomposition of a task Jacobian J (m, n).

    Attributes:
        U: Left singular vectors (m, k), k = min(m, n).
        sigma: Singular values (k,), descending.
        Vt: Right singular vectors (n, n): rows ``0..rank-1`` span the row space, the others
            the (numerical) null space.
        rank: Number of singular values above ``RANK_TOL * sigma[0]``.

    Raises:
        numpy.linalg.LinAlgError: LAPACK did not converge (pathological input only).
    """

    __slots__ = ("U", "Vt", "rank", "sigma")

    def __init__(self, J: Array) -> None:
        m, n = J.shape
        k = min(m, n)
        if k == 0:
            self.U, self.sigma, self.Vt = np.zeros((m, 0)), np.zeros(0), np.eye(n)
        else:
            # scipy's binding of LAPACK dgesvd: 8.6 us against numpy.linalg.svd's 15 us on a
            # 6x7 Jacobian (the largest cost of a resolver step)
            U, sigma, Vt, info = dgesvd(J, compute_uv=1, full_matrices=1)
            if info != 0:
                raise np.linalg.LinAlgError(f"dgesvd did not converge (info={info})")
            self.U, self.sigma, self.Vt = U[:, :k], sigma, Vt
        values = self.sigma.tolist()
        cut = RANK_TOL * values[0] if values else 0.0
        self.rank = sum(s > cut for s in values) if cut > 0.0 else 0

    def rates(self, b: Array, lambda_sq: Array | None = None) -> Array:
        r"""Least-squares rates of least norm (n,) for the task velocity ``b`` (m,).

        :math:`\sum_{i<r} \sigma_i/(\sigma_i^2 + \lambda_i^2)\, (u_i^T b)\, v_i`; exact
        (:math:`V_r\Sigma_r^{-1}U_r^Tb`) when ``lambda_sq`` is None.
        """
        r = self.rank
        coords = b @ self.U[:, :r]
        s = self.sigma[:r]
        weighted = coords / s if lambda_sq is None else coords * s / (s * s + lambda_sq[:r])
        return weighted @ self.Vt[:r]

    def null_basis(self) -> Array:
        """Orthonormal rows (n - rank, n) spanning the null space."""
        return self.Vt[self.rank :]


@dataclass(frozen=True)
class Damping:
    r"""Damping near singularities, where a command's exact rates exceed the limits.

    See the module docstring for the schedule.

    Attributes:
        ratio: :math:`\kappa` > 1: a singular direction is weak when, at full joint rate, it
            delivers less than 1/ratio of the task speed of the strongest direction.

    Raises:
        InputError: ``ratio`` not a finite number > 1.
    """

    ratio: float = 100.0

    def __post_init__(self) -> None:
        finite_number(self.ratio, "ratio", 1.0, inclusive=False)

    def lambda_sq(
        self, svd: JacobianSVD, velocity: Array, exact: Array, lb: Array, ub: Array,
        dt: float | None = None,
    ) -> Array | None:  # fmt: skip
        r"""Squared damping per singular direction (k,), or None where none is needed.

        Args:
            svd: The Jacobian's SVD.
            velocity: Joint velocity limits (n,) > 0 [rad/s or m/s].
            exact: The exact least-squares rates (n,), outside the bounds.
            lb: Lower joint-rate bounds of the step (n,).
            ub: Upper joint-rate bounds (n,).
            dt: The step [s], for the floor that keeps a step from crossing the singularity
                (module docstring); None: no such floor.

        Returns:
            :math:`\lambda_i^2` (k,), or None when every one is zero.
        """
        r = svd.rank
        if r == 0:
            return None
        # min(v) <= r_i <= sqrt(n) max(v): no direction is weak while sigma_1 / sigma_r is
        # below ratio min(v) / (sqrt(n) max(v)); and |u_i^T xdot| <= sigma_i |w|, so no step
        # reaches a singularity while sigma_r >= sigma_1 dt min(R, |w|): most steps, known
        # without V
        v = velocity.tolist()
        first, last = float(svd.sigma[0]), float(svd.sigma[r - 1])
        R = radius(lb, ub)
        reachable = 0.0 if dt is None else first * dt * min(R, norm(exact))
        if first * math.sqrt(len(v)) * max(v) <= last * min(v) * self.ratio and last >= reachable:
            return None
        # per direction, over Python floats (r <= 6 of them): 40k instructions against 200k
        # for the same formulas as some thirty numpy calls on (r,) arrays
        V = svd.Vt[:r]
        slowness = (np.abs(V) / velocity).max(axis=1).tolist()  # 1 / r_i
        along = np.abs(V @ exact).tolist()  # |v_i . w|: u_i^T xdot = sigma_i v_i . w
        sigma = svd.sigma[:r].tolist()
        onset = max(s / k for s, k in zip(sigma, slowness, strict=True)) / self.ratio  # c_on
        step = first * dt if dt is not None else 0.0  # sigma_1 dt
        lam_r = []
        for s, k, a in zip(sigma, slowness, along, strict=True):
            lam = (onset * k) ** 2 - s * s  # (1 - (c_i / c_on)^2) (c_on / r_i)^2, c_i = sigma_i r_i
            if step * R > 0.0:  # g_i (sigma_1 |u_i^T xdot| dt - sigma_i^2)
                lam = max(lam, max(1.0 - s / (step * R), 0.0) * (step * s * a - s * s))
            lam_r.append(max(lam, 0.0))
        s_exact = 0.0 if excludes_zero(lb, ub) else uniform_scale(exact, lb, ub)
        if max(lam_r) <= 0.0 or s_exact >= 1.0:
            return None  # far from singularities, or the exact rates fit
        out = np.zeros(svd.sigma.size)
        out[:r] = lam_r
        out *= 1.0 - s_exact
        return out
