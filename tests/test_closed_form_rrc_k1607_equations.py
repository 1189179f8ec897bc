"""Each kernel of Nguyen's equations (solvers/closed_form/rrc_k1607_equations.py) against numpy.

References: the DH chain's frames (numpy products of the modified-DH transforms), Pinocchio's
pose and LOCAL_WORLD_ALIGNED Jacobian of frame 7, and numpy's pseudo-inverse, at thousands of
seeded random configurations; the weighted rates also on random Jacobians of other shapes.
"""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.solvers.closed_form import rrc_k1607_equations as eqs

N = 2000
ARM = rrc_pin.load("rrc_k1607")
P = np.array(ARM.closed_form.a + ARM.closed_form.d)
A, D = P[:7], P[7:]


@pytest.fixture(scope="module")
def configurations() -> np.ndarray:
    rng = np.random.default_rng(1607)
    return rng.uniform(ARM.lower, ARM.upper, size=(N, 7))


def test_frame_axes_are_the_dh_frames(configurations: np.ndarray) -> None:
    chain = ARM.spec.chain
    for q in configurations[:500]:
        F = chain.frames(q)
        x, z = eqs.frame_axes(q)  # eqs. (8)-(11)
        assert np.abs(np.array(x) - F[:7, :3, 0]).max() < 1e-15
        assert np.abs(np.array(z) - F[1:, :3, 2]).max() < 1e-15


def test_pose_and_jacobian_are_pinocchios(configurations: np.ndarray) -> None:
    T, J = np.empty((4, 4)), np.empty((6, 7))
    for q in configurations:
        eqs.pose(A, D, q, T)  # eqs. (4)-(11)
        assert np.abs(T - ARM.fk(q)).max() < 1e-13  # the URDF holds 15 digits
        eqs.jacobian(A, D, q, J)  # eqs. (12)-(17)
        assert np.abs(J - ARM.jacobian(q)).max() < 1e-13


def random_spd(rng: np.random.Generator, n: int) -> np.ndarray:
    M = rng.normal(size=(n, n))
    return M @ M.T + 0.5 * np.eye(n)


@pytest.mark.parametrize("shape", [(6, 7), (3, 5), (6, 6), (2, 9)])
def test_weighted_rates_are_eqs_21_22(shape: tuple[int, int]) -> None:
    """Any full-row-rank J: eqs. (21)-(22) literally, with W = I and z = 0 as None."""
    rng = np.random.default_rng(sum(shape))
    m, n = shape
    qdot = np.empty(n)
    for _ in range(500):
        J, x = rng.normal(size=shape), rng.normal(size=m)
        W, z = random_spd(rng, n), rng.normal(size=n)
        L = np.linalg.cholesky(W)
        JW = W @ J.T @ np.linalg.inv(J @ W @ J.T)  # eq. (22)
        eqs.weighted_rates(J, L, x, z, 1e-6, qdot)
        ref = JW @ x + (np.eye(n) - JW @ J) @ z  # eq. (21)
        # the normal equations (and the reference's inverse) lose about eps kappa^2
        tol = 1e-12 + 1e-15 * np.linalg.cond(J @ L) ** 2
        assert np.abs(qdot - ref).max() <= tol * np.abs(ref).max()
        eqs.weighted_rates(J, None, x, None, 1e-6, qdot)  # eq. (23)
        ref = np.linalg.pinv(J) @ x
        tol = 1e-12 + 1e-15 * np.linalg.cond(J) ** 2
        assert np.abs(qdot - ref).max() <= tol * np.abs(ref).max()
        eqs.weighted_rates(J, None, x, z, 1e-6, qdot)  # W = I with a null-space term
        P = np.linalg.pinv(J)
        ref = P @ x + (np.eye(n) - P @ J) @ z
        assert np.abs(qdot - ref).max() <= tol * np.abs(ref).max()
        eqs.weighted_rates(J, L, x, None, 1e-6, qdot)  # weighted, z = 0
        ref = JW @ x
        tol = 1e-12 + 1e-15 * np.linalg.cond(J @ L) ** 2
        assert np.abs(qdot - ref).max() <= tol * np.abs(ref).max()


def test_weighted_rates_at_rank_deficient_jacobians_are_the_truncated_pinv() -> None:
    """Rows dependent: L (J L)^+ (x - J z) + z, singular values <= rcond sigma_max dropped."""
    rng = np.random.default_rng(22)
    qdot = np.empty(7)
    home = ARM.jacobian(np.zeros(7))  # Nguyen's home pose: rank 5
    assert np.linalg.matrix_rank(home) == 5
    for k in range(300):
        J = home if k == 0 else rng.normal(size=(6, 7))
        if k:  # one row a combination of two others
            i, j, h = rng.choice(6, size=3, replace=False)
            J[i] = rng.normal() * J[j] + rng.normal() * J[h]
        x, W, z = rng.normal(size=6), random_spd(rng, 7), rng.normal(size=7)
        L = np.linalg.cholesky(W)
        eqs.weighted_rates(J, L, x, z, 1e-6, qdot)
        ref = L @ np.linalg.pinv(J @ L, rcond=1e-6) @ (x - J @ z) + z
        assert np.all(np.isfinite(qdot))
        assert np.abs(qdot - ref).max() <= 1e-9 * max(1.0, np.abs(ref).max())


def test_entry_points_check_their_input(configurations: np.ndarray) -> None:
    q, J, qdot = configurations[0], np.empty((6, 7)), np.empty(7)
    assert eqs.jacobian_at(P, q, J)
    np.testing.assert_array_equal(J, ARM.closed_form.jacobian(q))
    for bad in (np.r_[q[:6], np.nan], q[:6], np.r_[q, 0.0]):
        assert not eqs.jacobian_at(P, bad, J)
        assert not eqs.joint_rates_at(P, bad, np.ones(6), None, None, 1e-6, qdot)
    assert not eqs.joint_rates_at(P, q, np.r_[np.ones(5), np.inf], None, None, 1e-6, qdot)
    Q = configurations[:50]
    X = np.random.default_rng(3).normal(size=(50, 6))
    out = np.empty((50, 7))
    eqs.joint_rates_batch(P, Q, X, None, None, 1e-6, out)
    for k in range(50):
        assert eqs.joint_rates_at(P, Q[k], X[k], None, None, 1e-6, qdot)
        np.testing.assert_array_equal(qdot, out[k])
