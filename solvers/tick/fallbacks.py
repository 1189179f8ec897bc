"""What answers the top level when the pipeline could not (:data:`.pipeline.METHODS`).

- ``scipy``: the same problem solved exactly by scipy.optimize: the direction LP by HiGHS
  (along the exact rates), or the bounded least squares by BVLS (without rows);
- ``scaling``: the least-squares rates of least norm scaled uniformly into the box (where
  standing still is allowed and the rows hold);
- ``hold``: the feasible rates nearest zero in the box, which always answers.

Each either answers (rates within the box, rows and equality rows) or raises
:class:`~rrc_pin.solvers.errors.NumericalFailure`, and the next one is tried.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.optimize import lsq_linear

from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.qp_backends.qp import FEASIBILITY_TOL, Work
from rrc_pin.solvers.tick import feasibility
from rrc_pin.solvers.tick.direction import direction_lp, uniform_scale
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.problem import Problem

Array = npt.NDArray[np.float64]


def fallback(name: str, problem: Problem, work: Work) -> Array:
    """The answer of fallback ``name`` to ``problem``'s top level (module docstring).

    Raises:
        NumericalFailure: The method has no answer here.
    """
    box = problem.box
    if name == "hold":
        return box.clip(0.0)
    A, b = problem.stacked[0]
    if problem.equalities is not None:
        raise NumericalFailure(f"{name}: does not keep equality rows")
    factor = Factorization(A)
    w = factor.least_norm(b)
    if name == "scipy" and problem.mode == "direction":
        qdot = direction_lp(w, factor.null_basis(), box, problem.rows)
    elif name == "scipy":
        qdot = _bvls(A, b, problem)
    elif not box.contains_zero:
        raise NumericalFailure("scaling: zero rates are outside the bounds")
    else:
        qdot = uniform_scale(w, box.lb, box.ub) * w
    rows = problem.rows
    tol = FEASIBILITY_TOL * (1.0 + float(np.abs(np.minimum(box.velocity, 1e300)).sum()))
    if rows is not None and not feasibility.rows_hold(rows.G, qdot, rows.h, tol):
        raise NumericalFailure(f"{name}: the answer breaks a constraint row")
    if not np.isfinite(qdot).all():
        raise NumericalFailure(f"{name}: non-finite answer")
    return box.clip(qdot)


def _bvls(A: Array, b: Array, problem: Problem) -> Array:
    """The top level's bounded least squares solved exactly by scipy's BVLS."""
    if problem.rows is not None:
        raise NumericalFailure("scipy: bounded least squares takes no constraint rows")
    box = problem.box
    x = box.clip(0.0)  # joints with lb == ub are fixed there
    free = box.lb < box.ub
    if free.any():
        rhs = b - A[:, ~free] @ x[~free]
        try:
            result = lsq_linear(A[:, free], rhs, bounds=(box.lb[free], box.ub[free]),
                                method="bvls")  # fmt: skip
        except ValueError as exc:  # data lsq_linear refuses (non-finite entries)
            raise NumericalFailure(f"lsq_linear: {exc}") from exc
        if not result.success:
            raise NumericalFailure(f"lsq_linear: {result.message}")
        x[free] = result.x
    return x
