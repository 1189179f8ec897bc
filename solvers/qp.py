r"""The QP of one priority level, built apart from solving it.

.. math::

    \min_z \tfrac12 z^T P z + q^T z \quad \text{s.t.} \quad l \le C z \le u, \quad
    lb \le z \le ub

(two-sided rows, as DAQP and OSQP take them; :meth:`QP.problem` gives the one-sided
``qpsolvers.Problem`` of the same QP), and how its solution z decodes into joint rates:
:math:`\dot q = x_0 + M z` (:class:`Decoding`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import qpsolvers

Array = npt.NDArray[np.float64]


class QP(NamedTuple):
    """A convex QP with two-sided constraint rows and a box (module docstring).

    Attributes:
        P: Symmetric positive definite cost matrix (nz, nz).
        q: Cost vector (nz,).
        C: Constraint rows (nc, nz), or None.
        l: Lower bounds of ``C z`` (nc,), -inf allowed, or None.
        u: Upper bounds of ``C z`` (nc,), +inf allowed, or None.
        lb: Lower bounds of z (nz,), -inf allowed.
        ub: Upper bounds of z (nz,), +inf allowed.
        key: Name of the problem's structure (kind and sizes): one warm start per key.
    """

    P: Array
    q: Array
    C: Array | None
    l: Array | None  # noqa: E741 - the usual name of the lower row bounds
    u: Array | None
    lb: Array
    ub: Array
    key: str

    def problem(self) -> qpsolvers.Problem:
        """The same QP as a ``qpsolvers.Problem``: rows ``G z <= h`` for every finite side.

        The box is passed as ``lb, ub`` when it is finite, else its finite sides become rows
        (some solvers mishandle infinite box bounds: proxqp reports no solution).
        """
        rows, rhs = [], []
        if self.C is not None and self.l is not None and self.u is not None:
            low, high = np.isfinite(self.l), np.isfinite(self.u)
            rows += [self.C[high], -self.C[low]]
            rhs += [self.u[high], -self.l[low]]
        lb: Array | None = self.lb
        ub: Array | None = self.ub
        if not (np.isfinite(self.lb).all() and np.isfinite(self.ub).all()):
            eye = np.eye(self.q.size)
            low, high = np.isfinite(self.lb), np.isfinite(self.ub)
            rows += [eye[high], -eye[low]]
            rhs += [self.ub[high], -self.lb[low]]
            lb = ub = None
        h = np.concatenate(rhs) if rhs else None
        G = np.vstack(rows) if h is not None and h.size else None  # no finite side: no rows
        return qpsolvers.Problem(self.P, self.q, G, h if G is not None else None, lb=lb, ub=ub)


class Decoding(NamedTuple):
    r"""Joint rates of a solution z: :math:`\dot q = x_0 + M z` (n,).

    Attributes:
        x0: Offset (n,), or None for zero.
        M: Map (n, nz), or None for the identity (z is the joint rates).
    """

    x0: Array | None
    M: Array | None

    def rates(self, z: Array) -> Array:
        """The joint rates (n,) of ``z`` (nz,)."""
        x = z if self.M is None else self.M @ z
        return x if self.x0 is None else x + self.x0
