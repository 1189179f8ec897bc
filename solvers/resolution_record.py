"""The record of one resolution: joint rates, method, scale, residual, active limits.

:class:`Resolution` is what :class:`~solvers.resolution.ResolutionChain` (and
``rrc_pin.Resolver``) return; :class:`ActiveLimit` names a bound the answer touches, with
the constraint behind it.
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.joint_bounds import BOUND_KINDS, VelocityBounds

Array = npt.NDArray[np.float64]


class ActiveLimit(NamedTuple):
    """A joint-rate bound that the answer touches.

    Attributes:
        joint: Joint index.
        side: ``"lower"`` or ``"upper"``.
        kind: The constraint behind the bound: ``"position"``, ``"velocity"`` or
            ``"acceleration"``.
        bound: The bound's value [rad/s or m/s].
        name: Joint name, when the caller knows it (else None).
    """

    joint: int
    side: Literal["lower", "upper"]
    kind: str
    bound: float
    name: str | None = None


class Resolution:
    r"""The answer to one command, and how it was obtained.

    ``scale`` (for the least-squares methods), ``residual`` and ``active`` are computed on
    first access, so that a control loop that does not read them does not pay for them.

    Attributes:
        qdot: Joint rates (n,) [rad/s or m/s], finite and within the step's bounds.
        method: ``"qp"``, ``"qp_direction"``, ``"qp_priority"`` (strict second level),
            ``"dls"``, ``"scaling"`` or ``"hold"``.
        scale: Direction-preserving methods (``qp_direction``, ``scaling``): the s in [0, 1]
            applied to the damped task velocity. Others: the achieved fraction of the command
            along its direction, :math:`\langle J\dot q, \dot x\rangle_W/\|\dot x\|_W^2`
            (1 for a zero command).
        residual: Task error :math:`\|J\dot q - \dot x\|_2` (unweighted, mixed units).
        active: Bounds the answer touches (within the chain's ``active_tol``), as
            :class:`ActiveLimit` records: joint, side, constraint kind, bound.
        status: The backend's status, ``"unconstrained optimum"`` when no backend was needed,
            or the fallback's reason.
        build_time: Time outside the backends' solvers: SVD, problem building, backend
            update [s].
        solve_time: Time inside the backends' solvers [s].
        clip: Largest change made by clipping the method's answer into the bounds [rad/s].
        iterations: Backend iterations (0 without a backend).
        backend: Name of the backend that answered, or "".
        attempts: ``(method, reason)`` of every method that failed before this one.
        damping: Squared damping :math:`\lambda^2` used at this Jacobian.
    """

    __slots__ = (
        "_J", "_active", "_bounds", "_factor", "_names", "_residual", "_scale", "_tol",
        "_xdot", "attempts", "backend", "build_time", "clip", "damping", "iterations",
        "method", "qdot", "solve_time", "status",
    )

    def __init__(
        self,
        qdot: Array,
        method: str,
        scale: float | None,
        status: str,
        build_time: float,
        solve_time: float,
        clip: float = 0.0,
        iterations: int = 0,
        backend: str = "",
        attempts: tuple[tuple[str, str], ...] = (),
        damping: float = 0.0,
        *,
        J: Array,
        xdot: Array,
        bounds: VelocityBounds,
        factor: Array | None = None,
        active_tol: float = 1e-6,
        joint_names: list[str] | None = None,
    ) -> None:
        self.qdot = qdot
        self.method = method
        self.status = status
        self.build_time = build_time
        self.solve_time = solve_time
        self.clip = clip
        self.iterations = iterations
        self.backend = backend
        self.attempts = attempts
        self.damping = damping
        self._scale = scale
        self._J = J
        self._xdot = xdot
        self._bounds = bounds
        self._factor = factor
        self._tol = active_tol
        self._names = joint_names
        self._residual: float | None = None
        self._active: tuple[ActiveLimit, ...] | None = None

    @property
    def scale(self) -> float:
        """See the class docstring."""
        if self._scale is None:
            self._scale = along(self._J @ self.qdot, self._xdot, self._factor)
        return float(self._scale)

    @property
    def residual(self) -> float:
        """See the class docstring."""
        if self._residual is None:
            err = self._J @ self.qdot - self._xdot
            self._residual = math.sqrt(float(err @ err))
        return self._residual

    @property
    def active(self) -> tuple[ActiveLimit, ...]:
        """See the class docstring."""
        if self._active is None:
            self._active = active_limits(self.qdot, self._bounds, self._tol, self._names)
        return self._active

    @property
    def bounds(self) -> VelocityBounds:
        """The joint-rate bounds of the step."""
        return self._bounds

    def __repr__(self) -> str:
        return (
            f"Resolution(method={self.method!r}, scale={self.scale:.6g}, "
            f"residual={self.residual:.3g}, active={len(self.active)}, status={self.status!r}, "
            f"qdot={np.array2string(self.qdot, precision=4)})"
        )


def active_limits(
    qdot: Array, bounds: VelocityBounds, tol: float, names: list[str] | None = None
) -> tuple[ActiveLimit, ...]:
    """The bounds that ``qdot`` touches within ``tol``, with the constraint behind each.

    Args:
        qdot: Joint rates (n,).
        bounds: The bounds they were computed within.
        tol: Distance under which a bound counts as active [rad/s].
        names: Joint names for :attr:`ActiveLimit.name`, or None.

    Returns:
        The active bounds, by joint then side (lower first).
    """
    out: list[ActiveLimit] = []
    low = (qdot - bounds.lb <= tol).tolist()
    high = (bounds.ub - qdot <= tol).tolist()
    if not (any(low) or any(high)):
        return ()
    for i, (is_low, is_high) in enumerate(zip(low, high, strict=True)):
        name = names[i] if names else None
        if is_low:
            kind = BOUND_KINDS[int(bounds.lower_kind[i])]
            out.append(ActiveLimit(i, "lower", kind, float(bounds.lb[i]), name))
        if is_high:
            kind = BOUND_KINDS[int(bounds.upper_kind[i])]
            out.append(ActiveLimit(i, "upper", kind, float(bounds.ub[i]), name))
    return tuple(out)


def along(Jq: Array, xdot: Array, factor: Array | None) -> float:
    """Achieved fraction of ``xdot`` along its direction, in the task-weighted norm."""
    if factor is not None:
        Jq, xdot = factor.T @ Jq, factor.T @ xdot
    den = float(xdot @ xdot)
    return float(Jq @ xdot) / den if den > 0.0 else 1.0
