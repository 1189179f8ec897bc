"""The dense linear algebra kernels (rrc_pin.solvers.linalg) against numpy (or LAPACK), to
1e-12. The whole suite also runs once with ``NUMBA_DISABLE_JIT=1`` (.ci/run), the same source as
plain Python.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rrc_pin.solvers import linalg


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
        linalg.householder_qr(J.T.copy(), Q, R)
        np.testing.assert_allclose(Q @ R, J.T, atol=1e-12 * np.abs(J).max(initial=1.0))
        np.testing.assert_allclose(Q.T @ Q, np.eye(n), atol=1e-13)
        assert np.allclose(np.tril(R, -1), 0.0)
        b = rng.normal(size=m)
        x = np.empty(n)
        assert linalg.least_norm_rates(Q, R, b, x)
        reference = np.linalg.pinv(J) @ b
        np.testing.assert_allclose(
            x, reference, rtol=0, atol=1e-12 * np.abs(reference).max(initial=1)
        )
    for _ in range(100 if m else 0):  # six decades: within rounding times the condition
        J = random_rows(rng, m, n, decades=6.0)
        Q, R = np.empty((n, n)), np.empty((n, m))
        linalg.householder_qr(J.T.copy(), Q, R)
        b = rng.normal(size=m)
        assert linalg.least_norm_rates(Q, R, b, x)
        np.testing.assert_allclose(J @ x, b, atol=1e-9 * max(1.0, np.abs(b).max()))


def test_least_norm_rates_refuses_dependent_rows(rng: np.random.Generator) -> None:
    J = random_rows(rng, 6, 7, rank=5)
    Q, R = np.empty((7, 7)), np.empty((7, 6))
    linalg.householder_qr(J.T.copy(), Q, R)
    x = np.full(7, 42.0)
    assert not linalg.least_norm_rates(Q, R, rng.normal(size=6), x)
    assert (x == 42.0).all()  # not set
    linalg.householder_qr(np.zeros((7, 6)), Q, R)
    assert not linalg.least_norm_rates(Q, R, np.ones(6), x)


@pytest.mark.parametrize(("m", "k"), [(6, 6), (6, 3), (15, 3), (1, 1), (3, 2)])
def test_jacobi_svd_against_lapack(m: int, k: int, rng: np.random.Generator) -> None:
    for rank in {k, max(k - 1, 0)}:
        for _ in range(100):
            A = random_rows(rng, m, k, rank)
            US, V, sigma = A.copy(), np.empty((k, k)), np.empty(k)
            linalg.jacobi_svd(US, V, sigma)
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
        linalg.jacobi_svd(US, V, sigma)
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
        linalg.jacobi_svd(US, V, sigma)
        reference = np.linalg.svd(A, compute_uv=False)
        np.testing.assert_allclose(sigma, reference, atol=1e-12 * reference[0])
        np.testing.assert_allclose(V.T @ V, np.eye(10), atol=1e-13)
        np.testing.assert_allclose(A @ V, US, atol=1e-12 * reference[0])


def test_jacobi_svd_rotates_blocks_as_the_whole_matrix(rng: np.random.Generator) -> None:
    """Diagonal blocks rotated one by one over their own rows give, bit for bit, the sweeps of
    every pair over every row (a row outside a block is zero in both columns of its pairs;
    pairs across blocks are orthogonal), then the same sort."""
    one = np.uint64(1)
    for _ in range(300):
        sizes = rng.integers(1, 5, size=rng.integers(1, 4))  # 1 to 3 blocks of 1 to 4 columns
        rows = rng.integers(1, 6, size=sizes.size)
        A = np.zeros((rows.sum(), sizes.sum()))
        r = c = 0
        for m_b, k_b in zip(rows, sizes, strict=True):
            A[r : r + m_b, c : c + k_b] = rng.normal(size=(m_b, k_b))
            r, c = r + m_b, c + k_b
        m, k = A.shape
        whole, V = A.copy(), np.eye(k)
        norms = np.zeros(k)
        for j in range(k):  # summed in row order (Python's sum compensates from 3.12 on)
            for x in whole[:, j].tolist():
                norms[j] += x * x
        linalg._rotate_block(whole, V, norms, np.uint64(0), np.uint64(m), np.uint64(0),
                             np.uint64(k), one)  # fmt: skip
        sigma = np.sqrt(norms)
        for j in range(k):  # the kernel's selection sort
            best = j + int(np.argmax(sigma[j:]))
            sigma[[j, best]], whole[:, [j, best]], V[:, [j, best]] = (
                sigma[[best, j]], whole[:, [best, j]], V[:, [best, j]])  # fmt: skip
        US, W, s = A.copy(), np.empty((k, k)), np.empty(k)
        linalg.jacobi_svd(US, W, s)
        assert np.array_equal(s, sigma) and np.array_equal(US, whole) and np.array_equal(W, V)


def test_svd_rates_are_damped_least_squares(rng: np.random.Generator) -> None:
    for _ in range(200):
        m, n = 6, 7
        J = random_rows(rng, m, n, rank=int(rng.integers(1, 7)))
        U, s, Vt = np.linalg.svd(J)
        rank = int((s > 1e-9 * s[0]).sum())
        lam = rng.uniform(0.0, 1.0, s.size) * s[0] ** 2 * rng.choice([0.0, 1e-4])
        b = rng.normal(size=m)
        x = np.empty(n)
        linalg.svd_rates(U[:, : s.size] * s, s, Vt[: s.size].T.copy(), b, lam, rank, x)
        reference = sum(s[i] / (s[i] ** 2 + lam[i]) * (U[:, i] @ b) * Vt[i] for i in range(rank))
        np.testing.assert_allclose(x, reference, atol=1e-12 * max(1.0, np.abs(reference).max()))
        if not lam.any():
            np.testing.assert_allclose(x, np.linalg.pinv(J, rcond=1e-9) @ b, rtol=1e-8, atol=1e-10)


def test_normal_equations_and_cholesky(rng: np.random.Generator) -> None:
    for m, n in itertools.product((3, 12, 27), (3, 7, 15)):
        A, b, w = rng.normal(size=(m, n)), rng.normal(size=m), rng.uniform(0.1, 10.0, m)
        H, g = np.empty((n, n)), np.empty(n)
        linalg.normal_equations(A, b, w, H, g)
        np.testing.assert_allclose(H, A.T @ (w[:, None] * A), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(g, A.T @ (w * b), rtol=1e-12, atol=1e-12)
        x = np.empty(n)
        definite = linalg.cholesky_solve(H, g, x)
        assert definite == (m >= n)
        if definite:
            np.testing.assert_allclose(x, np.linalg.solve(H, g), rtol=1e-9, atol=1e-12)
            L = np.zeros((n, n))
            assert linalg.cholesky(H, 1e-12, L)
            np.testing.assert_allclose(L, np.linalg.cholesky(H), rtol=1e-10, atol=1e-12)
    assert not linalg.cholesky_solve(np.zeros((2, 2)), np.ones(2), np.empty(2))
    assert not linalg.cholesky(np.array([[1.0, 0.0], [0.0, np.nan]]), 1e-12, np.zeros((2, 2)))


def test_weighted_rows(rng: np.random.Generator) -> None:
    A, b = rng.normal(size=(6, 7)), rng.normal(size=6)
    w, unit = rng.uniform(0.1, 10.0, 6), rng.uniform(0.5, 2.0, 6)
    A_out, b_out = np.empty((6, 7)), np.empty(6)
    peak = linalg.weighted_rows(A, b, w, 10.0, unit, 1.0, A_out, b_out)
    f = np.sqrt(w / 10.0) / unit
    np.testing.assert_allclose(A_out, A * f[:, None], rtol=1e-15)
    np.testing.assert_allclose(b_out, b * f, rtol=1e-15)
    assert peak == np.abs(b * f).max()


def test_row_values_against_numpy(rng: np.random.Generator) -> None:
    for _ in range(100):
        m, n = rng.integers(1, 9, 2)
        A, x = rng.normal(size=(m, n)), rng.normal(size=n)
        np.testing.assert_allclose(linalg.row_values(A, x), A @ x, atol=1e-13)


@pytest.mark.parametrize(("m", "n"), [(6, 7), (6, 14), (18, 24), (1, 4), (6, 6), (0, 3)])
def test_householder_null_is_q_s_trailing_columns(m: int, n: int, rng: np.random.Generator) -> None:
    """householder_vectors' reflectors: householder_qr's R bit for bit, and Q's trailing
    columns (the rows' null space) from them, to rounding; dependent and zero columns too."""
    for rank in {min(m, n), max(min(m, n) - 1, 0), 0}:
        for _ in range(50):
            J = random_rows(rng, m, n, rank)
            Q, R = np.empty((n, n)), np.empty((n, m))
            linalg.householder_qr(J.T.copy(), Q, R)
            k = max(min(n - 1, m), 0)
            R2, V, beta = np.empty((n, m)), np.empty((k, n)), np.empty(k)
            linalg.householder_vectors(J.T.copy(), R2, V, beta)
            np.testing.assert_array_equal(R2, R)
            N = np.empty((n - m, n))
            linalg.householder_null(V, beta, m, N)
            np.testing.assert_allclose(N, Q[:, m:].T, atol=1e-13)
            np.testing.assert_allclose(J @ N.T, 0.0, atol=1e-12 * np.abs(J).max(initial=1.0))
