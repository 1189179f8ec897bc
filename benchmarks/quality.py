"""The quality of each contender's answers to the same commands, judged independently of rrc-pin.

Every measure is computed from the recorded configurations, commands and each contender's
rates, with Pinocchio's Jacobians, the step's joint box (velocity limits and the position
limits over one Euler step, :func:`step_box`) and scipy (HiGHS and BVLS), never from a
contender's own report:

- the **LP maximum scale** along the command, per step (:func:`lp_scale`):
  ``max s in [0, 1]`` such that ``J qdot = s x`` with ``qdot`` in the box. Where it is 1
  (within :data:`REACHABLE_TOL`) the command can be met exactly;
- the **veer**: the angle between the achieved task rates ``J qdot`` and the command ``x``,
  both in the normalised metric (linear rows divided by the frame's reach, rrc-pin's
  documented metric, so that metres and radians weigh alike). Where the LP maximum is 1:
  the steps that veer by more than :data:`VEER_TOL` and the largest angle. On the too-fast
  segments where the LP maximum is below 1 but above :data:`BLOCKED` (the arm can move along
  the command, slower): the veer's median, p90 and largest (the direction error) over the
  answers that move, the answers that stand still (``stopped``: achieved rates below
  :data:`BLOCKED` of the command, no direction), and the share of steps that reach the LP's
  best speed along the command (scale within :data:`SPEED_TOL` of it, veer within
  :data:`VEER_TOL`). Where the LP maximum is :data:`BLOCKED` or less, a limit stops every
  motion along the command (``blocked_steps``): standing still is the best answer there;
- the **weighted optimum** (baxter, weighted): the distance [rad/s] of the rates from the
  exact optimum of rrc-pin's stated costs in the box (scipy's BVLS);
- the **limit excess**: the largest velocity and position excess (:mod:`timing`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

REACHABLE_TOL = 1e-9
"""An LP maximum scale within this of 1 counts as fully reachable."""
VEER_TOL = 1e-6
"""[rad] A veer above this counts (rrc-pin's exact answers veer by 1e-12 or less)."""
SPEED_TOL = 1e-6
"""Relative tolerance of "at the LP's best speed along the command"."""
BLOCKED = 1e-6
"""An LP maximum scale at most this: no motion along the command is possible (a limit
blocks it); achieved rates below this fraction of the command: the answer stands still."""


def step_box(robot: Any, q: Array, dt: float) -> tuple[Array, Array]:
    """Lower and upper joint-rate bounds (n,) of one step: velocity, and position over dt."""
    v = robot.velocity_limit
    lb = np.maximum(-v, (robot.lower - q) / dt)
    ub = np.minimum(v, (robot.upper - q) / dt)
    return lb, ub


def lp_scale(J: Array, x: Array, lb: Array, ub: Array) -> float:
    """``max s in [0, 1]`` with ``J qdot = s x``, ``lb <= qdot <= ub`` (HiGHS); 0 if infeasible."""
    from scipy.optimize import linprog

    m, n = J.shape
    c = np.zeros(n + 1)
    c[-1] = -1.0
    A_eq = np.hstack([J, -x[:, None]])
    bounds = [*zip(lb.tolist(), ub.tolist(), strict=True), (0.0, 1.0)]
    res = linprog(c, A_eq=A_eq, b_eq=np.zeros(m), bounds=bounds, method="highs")
    return float(res.x[-1]) if res.status == 0 else 0.0


def units(robot: Any, frames: list[str]) -> Array:
    """Each task row's unit (6 per frame): the frame's reach [m] for linear rows, 1 else."""
    from rrc_pin.kinematics import reach

    out = []
    for f in frames:
        r = reach(robot.model, robot.model.getFrameId(f))
        out += [r, r, r, 1.0, 1.0, 1.0]
    return np.array(out)


def jacobians(robot: Any, Q: Array, frames: list[str]) -> Array:
    """Stacked world-aligned Jacobians (steps, 6 * frames, n) of ``frames`` along ``Q``."""
    return np.array(
        [np.vstack([robot.jacobian(q, frame=f) for f in frames]) for q in Q]
    )


def reference(robot: Any, Q: Array, X: Array, J: Array, dt: float) -> dict[str, Array]:
    """What every contender is judged against: the LP maximum scale per step and the boxes."""
    lbs, ubs, best = [], [], []
    for q, x, Jk in zip(Q, X, J, strict=True):
        lb, ub = step_box(robot, q, dt)
        lbs.append(lb)
        ubs.append(ub)
        best.append(lp_scale(Jk, x, lb, ub))
    return {"lp_scale": np.array(best), "lb": np.array(lbs), "ub": np.array(ubs)}


def direction(
    J: Array, X: Array, rates: Array, unit: Array, ref: dict[str, Array], kinds: list[str],
    failed: Array,
) -> dict[str, Any]:  # fmt: skip
    """A contender's veer where the command is reachable, and its direction error and speed on
    the too-fast segments (module docstring). Failed steps (the library raised) are counted
    apart and left out."""
    y = np.einsum("kij,kj->ki", J, rates) / unit
    b = X / unit
    veer = np.array([_angle(yk, bk) for yk, bk in zip(y, b, strict=True)])
    bb = np.einsum("ki,ki->k", b, b)
    scale = np.einsum("ki,ki->k", y, b) / np.where(bb > 0, bb, 1.0)
    best = ref["lp_scale"]
    ok = ~failed
    reachable = ok & (best >= 1.0 - REACHABLE_TOL)
    too_fast = np.array([k == "too_fast" for k in kinds])
    fast = ok & (best < 1.0 - REACHABLE_TOL) & (best > BLOCKED) & too_fast
    stopped = np.linalg.norm(y, axis=1) <= BLOCKED * np.sqrt(bb)
    moving = fast & ~stopped
    at_best = (np.abs(scale - best) <= SPEED_TOL * np.maximum(best, 1e-12)) & (veer <= VEER_TOL)
    deg = np.degrees
    out: dict[str, Any] = {
        "reachable_steps": int(reachable.sum()),
        "veer_steps": int((reachable & (veer > VEER_TOL)).sum()),
        "veer_max_deg": float(deg(veer[reachable].max())) if reachable.any() else 0.0,
        "too_fast_steps": int(fast.sum()),
        "stopped_steps": int((fast & stopped).sum()),
        "blocked_steps": int((ok & (best <= BLOCKED)).sum()),
        "failed_steps": int(failed.sum()),
    }
    if fast.any():
        e = deg(veer[moving]) if moving.any() else np.zeros(1)
        out.update(
            direction_error_median_deg=float(np.median(e)),
            direction_error_p90_deg=float(np.percentile(e, 90)),
            direction_error_max_deg=float(e.max()),
            at_lp_best=float(at_best[fast].mean()),
            speed_median=float(np.median(scale[fast] / best[fast])),
        )
    return out


def _angle(y: Array, b: Array) -> float:
    """Angle [rad] between y and b (0 when b is zero; pi/2 when y is zero and b is not)."""
    nb, ny = math.sqrt(float(b @ b)), math.sqrt(float(y @ y))
    if nb == 0.0:
        return 0.0
    if ny == 0.0:
        return math.pi / 2
    return math.acos(min(max(float(y @ b) / (ny * nb), -1.0), 1.0))


def weighted_optimum(A: Array, b: Array, weights: Array, lb: Array, ub: Array) -> Array:
    """``argmin sum_i w_i (A_i qdot - b_i)^2`` with ``lb <= qdot <= ub`` (scipy's BVLS)."""
    from scipy.optimize import lsq_linear

    s = np.sqrt(weights)
    return np.asarray(lsq_linear(s[:, None] * A, s * b, bounds=(lb, ub), method="bvls",
                                 tol=1e-14).x)  # fmt: skip


def distance(rates: Array, optimum: Array, failed: Array) -> dict[str, float]:
    """Largest joint-rate difference [rad/s] from the optimum per step: median and largest."""
    d = np.abs(rates - optimum).max(axis=1)[~failed]
    if d.size == 0:
        return {"optimum_median": float("nan"), "optimum_max": float("nan")}
    return {"optimum_median": float(np.median(d)), "optimum_max": float(d.max())}
