"""Each kernel of Barker's equations (solvers/closed_form/barker_equations.py) against numpy.

References: Pinocchio's LOCAL_WORLD_ALIGNED Jacobian and pose of the wrist centre, the DH
chain's frames, and numpy's linear algebra on the blocks (solve, det, svd, the damped normal
equations), at thousands of seeded random configurations of the PUMA values and a variant
(alpha3 = 88 deg, A3 = 0.02 m, R3 = 0.01 m). The kernels are called one configuration at a
time, as the compiled paths call them (with ``NUMBA_DISABLE_JIT=1``, as plain Python).
"""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.models import barker6
from rrc_pin.solvers.closed_form import barker_equations as eqs

N = 2000
ARMS = {
    "puma": barker6.SPEC,
    "variant": barker6.build(alpha3=np.deg2rad(88), a3=0.02, r3=0.01, name="barker6_variant"),
}


class Case:
    """An arm, its closed form's geometry and N random configurations with Pinocchio's answers."""

    def __init__(self, key: str) -> None:
        spec = ARMS[key]
        self.robot = rrc_pin.load(spec)
        self.cf = self.robot.closed_form
        self.g = self.cf.geometry
        rng = np.random.default_rng(8565)
        self.Q = rng.uniform(spec.lower, spec.upper, size=(N, 6))
        self.J = np.array([self.robot.jacobian(q) for q in self.Q])
        self.X = rng.normal(size=(N, 6))
        self.trig = [eqs.joint_trig(q) for q in self.Q]
        self.chain = spec.chain


@pytest.fixture(scope="module", params=list(ARMS))
def case(request: pytest.FixtureRequest) -> Case:
    return Case(request.param)


def regular(case: Case, margin: float = 0.03) -> np.ndarray:
    """Indices of the configurations away from the three singular conditions."""
    s = case.cf.singularity_batch(case.Q)
    L = case.g.reach
    keep = (np.abs(s.eq32) > margin * L) & (np.abs(s.eq33) > margin * L) & (np.abs(s.s5) > margin)
    return np.flatnonzero(keep)


def test_parameters_round_trip_and_widths(case: Case) -> None:
    p = eqs.parameters(case.g, 0.01, 1e-10)
    assert p.shape == (17,)
    assert eqs.geometry(p) == case.g
    assert eqs.widths(p, False) == (0.01 * case.g.reach, 0.01)
    assert eqs.widths(p, True) == (1e-10 * case.g.reach, 1e-10)


def test_joint_trig_is_numpy(case: Case) -> None:
    Q = case.Q
    angles = np.column_stack([Q[:, 0], Q[:, 1], Q[:, 2], Q[:, 1] + Q[:, 2], Q[:, 3:]])
    expected = np.empty((N, 14))
    expected[:, 0::2], expected[:, 1::2] = np.sin(angles), np.cos(angles)
    assert np.abs(np.array(case.trig) - expected).max() <= 2.3e-16


def test_jacobian_and_m_matrix_are_pinocchios(case: Case) -> None:
    J, M = np.empty((6, 6)), np.empty((3, 3))
    for t, Jp in zip(case.trig, case.J, strict=True):
        eqs.jacobian(case.g, t, J)
        assert np.abs(J - Jp).max() < 1e-13  # the URDF holds 15 digits
        eqs.m_matrix(t, eqs.f_terms(case.g, t), M)  # eq. (26)
        np.testing.assert_array_equal(M, J[:3, :3])


def test_f_terms_eq33_and_singularity_values(case: Case) -> None:
    g = case.g
    values, flags = np.empty(4), np.empty(2, dtype=bool)
    for q, t, Jp in zip(case.Q[:500], case.trig[:500], case.J[:500], strict=True):
        F = eqs.f_terms(g, t)
        M = Jp[:3, :3]  # eq. (26): -F6, C1 F3, C1 F4; F7, S1 F3, S1 F4; 0, -F1, -F5
        entries = [M[0, 0], M[1, 0], M[2, 1], M[2, 2]]
        np.testing.assert_allclose([-F.f6, F.f7, -F.f1, -F.f5], entries, rtol=0, atol=1e-13)
        assert F.f3 * np.cos(q[0]) == pytest.approx(M[0, 1], abs=1e-13)
        assert F.f4 * np.sin(q[0]) == pytest.approx(M[1, 2], abs=1e-13)
        e33 = g.swe * np.sin(q[2]) + g.a3 * np.cos(q[2])
        assert eqs.eq33(g, t) == pytest.approx(e33, abs=1e-16)
        eqs.singularity(g, t, 0.01 * g.reach, 0.01, values, flags)
        np.testing.assert_allclose(values[:3], [F.f1, e33, np.sin(q[4])], rtol=0, atol=1e-16)
        assert values[3] == pytest.approx(np.linalg.det(M), abs=1e-14)


