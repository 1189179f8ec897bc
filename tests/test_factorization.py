"""Factorization: QR least-norm rates, the SVD on demand, null spaces and the condition."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.tick.factorization import RANK_TOL, Factorization


@pytest.mark.parametrize(
    ("m", "n", "rank"),
    [(6, 7, 6), (6, 7, 5), (6, 6, 6), (6, 6, 4), (12, 15, 12), (12, 7, 7), (15, 3, 3), (3, 3, 0)],
)
def test_rates_null_space_and_condition(
    m: int, n: int, rank: int, rng: np.random.Generator
) -> None:
    for _ in range(100):
        U, _ = np.linalg.qr(rng.normal(size=(m, m)))
        V, _ = np.linalg.qr(rng.normal(size=(n, n)))
        sigma = np.zeros(min(m, n))
        sigma[:rank] = 10.0 ** rng.uniform(-2, 2, rank)
        J = (U[:, : sigma.size] * sigma) @ V[:, : sigma.size].T
        b = rng.normal(size=m)
        f = Factorization(J)
        x = f.least_norm(b)
        np.testing.assert_allclose(x, np.linalg.pinv(J, rcond=RANK_TOL) @ b, atol=1e-9)
        null = f.null_basis()
        assert null.shape == (n - rank, n)
        np.testing.assert_allclose(null @ null.T, np.eye(n - rank), atol=1e-12)
        np.testing.assert_allclose(J @ null.T, 0.0, atol=1e-12 * max(1.0, sigma.max()))
        _, s, _, r = f.svd
        assert r == rank
        np.testing.assert_allclose(
            s, np.linalg.svd(J, compute_uv=False), atol=1e-12 * s[0] + 1e-300
        )
        expected = np.inf if rank < min(m, n) or rank == 0 else sigma.max() / sigma[:rank].min()
        assert f.condition() == pytest.approx(expected, rel=1e-9)


def test_damped_rates(rng: np.random.Generator) -> None:
    J = rng.normal(size=(6, 7))
    b = rng.normal(size=6)
    f = Factorization(J)
    lam = np.full(6, 0.3)
    expected = J.T @ np.linalg.solve(J @ J.T + 0.3 * np.eye(6), b)
    np.testing.assert_allclose(f.rates(b, lam), expected, atol=1e-12)
