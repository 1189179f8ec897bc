"""The exam's 3R arm: its worked numbers, and the closed forms against Pinocchio."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.solvers.closed_form.three_r import AngularRates, ThreeRClosedForm, minimum_norm_shift
from rrc_pin.solvers.errors import InvalidInput

ARM = rrc_pin.load("kr5_3r")  # Pinocchio, from the generated URDF
CF = ARM.closed_form
EXAM_Q = np.array([0.0, np.pi / 4, -np.pi / 4])
EXAM_V = np.array([1.0, 1.0, 0.5])
TOL = 5e-5 + 5e-5  # the exam prints 4 decimals: rounding (5e-5) plus our margin (5e-5)
SIGMA_MIN = 0.05  # [m] away from singularities (largest singular value ~1.2)


def sample(rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.uniform(ARM.lower, ARM.upper, size=(n, 3))


def relative(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    axes = tuple(range(1, a.ndim))
    return np.sqrt(((a - b) ** 2).sum(axis=axes) / (b**2).sum(axis=axes))


@pytest.fixture(scope="module")
def regular():
    """>= 10000 random configurations within the limits, away from singularities."""
    rng = np.random.default_rng(3003)
    Q = sample(rng, 12_000)
    J = np.array([ARM.jacobian(q) for q in Q])
    keep = np.linalg.svd(J[:, :3], compute_uv=False)[:, -1] > SIGMA_MIN
    assert keep.sum() >= 10_000
    return Q[keep], J[keep], rng.standard_normal((keep.sum(), 3))


# ------------------------------------------------------------- the exam's numbers


def test_catalogue_passes_the_exam_lengths():
    assert isinstance(CF, ThreeRClosedForm)
    assert (CF.a1, CF.a2, CF.a3) == (0.2, 0.5, 0.5)
    assert (CF.nq, CF.task_dim) == (3, 3)


def test_exam_jacobians_eq_2():
    np.testing.assert_allclose(
        CF.jacobian(EXAM_Q), [[0, -0.3536, 0], [1.0536, 0, 0], [0, 0.8536, 0.5]], rtol=0, atol=TOL
    )
    np.testing.assert_allclose(
        CF.angular_jacobian(EXAM_Q), [[0, 0, 0], [0, -1, -1], [1, 0, 0]], rtol=0, atol=1e-15
    )


def test_exam_joint_rates_and_angular_velocity_eq_3():
    thetadot = CF.joint_rates(EXAM_Q, EXAM_V)
    np.testing.assert_allclose(thetadot, [0.9492, -2.8284, 5.8284], rtol=0, atol=TOL)
    omega = CF.angular_velocity(EXAM_Q, thetadot)
    np.testing.assert_allclose(omega, [0, -3, 0.9492], rtol=0, atol=TOL)
    assert np.linalg.norm(thetadot) == pytest.approx(6.5476, abs=TOL)


def test_exam_null_space_gamma_and_minimum_norm_step_5():
    thetadot = CF.joint_rates(EXAM_Q, EXAM_V)
    omega = CF.angular_velocity(EXAM_Q, thetadot)
    n = CF.angular_null_space(EXAM_Q)
    np.testing.assert_allclose(n * np.sqrt(2.0), [0, 1, -1], atol=1e-15)  # span (0, 1, -1)
    gamma = minimum_norm_shift(thetadot, [0, 1, -1])
    assert gamma == pytest.approx(4.3284, abs=TOL)
    best = thetadot + gamma * np.array([0, 1, -1])
    np.testing.assert_allclose(best, [0.9492, 1.5, 1.5], rtol=0, atol=TOL)
    assert np.linalg.norm(best) == pytest.approx(2.3240, abs=TOL)
    rates = CF.rates_for_angular_velocity(EXAM_Q, omega)
    assert isinstance(rates, AngularRates)
    np.testing.assert_allclose(rates.minimum_norm, best, atol=1e-12)
    np.testing.assert_allclose(rates.null_direction, n, atol=0)
    assert rates.residual < 1e-15
    # The exam's thetadot is one of the solutions: particular + gamma' n.
    g = (thetadot - rates.particular) @ n
    np.testing.assert_allclose(rates.particular + g * n, thetadot, atol=1e-12)


def test_exam_erratum_beta_is_thetadot2_plus_thetadot3():
    # Printed (step 6): omega = alpha z0 + beta (s1, -c1, 0) "with alpha = thetadot_1 and
    # beta = thetadot_1 + thetadot_2". From eq. (1), beta = thetadot_2 + thetadot_3.
    rng = np.random.default_rng(1)
    for q, qd in zip(sample(rng, 100), rng.standard_normal((100, 3)), strict=True):
        s1, c1 = np.sin(q[0]), np.cos(q[0])
        omega = CF.angular_velocity(q, qd)
        np.testing.assert_allclose(omega, ARM.jacobian(q)[3:] @ qd, atol=1e-14)
        corrected = qd[0] * np.array([0, 0, 1]) + (qd[1] + qd[2]) * np.array([s1, -c1, 0])
        printed = qd[0] * np.array([0, 0, 1]) + (qd[0] + qd[1]) * np.array([s1, -c1, 0])
        np.testing.assert_allclose(omega, corrected, atol=1e-14)
        assert np.abs(omega - printed).max() > 1e-3 * abs(qd[2] - qd[0])


# ------------------------------------------------------------- against Pinocchio


def test_jacobians_match_pinocchio(regular):
    Q, J_pin, _ = regular
    assert relative(CF.jacobian_batch(Q), J_pin[:, :3]).max() < 1e-9  # reached: ~3e-16
    assert relative(CF.angular_jacobian_batch(Q), J_pin[:, 3:]).max() < 1e-9
    scalar = np.array([CF.twist_jacobian(q) for q in Q])
    assert relative(scalar, J_pin).max() < 1e-9


def test_joint_rates_match_a_solve_with_pinocchios_jacobian(regular):
    Q, J_pin, V = regular
    ref = np.linalg.solve(J_pin[:, :3], V[:, :, None])[:, :, 0]
    assert relative(CF.joint_rates_batch(Q, V), ref).max() < 1e-9  # reached: ~1e-14
    scalar = np.array([CF.joint_rates(q, v) for q, v in zip(Q, V, strict=True)])
    assert relative(scalar, ref).max() < 1e-9


def test_home_and_each_joint_zero_match_lstsq():
    # theta3 = 0 (arm stretched, home included) is singular: minimum-norm least squares there.
    rng = np.random.default_rng(2)
    Q = [np.zeros(3)]
    for i in range(3):
        Qi = sample(rng, 200)
        Qi[:, i] = 0.0
        Q.extend(Qi)
    Q = np.array(Q)
    V = rng.standard_normal((len(Q), 3))
    J_pin = np.array([ARM.jacobian(q)[:3] for q in Q])
    np.testing.assert_allclose(CF.jacobian_batch(Q), J_pin, atol=1e-13)  # URDF: 15 digits
    # exactly singular configurations: the reference is the exact DH table (not the URDF)
    J_dh = np.array([ARM.spec.chain.jacobian(q, "world_aligned")[:3] for q in Q])
    ref = np.array([np.linalg.lstsq(J, v, rcond=None)[0] for J, v in zip(J_dh, V, strict=True)])
    kappa = np.linalg.cond(J_dh)
    for rates in (
        CF.joint_rates_batch(Q, V),
        np.array([CF.joint_rates(q, v) for q, v in zip(Q, V, strict=True)]),
    ):
        err = relative(rates, ref)
        assert err[0] < 1e-9  # home: singular
        assert np.all(err <= 1e-12 + 1e-15 * np.where(np.isfinite(kappa), kappa, 0.0) ** 2)
        assert err[kappa < 1e3].max() < 1e-9


def test_singularities_give_the_pseudo_inverse_never_nan():
    # r = 0 (O3 on axis 1): theta2 = 90 deg, cos(theta2 + theta3) = -a1 / a3.
    q_axis = np.array([0.3, np.pi / 2, np.arccos(-0.4) - np.pi / 2])
    q_stretched = np.array([0.3, 0.7, 0.0])
    q_backwards = np.array([0.0, np.pi, 0.0])  # stretched backwards: s3 = 0, r = -0.8
    for q in (q_axis, q_stretched, q_backwards, np.zeros(3)):
        J = ARM.jacobian(q)[:3]
        for v in np.eye(3):
            rates = CF.joint_rates(q, v)
            assert np.all(np.isfinite(rates))
            np.testing.assert_allclose(rates, np.linalg.pinv(J, rcond=1e-8) @ v, atol=1e-9)
        np.testing.assert_allclose(
            CF.joint_rates_batch(np.array([q] * 3), np.eye(3)),
            [CF.joint_rates(q, v) for v in np.eye(3)],
            atol=1e-15,
        )


def test_angular_solutions_all_realise_omega(regular):
    Q, J_pin, _ = regular
    rng = np.random.default_rng(3)
    for q, J in zip(Q[:300], J_pin[:300], strict=True):
        J_A = J[3:]
        omega = J_A @ rng.standard_normal(3)  # a feasible omega
        rates = CF.rates_for_angular_velocity(q, omega)
        assert rates.residual < 1e-14
        np.testing.assert_allclose(J_A @ CF.angular_null_space(q), 0.0, atol=1e-15)
        for gamma in (0.0, -2.5, 7.0):
            np.testing.assert_allclose(J_A @ (rates.particular + gamma * rates.null_direction),
                                       omega, atol=1e-14)
        np.testing.assert_allclose(rates.minimum_norm, np.linalg.pinv(J_A) @ omega, atol=1e-14)
        assert abs(rates.minimum_norm @ rates.null_direction) < 1e-15
    # An omega outside R(J_A): least squares, with its residual.
    q = Q[0]
    u = np.array([np.cos(q[0]), np.sin(q[0]), 0.0])  # radial: never reachable
    rates = CF.rates_for_angular_velocity(q, 2.0 * u + [0, 0, 1])
    assert rates.residual == pytest.approx(2.0, abs=1e-14)
    ref = np.linalg.pinv(J_pin[0, 3:]) @ (2 * u + [0, 0, 1])
    np.testing.assert_allclose(rates.minimum_norm, ref, atol=1e-14)


def test_batch_equals_scalar_for_1000(regular):
    Q, _, V = regular
    Q, V = Q[:1000], V[:1000]
    np.testing.assert_allclose(CF.jacobian_batch(Q), [CF.jacobian(q) for q in Q], atol=1e-15)
    np.testing.assert_allclose(
        CF.angular_jacobian_batch(Q), [CF.angular_jacobian(q) for q in Q], atol=1e-15
    )
    scalar = np.array([CF.joint_rates(q, v) for q, v in zip(Q, V, strict=True)])
    assert relative(CF.joint_rates_batch(Q, V), scalar).max() < 1e-14


# ------------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda: CF.jacobian(np.zeros(2)), "q"),
        (lambda: CF.jacobian([0.0, np.nan, 0.0]), "q"),
        (lambda: CF.joint_rates(np.zeros(3), np.zeros(4)), "xdot"),
        (lambda: CF.joint_rates(np.zeros(3), [np.inf, 0, 0]), "xdot"),
        (lambda: CF.angular_velocity(np.zeros(3), np.zeros((3, 1))), "qdot"),
        (lambda: CF.rates_for_angular_velocity(np.zeros(3), [0, 0, np.nan]), "omega"),
        (lambda: CF.angular_null_space(np.zeros(4)), "q"),
        (lambda: CF.jacobian_batch(np.zeros(3)), "Q"),
        (lambda: CF.joint_rates_batch(np.zeros((2, 3)), np.zeros((3, 3))), "X"),
        (lambda: CF.joint_rates_batch(np.full((2, 3), np.nan), np.zeros((2, 3))), "Q"),
        (lambda: ThreeRClosedForm(a1=0.2, a2=0.0, a3=0.5), "a2"),
        (lambda: ThreeRClosedForm(a1=-0.1, a2=0.5, a3=0.5), "a1"),
        (lambda: ThreeRClosedForm(a1=0.2, a2=0.5, a3=np.nan), "a3"),
        (lambda: ThreeRClosedForm(a1=0.2, a2=0.5, a3=0.5, rcond=1.0), "rcond"),
        (lambda: minimum_norm_shift([1.0, 2.0], [0.0, 0.0]), "direction"),
        (lambda: minimum_norm_shift([1.0, 2.0, 3.0], [0.0, 1.0]), "qdot"),
    ],
)
def test_bad_input_raises_input_error_naming_the_argument(call, argument):
    with pytest.raises(InvalidInput) as info:
        call()
    assert info.value.argument == argument
