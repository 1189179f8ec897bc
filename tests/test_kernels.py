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


def scale_and_veer_reference(y: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """The scale and veer in plain numpy (the pipeline's former Python implementation)."""
    top_b = float(np.abs(b).max()) if b.size else 0.0
    if top_b == 0.0:
        return 1.0, 0.0
    top_y = float(np.abs(y).max())
    if top_y == 0.0:
        return 0.0, 0.0
    bn, yn = b / top_b, y / top_y
    cosine = float(yn @ bn) / (np.linalg.norm(yn) * np.linalg.norm(bn))
    veer = float(np.arccos(np.clip(cosine, -1.0, 1.0)))
    with np.errstate(over="ignore"):
        ratio = float(np.float64(top_y) / top_b) * float(yn @ bn) / float(bn @ bn)
    return min(max(ratio, 0.0), 1.0), veer


def test_scale_and_veer_against_numpy(rng: np.random.Generator) -> None:
    for _ in range(2000):
        m = int(rng.integers(1, 13))
        b = rng.normal(size=m) * 10.0 ** rng.uniform(-300, 300)
        y = (rng.uniform(-0.5, 1.5) * b + rng.normal(size=m) * rng.choice([0.0, 1e-6, 1.0])
             * np.abs(b).max())  # fmt: skip
        y = y / np.abs(y).max() * 10.0 ** rng.uniform(-300, 300) if rng.random() < 0.3 else y
        scale, veer = kernels.scale_and_veer(y, b)
        reference = scale_and_veer_reference(y, b)
        assert scale == pytest.approx(reference[0], rel=1e-12, abs=1e-300)
        assert veer == pytest.approx(reference[1], abs=1e-7)  # acos near 0: sqrt of rounding
        factor = rng.uniform(0.01, 100.0, m)  # a level's metric: command first divided down
        peak = max(1.0, float(np.abs(b).max()))
        scale, veer = kernels.scale_and_veer(y, b, factor)
        reference = scale_and_veer_reference(factor * (y / peak), factor * (b / peak))
        assert scale == pytest.approx(reference[0], rel=1e-12, abs=1e-300)
        assert veer == pytest.approx(reference[1], abs=1e-7)
    assert kernels.scale_and_veer(np.zeros(0), np.zeros(0)) == (1.0, 0.0)
    huge = np.array([1.7e308, -1.7e308])  # times 100 would overflow
    scale, veer = kernels.scale_and_veer(0.5 * huge, huge, np.full(2, 100.0))
    assert scale == pytest.approx(0.5) and veer < 1e-7
    assert kernels.scale_and_veer(np.array([1.0, 0.0]), np.array([5e-324, 0.0])) == (1.0, 0.0)
    assert kernels.scale_and_veer(np.array([5e-324, 0.0]), np.array([1e308, 0.0]))[0] == 0.0


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


def lambda_sq_reference(
    sigma: np.ndarray, rank: int, scale: float, along: np.ndarray, dt: float, threshold: float
) -> np.ndarray | None:
    """The damping schedule in plain numpy (solvers/tick/damping.py's former implementation)."""
    if rank == 0 or scale >= 1.0:
        return None
    onset = float(sigma[0]) / threshold
    s = sigma[:rank]
    if float(s[-1]) >= onset:
        return None
    lam = np.zeros(sigma.size)
    weak = s < onset
    floor = np.maximum(onset * onset, float(sigma[0]) * along[:rank][weak] * dt)
    lam[:rank][weak] = (1.0 - (s[weak] / onset) ** 2) * floor * (1.0 - scale)
    return lam


def test_damping_lambda_sq_against_numpy(rng: np.random.Generator) -> None:
    for _ in range(2000):
        k = int(rng.integers(1, 8))
        sigma = np.sort(10.0 ** rng.uniform(-5, 1, k))[::-1].copy()
        rank = int(rng.integers(0, k + 1))
        scale = float(rng.choice([rng.uniform(0, 1), 1.0, 0.0]))
        along = np.abs(rng.normal(size=k)) * 10.0 ** rng.uniform(-4, 2)
        dt, threshold = float(rng.choice([0.001, 0.01, 0.05])), float(rng.uniform(10, 1e4))
        lam = np.full(k, np.nan)
        applies = kernels.damping_lambda_sq(sigma, rank, scale, along, dt, threshold, lam)
        reference = lambda_sq_reference(sigma, rank, scale, along, dt, threshold)
        assert applies == (reference is not None)
        if reference is not None:
            np.testing.assert_allclose(lam, reference, rtol=1e-14, atol=0)