def test_det_adj2_are_numpy_det_and_adjugate(case: Case) -> None:
    for t, Jp in zip(case.trig, case.J, strict=True):
        M = Jp[:3, :3]
        det, adj2 = eqs.det_adj2(case.g, t, eqs.f_terms(case.g, t))
        adjugate = np.stack([np.cross(M[1], M[2]), np.cross(M[2], M[0]), np.cross(M[0], M[1])])
        assert det == pytest.approx(np.linalg.det(M), abs=1e-14)  # eq. (D9)
        assert adj2 == pytest.approx((adjugate**2).sum(), rel=1e-12, abs=1e-16)


def test_arm_full_and_the_reduced_system_solve_eq_25(case: Case) -> None:
    A, b = np.empty((2, 2)), np.empty(2)
    for k in regular(case):
        t, T, M = case.trig[k], case.X[k, :3], case.J[k, :3, :3]
        ref = np.linalg.solve(M, T)
        F = eqs.f_terms(case.g, t)
        det = eqs.det_adj2(case.g, t, F)[0]
        np.testing.assert_allclose(eqs.arm_full(t, F, det, *T), ref, rtol=1e-10)  # eqs (34)-(36)
        ta = eqs.m1_system(t, F, *T, A, b)  # eqs (40)-(43) corrected
        th23 = np.linalg.solve(A, b)  # eq. (44)
        np.testing.assert_allclose(th23, ref[1:], rtol=1e-10)
        assert eqs.arm_from_m1(F, *th23, ta) == pytest.approx(ref[0], rel=1e-10)  # eq. (39)


def test_m_rotated_is_m_with_rows_turned_by_theta1(case: Case) -> None:
    A, b = np.empty((3, 3)), np.empty(3)
    for q, t, Jp, x in zip(case.Q[:500], case.trig[:500], case.J[:500], case.X[:500], strict=True):
        c1, s1 = np.cos(q[0]), np.sin(q[0])
        turn = np.array([[c1, s1, 0.0], [s1, -c1, 0.0], [0.0, 0.0, 1.0]])  # its own inverse
        eqs.m_rotated(t, eqs.f_terms(case.g, t), *x[:3], A, b)
        assert np.abs(A - turn @ Jp[:3, :3]).max() < 1e-13
        assert np.abs(b - turn @ x[:3]).max() < 1e-15
        assert eqs.turn1(t, x[0], x[1]) == pytest.approx((turn @ x[:3])[:2], abs=1e-15)


def test_rvel_tilde_and_the_wrist_equations(case: Case) -> None:
    M2 = np.empty((2, 2))
    for k in regular(case):
        t, x, Jp = case.trig[k], case.X[k], case.J[k]
        arm = np.linalg.solve(Jp[:3, :3], x[:3])
        rt = eqs.rvel_tilde(t, *arm, *x[3:])  # eq. (48)
        np.testing.assert_allclose(rt, x[3:] - Jp[3:, :3] @ arm, rtol=0, atol=1e-12)
        wrist = np.linalg.solve(Jp[3:, 3:], rt)
        th5, ga, gb = eqs.wrist_equations(case.g, t, *rt)  # eqs (49), (52)-(59)
        th4, th6 = eqs.wrist_regular(t, ga, gb)  # eqs (50), (51)
        np.testing.assert_allclose([th4, th5, th6], wrist, rtol=1e-10, atol=1e-12)
        eqs.m2_matrix(t, M2)  # eq. (58)
        np.testing.assert_allclose(M2 @ [th4, th6], [ga, gb], rtol=1e-12, atol=1e-12)


