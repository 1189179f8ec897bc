"""Every compiled kernel against a plain numpy (or scipy) reference, to 1e-12.

The joint box has its own tests (tests/test_joint_limits.py: exact in floating point, the
priorities and kinds); here the linear algebra and the scales. The whole suite also runs once
with ``NUMBA_DISABLE_JIT=1`` (.ci/run), the same source as plain Python.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rrc_pin.solvers.tick import kernels


def random_rows(
    rng: np.random.Generator, m: int, n: int, rank: int | None = None, decades: float = 2.0
) -> np.ndarray:
    """Rows (m, n) of the given rank with singular values spread over ``decades`` decades."""
    rank = min(m, n) if rank is None else rank
    U, _ = np.linalg.qr(rng.normal(size=(m, m)))
    V, _ = np.linalg.qr(rng.normal(size=(n, n)))
    sigma = np.zeros(min(m, n))
    sigma[:rank] = 10.0 ** rng.uniform(-decades / 2, decades / 2, rank)
    return (U[:, : sigma.size] * sigma) @ V[:, : sigma.size].T


@pytest.mark.parametrize(("m", "n"), [(6, 7), (6, 6), (3, 3), (12, 15), (1, 4), (6, 9), (0, 3)])
def test_householder_qr_and_least_norm_rates(m: int, n: int, rng: np.random.Generator) -> None:
    for _ in range(200):
        J = random_rows(rng, m, n)
        Q, R = np.empty((n, n)), np.empty((n, m))
        kernels.householder_qr(J.T.copy(), Q, R)
        np.testing.assert_allclose(Q @ R, J.T, atol=1e-12 * np.abs(J).max(initial=1.0))
        np.testing.assert_allclose(Q.T @ Q, np.eye(n), atol=1e-13)
        assert np.allclose(np.tril(R, -1), 0.0)
        b = rng.normal(size=m)
        x = np.empty(n)
        assert kernels.least_norm_rates(Q, R, b, x)
        reference = np.linalg.pinv(J) @ b
        np.testing.assert_allclose(
            x, reference, rtol=0, atol=1e-12 * np.abs(reference).max(initial=1)
        )
    for _ in range(100 if m else 0):  # six decades: within rounding times the condition
        J = random_rows(rng, m, n, decades=6.0)
        Q, R = np.empty((n, n)), np.empty((n, m))
        kernels.householder_qr(J.T.copy(), Q, R)
        b = rng.normal(size=m)
        assert kernels.least_norm_rates(Q, R, b, x)
        np.testing.assert_allclose(J @ x, b, atol=1e-9 * max(1.0, np.abs(b).max()))


def test_least_norm_rates_refuses_dependent_rows(rng: np.random.Generator) -> None:
    J = random_rows(rng, 6, 7, rank=5)
    Q, R = np.empty((7, 7)), np.empty((7, 6))
    kernels.householder_qr(J.T.copy(), Q, R)
    x = np.full(7, 42.0)
    assert not kernels.least_norm_rates(Q, R, rng.normal(size=6), x)
    assert (x == 42.0).all()  # not set
    kernels.householder_qr(np.zeros((7, 6)), Q, R)
    assert not kernels.least_norm_rates(Q, R, np.ones(6), x)


@pytest.mark.parametrize(("m", "k"), [(6, 6), (6, 3), (15, 3), (1, 1), (3, 2)])
def test_jacobi_svd_against_lapack(m: int, k: int, rng: np.random.Generator) -> None:
    for rank in {k, max(k - 1, 0)}:
        for _ in range(100):
            A = random_rows(rng, m, k, rank)
            US, V, sigma = A.copy(), np.empty((k, k)), np.empty(k)
            kernels.jacobi_svd(US, V, sigma)
            reference = np.linalg.svd(A, compute_uv=False)
            np.testing.assert_allclose(sigma, reference, atol=1e-12 * reference[0])
            assert (np.diff(sigma) <= 0.0).all()
            np.testing.assert_allclose(V.T @ V, np.eye(k), atol=1e-13)
            np.testing.assert_allclose(A @ V, US, atol=1e-12 * reference[0])
            np.testing.assert_allclose(np.linalg.norm(US, axis=0), sigma, atol=1e-12 * sigma[0])


@pytest.mark.parametrize("size", [1e-76, 1e-30, 1e30, 1e76])
def test_jacobi_svd_of_tiny_and_huge_matrices_against_lapack(
    size: float, rng: np.random.Generator
) -> None:
    """Entries whose squares leave the range of normal floats (1e-76, 1e76: the rotation's
    root by hypot) or stay within it: the SVD is LAPACK's, relative to the largest value."""
    for _ in range(100):
        A = random_rows(rng, 6, 6, 6) * size
        US, V, sigma = A.copy(), np.empty((6, 6)), np.empty(6)
        kernels.jacobi_svd(US, V, sigma)
        reference = np.linalg.svd(A / size, compute_uv=False) * size
        np.testing.assert_allclose(sigma, reference, rtol=0.0, atol=1e-12 * reference[0])
        np.testing.assert_allclose(V.T @ V, np.eye(6), atol=1e-13)
        np.testing.assert_allclose((A / size) @ V, US / size, atol=1e-12 * reference[0] / size)


