"""The compiled tick's top level (solvers/tick/top.py): its status codes are the pipeline's, its
small pieces against numpy; its stages against the pipeline's run in tests/test_tick.py and
tests/test_tick_answers.py."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.tick import factor, pipeline, statuses, top
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.direction import along
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.problem import Box
from rrc_pin.solvers.tick.statuses import scale_and_veer

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]


@pytest.mark.parametrize("seed", SEEDS)
def test_norm_scale_and_veer_against_numpy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(200):
        x = rng.normal(size=int(rng.integers(1, 9))) * 10.0 ** rng.integers(-200, 200)
        peak = float(np.abs(x).max())  # numpy's squares overflow beyond 1e154
        assert statuses.norm(x) == pytest.approx(peak * float(np.linalg.norm(x / peak)), rel=1e-14)
        A = rng.normal(size=(3, 5))
        b, qdot = rng.normal(size=3), rng.normal(size=5)
        per_unit = rng.uniform(0.5, 2.0, 3)
        scale, veer = scale_and_veer(A @ qdot, b, per_unit)
        got = top.along_command(A, b, qdot, per_unit, 0.5)
        assert got == pytest.approx((0.5 * scale, veer), abs=1e-12)
    assert statuses.norm(np.zeros(3)) == 0.0


@pytest.mark.parametrize("seed", SEEDS)
def test_the_box_scale_of_no_or_one_null_direction_is_the_pipelines(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 6
    lb, ub = -rng.uniform(0.1, 1.0, n), rng.uniform(0.1, 1.0, n)
    rows = top.Rows(lb, ub, np.zeros((0, n)), np.zeros(0), np.zeros(0), 1e-6, np.zeros(2))
    box = Box(lb, ub, np.zeros((2, n), np.int8), True, False, np.ones(n))
    for d in (0, 1):
        for _ in range(100):
            w = rng.normal(size=n) * 3.0
            null = np.linalg.qr(rng.normal(size=(n, n)))[0][:, :d].T.copy()
            qdot, u, veer = top.scaled_along(np.eye(n), w, null, rows)
            want = along(w, null, box, None)
            assert want is not None and u == want.u and veer == want.veer == 0.0
            np.testing.assert_allclose(qdot, want.qdot, atol=1e-15)


def test_slide_rows_are_the_marked_ones() -> None:
    G, h = np.arange(12.0).reshape(4, 3), np.arange(4.0)
    rows = top.Rows(np.zeros(3), np.ones(3), G, h, np.array([1.0, 0.0, 1.0, 0.0]), 1e-6,
                    np.zeros(2))
    Gs, hs = top.slide_rows(rows)
    np.testing.assert_array_equal(Gs, G[[0, 2]])
    np.testing.assert_array_equal(hs, h[[0, 2]])


@pytest.mark.parametrize("seed", SEEDS)
def test_the_damping_of_rows_clamped_short_of_rank_is_the_pipelines(seed: int) -> None:
    """Up to two of seven joints held: where the clamped rows are short of rank, the rows' own
    factorisation is damped where its rank is higher, as the pipeline's ``_damping`` (its
    ``|u_i^T b|`` by numpy's product: equal within rounding).
    """
    rng = np.random.default_rng(seed)
    m, n, dt, kappa = 6, 7, 0.01, 100.0
    for _ in range(100):
        U, V = np.linalg.qr(rng.normal(size=(m, m)))[0], np.linalg.qr(rng.normal(size=(n, n)))[0]
        smallest = 10.0 ** -rng.uniform(1.5, 4.0)  # past the damping's threshold
        sigma = np.sort(rng.uniform(0.5, 2.0, m))[::-1] * np.r_[np.ones(m - 1), smallest]
        A = U @ np.diag(sigma) @ V[:, :m].T
        b = rng.normal(size=m)
        held = rng.choice(n, size=int(rng.integers(0, 3)), replace=False)
        w = np.linalg.pinv(A) @ b
        lb, ub = -rng.uniform(0.1, 1.0, n), rng.uniform(0.1, 1.0, n)
        for j in held:  # the bound w pushes against holds the joint still
            (ub if w[j] > 0.0 else lb)[j] = 0.0
        rows = top.Rows(lb, ub, np.zeros((0, n)), np.zeros(0), np.zeros(0), 1e-6, np.zeros(2))
        box = Box(lb, ub, np.zeros((2, n), np.int8), True, False, np.ones(n))
        scale = float(rng.uniform(0.0, 0.9))
        usable, lam = top.damping(factor.qr(A), b, w, scale, rows, dt, kappa)
        want, chosen = pipeline._damping(Damping(kappa), Factorization(A), b, w, scale, box, dt,
                                         True)  # fmt: skip
        np.testing.assert_array_equal(usable.J, chosen.J)
        np.testing.assert_allclose(lam, np.empty(0) if want is None else want, rtol=1e-12)
