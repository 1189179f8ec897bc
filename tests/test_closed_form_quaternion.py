"""Nguyen's quaternion tools (eqs. 24-37): robust Q{R}, corrected eqs. (28) and (36)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.solvers.closed_form.quaternion import (
    differential_rotation,
    matrix_from_quaternion,
    quaternion_difference,
    quaternion_from_matrix,
    rotation_vector,
    small_rotation,
)
from rrc_pin.solvers.errors import InvalidInput


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """Uniform random rotations (normalised Gaussian quaternions, through Pinocchio)."""
    q = rng.standard_normal((n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    return np.array([pin.Quaternion(w, x, y, z).matrix() for w, x, y, z in q])


def half_turns(rng: np.random.Generator, n: int) -> np.ndarray:
    """Rotations by exactly 180 deg about random axes: 2 k k^T - I."""
    k = rng.standard_normal((n, 3))
    k /= np.linalg.norm(k, axis=1)[:, None]
    return 2.0 * k[:, :, None] * k[:, None, :] - np.eye(3)


def same_rotation(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Distance between quaternions up to their sign, per row."""
    return np.minimum(np.abs(q1 - q2).max(axis=-1), np.abs(q1 + q2).max(axis=-1))


# ------------------------------------------------------------- Q{R} and its inverse


def test_round_trip_random_rotations():
    R = random_rotations(np.random.default_rng(1), 2000)
    q = quaternion_from_matrix(R)
    assert np.abs(matrix_from_quaternion(q) - R).max() < 1e-12  # reached: ~1e-15
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    assert np.all(q[:, 0] >= 0.0)


def test_round_trip_half_turns_about_random_axes():
    R = half_turns(np.random.default_rng(2), 2000)
    q = quaternion_from_matrix(R)
    assert np.abs(matrix_from_quaternion(q) - R).max() < 1e-12
    assert np.abs(q[:, 0]).max() < 1e-15  # eta = cos(90 deg)


@pytest.mark.parametrize("axis", range(3))
def test_round_trip_half_turns_about_x_y_z(axis):
    R = 2.0 * np.outer(np.eye(3)[axis], np.eye(3)[axis]) - np.eye(3)
    q = quaternion_from_matrix(R)
    np.testing.assert_array_equal(q, np.concatenate([[0.0], np.eye(3)[axis]]))
    np.testing.assert_array_equal(matrix_from_quaternion(q), R)
    # Printed eq. (26) divides by 4 eta = 0 here.
    with np.errstate(divide="ignore", invalid="ignore"):
        eta = np.sqrt(1.0 + np.trace(R)) / 2.0
        beta = (R[2, 1] - R[1, 2]) / (4.0 * eta)
    assert eta == 0.0 and not np.isfinite(beta)


def test_near_half_turn_stays_accurate():
    rng = np.random.default_rng(3)
    k = rng.standard_normal((500, 3))
    k /= np.linalg.norm(k, axis=1)[:, None]
    angle = np.pi - 10.0 ** rng.uniform(-12, -4, 500)
    R = np.array([pin.exp3(a * kk) for a, kk in zip(angle, k, strict=True)])
    assert np.abs(matrix_from_quaternion(quaternion_from_matrix(R)) - R).max() < 1e-12


def test_q_of_r_is_pinocchios_quaternion_and_eq_26_where_eta_is_large():
    R = random_rotations(np.random.default_rng(4), 500)
    q = quaternion_from_matrix(R)
    ref = np.array([[Q.w, Q.x, Q.y, Q.z] for Q in map(pin.Quaternion, R)])
    assert same_rotation(q, ref).max() < 1e-14
    # Where 1 + tr R is the largest square, it is eq. (26) as printed.
    trace = np.trace(R, axis1=1, axis2=2)
    big = trace > np.abs(np.diagonal(R, axis1=1, axis2=2)).max(axis=1)
    eta = np.sqrt(1.0 + np.trace(R[big], axis1=1, axis2=2)) / 2.0
    eq26 = np.stack(
        [eta, (R[big, 2, 1] - R[big, 1, 2]) / (4 * eta), (R[big, 0, 2] - R[big, 2, 0]) / (4 * eta),
         (R[big, 1, 0] - R[big, 0, 1]) / (4 * eta)],
        axis=1,
    )
    assert big.sum() > 100
    np.testing.assert_allclose(q[big], eq26, atol=1e-15)


