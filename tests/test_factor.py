"""The compiled tick's factorisation record (solvers/tick/factor.py) against numpy, and against
the Factorization class it twins (the same kernels in the same order: the same floats)."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.tick import factor
from rrc_pin.solvers.tick.factorization import RANK_TOL, Factorization

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]
TOL = 1e-12


def rows(rng: np.random.Generator) -> np.ndarray:
    """Rows (m, n) of a random shape: full rank, rank deficient, or more rows than joints."""
    m, n = int(rng.integers(1, 8)), int(rng.integers(1, 9))
    J = rng.normal(size=(m, n))
    if m > 1 and rng.random() < 0.3:  # a dependent row
        J[-1] = J[0] * rng.normal()
    return J


@pytest.mark.parametrize("seed", SEEDS)
def test_qr_svd_rates_and_null_space_against_numpy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(200):
        J = rows(rng)
        m, n = J.shape
        b = rng.normal(size=m)
        f = factor.qr(J)
        np.testing.assert_allclose(f.Q @ f.R, J.T, atol=TOL * (1 + np.abs(J).max()))
        np.testing.assert_allclose(f.Q.T @ f.Q, np.eye(n), atol=TOL)
        f, x = factor.least_norm(f, b)
        np.testing.assert_allclose(x, np.linalg.pinv(J, rcond=RANK_TOL) @ b, atol=1e-9)
        f = factor.with_svd(f)
        sigma = np.linalg.svd(J, compute_uv=False)
        np.testing.assert_allclose(f.sigma, sigma, atol=TOL * (1 + sigma[0]))
        assert f.rank == int(np.sum(sigma > RANK_TOL * sigma[0]))
        _, N = factor.null_basis(f)
        assert N.shape == (n - f.rank, n)
        np.testing.assert_allclose(J @ N.T, 0.0, atol=1e-9 * (1 + sigma[0]))
        np.testing.assert_allclose(N @ N.T, np.eye(N.shape[0]), atol=TOL)
        expected = sigma[0] / sigma[f.rank - 1] if f.rank == min(m, n) else np.inf
        assert factor.condition(f) == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("seed", SEEDS)
def test_the_record_gives_the_class_floats(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(200):
        J = rows(rng)
        m, n = J.shape
        b = rng.normal(size=m)
        lb, ub = -rng.uniform(0.1, 2.0, n), rng.uniform(0.1, 2.0, n)
        f, w, fits, boxed, u = factor.fitted(J, b, lb, ub)
        g, x, fit, along = Factorization.fitted(J, b, lb, ub)
        assert np.array_equal(w, x) and fits == fit and f.regular == g.regular
        assert (u >= 0.0) == (along is not None)
        if along is not None:
            assert u == along.u and np.array_equal(boxed, along.qdot)
        f, null = factor.null_basis(f)
        assert np.array_equal(null, g.null_basis())
        lam = rng.uniform(0.0, 1.0, min(m, n))
        assert np.array_equal(factor.rates(factor.with_svd(f), b, lam), g.rates(b, lam))


@pytest.mark.parametrize("seed", SEEDS)
def test_surely_conditioned_only_where_numpys_condition_is_below(seed: int) -> None:
    """True only for full row rank and numpy's condition number at most the threshold; and
    true for rows well below it (the Frobenius bound is at most m times the condition)."""
    rng = np.random.default_rng(seed)
    said = 0
    for _ in range(400):
        J = rows(rng) * 10.0 ** rng.uniform(-3, 3)
        m, n = J.shape
        f = factor.qr(J)
        sigma = np.linalg.svd(J, compute_uv=False)
        full = m <= n and sigma[-1] > RANK_TOL * sigma[0]
        kappa = float(sigma[0] / sigma[-1]) if full else np.inf
        threshold = float(10.0 ** rng.uniform(0, 3))
        sure = factor.surely_conditioned(f, threshold)
        assert not sure or kappa <= threshold, (seed, kappa, threshold)
        if kappa * m <= threshold * (1 - 1e-8):
            assert sure, (seed, kappa, threshold)
        said += sure
    assert said > 20, seed
