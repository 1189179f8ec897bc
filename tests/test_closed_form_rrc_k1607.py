"""Nguyen's closed forms for the RRC K-1607 against Pinocchio, and the report's printed errors."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.solvers.closed_form import (
    null_space_projector,
    weighted_pseudo_inverse,
    weighted_rates,
)
from rrc_pin.solvers.closed_form.rrc_k1607 import RrcK1607ClosedForm
from rrc_pin.solvers.errors import InvalidInput

ARM = rrc_pin.load("rrc_k1607")  # Pinocchio, from the generated URDF
CF = ARM.closed_form
N_RANDOM = 10_000
SIGMA_MIN = 0.05  # away from singularities: smallest singular value of J (largest ~2)
INCH = 0.0254


def sample(rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.uniform(ARM.lower, ARM.upper, size=(n, 7))


def pin_jacobians(Q: np.ndarray) -> np.ndarray:
    return np.array([ARM.jacobian(q) for q in Q])


def relative(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per-item relative difference ||a - b|| / ||b|| (Frobenius over the trailing axes)."""
    axes = tuple(range(1, a.ndim))
    return np.sqrt(((a - b) ** 2).sum(axis=axes) / (b**2).sum(axis=axes))


@pytest.fixture(scope="module")
def regular():
    """>= 10000 random configurations within the limits, away from singularities."""
    rng = np.random.default_rng(160701)
    Q = sample(rng, 12_000)
    J = pin_jacobians(Q)
    keep = np.linalg.svd(J, compute_uv=False)[:, -1] > SIGMA_MIN
    assert keep.sum() >= N_RANDOM
    X = rng.standard_normal((keep.sum(), 6))
    return Q[keep], J[keep], X


def test_catalogue_passes_table_1_in_metres():
    assert isinstance(CF, RrcK1607ClosedForm)
    a_in = (0.0, 0.0, 5.625, 4.25, -4.25, 3.125, -3.125)
    d_in = (0.0, 0.0, 27.0, 0.0, 27.0, 0.0, 0.0)
    np.testing.assert_allclose(CF.a, np.array(a_in) * INCH, rtol=0, atol=1e-14)
    np.testing.assert_allclose(CF.d, np.array(d_in) * INCH, rtol=0, atol=1e-14)
    assert (CF.nq, CF.task_dim) == (7, 6)


# ---------------------------------------------------------------- forward kinematics


def test_fk_eqs_5_to_11_match_pinocchio(regular):
    Q = regular[0]
    T_pin = np.array([ARM.fk(q) for q in Q])
    T_batch = CF.fk_batch(Q)
    assert np.abs(T_batch - T_pin).max() < 1e-9  # reached: ~1e-15 (rotation) and m
    T_scalar = np.array([CF.fk(q) for q in Q[:1000]])
    assert np.abs(T_scalar - T_pin[:1000]).max() < 1e-9


def test_fk_home_pose_is_nguyen_figure_2():
    # Table 1 at theta = 0: p = (a2 + a3 + a4 + a5 + a6, 0, d3 + d5) = (5.625, 0, 54) in.
    T = CF.fk(np.zeros(7))
    np.testing.assert_allclose(T[:3, 3], np.array([5.625, 0.0, 54.0]) * INCH, atol=1e-15)
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-15)
    np.testing.assert_allclose(T, ARM.fk(np.zeros(7)), atol=1e-14)  # URDF: 15 digits


# ------------------------------------------------------------------------ Jacobian


def test_jacobian_all_seven_columns_match_pinocchio(regular):
    Q, J_pin, _ = regular
    assert relative(CF.jacobian_batch(Q), J_pin).max() < 1e-9  # reached: ~5e-16
    J_scalar = np.array([CF.jacobian(q) for q in Q[:2000]])
    assert relative(J_scalar, J_pin[:2000]).max() < 1e-9