def test_eq_28_as_printed_gives_the_transpose():
    # Printed: R = (eta^2 - s.s) I_6 + 2 s s^T - 2 eta s^x. I_6 cannot be added to 3x3 terms;
    # with I_3 and the printed sign it yields R^T (the inverse rotation), with + it yields R.
    R = random_rotations(np.random.default_rng(5), 200)
    q = quaternion_from_matrix(R)
    for Ri, (eta, *s) in zip(R, q, strict=True):
        s = np.array(s)
        sx = np.array([[0, -s[2], s[1]], [s[2], 0, -s[0]], [-s[1], s[0], 0]])  # eq. (29)
        base = (eta**2 - s @ s) * np.eye(3) + 2 * np.outer(s, s)
        np.testing.assert_allclose(base - 2 * eta * sx, Ri.T, atol=1e-14)
        np.testing.assert_allclose(base + 2 * eta * sx, Ri, atol=1e-14)
    np.testing.assert_allclose(matrix_from_quaternion(q), R, atol=1e-14)


def test_matrix_from_non_unit_quaternion_is_normalised():
    q = np.array([1.0, 2.0, -0.5, 0.25])
    R = matrix_from_quaternion(3.0 * q)
    np.testing.assert_allclose(R, matrix_from_quaternion(q / np.linalg.norm(q)), atol=1e-15)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)


# -------------------------------------------------- orientation differences (32)-(34)


def test_quaternion_difference_eqs_33_34_is_q_of_r2_r1t():
    rng = np.random.default_rng(6)
    R1, R2 = random_rotations(rng, 1000), random_rotations(rng, 1000)
    dq = quaternion_difference(quaternion_from_matrix(R1), quaternion_from_matrix(R2))
    ref = quaternion_from_matrix(R2 @ np.transpose(R1, (0, 2, 1)))  # eq. (32), (38)
    assert same_rotation(dq, ref).max() < 1e-14
    single = quaternion_difference(quaternion_from_matrix(R1[0]), quaternion_from_matrix(R2[0]))
    np.testing.assert_allclose(single, dq[0], atol=1e-16)


# ------------------------------------------------------ differential rotations (35)-(37)


@pytest.mark.parametrize("angle", [1e-1, 1e-2, 1e-3, 1e-4])
def test_eq_37_is_the_rotation_vector_to_second_order(angle):
    rng = np.random.default_rng(7)
    k = rng.standard_normal((300, 3))
    k /= np.linalg.norm(k, axis=1)[:, None]
    R1 = random_rotations(rng, 300)
    R2 = np.array([pin.exp3(angle * kk) @ r for kk, r in zip(k, R1, strict=True)])  # eq. (31)
    dq = quaternion_difference(quaternion_from_matrix(R1), quaternion_from_matrix(R2))
    delta = differential_rotation(dq)
    exact = rotation_vector(dq)
    np.testing.assert_allclose(exact, angle * k, atol=1e-13)
    # 2 sin(theta/2) k vs theta k: the error is theta^3 / 24 (third order).
    err = np.linalg.norm(delta - exact, axis=1)
    assert err.max() <= angle**3 / 24 * 1.001 + 1e-15
    if angle >= 1e-2:
        assert err.max() >= angle**3 / 24 * 0.999


def test_small_rotation_eq_36_corrected_is_second_order():
    rng = np.random.default_rng(8)
    for scale in (1e-2, 1e-3, 1e-4):
        d = scale * rng.standard_normal((200, 3))
        exact = np.array([pin.exp3(v) for v in d])
        err = np.abs(small_rotation(d) - exact).max(axis=(1, 2))
        assert np.all(err <= np.linalg.norm(d, axis=1) ** 2)
        np.testing.assert_allclose(
            small_rotation(d) - np.eye(3), -np.transpose(small_rotation(d) - np.eye(3), (0, 2, 1))
        )


