"""Damped least squares with adaptive damping, and Nguyen's weighted pseudo-inverse (eqs 21-23)."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from solvers.dls import (
    Damping,
    damped_least_squares,
    null_space_projector,
    task_svd,
    weight_factor,
    weighted_pseudo_inverse,
    weighted_rates,
)
from solvers.errors import InputError


def spd(rng: np.random.Generator, n: int) -> np.ndarray:
    A = rng.standard_normal((n, n))
    return A @ A.T + n * np.eye(n)


# --- the damping schedule ---------------------------------------------------------------


def test_sigma_schedule_values() -> None:
    d = Damping(lambda_max=0.1, threshold=0.05)
    assert d.lambda_sq(np.array([1.0, 0.05])) == 0.0
    assert d.lambda_sq(np.array([1.0, 0.0])) == pytest.approx(0.01, abs=1e-15)
    # (1 - (0.025/0.05)^2) * 0.1^2 = 0.0075
    assert d.lambda_sq(np.array([1.0, 0.025])) == pytest.approx(0.0075, abs=1e-15)
    # continuous at the threshold, monotone below it
    s = np.linspace(0.0, 0.06, 61)
    lam = [d.lambda_sq(np.array([1.0, x])) for x in s]
    assert np.all(np.diff(lam) <= 0.0)
    assert d.lambda_sq(np.array([1.0, 0.05 - 1e-12])) < 1e-12


def test_manipulability_schedule_and_floor() -> None:
    d = Damping(lambda_max=0.2, threshold=0.01, measure="manipulability", floor=0.001)
    # w = 0.1 * 0.05 = 0.005 -> lambda = 0.2 * (1 - 0.5)^2 = 0.05
    assert d.lambda_sq(np.array([0.1, 0.05])) == pytest.approx(0.05**2 + 1e-6, rel=1e-12)
    assert d.lambda_sq(np.array([1.0, 1.0])) == pytest.approx(1e-6, rel=1e-12)
    assert d.lambda_sq(np.array([1.0, 0.0])) == pytest.approx(0.04 + 1e-6, rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"lambda_max": -1.0}, "lambda_max"),
        ({"floor": float("nan")}, "floor"),
        ({"threshold": 0.0}, "threshold"),
        ({"measure": "cond"}, "measure"),
    ],
)
def test_damping_rejects_bad_values(kwargs: dict, argument: str) -> None:
    with pytest.raises(InputError) as info:
        Damping(**kwargs)
    assert info.value.argument == argument


# --- damped least squares -------------------------------------------------------------


def test_dls_equals_normal_equations(rng: np.random.Generator) -> None:
    for _ in range(200):
        m, n = rng.integers(2, 7), rng.integers(2, 8)
        J = rng.standard_normal((m, n)) * rng.choice([1e-3, 1.0, 10.0])
        x = rng.standard_normal(m)
        W = spd(rng, m)
        d = Damping(lambda_max=0.3, threshold=1e4)  # damped at every J drawn here
        svd = task_svd(J, weight_factor(W, m), d)
        lam = svd.lambda_sq
        assert lam > 0.0
        ref = np.linalg.solve(J.T @ W @ J + lam * np.eye(n), J.T @ W @ x)
        got = damped_least_squares(J, x, d, W)
        assert np.allclose(got, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())


def test_dls_undamped_is_the_pseudo_inverse(rng: np.random.Generator) -> None:
    for _ in range(200):
        m, n = 6, rng.integers(6, 9)
        J = rng.standard_normal((m, n))
        x = rng.standard_normal(m)
        got = damped_least_squares(J, x, Damping(lambda_max=0.0))
        assert np.allclose(got, np.linalg.pinv(J) @ x, rtol=1e-9, atol=1e-12)


def test_dls_finite_at_exact_singularities() -> None:
    cases = [("barker6", np.zeros(6)), ("rrc_k1607", np.zeros(7)), ("kr5_3r", np.zeros(3))]
    for name, q in cases:
        arm = rrc_pin.load(name)
        J = arm.jacobian(q)
        sigma = np.linalg.svd(J, compute_uv=False)
        for scale in (1.0, 1e6):
            x = scale * np.ones(6)
            qdot = damped_least_squares(J, x)
            assert np.all(np.isfinite(qdot)), name
            # the damping bounds every gain by 1 / (2 lambda_max) = 10
            assert np.linalg.norm(qdot) <= 10.0 * np.linalg.norm(x) * (1 + 1e-12), name
        if name != "kr5_3r":
            assert sigma[-1] < 1e-12  # these really are singular


def test_dls_rejects_bad_input() -> None:
    J = np.eye(3)
    with pytest.raises(InputError) as info:
        damped_least_squares(J, [1.0, 2.0])
    assert info.value.argument == "xdot"
    with pytest.raises(InputError) as info:
        damped_least_squares(np.array([[np.nan, 0, 0]] * 3), np.ones(3))
    assert info.value.argument == "J"
    with pytest.raises(InputError) as info:
        damped_least_squares(J, np.ones(3), weights=[1.0, -1.0, 1.0])
    assert info.value.argument == "weights"
    with pytest.raises(InputError) as info:
        damped_least_squares(J, np.ones(3), weights=-np.eye(3))
    assert info.value.argument == "weights"


# --- Nguyen eqs. (21)-(23) -------------------------------------------------------------


def test_weighted_pseudo_inverse_is_eq_22(rng: np.random.Generator) -> None:
    for _ in range(200):
        n = rng.integers(6, 10)
        J = rng.standard_normal((6, n))
        W = spd(rng, n)
        ref = W @ J.T @ np.linalg.inv(J @ W @ J.T)  # Nguyen eq. (22) as printed
        assert np.allclose(weighted_pseudo_inverse(J, W), ref, rtol=1e-8, atol=1e-10)
        w = rng.uniform(0.1, 10.0, n)
        ref = np.diag(w) @ J.T @ np.linalg.inv(J @ np.diag(w) @ J.T)
        assert np.allclose(weighted_pseudo_inverse(J, w), ref, rtol=1e-8, atol=1e-10)


def test_identity_weight_is_moore_penrose_eq_23(rng: np.random.Generator) -> None:
    J = rng.standard_normal((6, 7))
    assert np.allclose(weighted_pseudo_inverse(J), J.T @ np.linalg.inv(J @ J.T), atol=1e-12)
    assert np.allclose(weighted_pseudo_inverse(J), np.linalg.pinv(J), atol=1e-12)


def test_eq_21_minimises_the_weighted_norm(rng: np.random.Generator) -> None:
    """Among all q with J q = x, J_W^+ x has the least q^T W^-1 q (Nguyen eq. (20)-(22))."""
    for _ in range(100):
        J = rng.standard_normal((6, 7))
        W = spd(rng, 7)
        x = rng.standard_normal(6)
        q0 = weighted_rates(J, x, W)
        assert np.allclose(J @ q0, x, atol=1e-10)
        Winv = np.linalg.inv(W)
        for _ in range(5):
            z = rng.standard_normal(7)
            q = weighted_rates(J, x, W, z)
            assert np.allclose(J @ q, x, atol=1e-9)  # the z term lies in the null space
            assert q @ Winv @ q >= q0 @ Winv @ q0 - 1e-10


def test_rrc_k1607_pseudo_inverse_reproduces_joint_rates(rng: np.random.Generator) -> None:
    """Section 5 of Nguyen: x = J qdot, then J^+ x; the difference lies in the null space."""
    arm = rrc_pin.load("rrc_k1607")
    for _ in range(50):
        q = arm.random_q(rng)
        J = arm.jacobian(q)
        qdot = rng.uniform(-1.0, 1.0, 7)
        back = weighted_rates(J, J @ qdot)
        assert np.allclose(J @ back, J @ qdot, atol=1e-10)
        assert np.allclose(null_space_projector(J) @ (qdot - back), qdot - back, atol=1e-9)


def test_singular_jwj_stays_finite() -> None:
    """J W J^T singular (rrc_k1607 at home): eq. (22) cannot be evaluated, the SVD form can."""
    arm = rrc_pin.load("rrc_k1607")
    J = arm.jacobian(np.zeros(7))
    W = np.diag([1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0])
    assert np.linalg.matrix_rank(J @ W @ J.T) == 5
    pinv = weighted_pseudo_inverse(J, W)
    assert np.all(np.isfinite(pinv))
    assert np.allclose(J @ pinv @ J, J, atol=1e-10)  # generalized inverse property
    N = null_space_projector(J, W)
    assert np.allclose(J @ N, 0.0, atol=1e-10)
    assert np.allclose(N @ N, N, atol=1e-10)


def test_nguyen_functions_reject_bad_input() -> None:
    J = np.ones((6, 7))
    with pytest.raises(InputError) as info:
        weighted_pseudo_inverse(J, np.ones(6))
    assert info.value.argument == "W"
    with pytest.raises(InputError) as info:
        weighted_rates(J, np.ones(6), z=np.ones(6))
    assert info.value.argument == "z"
    with pytest.raises(InputError) as info:
        weighted_pseudo_inverse(J, rcond=1.5)
    assert info.value.argument == "rcond"
