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
        """The same QP as a ``qpsolvers.Problem`` (rows ``G z <= h``, finite sides only)."""
        G: Array | None = None
        h: Array | None = None
        if self.C is not None and self.l is not None and self.u is not None:
            low, high = np.isfinite(self.l), np.isfinite(self.u)
            G = np.vstack([self.C[high], -self.C[low]])
            h = np.concatenate([self.u[high], -self.l[low]])
        lb = self.lb if np.isfinite(self.lb).any() else None
        ub = self.ub if np.isfinite(self.ub).any() else None
        return qpsolvers.Problem(self.P, self.q, G, h, lb=lb, ub=ub)

    def feasible(self, z: Array, tol: float = 0.0) -> bool:
        """True when ``z`` satisfies every bound and row within ``tol`` (False for NaN)."""
        if not ((z >= self.lb - tol).all() and (z <= self.ub + tol).all()):
            return False
        if self.C is None or self.l is None or self.u is None:
            return True
        c = self.C @ z
        return bool((c >= self.l - tol).all() and (c <= self.u + tol).all())


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