def test_eq_36_as_printed_is_not_a_small_rotation():
    # Printed: [[1, -dz, -dy], [dz, 1, -dx], [-dy, dx, 1]]: r13 = -dy makes it I + (a symmetric
    # part): first-order wrong, and eq. (26) applied to it (as eq. (37) is derived) loses dy.
    d = np.array([2e-3, -1e-3, 3e-3])
    dx, dy, dz = d
    printed = np.array([[1, -dz, -dy], [dz, 1, -dx], [-dy, dx, 1]])
    exact = pin.exp3(d)
    assert np.abs(printed - exact).max() > 1.9 * abs(dy)
    assert np.abs(small_rotation(d) - exact).max() < np.linalg.norm(d) ** 2
    eta = np.sqrt(1 + np.trace(printed)) / 2
    gamma = (printed[0, 2] - printed[2, 0]) / (4 * eta)
    assert gamma == 0.0  # eq. (37) would give delta_y = 0
    fixed = small_rotation(d)
    eta = np.sqrt(1 + np.trace(fixed)) / 2
    recovered = 2 * np.array(
        [fixed[2, 1] - fixed[1, 2], fixed[0, 2] - fixed[2, 0], fixed[1, 0] - fixed[0, 1]]
    ) / (4 * eta)
    np.testing.assert_allclose(recovered, d, rtol=1e-5)


# ----------------------------------------------------------------- batch == single


def test_batch_equals_single_for_1000():
    rng = np.random.default_rng(9)
    R = np.concatenate([random_rotations(rng, 800), half_turns(rng, 200)])
    q = quaternion_from_matrix(R)
    np.testing.assert_array_equal(q, [quaternion_from_matrix(r) for r in R])
    np.testing.assert_array_equal(matrix_from_quaternion(q), [matrix_from_quaternion(v) for v in q])
    q2 = np.roll(q, 1, axis=0)
    dq = quaternion_difference(q, q2)
    pairs = zip(q, q2, strict=True)
    np.testing.assert_array_equal(dq, [quaternion_difference(a, b) for a, b in pairs])
    np.testing.assert_array_equal(differential_rotation(dq), [differential_rotation(v) for v in dq])
    np.testing.assert_array_equal(rotation_vector(dq), [rotation_vector(v) for v in dq])
    d = q[:, 1:]
    np.testing.assert_array_equal(small_rotation(d), [small_rotation(v) for v in d])


# ------------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda: quaternion_from_matrix(np.eye(4)), "R"),
        (lambda: quaternion_from_matrix(np.full((3, 3), np.nan)), "R"),
        (lambda: quaternion_from_matrix(2.0 * np.eye(3)), "R"),
        (lambda: quaternion_from_matrix(np.diag([1.0, 1.0, -1.0])), "R"),
        (lambda: quaternion_from_matrix(np.zeros((2, 3, 3))), "R"),
        (lambda: quaternion_from_matrix("R"), "R"),
        (lambda: matrix_from_quaternion(np.zeros(4)), "q"),
        (lambda: matrix_from_quaternion(np.ones(3)), "q"),
        (lambda: matrix_from_quaternion([1.0, np.inf, 0.0, 0.0]), "q"),
        (lambda: quaternion_difference(np.ones(4), np.ones(3)), "q2"),
        (lambda: quaternion_difference(np.ones(5), np.ones(5)), "q1"),
        (lambda: differential_rotation(np.ones((2, 3))), "dq"),
        (lambda: rotation_vector(np.zeros(4)), "dq"),
        (lambda: small_rotation([0.0, np.nan, 0.0]), "delta"),
    ],
)
def test_bad_input_raises_input_error_naming_the_argument(call, argument):
    with pytest.raises(InvalidInput) as info:
        call()
    assert info.value.argument == argument
