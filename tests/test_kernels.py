"""Every compiled kernel against a plain numpy (or scipy) reference, to 1e-12.

The joint box has its own tests (tests/test_joint_limits.py: exact in floating point, the
priorities and kinds); here the linear algebra and the scales. The whole suite also runs once
with ``NUMBA_DISABLE_JIT=1`` (.ci/run), the same source as plain Python.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_linalg import random_rows

from rrc_pin.solvers.tick import kernels, linalg


@pytest.mark.parametrize(("m", "n"), [(6, 7), (6, 6), (3, 3), (6, 9), (7, 6), (1, 2)])
def test_direction_step_against_its_parts(m: int, n: int, rng: np.random.Generator) -> None:
    """The fused step: the QR and least-norm rates, the box check, then the exact scale (the
    uniform scale without a null direction, the line scale with one), as the parts give."""
    for _ in range(300):
        J = random_rows(rng, m, n, rank=min(m, n) - int(rng.random() < 0.1))
        b = rng.normal(size=m)
        lb, ub = -rng.uniform(0.0, 2.0, n), rng.uniform(0.0, 2.0, n)
        Q, R, w, qdot = np.empty((n, n)), np.empty((n, m)), np.empty(n), np.empty(n)
        fit, u = kernels.direction_step(J, b, lb, ub, Q, R, w, qdot)
        Q0, R0, x = np.empty((n, n)), np.empty((n, m)), np.empty(n)
        linalg.householder_qr(J.T.copy(), Q0, R0)
        np.testing.assert_array_equal(Q, Q0)
        np.testing.assert_array_equal(R, R0)
        if m > n or not linalg.least_norm_rates(Q0, R0, b, x):
            assert (fit, u) == (0, -1.0)
            continue
        np.testing.assert_array_equal(w, x)
        inside = bool(((x >= lb) & (x <= ub)).all())
        assert fit == (2 if inside else 1)
        if inside or n - m > 1:
            assert u == -1.0
        elif n == m:
            assert u == kernels.uniform_scale(x, lb, ub)
            np.testing.assert_array_equal(qdot, u * x)
        else:
            u0, y0 = kernels.line_scale(x, Q0[:, m].copy(), lb, ub)
            assert u == u0
            np.testing.assert_allclose(qdot, u0 * x + y0 * Q0[:, m], rtol=0, atol=1e-15)
            assert (qdot >= lb - 1e-12).all() and (qdot <= ub + 1e-12).all()
