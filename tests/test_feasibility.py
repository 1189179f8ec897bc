"""Rates against the step's bounds (rrc_pin.solvers.tick.feasibility) against plain numpy. The
whole suite also runs once with ``NUMBA_DISABLE_JIT=1`` (.ci/run), the same source as plain
Python.
"""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.tick import feasibility


def test_inside_and_rows_hold(rng: np.random.Generator) -> None:
    for _ in range(500):
        n = int(rng.integers(1, 9))
        lb, ub = -rng.uniform(0, 1, n), rng.uniform(0, 1, n)
        x = rng.uniform(-1.2, 1.2, n)
        assert feasibility.inside(x, lb, ub) == bool(((x >= lb) & (x <= ub)).all())
        G, h = rng.normal(size=(3, n)), rng.normal(size=3)
        tol = float(rng.choice([0.0, 0.5]))
        assert feasibility.rows_hold(G, x, h, tol) == bool((G @ x <= h + tol).all())
    assert not feasibility.inside(np.array([np.nan]), np.array([-1.0]), np.array([1.0]))
    assert not feasibility.rows_hold(np.ones((1, 1)), np.array([np.nan]), np.zeros(1), 0.0)


def test_clip_into(rng: np.random.Generator) -> None:
    x = rng.normal(size=9) * 2.0
    lb, ub = -np.ones(9), np.ones(9)
    before, clipped = x.copy(), np.clip(x, lb, ub)
    size = feasibility.clip_into(x, lb, ub)
    np.testing.assert_array_equal(x, clipped)
    assert size == pytest.approx(np.linalg.norm(clipped - before), rel=1e-15)


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
        got = feasibility.into_rows(G, h, x)
        assert got == pytest.approx(want, rel=1e-12, abs=0.0)
        assert (G @ (x * got) <= h + 1e-15).all()


def test_a_row_held_at_zero_and_met_to_rounding_keeps_the_rates() -> None:
    """0.1 + 0.2 - 0.3 is 5.6e-17 in floating point: a row at bound 0 met to rounding, which
    used to scale the whole answer to zero (a tripod stopped mid-walk, reported exact)."""
    G, x = np.array([[0.1, 0.2, -0.3]]), np.ones(3)
    assert (G @ x)[0] > 0.0
    assert feasibility.into_rows(G, np.zeros(1), x) == 1.0
    left = x + np.array([1e-9, 0.0, 0.0])  # the row left: standing still
    assert feasibility.into_rows(G, np.zeros(1), left) == 0.0


def test_around_start_against_numpy(rng: np.random.Generator) -> None:
    """A bound z = 0 breaks by at most tol is widened to it, one it breaks by more kept; every
    bound widened by the rounding."""
    tol, rounding = 1e-6, 1e-12
    for _ in range(200):
        lo = rng.choice([-np.inf, -1.0, -1e-7, 0.0, 5e-7, 2e-6, 1.0], size=8)
        hi = rng.choice([np.inf, 1.0, 1e-7, 0.0, -5e-7, -2e-6, -1.0], size=8)
        want_lo = np.where(lo <= tol, np.minimum(lo, 0.0), lo) - rounding
        want_hi = np.where(hi >= -tol, np.maximum(hi, 0.0), hi) + rounding
        feasibility.around_start(lo, hi, tol, rounding)
        np.testing.assert_array_equal(lo, want_lo)
        np.testing.assert_array_equal(hi, want_hi)


def test_release_unmoved_against_numpy(rng: np.random.Generator) -> None:
    """A row the start meets whose coefficients are at most UNMOVED of its row's size (the box's
    rows of unit size, then G's) is dropped; every other row kept as it is."""
    n, p, d = 5, 3, 3
    for _ in range(200):
        G = rng.normal(size=(p, n)) * rng.choice([1e-3, 1.0, 1e3], size=(p, 1))
        C = rng.normal(size=(n + p, d))
        size = np.concatenate([np.ones(n), np.linalg.norm(G, axis=1)])
        rounding = rng.random(n + p) < 0.5
        C[rounding] *= (size[rounding] * rng.choice([1e-17, 1e-16, 1e-12], rounding.sum()))[:, None]
        lo = rng.choice([-np.inf, -1.0, 0.0, 1e-7], size=n + p)
        hi = rng.choice([np.inf, 1.0, 0.0, -1e-7], size=n + p)
        unmoved = np.linalg.norm(C, axis=1) <= feasibility.UNMOVED * size
        dropped = unmoved & (lo <= 0.0) & (hi >= 0.0)
        want_lo, want_hi = np.where(dropped, -np.inf, lo), np.where(dropped, np.inf, hi)
        feasibility.release_unmoved(C, G, lo, hi)
        np.testing.assert_array_equal(lo, want_lo)
        np.testing.assert_array_equal(hi, want_hi)