def test_jacobian_at_home_and_along_each_joint_zero():
    rng = np.random.default_rng(7)
    Q = [np.zeros(7)]
    for i in range(7):
        Qi = sample(rng, 100)
        Qi[:, i] = 0.0
        Q.extend(Qi)
    Q = np.array(Q)
    J_pin = pin_jacobians(Q)
    assert np.abs(CF.jacobian_batch(Q) - J_pin).max() < 1e-12
    assert np.abs(np.array([CF.jacobian(q) for q in Q]) - J_pin).max() < 1e-12


# --------------------------------------------------------------------- joint rates


def test_minimum_norm_rates_match_lstsq_with_pinocchio_jacobian(regular):
    Q, J_pin, X = regular
    ref = np.linalg.pinv(J_pin) @ X[:, :, None]
    ref = ref[:, :, 0]
    assert relative(CF.joint_rates_batch(Q, X), ref).max() < 1e-9  # reached: ~1e-13
    scalar = np.array([CF.joint_rates(q, x) for q, x in zip(Q, X, strict=True)])
    assert relative(scalar, ref).max() < 1e-9
    pairs = zip(J_pin[:500], X[:500], strict=True)
    lstsq = np.array([np.linalg.lstsq(J, x, rcond=None)[0] for J, x in pairs])
    assert relative(scalar[:500], lstsq).max() < 1e-9


def test_rates_at_home_and_along_each_joint_zero_match_lstsq():
    rng = np.random.default_rng(8)
    Q = [np.zeros(7)]
    for i in range(7):
        Qi = sample(rng, 50)
        Qi[:, i] = 0.0
        Q.extend(Qi)
    Q = np.array(Q)
    X = rng.standard_normal((len(Q), 6))
    J_pin = pin_jacobians(Q)
    ref = np.array([np.linalg.lstsq(J, x, rcond=None)[0] for J, x in zip(J_pin, X, strict=True)])
    sv = np.linalg.svd(J_pin, compute_uv=False)
    # The home pose is singular (rank 5): both answer with the least-squares minimum norm.
    assert np.linalg.matrix_rank(J_pin[0]) == 5
    kappa = sv[1:, 0] / sv[1:, -1]
    for rates in (
        CF.joint_rates_batch(Q, X),
        np.array([CF.joint_rates(q, x) for q, x in zip(Q, X, strict=True)]),
    ):
        err = relative(rates, ref)
        assert err[0] < 1e-9
        # Elsewhere the normal equations J J^T y = x lose about eps kappa^2 (some of these
        # configurations are near a singularity, kappa up to ~2e4): 1e-9 where kappa < 1e3.
        assert np.all(err[1:] <= 1e-12 + 1e-15 * kappa**2)
        assert err[1:][kappa < 1e3].max() < 1e-9


def test_singular_configurations_never_give_nan():
    rng = np.random.default_rng(9)
    home = np.zeros(7)
    Q = np.array([home, home + 1e-9 * rng.standard_normal(7), home + 1e-5 * rng.standard_normal(7)])
    X = np.array([[1.0, 2.0, -1.0, 0.5, 0.1, -3.0]] * 3)
    for q, x in zip(Q, X, strict=True):
        qdot = CF.joint_rates(q, x)
        assert np.all(np.isfinite(qdot))
        assert np.all(np.isfinite(CF.joint_rates(q, 1e6 * x)))
        ref = np.linalg.pinv(ARM.jacobian(q), rcond=CF.rcond) @ x
        # Exactly singular: the truncated pseudo-inverse; near it, the exact rates or it.
        if np.linalg.svd(ARM.jacobian(q), compute_uv=False)[-1] < 1e-12:
            np.testing.assert_allclose(qdot, ref, rtol=1e-9, atol=1e-12)
    batch = CF.joint_rates_batch(Q, X)
    assert np.all(np.isfinite(batch))
    np.testing.assert_allclose(batch[0], CF.joint_rates(Q[0], X[0]), rtol=1e-12, atol=1e-15)
    # Weighted, with a null-space vector, at the singular home pose: L (J L)^+ (x - J z) + z.
    W, z = random_spd(rng), rng.standard_normal(7)
    J = ARM.jacobian(home)
    L = np.linalg.cholesky(W)
    ref = L @ np.linalg.pinv(J @ L, rcond=CF.rcond) @ (X[0] - J @ z) + z
    np.testing.assert_allclose(CF.joint_rates(home, X[0], W=W, z=z), ref, rtol=1e-9, atol=1e-12)
    batch = CF.joint_rates_batch(Q[:1], X[:1], W=W, Z=z[None])
    np.testing.assert_allclose(batch[0], ref, rtol=1e-9, atol=1e-12)


