"""The QP builders, tested without any backend: optimality of x_free, the null-space terms."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from solvers.dls import Damping, damped_least_squares, task_svd
from solvers.errors import InputError
from solvers.joint_bounds import VelocityBounds, joint_velocity_bounds
from solvers.qp_problem import direction_problem, priority_problem, tracking_problem


def wide(n: int, v: float = 1e9) -> VelocityBounds:
    kinds = np.zeros(n, dtype=np.int8)
    return VelocityBounds(np.full(n, -v), np.full(n, v), kinds, kinds)


def jacobians(rng: np.random.Generator, count: int) -> list[np.ndarray]:
    arms = [rrc_pin.load(name) for name in ("rrc_k1607", "panda", "barker6")]
    out = []
    for k in range(count):
        arm = arms[k % len(arms)]
        out.append(arm.jacobian(arm.random_q(rng)))
    out.append(arms[0].jacobian(np.zeros(7)))  # exactly singular
    return out


def test_tracking_free_minimiser_is_damped_least_squares(rng: np.random.Generator) -> None:
    for J in jacobians(rng, 60):
        n = J.shape[1]
        x = rng.standard_normal(6)
        svd = task_svd(J, None, Damping())
        p = tracking_problem(svd, x, wide(n))
        assert np.allclose(p.P, p.P.T, atol=1e-12)
        assert np.linalg.eigvalsh(p.P).min() > 0.0
        assert np.allclose(p.P @ p.x_free + p.q, 0.0, atol=1e-9 * (1 + np.abs(p.q).max()))
        assert np.allclose(p.x_free, damped_least_squares(J, x), atol=1e-9)
        assert p.free_in_box() and p.rates(p.x_free) is p.x_free


def test_tracking_secondary_acts_in_the_null_space_only(rng: np.random.Generator) -> None:
    for J in jacobians(rng, 60):
        n = J.shape[1]
        x = rng.standard_normal(6)
        z = rng.standard_normal(n)
        svd = task_svd(J, None, Damping())
        p0 = tracking_problem(svd, x, wide(n))
        p1 = tracking_problem(svd, x, wide(n), secondary=z, secondary_weight=0.05)
        assert np.allclose(J @ p1.x_free, J @ p0.x_free, atol=1e-9)
        assert np.allclose(p1.P @ p1.x_free + p1.q, 0.0, atol=1e-8)
        if n > 6 and svd.rank == 6:  # the secondary gets its null-space part, discounted
            Vn = svd.Vt[6:]
            mu, lam = 0.05, svd.lambda_sq
            assert np.allclose(Vn @ p1.x_free, mu / (mu + lam) * (Vn @ z), atol=1e-9)


def test_tracking_rejects_zero_secondary_weight() -> None:
    svd = task_svd(np.eye(3), None, Damping())
    with pytest.raises(InputError) as info:
        tracking_problem(svd, np.ones(3), wide(3), secondary_weight=0.0)
    assert info.value.argument == "secondary_weight"


def test_direction_keeps_the_direction_for_every_x(rng: np.random.Generator) -> None:
    for J in jacobians(rng, 60):
        n = J.shape[1]
        x = rng.standard_normal(6) * rng.choice([0.1, 1.0, 1e6])
        svd = task_svd(J, None, Damping())
        dls = svd.dls(x)
        bounds = VelocityBounds(-np.ones(n), np.ones(n), np.zeros(n, np.int8), np.zeros(n, np.int8))
        p = direction_problem(svd, dls, bounds)
        assert p.P.shape == (n - svd.rank + 1,) * 2
        assert 0.0 < p.scale_factor <= 1.0
        assert np.linalg.norm(p.G[:, -1]) <= np.sqrt(n) * (1 + 1e-12)  # capped by the box
        for _ in range(5):
            xv = rng.standard_normal(p.P.shape[0])
            rates = p.rates(xv)
            # J qdot = s J qdot_dls with s = u * scale_factor, whatever the null coordinates
            s = p.scale(xv)
            tol = 1e-9 * (1 + abs(s) * np.abs(J @ dls).max())
            assert np.allclose(J @ rates, s * (J @ dls), atol=tol)


def test_direction_free_point_is_the_full_damped_step(rng: np.random.Generator) -> None:
    arm = rrc_pin.load("panda")
    J = arm.jacobian(arm.random_q(rng))
    x = np.array([0.01, 0.0, 0.02, 0.0, 0.05, 0.0])
    svd = task_svd(J, None, Damping())
    dls = svd.dls(x)
    p = direction_problem(svd, dls, wide(7, 10.0))
    assert p.free_in_box()
    assert p.scale(p.x_free) == 1.0
    assert np.allclose(p.rates(p.x_free), dls, atol=1e-12)


def test_direction_needs_zero_in_the_bounds() -> None:
    svd = task_svd(np.eye(3), None, Damping())
    b = joint_velocity_bounds([2.0, 0.0, 0.0], [-1.0] * 3, [1.0] * 3, [1.0] * 3, 0.01)
    with pytest.raises(InputError) as info:
        direction_problem(svd, np.ones(3), b)
    assert info.value.argument == "bounds"


def test_priority_keeps_the_primary_task_velocity(rng: np.random.Generator) -> None:
    for J in jacobians(rng, 60):
        n = J.shape[1]
        svd = task_svd(J, None, Damping())
        q1 = rng.standard_normal(n)
        z = rng.standard_normal(n)
        p = priority_problem(svd, q1, wide(n), z)
        assert p.P.shape == (n - svd.rank,) * 2
        for _ in range(5):
            xv = rng.standard_normal(p.P.shape[0])
            assert np.allclose(J @ p.rates(xv), J @ q1, atol=1e-9)
        # free point: the rates nearest z among those with the primary's task velocity
        free = p.rates(p.x_free)
        Vn = svd.Vt[svd.rank :]
        assert np.allclose(Vn @ free, Vn @ z, atol=1e-10)