def test_band_measures(case: Case) -> None:
    M2 = np.empty((2, 2))
    eps = 0.01 * case.g.reach
    for t, Jp in zip(case.trig, case.J, strict=True):
        eqs.m2_matrix(t, M2)
        sigma2 = np.linalg.svd(M2, compute_uv=False)[-1] ** 2
        assert eqs.wrist_s2(t) == pytest.approx(sigma2, rel=1e-9, abs=1e-15)  # exact for M2
        det, adj2 = eqs.det_adj2(case.g, t, eqs.f_terms(case.g, t))
        s2 = eqs.arm_s2(det, adj2)
        assert s2 <= np.linalg.svd(Jp[:3, :3], compute_uv=False)[-1] ** 2 * (1 + 1e-9) + 1e-18
        assert eqs.arm_in_band(det, adj2, eps) == (s2 <= eps * eps)
    assert eqs.arm_s2(0.0, 0.0) == 0.0  # rank <= 1: the adjugate vanishes


@pytest.mark.parametrize("m", [2, 3])
def test_band_solve_is_damped_least_squares_or_the_truncated_pinv(m: int) -> None:
    rng = np.random.default_rng(60 + m)
    for k in range(1000):
        A = rng.normal(size=(m, m))
        if k % 3 == 0:  # rank deficient, as on the singular set
            A[-1] = rng.normal() * A[0]
        b = rng.normal(size=m)
        sigma = np.linalg.svd(A, compute_uv=False)
        eps = sigma[-1] * rng.uniform(1.0, 3.0) + 1e-3
        s2 = min(sigma[-1] ** 2, eps * eps)
        x = np.empty(m)
        U, sv, Vt = np.linalg.svd(A)
        eqs.band_solve(A.copy(), b, s2, eps, False, x)  # damped, lambda^2 = eps^2 - s^2
        lam2 = eps * eps - s2
        ref = Vt.T @ (sv / (sv**2 + lam2) * (U.T @ b))  # (A^T A + lambda^2)^-1 A^T b
        # a singular value of rounding size (1e-16 sigma_max) is amplified by 1 / lambda^2
        tol = 1e-12 * max(1.0, np.abs(ref).max()) + 1e-15 * sv[0] * np.abs(b).sum() / lam2
        assert np.abs(x - ref).max() <= tol
        eqs.band_solve(A.copy(), b, s2, eps, True, x)  # truncated at eps
        keep = sv > eps
        ref = Vt[keep].T @ ((U[:, keep].T @ b) / sv[keep])
        assert np.abs(x - ref).max() <= 1e-10 * max(1.0, np.abs(ref).max())


def test_arm_wrist_and_joint_rates_kernels_match_the_blocks(case: Case) -> None:
    g, out = case.g, np.empty(6)
    eps_arm, eps_wrist = 0.01 * g.reach, 0.01
    for k in regular(case)[:500]:
        t, x, Jp = case.trig[k], case.X[k], case.J[k]
        ref = np.linalg.solve(Jp, x)
        for reduced in (False, True):
            *arm, bad = eqs.arm_rates(g, t, *x[:3], reduced, False, eps_arm)
            assert not bad
            np.testing.assert_allclose(arm, ref[:3], rtol=1e-10)
            eqs.joint_rates(g, t, x, reduced, False, eps_arm, eps_wrist, out)
            np.testing.assert_allclose(out, ref, rtol=1e-9, atol=1e-12)
        rt = eqs.rvel_tilde(t, *ref[:3], *x[3:])
        *wrist, bad = eqs.wrist_rates(g, t, *rt, False, eps_wrist)
        assert not bad
        np.testing.assert_allclose(wrist, ref[3:], rtol=1e-9, atol=1e-12)


def test_hand_to_base_and_tvel_frame2(case: Case) -> None:
    R = np.empty((3, 3))
    for q, t, x in zip(case.Q[:500], case.trig[:500], case.X[:500], strict=True):
        eqs.hand_to_base(case.g, t, R)  # eqs (B6)-(B24)
        assert np.abs(R - case.robot.fk(q)[:3, :3]).max() < 1e-13
        R2 = case.chain.frames(q)[2][:3, :3]
        np.testing.assert_allclose(eqs.tvel_frame2(t, *x[:3]), R2.T @ x[:3], rtol=0, atol=1e-14)