def test_jacobi_svd_of_blocks_against_lapack(rng: np.random.Generator) -> None:
    """Columns without a row in common (two arms' blocks, a zero column): orthogonal exactly,
    left as they are; the SVD is LAPACK's."""
    for trial in range(200):
        A = np.zeros((12, 10))
        A[:6, :5], A[6:, 5:] = rng.normal(size=(6, 5)), rng.normal(size=(6, 5))
        A[:, trial % 10] = 0.0 if trial % 3 == 0 else A[:, trial % 10]
        US, V, sigma = A.copy(), np.empty((10, 10)), np.empty(10)
        kernels.jacobi_svd(US, V, sigma)
        reference = np.linalg.svd(A, compute_uv=False)
        np.testing.assert_allclose(sigma, reference, atol=1e-12 * reference[0])
        np.testing.assert_allclose(V.T @ V, np.eye(10), atol=1e-13)
        np.testing.assert_allclose(A @ V, US, atol=1e-12 * reference[0])


def test_svd_rates_are_damped_least_squares(rng: np.random.Generator) -> None:
    for _ in range(200):
        m, n = 6, 7
        J = random_rows(rng, m, n, rank=int(rng.integers(1, 7)))
        U, s, Vt = np.linalg.svd(J)
        rank = int((s > 1e-9 * s[0]).sum())
        lam = rng.uniform(0.0, 1.0, s.size) * s[0] ** 2 * rng.choice([0.0, 1e-4])
        b = rng.normal(size=m)
        x = np.empty(n)
        kernels.svd_rates(U[:, : s.size] * s, s, Vt[: s.size].T.copy(), b, lam, rank, x)
        reference = sum(s[i] / (s[i] ** 2 + lam[i]) * (U[:, i] @ b) * Vt[i] for i in range(rank))
        np.testing.assert_allclose(x, reference, atol=1e-12 * max(1.0, np.abs(reference).max()))
        if not lam.any():
            np.testing.assert_allclose(x, np.linalg.pinv(J, rcond=1e-9) @ b, rtol=1e-8, atol=1e-10)


def test_inside_and_rows_hold(rng: np.random.Generator) -> None:
    for _ in range(500):
        n = int(rng.integers(1, 9))
        lb, ub = -rng.uniform(0, 1, n), rng.uniform(0, 1, n)
        x = rng.uniform(-1.2, 1.2, n)
        assert kernels.inside(x, lb, ub) == bool(((x >= lb) & (x <= ub)).all())
        G, h = rng.normal(size=(3, n)), rng.normal(size=3)
        tol = float(rng.choice([0.0, 0.5]))
        assert kernels.rows_hold(G, x, h, tol) == bool((G @ x <= h + tol).all())
    assert not kernels.inside(np.array([np.nan]), np.array([-1.0]), np.array([1.0]))
    assert not kernels.rows_hold(np.ones((1, 1)), np.array([np.nan]), np.zeros(1), 0.0)


def test_around_start_against_numpy(rng: np.random.Generator) -> None:
    """A bound z = 0 breaks by at most tol is widened to it, one it breaks by more kept; every
    bound widened by the rounding."""
    tol, rounding = 1e-6, 1e-12
    for _ in range(200):
        lo = rng.choice([-np.inf, -1.0, -1e-7, 0.0, 5e-7, 2e-6, 1.0], size=8)
        hi = rng.choice([np.inf, 1.0, 1e-7, 0.0, -5e-7, -2e-6, -1.0], size=8)
        want_lo = np.where(lo <= tol, np.minimum(lo, 0.0), lo) - rounding
        want_hi = np.where(hi >= -tol, np.maximum(hi, 0.0), hi) + rounding
        kernels.around_start(lo, hi, tol, rounding)
        np.testing.assert_array_equal(lo, want_lo)
        np.testing.assert_array_equal(hi, want_hi)