# ------------------------------------------------------- weighted pseudo-inverse


def random_spd(rng: np.random.Generator) -> np.ndarray:
    A = rng.standard_normal((7, 7))
    return A @ A.T + 0.5 * np.eye(7)


def eq_21_22(J: np.ndarray, W: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Nguyen eqs. (21)-(22) literally, with numpy."""
    JW = W @ J.T @ np.linalg.inv(J @ W @ J.T)
    return JW @ x + (np.eye(7) - JW @ J) @ z


def null_vector(J: np.ndarray) -> np.ndarray:
    return np.linalg.svd(J)[2][-1]


def test_weighted_rates_are_eqs_21_22_and_realise_xdot(regular):
    Q, J_pin, X = regular
    rng = np.random.default_rng(10)
    for k in range(200):
        q, J, x = Q[k], J_pin[k], X[k]
        W, z = random_spd(rng), rng.standard_normal(7)
        qdot = CF.joint_rates(q, x, W=W, z=z)
        np.testing.assert_allclose(J @ qdot, x, rtol=0, atol=1e-10 * np.abs(x).max())
        ref = eq_21_22(J, W, x, z)
        assert np.linalg.norm(qdot - ref) <= 1e-9 * np.linalg.norm(ref)


def test_weighted_rates_minimise_qdot_w_inverse_qdot(regular):
    Q, J_pin, X = regular
    rng = np.random.default_rng(11)
    for k in range(200):
        J, x = J_pin[k], X[k]
        W = random_spd(rng)
        qdot = CF.joint_rates(Q[k], x, W=W)
        Winv = np.linalg.inv(W)
        n = null_vector(J)
        # Every solution is qdot + t n; the W^-1 norm is least at t = 0: gradient zero ...
        grad = n @ Winv @ qdot
        assert abs(grad) <= 1e-9 * np.linalg.norm(Winv @ qdot)
        # ... and moving along the null space only increases it.
        cost = qdot @ Winv @ qdot
        for t in (-1e-3, 1e-3, -1.0, 1.0):
            other = qdot + t * n
            assert other @ Winv @ other > cost


def test_null_space_term_does_not_change_the_twist(regular):
    Q, J_pin, X = regular
    rng = np.random.default_rng(12)
    for k in range(200):
        J = J_pin[k]
        z = 10.0 * rng.standard_normal(7)
        W = random_spd(rng) if k % 2 else None
        base = CF.joint_rates(Q[k], X[k], W=W)
        with_z = CF.joint_rates(Q[k], X[k], W=W, z=z)
        np.testing.assert_allclose(J @ (with_z - base), 0.0, atol=1e-10 * np.abs(z).max())
        # (I - J_W^+ J) z is a projector: applying it twice changes nothing.
        proj = with_z - base
        again = CF.joint_rates(Q[k], X[k], W=W, z=proj) - base
        np.testing.assert_allclose(again, proj, atol=1e-10 * np.abs(z).max())


def test_default_weight_is_identity_and_zero_z(regular):
    Q, _, X = regular
    for q, x in zip(Q[:100], X[:100], strict=True):
        plain = CF.joint_rates(q, x)
        np.testing.assert_allclose(CF.joint_rates(q, x, W=np.eye(7), z=np.zeros(7)), plain,
                                   rtol=1e-12, atol=1e-14)


def test_weighted_batch_equals_scalar(regular):
    Q, _, X = regular
    rng = np.random.default_rng(13)
    Q, X = Q[:1000], X[:1000]
    Z = rng.standard_normal((1000, 7))
    for W in (random_spd(rng), rng.uniform(0.1, 10.0, 7)):  # a matrix, a diagonal
        batch = CF.joint_rates_batch(Q, X, W=W, Z=Z)
        pairs = zip(Q, X, Z, strict=True)
        scalar = np.array([CF.joint_rates(q, x, W=W, z=z) for q, x, z in pairs])
        assert relative(batch, scalar).max() < 1e-10
        triples = zip(Q[:50], X[:50], Z[:50], strict=True)
        svd = [weighted_rates(ARM.jacobian(q), x, W, z) for q, x, z in triples]
        assert relative(batch[:50], np.array(svd)).max() < 1e-9


# ------------------------------------------------------------------ batch == scalar


def test_batch_equals_scalar_for_1000_configurations(regular):
    Q, _, X = regular
    Q, X = Q[:1000], X[:1000]
    np.testing.assert_allclose(CF.fk_batch(Q), [CF.fk(q) for q in Q], rtol=0, atol=1e-14)
    np.testing.assert_allclose(
        CF.jacobian_batch(Q), [CF.jacobian(q) for q in Q], rtol=0, atol=1e-14
    )
    scalar = np.array([CF.joint_rates(q, x) for q, x in zip(Q, X, strict=True)])
    assert relative(CF.joint_rates_batch(Q, X), scalar).max() < 1e-12
    assert CF.joint_rates_batch(Q[:0], X[:0]).shape == (0, 7)


# ------------------------------------- Nguyen eqs. (21)-(23) for any Jacobian (weighted.py)


def spd(rng: np.random.Generator, n: int) -> np.ndarray:
    A = rng.standard_normal((n, n))
    return A @ A.T + n * np.eye(n)


def test_weighted_pseudo_inverse_is_eq_22() -> None:
    rng = np.random.default_rng(20261122)
    for _ in range(200):
        n = rng.integers(6, 10)
        J = rng.standard_normal((6, n))
        W = spd(rng, n)
        ref = W @ J.T @ np.linalg.inv(J @ W @ J.T)  # Nguyen eq. (22) as printed
        assert np.allclose(weighted_pseudo_inverse(J, W), ref, rtol=1e-8, atol=1e-10)
        w = rng.uniform(0.1, 10.0, n)
        ref = np.diag(w) @ J.T @ np.linalg.inv(J @ np.diag(w) @ J.T)
        assert np.allclose(weighted_pseudo_inverse(J, w), ref, rtol=1e-8, atol=1e-10)


def test_identity_weight_is_moore_penrose_eq_23() -> None:
    J = np.random.default_rng(20261122).standard_normal((6, 7))
    assert np.allclose(weighted_pseudo_inverse(J), J.T @ np.linalg.inv(J @ J.T), atol=1e-12)
    assert np.allclose(weighted_pseudo_inverse(J), np.linalg.pinv(J), atol=1e-12)


def test_eq_21_minimises_the_weighted_norm() -> None:
    """Among all q with J q = x, J_W^+ x has the least q^T W^-1 q (Nguyen eq. (20)-(22))."""
    rng = np.random.default_rng(20261122)
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


def test_rrc_k1607_pseudo_inverse_reproduces_joint_rates() -> None:
    """Section 5 of Nguyen: x = J qdot, then J^+ x; the difference lies in the null space."""
    rng = np.random.default_rng(20261122)
    for _ in range(50):
        q = ARM.random_q(rng)
        J = ARM.jacobian(q)
        qdot = rng.uniform(-1.0, 1.0, 7)
        back = weighted_rates(J, J @ qdot)
        assert np.allclose(J @ back, J @ qdot, atol=1e-10)
        assert np.allclose(null_space_projector(J) @ (qdot - back), qdot - back, atol=1e-9)


def test_singular_jwj_stays_finite() -> None:
    """J W J^T singular (rrc_k1607 at home): eq. (22) cannot be evaluated, the SVD form can."""
    J = ARM.jacobian(np.zeros(7))
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
    cases = [
        (lambda: weighted_pseudo_inverse(J, np.ones(6)), "W"),
        (lambda: weighted_pseudo_inverse(J, -np.eye(7)), "W"),
        (lambda: weighted_rates(J, np.ones(6), z=np.ones(6)), "z"),
        (lambda: weighted_rates(J, np.ones(5)), "xdot"),
        (lambda: weighted_pseudo_inverse(J, rcond=1.5), "rcond"),
        (lambda: null_space_projector(np.full((6, 7), np.nan)), "J"),
    ]
    for call, argument in cases:
        with pytest.raises(InvalidInput) as info:
            call()
        assert info.value.argument == argument


# ---------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda: CF.fk(np.zeros(6)), "q"),
        (lambda: CF.jacobian([0, 0, 0, np.nan, 0, 0, 0]), "q"),
        (lambda: CF.joint_rates(np.zeros(7), np.zeros(5)), "xdot"),
        (lambda: CF.joint_rates(np.zeros(7), [0, 0, np.inf, 0, 0, 0]), "xdot"),
        (lambda: CF.joint_rates(np.zeros((7, 1)), np.zeros(6)), "q"),
        (lambda: CF.joint_rates(np.zeros(7), np.zeros(6), W=np.eye(6)), "W"),
        (lambda: CF.joint_rates(np.zeros(7), np.zeros(6), W=-np.eye(7)), "W"),
        (lambda: CF.joint_rates(np.zeros(7), np.zeros(6), W=np.triu(np.ones((7, 7)))), "W"),
        (lambda: CF.joint_rates(np.zeros(7), np.zeros(6), z=np.full(7, np.nan)), "z"),
        (lambda: CF.fk_batch(np.zeros((3, 6))), "Q"),
        (lambda: CF.jacobian_batch(np.zeros(7)), "Q"),
        (lambda: CF.joint_rates_batch(np.zeros((3, 7)), np.zeros((2, 6))), "X"),
        (lambda: CF.joint_rates_batch(np.full((3, 7), np.nan), np.zeros((3, 6))), "Q"),
        (lambda: CF.joint_rates_batch(np.zeros((3, 7)), np.zeros((3, 6)), Z=np.zeros(7)), "Z"),
        (lambda: CF.joint_rates_batch(np.zeros((3, 7)), np.zeros((3, 6)), W=np.ones((7, 7))), "W"),
        (lambda: CF.joint_rates(np.zeros(7), np.zeros(6), W=[1, 1, 1, 0, 1, 1, 1]), "W"),
        (lambda: RrcK1607ClosedForm(a=np.zeros(6), d=np.zeros(7)), "a"),
        (lambda: RrcK1607ClosedForm(a=np.zeros(7), d=[0, 0, 0, 0, 0, 0, np.nan]), "d"),
        (lambda: RrcK1607ClosedForm(a=np.zeros(7), d=np.zeros(7), rcond=0.0), "rcond"),
        (lambda: CF.fk("abc"), "q"),
    ],
)
def test_bad_input_raises_input_error_naming_the_argument(call, argument):
    with pytest.raises(InvalidInput) as info:
        call()
    assert info.value.argument == argument


def test_other_geometry_matches_its_dh_chain():
    # Every a_{i-1} and d_i is honoured (a tool offset d7, a base height d1, ...).
    from rrc_pin.dh import DHChain, DHRow

    rng = np.random.default_rng(15)
    a = rng.uniform(-0.2, 0.2, 7)
    d = rng.uniform(-0.5, 0.5, 7)
    alpha = np.deg2rad([0, -90, 90, -90, 90, -90, 90])
    chain = DHChain("modified", tuple(DHRow(a[i], alpha[i], d[i], 0.0) for i in range(7)))
    cf = RrcK1607ClosedForm(a=a, d=d)
    Q = sample(rng, 200)
    for q in Q:
        np.testing.assert_allclose(cf.fk(q), chain.fk(q), atol=1e-14)
        np.testing.assert_allclose(cf.jacobian(q), chain.jacobian(q), atol=1e-14)
    np.testing.assert_allclose(cf.jacobian_batch(Q), [chain.jacobian(q) for q in Q], atol=1e-14)


# ------------------------------------------------------ errata: the printed equations


def nguyen_printed(q: np.ndarray, printed: frozenset[str] = frozenset()):
    """Nguyen eqs. (5)-(11) transcribed; the names in ``printed`` keep the report's typo.

    Typos: "f3" (eq. 8), "f6" (eq. 8), "g1" (eq. 9), "px" (eq. 5, d5 term). Returns (R, p)
    with Table 1 in metres. Independent of rrc_pin.solvers.closed_form.
    """
    c, s = np.cos(q), np.sin(q)
    c1, c2, c3, c4, c5, c6, c7 = c
    s1, s2, s3, s4, s5, s6, s7 = s
    a2, a3, a4, a5, a6 = np.array([5.625, 4.25, -4.25, 3.125, -3.125]) * INCH
    d3 = d5 = 27.0 * INCH
    f1 = -c1 * c2 * s3 - s1 * c3
    f2 = c1 * c2 * c3 - s1 * s3
    f3 = -s1 * c2 * s3 - c1 * c3 if "f3" in printed else -s1 * c2 * s3 + c1 * c3
    f4 = s1 * c2 * c3 + c1 * s3
    f5 = -s2 * c3 * c4 - c2 * s4
    f6 = -s1 * c3 * s4 + c2 * c4 if "f6" in printed else -s2 * c3 * s4 + c2 * c4
    g1 = -c1 * s2 * s4 + (c2 if "g1" in printed else c4) * f2
    g2 = c1 * s2 * c4 + s4 * f2
    g3 = -s1 * s2 * s4 + c4 * f4
    g4 = s1 * s2 * c4 + s4 * f4
    g5 = s2 * s3 * c5 - s5 * f5
    g6 = s2 * s3 * s5 + c5 * f5
    h1 = c5 * f1 - s5 * g1
    h2 = s5 * f1 + c5 * g1
    h3 = c5 * f3 - s5 * g3
    h4 = s5 * f3 + c5 * g3
    h5 = c6 * g6 - s6 * f6
    j1 = c6 * h2 - s6 * g2
    j2 = c6 * h4 - s6 * g4
    j3 = d3 * s2 + a2 * c2
    n = [s7 * h1 + c7 * j1, s7 * h3 + c7 * j2, s7 * g5 + c7 * h5]
    o = [c7 * h1 - s7 * j1, c7 * h3 - s7 * j2, c7 * g5 - s7 * h5]
    a = [s6 * h2 + c6 * g2, s6 * h4 + c6 * g4, s6 * g6 + c6 * f6]
    px_d5 = s4 * (f1 if "px" in printed else f2) + c1 * s2 * c4
    p = [
        a6 * j1 + a5 * h2 + d5 * px_d5 + a4 * g1 + a3 * f2 + c1 * j3,
        a6 * j2 + a5 * h4 + d5 * (s4 * f4 + s1 * s2 * c4) + a4 * g3 + a3 * f4 + s1 * j3,
        a6 * h5 + a5 * g6 + d5 * (c2 * c4 - s2 * c3 * s4) + a4 * f5 - a3 * s2 * c3 - a2 * s2
        + d3 * c2,
    ]
    return np.array([n, o, a]).T, np.array(p)


def fk_error(Q: np.ndarray, printed: frozenset[str]) -> float:
    worst = 0.0
    for q in Q:
        R, p = nguyen_printed(q, printed)
        T = ARM.fk(q)
        worst = max(worst, np.abs(R - T[:3, :3]).max(), np.abs(p - T[:3, 3]).max())
    return worst


def test_eqs_5_to_11_corrected_match_pinocchio():
    Q = sample(np.random.default_rng(16), 300)
    assert fk_error(Q, frozenset()) < 1e-12


@pytest.mark.parametrize("typo", ["f3", "f6", "g1", "px"])
def test_eqs_5_8_9_as_printed_are_wrong(typo):
    # Each typo alone, as printed, moves the hand by centimetres or turns it by > 0.1.
    Q = sample(np.random.default_rng(17), 300)
    assert fk_error(Q, frozenset({typo})) > 0.01


def test_eq_18_first_column_as_printed_has_a_sign_error():
    Q = sample(np.random.default_rng(18), 100)
    for q in Q:
        p = ARM.fk(q)[:3, 3]
        J = ARM.jacobian(q)
        printed = np.array([-p[1], -p[0], 0, 0, 0, 1])
        corrected = np.array([-p[1], p[0], 0, 0, 0, 1])
        np.testing.assert_allclose(J[:, 0], corrected, atol=1e-14)
        assert abs(printed[1] - J[1, 0]) > 1e-3 * np.linalg.norm(p[:2]) or abs(p[0]) < 1e-6


def test_eqs_18_19_columns_2_and_3_as_printed_are_right():
    Q = sample(np.random.default_rng(19), 100)
    a2, d3 = 5.625 * INCH, 27.0 * INCH
    for q in Q:
        c1, c2 = np.cos(q[:2])
        s1, s2 = np.sin(q[:2])
        px, py, pz = ARM.fk(q)[:3, 3]
        J = ARM.jacobian(q)
        J2 = [c1 * pz, s1 * pz, -s1 * py - c1 * px, -s1, c1, 0.0]
        Pz, Py, Px = pz + a2 * s2 - d3 * c2, py - a2 * s1 * c2 - d3 * s1 * s2, px - a2 * c1 * c2 - (
            d3 * c1 * s2
        )
        J3 = [
            s1 * s2 * Pz - c2 * Py,
            -c1 * s2 * Pz + c2 * Px,
            c1 * s2 * Py - s1 * s2 * Px,
            c1 * s2,
            s1 * s2,
            c2,
        ]
        np.testing.assert_allclose(J[:, 1], J2, atol=1e-14)
        np.testing.assert_allclose(J[:, 2], J3, atol=1e-14)


def test_eq_16_position_vectors_run_from_frame_i_to_frame_7():
    # As printed, p_i = T_i x0 - T_i x0 = 0 (every linear column would vanish); corrected,
    # [p_i; 0] = 0T7 x0 - 0Ti x0, the cross-product columns are Pinocchio's.
    from rrc_pin.models import CATALOGUE

    chain = CATALOGUE["rrc_k1607"].chain
    rng = np.random.default_rng(20)
    x0 = np.array([0.0, 0.0, 0.0, 1.0])
    for q in sample(rng, 50):
        F = chain.frames(q)
        J = ARM.jacobian(q)
        for i in range(7):
            p_i = F[7] @ x0 - F[i + 1] @ x0
            assert p_i[3] == 0.0
            b_i = F[i + 1][:3, 2]
            np.testing.assert_allclose(J[:3, i], np.cross(b_i, p_i[:3]), atol=1e-14)
        assert np.abs(J[:3]).max() > 0.1
