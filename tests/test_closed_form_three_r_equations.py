"""Each kernel of the exam's 3R equations (solvers/closed_form/three_r_equations.py) against numpy.

References: Pinocchio's LOCAL_WORLD_ALIGNED Jacobian of O3, numpy's solve, pinv and lstsq, at
thousands of seeded random configurations.
"""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.solvers.closed_form import three_r_equations as eqs

N = 3000
ARM = rrc_pin.load("kr5_3r")
CF = ARM.closed_form
P = np.array([CF.a1, CF.a2, CF.a3, CF.a1 + CF.a2 + CF.a3])


@pytest.fixture(scope="module")
def configurations() -> np.ndarray:
    return np.random.default_rng(2012).uniform(ARM.lower, ARM.upper, size=(N, 3))


def test_terms_are_numpy(configurations: np.ndarray) -> None:
    for q in configurations[:500]:
        c1, s1, r, h, c23, s23, s3 = eqs.terms(P, q)
        q23 = q[1] + q[2]
        expected = [np.cos(q[0]), np.sin(q[0]), np.cos(q23), np.sin(q23), np.sin(q[2])]
        np.testing.assert_allclose([c1, s1, c23, s23, s3], expected, rtol=0, atol=2.3e-16)
        assert r == pytest.approx(CF.a1 + CF.a2 * np.cos(q[1]) + CF.a3 * c23, abs=1e-15)
        assert h == pytest.approx(CF.a2 * np.sin(q[1]) + CF.a3 * s23, abs=1e-15)


def test_jacobians_are_pinocchios(configurations: np.ndarray) -> None:
    JL, JA = np.empty((3, 3)), np.empty((3, 3))
    for q in configurations:
        t = eqs.terms(P, q)
        eqs.linear_jacobian(P, t, JL)  # above eq. (1)
        eqs.angular_jacobian(t, JA)  # eq. (1)
        J = ARM.jacobian(q)
        assert np.abs(JL - J[:3]).max() < 1e-13  # the URDF holds 15 digits
        assert np.abs(JA - J[3:]).max() < 1e-13


def test_linear_rates_solve_j_l_or_take_its_pinv(configurations: np.ndarray) -> None:
    rng = np.random.default_rng(3)
    singular = [[0.3, np.pi / 2, np.arccos(-0.4) - np.pi / 2], [0.3, 0.7, 0.0], [0.0, np.pi, 0.0]]
    for k, q in enumerate(np.concatenate([configurations, singular])):
        v = rng.normal(size=3)
        rates = eqs.linear_rates(P, CF.rcond, eqs.terms(P, q), *v)
        J = ARM.spec.chain.jacobian(q, "world_aligned")[:3]  # exact DH table
        sv = np.linalg.svd(J, compute_uv=False)
        if k < N and sv[-1] > 1e-3:
            np.testing.assert_allclose(rates, np.linalg.solve(J, v), rtol=1e-9, atol=1e-12)
        elif k >= N:  # O3 on axis 1, stretched, stretched backwards: minimum-norm least squares
            np.testing.assert_allclose(rates, np.linalg.pinv(J, rcond=1e-8) @ v, atol=1e-9)


def test_angular_split_is_least_squares_on_j_a(configurations: np.ndarray) -> None:
    rng = np.random.default_rng(4)
    JA = np.empty((3, 3))
    for q in configurations[:500]:
        w = rng.normal(size=3)
        beta, residual = eqs.angular_split(q[0], w[0], w[1])
        eqs.angular_jacobian(eqs.terms(P, q), JA)
        best = np.linalg.lstsq(JA, w, rcond=None)[0]  # (omega_z, beta / 2, beta / 2)
        np.testing.assert_allclose(best, [w[2], beta / 2, beta / 2], atol=1e-14)
        assert residual == pytest.approx(np.linalg.norm(JA @ best - w), abs=1e-14)


def test_entry_points_and_batches(configurations: np.ndarray) -> None:
    Q = configurations[:100]
    V = np.random.default_rng(5).normal(size=(100, 3))
    out, J, rates = np.empty((100, 3, 3)), np.empty((3, 3)), np.empty(3)
    eqs.jacobian_batch(P, Q, out)
    rows = np.empty((100, 3))
    eqs.joint_rates_batch(P, CF.rcond, Q, V, rows)
    for k in range(100):
        assert eqs.jacobian_at(P, Q[k], J)
        np.testing.assert_array_equal(J, out[k])
        assert eqs.joint_rates_at(P, CF.rcond, Q[k], V[k], rates)
        np.testing.assert_array_equal(rates, rows[k])
    eqs.angular_jacobian_batch(P, Q, out)
    np.testing.assert_allclose(out, [ARM.jacobian(q)[3:] for q in Q], atol=1e-13)
    for bad in ([0.0, np.nan, 0.0], [0.0, 0.0], [0.0, 0.0, 0.0, 0.0]):
        assert not eqs.jacobian_at(P, np.array(bad), J)
        assert not eqs.joint_rates_at(P, CF.rcond, np.array(bad), np.zeros(3), rates)