def test_normal_equations_and_cholesky(rng: np.random.Generator) -> None:
    for m, n in itertools.product((3, 12, 27), (3, 7, 15)):
        A, b, w = rng.normal(size=(m, n)), rng.normal(size=m), rng.uniform(0.1, 10.0, m)
        H, g = np.empty((n, n)), np.empty(n)
        kernels.normal_equations(A, b, w, H, g)
        np.testing.assert_allclose(H, A.T @ (w[:, None] * A), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(g, A.T @ (w * b), rtol=1e-12, atol=1e-12)
        x = np.empty(n)
        definite = kernels.cholesky_solve(H, g, x)
        assert definite == (m >= n)
        if definite:
            np.testing.assert_allclose(x, np.linalg.solve(H, g), rtol=1e-9, atol=1e-12)
            L = np.zeros((n, n))
            assert kernels.cholesky(H, 1e-12, L)
            np.testing.assert_allclose(L, np.linalg.cholesky(H), rtol=1e-10, atol=1e-12)
    assert not kernels.cholesky_solve(np.zeros((2, 2)), np.ones(2), np.empty(2))
    assert not kernels.cholesky(np.array([[1.0, 0.0], [0.0, np.nan]]), 1e-12, np.zeros((2, 2)))


def test_weighted_rows_and_clip_into(rng: np.random.Generator) -> None:
    A, b = rng.normal(size=(6, 7)), rng.normal(size=6)
    w, unit = rng.uniform(0.1, 10.0, 6), rng.uniform(0.5, 2.0, 6)
    A_out, b_out = np.empty((6, 7)), np.empty(6)
    peak = kernels.weighted_rows(A, b, w, 10.0, unit, 1.0, A_out, b_out)
    f = np.sqrt(w / 10.0) / unit
    np.testing.assert_allclose(A_out, A * f[:, None], rtol=1e-15)
    np.testing.assert_allclose(b_out, b * f, rtol=1e-15)
    assert peak == np.abs(b * f).max()
    x = rng.normal(size=9) * 2.0
    lb, ub = -np.ones(9), np.ones(9)
    before, clipped = x.copy(), np.clip(x, lb, ub)
    size = kernels.clip_into(x, lb, ub)
    np.testing.assert_array_equal(x, clipped)
    assert size == pytest.approx(np.linalg.norm(clipped - before), rel=1e-15)


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
        kernels.householder_qr(J.T.copy(), Q0, R0)
        np.testing.assert_array_equal(Q, Q0)
        np.testing.assert_array_equal(R, R0)
        if m > n or not kernels.least_norm_rates(Q0, R0, b, x):
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


def test_row_values_against_numpy(rng: np.random.Generator) -> None:
    for _ in range(100):
        m, n = rng.integers(1, 9, 2)
        A, x = rng.normal(size=(m, n)), rng.normal(size=n)
        np.testing.assert_allclose(kernels.row_values(A, x), A @ x, atol=1e-13)


def test_into_rows_against_numpy(rng: np.random.Generator) -> None:
    """The factor that scales rates into the rows: the least h_i / (G x)_i over the rows left by
    more than their sum's rounding, 4 eps below it; 1 where every row holds."""
    eps = np.finfo(np.float64).eps
    for _ in range(400):
        p, n = rng.integers(1, 7), rng.integers(1, 9)
        G, x = rng.normal(size=(p, n)), rng.normal(size=n)
        h = np.abs(rng.normal(size=p)) * rng.choice([0.0, 1.0], size=p)
        values = G @ x
        left = values - h > 1e-12
        want = 1.0 if not left.any() else float(np.min(h[left] / values[left])) * (1 - 4 * eps)
        got = kernels.into_rows(G, h, x)
        assert got == pytest.approx(want, rel=1e-12, abs=0.0)
        assert (G @ (x * got) <= h + 1e-15).all()


def test_a_row_held_at_zero_and_met_to_rounding_keeps_the_rates() -> None:
    """0.1 + 0.2 - 0.3 is 5.6e-17 in floating point: a row at bound 0 met to rounding, which
    used to scale the whole answer to zero (a tripod stopped mid-walk, reported exact)."""
    G, x = np.array([[0.1, 0.2, -0.3]]), np.ones(3)
    assert (G @ x)[0] > 0.0
    assert kernels.into_rows(G, np.zeros(1), x) == 1.0
    left = x + np.array([1e-9, 0.0, 0.0])  # the row left: standing still
    assert kernels.into_rows(G, np.zeros(1), left) == 0.0
