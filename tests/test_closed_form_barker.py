"""Barker's closed form (solvers/closed_form/barker*.py) against Pinocchio, and its errata.

Reference everywhere: ``rrc_pin.load(...)`` (Pinocchio's LOCAL_WORLD_ALIGNED Jacobian of the
wrist centre), for the PUMA defaults and the variant alpha3 = 88 deg, A3 = 0.02 m, R3 = 0.01 m.
In the singular bands the reference of the default path is damped least squares on
Pinocchio's blocks (:func:`damped_reference`); of ``exact=True`` at singular configurations
the decoupled truncated pseudo-inverse: ``pinv(J[:3, :3], rcond) TVEL`` then
``pinv(J[3:, 3:], rcond) (RVEL - J[3:, :3] arm)``.
"""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.models import barker6
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm, BarkerSingularity
from rrc_pin.solvers.errors import InvalidInput

TOL = 1e-9
MODEL_TOL = 1e-13  # Pinocchio (URDF at 15 significant digits) against exact formulas
N_RANDOM = 10_000
METHODS = ("full", "reduced")
ARMS = {
    "puma": barker6.SPEC,
    "variant": barker6.build(alpha3=np.deg2rad(88), a3=0.02, r3=0.01, name="barker6_variant"),
}


class Arm:
    """A loaded arm, its closed form and Pinocchio helpers."""

    def __init__(self, key: str) -> None:
        self.spec = ARMS[key]
        self.robot = rrc_pin.load(self.spec)
        self.cf: BarkerClosedForm = self.robot.closed_form
        self.lower, self.upper = np.asarray(self.spec.lower), np.asarray(self.spec.upper)
        self.length = self.spec.parameters["es"] + self.spec.parameters["we"]

    def jac(self, Q: np.ndarray) -> np.ndarray:
        return np.array([self.robot.jacobian(q) for q in Q])

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(self.lower, self.upper, size=(n, 6))

    def regular(self, Q: np.ndarray, margin: float = 3e-2) -> np.ndarray:
        s = self.cf.singularity_batch(Q)
        return (
            (np.abs(s.eq32) > margin * self.length)
            & (np.abs(s.eq33) > margin * self.length)
            & (np.abs(s.s5) > margin)
        )


@pytest.fixture(scope="module", params=list(ARMS))
def arm(request: pytest.FixtureRequest) -> Arm:
    return Arm(request.param)


@pytest.fixture(scope="module")
def regular_set(arm: Arm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """>= 10000 configurations off the three conditions and outside the bands, with their
    Pinocchio Jacobians and twists."""
    rng = np.random.default_rng(1983)
    Q = arm.sample(rng, 12_000)
    Q = Q[arm.regular(Q)]
    assert len(Q) >= N_RANDOM
    X = rng.normal(size=(len(Q), 6)) * [0.3, 0.3, 0.3, 1.0, 1.0, 1.0]
    return Q, arm.jac(Q), X


def rel(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Norm-based relative error per leading index (Frobenius over the remaining axes)."""
    a, b = np.asarray(a), np.asarray(b)
    axes = tuple(range(1, a.ndim)) if a.ndim > 1 else None
    return np.linalg.norm(a - b, axis=axes) / np.maximum(np.linalg.norm(b, axis=axes), 1e-300)


def decoupled_reference(J: np.ndarray, x: np.ndarray, rcond: float) -> np.ndarray:
    """Minimum-norm least squares of the arm block, then of the wrist block (stacks)."""
    arm = np.einsum("nij,nj->ni", np.linalg.pinv(J[:, :3, :3], rcond=rcond), x[:, :3])
    rt = x[:, 3:] - np.einsum("nij,nj->ni", J[:, 3:, :3], arm)
    wrist = np.einsum("nij,nj->ni", np.linalg.pinv(J[:, 3:, 3:], rcond=rcond), rt)
    return np.concatenate([arm, wrist], axis=1)


def damped_reference(arm: Arm, Q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The default path from Pinocchio's blocks: exact outside the bands, damped inside.

    Arm: ``(M^T M + lambda^2 I)^-1 M^T TVEL`` with ``lambda^2 = eps^2 - s^2``, ``s = |det M| /
    ||adj M||_F``, ``eps = band L``; wrist: the damping on thetadot_4 and thetadot_6 only,
    ``(W^T W + lambda^2 diag(1, 0, 1))^-1 W^T RVEL~`` with ``s = sigma_min(W)``, ``eps = band``.
    """
    J, p = arm.jac(Q), arm.spec.parameters
    reach = abs(p["es"]) + np.hypot(np.sin(p["alpha3"]) * p["we"], p["a3"])
    M, W = J[:, :3, :3], J[:, 3:, 3:]
    adj = np.stack([np.cross(M[:, 1], M[:, 2]), np.cross(M[:, 2], M[:, 0]),
                    np.cross(M[:, 0], M[:, 1])], axis=1)  # fmt: skip
    s2 = np.linalg.det(M) ** 2 / np.maximum((adj**2).sum(axis=(1, 2)), 1e-300)
    lam2 = np.maximum((arm.cf.band * reach) ** 2 - s2, 0.0)
    Mt = M.transpose(0, 2, 1)
    damped = np.linalg.solve(Mt @ M + lam2[:, None, None] * np.eye(3), Mt @ x[:, :3, None])
    exact = np.linalg.solve(np.where(lam2[:, None, None] > 0, np.eye(3), M), x[:, :3, None])
    rates = np.where(lam2[:, None] > 0, damped[..., 0], exact[..., 0])
    rt = x[:, 3:] - np.einsum("nij,nj->ni", J[:, 3:, :3], rates)
    lam2 = np.maximum(arm.cf.band**2 - np.linalg.svd(W, compute_uv=False)[:, -1] ** 2, 0.0)
    Wt = W.transpose(0, 2, 1)
    A = Wt @ W + lam2[:, None, None] * np.diag([1.0, 0.0, 1.0])
    wrist = np.linalg.solve(A, np.einsum("nij,nj->ni", Wt, rt)[..., None])[..., 0]
    return np.concatenate([rates, wrist], axis=1)


def truncated_pinv(A: np.ndarray, cutoff: float) -> np.ndarray:
    """Pseudo-inverse of A keeping the singular values above an absolute ``cutoff``."""
    U, sv, Vt = np.linalg.svd(A, full_matrices=False)
    keep = sv > cutoff
    return (Vt[keep].T / sv[keep]) @ U[:, keep].T


# -- catalogue ----------------------------------------------------------------------------


def test_catalogue_builds_the_matching_closed_form(arm: Arm) -> None:
    g = arm.cf.geometry
    for name, value in arm.spec.parameters.items():
        if name != "hw":
            assert getattr(g, name) == value
    assert (arm.cf.nq, arm.cf.task_dim) == (6, 6)


# -- Jacobian ------------------------------------------------------------------------------


def test_jacobian_equals_pinocchio(arm: Arm, regular_set) -> None:
    Q, Jp, _ = regular_set
    Jc = arm.cf.jacobian_batch(Q)
    assert rel(Jc, Jp).max() < TOL
    assert np.all(Jc[:, :3, 3:] == 0.0)  # eq. (22): the wrist does not move the wrist centre
    assert np.abs(Jp[:, :3, 3:]).max() < 1e-15
    scalar = np.array([arm.cf.jacobian(q) for q in Q[:300]])
    assert rel(scalar, Jp[:300]).max() < TOL


def test_jacobian_equals_pinocchio_on_the_singular_set(arm: Arm) -> None:
    rng = np.random.default_rng(5)
    Q = np.concatenate([on_condition(arm, c, rng, 50) for c in ("eq32", "eq33", "s5", "double")])
    assert rel(arm.cf.jacobian_batch(Q), arm.jac(Q)).max() < TOL


# -- joint rates away from singularities ---------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_joint_rates_equal_solve_with_pinocchio(arm: Arm, regular_set, method: str) -> None:
    Q, Jp, X = regular_set
    ref = np.linalg.solve(Jp, X[..., None])[..., 0]
    out = arm.cf.joint_rates_batch(Q, X, method=method)
    assert rel(out, ref).max() < TOL
    pairs = zip(Q[:300], X[:300], strict=True)
    scalar = np.array([arm.cf.joint_rates(q, x, method=method) for q, x in pairs])
    assert rel(scalar, ref[:300]).max() < TOL


@pytest.mark.parametrize("method", METHODS)
def test_arm_and_wrist_rates_solve_their_blocks(arm: Arm, regular_set, method: str) -> None:
    Q, Jp, X = regular_set
    Q, Jp, X = Q[:2000], Jp[:2000], X[:2000]
    arm_ref = np.linalg.solve(Jp[:, :3, :3], X[:, :3, None])[..., 0]
    assert rel(arm.cf.arm_rates_batch(Q, X[:, :3], method=method), arm_ref).max() < TOL
    wrist_ref = np.linalg.solve(Jp[:, 3:, 3:], X[:, 3:, None])[..., 0]
    assert rel(arm.cf.wrist_rates_batch(Q, X[:, 3:]), wrist_ref).max() < TOL  # no method
    rows = zip(Q[:50], arm_ref[:50], X[:50], strict=True)
    rt = np.array([arm.cf.rvel_tilde(q, a, x[3:]) for q, a, x in rows])
    assert rel(rt, X[:50, 3:] - np.einsum("nij,nj->ni", Jp[:50, 3:, :3], arm_ref[:50])).max() < TOL


# -- special poses: start pose and the joints' zeros ---------------------------------------


def special_poses(arm: Arm, rng: np.random.Generator) -> np.ndarray:
    """q = 0 (Barker fig. 3), one joint zero and the others random, all but one zero."""
    poses = [np.zeros(6)]
    for j in range(6):
        one_zero = arm.sample(rng, 4)
        one_zero[:, j] = 0.0
        poses.extend(one_zero)
        for value in [*rng.uniform(arm.lower[j], arm.upper[j], 3).tolist(), arm.upper[j] / 2]:
            q = np.zeros(6)
            q[j] = value
            poses.append(q)
    return np.array(poses)


@pytest.mark.parametrize("method", METHODS)
def test_every_path_at_start_pose_and_joint_zeros(arm: Arm, method: str) -> None:
    Q = special_poses(arm, np.random.default_rng(7))
    Jp = arm.jac(Q)
    X = np.random.default_rng(8).normal(size=(len(Q), 6))
    s = arm.cf.singularity_batch(Q)
    # the wrist is exactly singular wherever theta_5 = 0: M2* gives the minimum-norm rates with
    # ``exact``, the default path the damped ones; the arm is regular but in its band at
    # q = 0 (det M = ES A3^2) and wherever theta_2 = theta_3 = 0
    assert np.sum(s.wrist_singular) == np.sum(Q[:, 4] == 0.0) >= 25
    assert s.arm_singular[0] and abs(s.det_m[0]) > 1e-4
    cf = arm.cf
    # the reduced path damps M1, not M: compared outside the arm's band
    keep = ~s.arm_singular if method == "reduced" else np.ones(len(Q), dtype=bool)
    for exact, ref in ((True, decoupled_reference(Jp, X, cf.rcond)),
                       (False, damped_reference(arm, Q, X))):  # fmt: skip
        rows = np.ones(len(Q), dtype=bool) if exact else keep
        out = cf.joint_rates_batch(Q, X, method=method, exact=exact)
        assert np.all(np.isfinite(out))
        assert rel(out[rows], ref[rows]).max() < TOL
        pairs = zip(Q, X, strict=True)
        scalar = np.array([cf.joint_rates(q, x, method=method, exact=exact) for q, x in pairs])
        assert rel(scalar[rows], ref[rows]).max() < TOL
        arm_rates = cf.arm_rates_batch(Q, X[:, :3], method, exact)
        assert rel(arm_rates[rows], ref[rows, :3]).max() < TOL
    wrist_ref = np.einsum("nij,nj->ni", np.linalg.pinv(Jp[:, 3:, 3:], rcond=cf.rcond), X[:, 3:])
    wrist = cf.wrist_rates_batch(Q, X[:, 3:], exact=True)
    assert rel(wrist, wrist_ref).max() < TOL


def test_wrist_generalized_inverse_splits_equally_at_theta5_zero(arm: Arm) -> None:
    """Barker: at theta_5 = 0 'the generalized matrix inverse solution splits the rotational
    task equally between theta_4 and theta_6' (eq. (61))."""
    rng = np.random.default_rng(11)
    Q = arm.sample(rng, 100)
    Q[:, 4] = 0.0
    # damping keeps the split (it acts on (1, 1) and (1, -1)), to the rounding of its normal
    # equations (condition number 2 / band^2)
    for exact, tol in ((True, 1e-15), (False, 1e-11)):
        W = arm.cf.wrist_rates_batch(Q, rng.normal(size=(100, 3)), exact)
        assert np.all(np.abs(W[:, 0] - W[:, 2]) <= tol * np.abs(W).max())


# -- determinant and the singular set ------------------------------------------------------


def on_condition(arm: Arm, which: str, rng: np.random.Generator, n: int) -> np.ndarray:
    """Configurations within the limits exactly on one singularity condition."""
    g = arm.cf.geometry
    Q = arm.sample(rng, 4 * n)
    if which in ("eq33", "double"):  # SAL3 WE S3 + A3 C3 = 0 (eq. (33))
        Q[:, 2] = np.arctan2(-g.a3, g.swe)
    if which == "double":  # S2 = 0 with eq. (33): F1 = F5 = 0 and M has rank one
        Q[:, 1] = 0.0
    if which == "eq32":  # S2 (ES + SAL3 WE C3 - A3 S3) + C2 (SAL3 WE S3 + A3 C3) = 0
        s3, c3 = np.sin(Q[:, 2]), np.cos(Q[:, 2])
        theta2 = np.arctan2(-(g.swe * s3 + g.a3 * c3), g.es + g.swe * c3 - g.a3 * s3)
        flip = rng.random(len(Q)) < 0.5
        Q[:, 1] = np.where(flip, theta2 + np.where(theta2 > 0, -np.pi, np.pi), theta2)
    if which == "s5":
        Q[:, 4] = 0.0
    inside = np.all((Q >= arm.lower) & (Q <= arm.upper), axis=1)
    assert inside.sum() >= n
    return Q[inside][:n]


def test_det_m_factored_form_d9(arm: Arm, regular_set) -> None:
    Q, Jp, _ = regular_set
    det = arm.cf.det_m_batch(Q)
    scale = np.linalg.norm(Jp[:, :3, :3], axis=(1, 2)) ** 3
    assert np.max(np.abs(det - np.linalg.det(arm.cf.m_matrix_batch(Q))) / scale) < 1e-14
    assert np.max(np.abs(det - np.linalg.det(Jp[:, :3, :3])) / scale) < 1e-14
    # det J = det M det W with det W = -S5: the singular set is exactly the three conditions
    s = arm.cf.singularity_batch(Q)
    assert rel(np.linalg.det(Jp), -arm.cf.geometry.es * s.eq32 * s.eq33 * s.s5).max() < 1e-12
    assert rel(s.eq32, -Jp[:, 2, 1]).max() < 1e-13  # eq. (32) is F1 = -M[2, 1]


@pytest.mark.parametrize("which", ["eq32", "eq33", "s5", "double"])
def test_smallest_singular_value_vanishes_on_each_condition(arm: Arm, which: str) -> None:
    Q = on_condition(arm, which, np.random.default_rng(3), 200)
    sv = np.linalg.svd(arm.jac(Q), compute_uv=False)
    assert np.max(sv[:, -1] / sv[:, 0]) < 1e-14
    if which == "double":  # rank 4: two singular values of M vanish
        assert np.max(sv[:, -2] / sv[:, 0]) < 1e-14
    s = arm.cf.singularity_batch(Q)
    value = {"eq32": s.eq32, "eq33": s.eq33, "s5": s.s5, "double": s.eq32}[which]
    assert np.max(np.abs(value)) < 1e-15
    flag = s.wrist_singular if which == "s5" else s.arm_singular
    assert np.all(flag)


def test_smallest_singular_value_off_the_conditions(arm: Arm, regular_set) -> None:
    Q, Jp, _ = regular_set
    sv = np.linalg.svd(Jp, compute_uv=False)
    assert np.min(sv[:, -1] / sv[:, 0]) > 1e-6
    s = arm.cf.singularity_batch(Q)
    assert not np.any(s.arm_singular) and not np.any(s.wrist_singular)


def test_singularity_record(arm: Arm) -> None:
    q = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    s = arm.cf.singularity(q)
    assert isinstance(s, BarkerSingularity)
    g = arm.cf.geometry
    F = arm.cf.f_terms(q)
    assert s.eq32 == pytest.approx(np.sin(0.2) * g.es + F.f5, rel=1e-15)
    assert s.eq33 == pytest.approx(g.swe * np.sin(0.3) + g.a3 * np.cos(0.3), rel=1e-15)
    assert s.s5 == np.sin(0.5)
    assert s.det_m == pytest.approx(arm.cf.det_m(q), rel=1e-15)
    assert s.arm_singular is False and s.wrist_singular is False


# -- exactly singular configurations: finite, minimum norm ---------------------------------


@pytest.mark.parametrize("which", ["eq32", "eq33", "s5", "double"])
def test_full_path_at_singularities_damped_or_minimum_norm(arm: Arm, which: str) -> None:
    """Default: damped least squares (the null direction gets nothing, the others are damped
    by sigma^2 / (sigma^2 + eps^2)); ``exact``: the minimum-norm M*, M2* (eqs (38), (60))."""
    rng = np.random.default_rng(13)
    Q = on_condition(arm, which, rng, 100)
    X = rng.normal(size=(100, 6))
    cf = arm.cf
    minimum_norm = decoupled_reference(arm.jac(Q), X, cf.rcond)
    for exact, ref in ((True, minimum_norm), (False, damped_reference(arm, Q, X))):
        out = cf.joint_rates_batch(Q, X, exact=exact)
        assert np.all(np.isfinite(out))
        assert rel(out, ref).max() < TOL
        pairs = zip(Q[:30], X[:30], strict=True)
        scalar = np.array([cf.joint_rates(q, x, exact=exact) for q, x in pairs])
        assert rel(scalar, ref[:30]).max() < TOL


@pytest.mark.parametrize("which", ["eq32", "eq33", "double"])
def test_reduced_path_at_arm_singularities(arm: Arm, which: str) -> None:
    """Eq. (39) + eq. (44) with the exact M1*: least squares of eq. (25) among rates
    satisfying eq. (39), least (thetadot_2, thetadot_3) norm; the minimum-norm answer at
    eq. (33) for realisable commands, not at eq. (32) (M* also moves thetadot_1 there)."""
    rng = np.random.default_rng(17)
    Q = on_condition(arm, which, rng, 100)
    T = rng.normal(size=(100, 3))
    out = arm.cf.arm_rates_batch(Q, T, method="reduced", exact=True)
    assert np.all(np.isfinite(out))
    F = arm.cf.f_terms_batch(Q)
    f2 = arm.cf.geometry.f2
    assert rel(out[:, 0], (F.f3 * out[:, 1] + F.f4 * out[:, 2] - np.cos(Q[:, 0]) * T[:, 0]
                           - np.sin(Q[:, 0]) * T[:, 1]) / f2).max() < TOL  # eq. (39)  # fmt: skip
    # reference: eliminate thetadot_1 by eq. (39), then min-norm least squares in (2, 3)
    M = arm.jac(Q)[:, :3, :3]
    ta = np.cos(Q[:, 0]) * T[:, 0] + np.sin(Q[:, 0]) * T[:, 1]
    A = M[:, :, 1:] + M[:, :, :1] * np.stack([F.f3, F.f4], axis=-1)[:, None, :] / f2
    b = T + M[:, :, 0] * (ta / f2)[:, None]
    cutoff = arm.cf.rcond * np.linalg.norm(M, axis=(1, 2))  # M1*: an absolute cut (rcond L)
    th23 = np.array([truncated_pinv(a, c) @ v for a, c, v in zip(A, cutoff, b, strict=True)])
    assert rel(out[:, 1:], th23).max() < TOL
    # realisable commands: compare with M* (eq. (38))
    T_in = np.einsum("nij,nj->ni", M, rng.normal(size=(100, 3)))
    red = arm.cf.arm_rates_batch(Q, T_in, method="reduced", exact=True)
    full = arm.cf.arm_rates_batch(Q, T_in, exact=True)
    assert rel(np.einsum("nij,nj->ni", M, red), T_in).max() < 1e-8
    if which == "eq33":
        assert rel(red, full).max() < TOL
    else:
        assert np.all(np.linalg.norm(red, axis=1) > np.linalg.norm(full, axis=1) * (1 + 1e-6))


# -- continuity across the singular neighbourhoods (issue 18) ------------------------------

GRID = np.concatenate([-np.logspace(-1, -12, 56), [0.0], np.logspace(-12, -1, 56)])
"""Offsets [rad] from a singular configuration: a fine logarithmic grid through zero."""
SWEEP_BASE = np.array([0.3, -0.5, 0.8, 0.4, 0.6, 0.2])
SWEEP_TWIST = np.array([0.1, -0.2, 0.15, 0.1, 0.2, 0.3])


def sweep(arm: Arm, which: str) -> np.ndarray:
    """(len(GRID), 6) configurations crossing one singularity at offset 0: theta_5 = 0,
    eq. (33) in theta_3, eq. (32) in theta_2, or the double singularity (S2 = 0, eq. (33))."""
    g = arm.cf.geometry
    Q = np.tile(SWEEP_BASE, (len(GRID), 1))
    t3 = np.arctan2(-g.a3, g.swe)  # SAL3 WE S3 + A3 C3 = 0
    if which == "s5":
        Q[:, 4] = GRID
    elif which == "eq33":
        Q[:, 2] = t3 + GRID
    elif which == "double":
        Q[:, 1], Q[:, 2] = GRID, t3 + GRID
    else:  # eq. (32): S2 (ES + SAL3 WE C3 - A3 S3) + C2 (SAL3 WE S3 + A3 C3) = 0
        s3, c3 = np.sin(SWEEP_BASE[2]), np.cos(SWEEP_BASE[2])
        Q[:, 1] = np.arctan2(-(g.swe * s3 + g.a3 * c3), g.es + g.swe * c3 - g.a3 * s3) + GRID
    return Q


@pytest.mark.parametrize("which", ["s5", "eq32", "eq33", "double"])
def test_default_rates_are_continuous_through_every_singularity(arm: Arm, which: str) -> None:
    """Issue 18: across 1e-12 rad the rates jumped from 0.33 to 2.5e11 rad/s (theta_5). The
    default path must be continuous (bounded jumps), finite, bounded by 1 / band times the
    command, and still Pinocchio's exact solve far outside the bands."""
    Q = sweep(arm, which)
    X = np.tile(SWEEP_TWIST, (len(Q), 1))
    band = 1e-2  # the documented default
    p = arm.spec.parameters
    eps = band * (abs(p["es"]) + np.hypot(np.sin(p["alpha3"]) * p["we"], p["a3"]))
    for out in (arm.cf.joint_rates_batch(Q, X),
                np.array([arm.cf.joint_rates(q, x) for q, x in zip(Q, X, strict=True)])):
        assert np.all(np.isfinite(out))
        # bounded: no block amplifies its command by more than 1 / eps
        assert np.all(np.linalg.norm(out[:, :3], axis=1) <= np.linalg.norm(X[0, :3]) / eps)
        rt = X[:, 3:] - np.einsum("nij,nj->ni", arm.jac(Q)[:, 3:, :3], out[:, :3])
        assert np.all(np.linalg.norm(out[:, 3::2], axis=1)
                      <= np.linalg.norm(rt, axis=1) / band * (1 + 1e-9))  # fmt: skip
        # continuous: jumps bounded by a Lipschitz constant of the damped solve (|x| / eps^2)
        slope = np.linalg.norm(np.diff(out, axis=0), axis=1) / np.diff(GRID)
        assert slope.max() < 10.0 * np.linalg.norm(SWEEP_TWIST) / eps**2
    far = np.abs(GRID) >= 0.1
    s = arm.cf.singularity_batch(Q[far])
    assert not np.any(s.arm_singular | s.wrist_singular)
    ref = np.linalg.solve(arm.jac(Q[far]), X[far][..., None])[..., 0]
    assert rel(arm.cf.joint_rates_batch(Q[far], X[far]), ref).max() < TOL
    # on request, the exact inverse: as large as 1 / sigma_min near the singularity
    near = np.abs(GRID) == 1e-6
    J = np.array([arm.spec.chain.jacobian(q, "world_aligned") for q in Q[near]])
    exact = arm.cf.joint_rates_batch(Q[near], X[near], exact=True)
    assert rel(exact, np.linalg.solve(J, X[near][..., None])[..., 0]).max() < 1e-6
    assert np.linalg.norm(exact, axis=1).min() > 1e3


def test_rates_are_bounded_by_the_band(arm: Arm) -> None:
    """|thetadot_123| <= |TVEL| / (band L), |(thetadot_4, thetadot_6)| <= |RVEL~| / band."""
    rng = np.random.default_rng(61)
    Q = np.concatenate([arm.sample(rng, 2000)]
                       + [on_condition(arm, c, rng, 200) for c in ("eq32", "eq33", "s5", "double")])
    Q += rng.choice([0.0, 1e-9, 1e-6, 1e-3], size=Q.shape)  # and their neighbourhoods
    X = rng.normal(size=(len(Q), 6))
    cf = arm.cf
    out = cf.joint_rates_batch(Q, X)
    eps = cf.band * cf.geometry.reach
    assert np.all(np.linalg.norm(out[:, :3], axis=1) <= np.linalg.norm(X[:, :3], axis=1) / eps)
    rt = cf.rvel_tilde_batch(Q, out[:, :3], X[:, 3:])
    assert np.all(np.linalg.norm(out[:, 3::2], axis=1)
                  <= np.linalg.norm(rt, axis=1) / cf.band * (1 + 1e-12))  # fmt: skip
    # the damped normal equations have a condition number up to (sigma_max / eps)^2 ~ 1e4
    assert rel(out, damped_reference(arm, Q, X)).max() < 1e-8  # reached: 3e-10


# -- appendix B: hand to base, frame 2 -----------------------------------------------------


def test_hand_to_base_equals_pinocchio_rotation(arm: Arm) -> None:
    rng = np.random.default_rng(19)
    Q = np.concatenate([arm.sample(rng, 300), special_poses(arm, rng)])
    R = arm.cf.hand_to_base_batch(Q)
    ref = np.array([arm.robot.fk(q)[:3, :3] for q in Q])
    assert np.abs(R - ref).max() < MODEL_TOL
    q, twist = Q[0], rng.normal(size=6)
    J_local = arm.robot.jacobian(q, "local")
    qd = np.linalg.solve(J_local, twist)  # eq. (20): hand-axis command -> base axes
    assert rel(arm.cf.hand_twist_to_base(q, twist), arm.robot.jacobian(q) @ qd) < 1e-12


def test_tvel_frame2_equals_r2_transpose(arm: Arm) -> None:
    rng = np.random.default_rng(23)
    Q = np.concatenate([arm.sample(rng, 200), special_poses(arm, rng)])
    T = rng.normal(size=(len(Q), 3))
    ref = np.array([arm.spec.chain.frames(q)[2][:3, :3].T @ t for q, t in zip(Q, T, strict=True)])
    assert np.abs(arm.cf.tvel_frame2_batch(Q, T) - ref).max() < 1e-14
    assert np.abs(arm.cf.tvel_frame2(Q[0], T[0]) - ref[0]).max() < 1e-14


# -- batch == scalar -----------------------------------------------------------------------


def test_batch_equals_scalar(arm: Arm) -> None:
    """One configuration and a batch run the same kernels: the same floats, bit for bit."""
    rng = np.random.default_rng(29)
    singular = [on_condition(arm, c, rng, 25) for c in ("eq32", "eq33", "s5", "double")]
    Q = np.concatenate([arm.sample(rng, 900), *singular])
    X = rng.normal(size=(1000, 6))
    cf = arm.cf
    same = np.testing.assert_array_equal
    for method, exact in ((m, e) for m in METHODS for e in (False, True)):
        B = cf.joint_rates_batch(Q, X, method, exact)
        same(np.array([cf.joint_rates(q, x, method, exact) for q, x in zip(Q, X, strict=True)]), B)
        B = cf.arm_rates_batch(Q, X[:, :3], method, exact)
        same(np.array([cf.arm_rates(q, x[:3], method, exact) for q, x in zip(Q, X, strict=True)]),
             B)  # fmt: skip
    for exact in (False, True):  # the wrist has no method
        B = cf.wrist_rates_batch(Q, X[:, 3:], exact)
        same(np.array([cf.wrist_rates(q, x[3:], exact) for q, x in zip(Q, X, strict=True)]), B)
    same(np.array([cf.jacobian(q) for q in Q]), cf.jacobian_batch(Q))
    sb, d, M = cf.singularity_batch(Q), cf.det_m_batch(Q), cf.m_matrix_batch(Q)
    for i in range(0, 1000, 37):
        s = cf.singularity(Q[i])
        assert s == tuple(v[i] for v in sb)
        assert type(s.eq32) is float and type(s.arm_singular) is bool
        assert cf.det_m(Q[i]) == d[i]
        same(cf.m_matrix(Q[i]), M[i])
        assert cf.f_terms(Q[i]) == tuple(v[i] for v in cf.f_terms_batch(Q))
    rt = rng.normal(size=(1000, 3))
    S = np.array([np.concatenate([cf.rvel_tilde(q, a, r), cf.hand_twist_to_base(q, x)])
                  for q, x, (a, r) in zip(Q, X, zip(rt, X[:, 3:], strict=True), strict=True)])
    B = np.concatenate([cf.rvel_tilde_batch(Q, rt, X[:, 3:]), cf.hand_twist_to_base_batch(Q, X)], 1)
    same(S, B)


def test_batch_equals_its_parts(arm: Arm) -> None:
    """A batch computes each row by itself: the whole equals its parts computed apart."""
    rng = np.random.default_rng(31)
    Q = np.concatenate([arm.sample(rng, 3000), on_condition(arm, "s5", rng, 20)])
    X = rng.normal(size=(len(Q), 6))
    whole = arm.cf.joint_rates_batch(Q, X)
    parts = np.concatenate([arm.cf.joint_rates_batch(Q[i : i + 999], X[i : i + 999])
                            for i in range(0, len(Q), 999)])  # fmt: skip
    np.testing.assert_array_equal(whole, parts)
    assert arm.cf.joint_rates_batch(Q[:0], X[:0]).shape == (0, 6)


# -- bad input ------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [np.zeros(5), np.zeros((1, 6)), [0, 0, 0, np.nan, 0, 0],
                                 [0, 0, 0, 0, np.inf, 0], "abc"])  # fmt: skip
def test_bad_q_raises_input_error(bad) -> None:
    cf = Arm("puma").cf
    calls = [
        lambda: cf.jacobian(bad), lambda: cf.joint_rates(bad, np.zeros(6)),
        lambda: cf.arm_rates(bad, np.zeros(3)), lambda: cf.wrist_rates(bad, np.zeros(3)),
        lambda: cf.singularity(bad), lambda: cf.hand_to_base(bad), lambda: cf.det_m(bad),
        lambda: cf.tvel_frame2(bad, np.zeros(3)), lambda: cf.m_matrix(bad),
    ]  # fmt: skip
    for call in calls:
        with pytest.raises(InvalidInput) as info:
            call()
        assert info.value.argument == "q"
        assert isinstance(info.value, ValueError)


def test_bad_velocities_and_batches_raise_input_error() -> None:
    cf = Arm("puma").cf
    q, Q = np.zeros(6), np.zeros((4, 6))
    cases = [
        (lambda: cf.joint_rates(q, np.zeros(5)), "xdot"),
        (lambda: cf.joint_rates(q, [0, 0, np.nan, 0, 0, 0]), "xdot"),
        (lambda: cf.arm_rates(q, np.zeros(6)), "tvel"),
        (lambda: cf.wrist_rates(q, [np.inf, 0, 0]), "rvel_tilde"),
        (lambda: cf.rvel_tilde(q, np.zeros(2), np.zeros(3)), "arm_rates"),
        (lambda: cf.joint_rates_batch(np.zeros((4, 5)), np.zeros((4, 6))), "Q"),
        (lambda: cf.joint_rates_batch(Q, np.zeros((3, 6))), "X"),
        (lambda: cf.joint_rates_batch(np.full((4, 6), np.nan), np.zeros((4, 6))), "Q"),
        (lambda: cf.jacobian_batch(np.zeros(6)), "Q"),
        (lambda: cf.arm_rates_batch(Q, np.zeros((4, 2))), "TVEL"),
        (lambda: cf.wrist_rates_batch(Q, np.full((4, 3), np.nan)), "RVEL_TILDE"),
        (lambda: cf.tvel_frame2_batch(Q, np.zeros((5, 3))), "TVEL"),
        (lambda: cf.joint_rates(q, np.zeros(6), method="pinv"), "method"),
        (lambda: cf.joint_rates_batch(Q, np.zeros((4, 6)), method="fast"), "method"),
        (lambda: cf.hand_twist_to_base(q, np.zeros(3)), "twist"),
    ]
    for call, name in cases:
        with pytest.raises(InvalidInput) as info:
            call()
        assert info.value.argument == name


@pytest.mark.parametrize("name", ["no", "es", "sn", "we", "a3", "r3", "alpha3", "rcond"])
@pytest.mark.parametrize("value", [np.nan, np.inf, "x", None])
def test_constructor_validates_parameters(name: str, value) -> None:
    params = dict(no=0.6718, es=0.4318, sn=0.15, we=0.4318, a3=0.0203, r3=0.0, alpha3=np.pi / 2)
    params[name] = value
    with pytest.raises(InvalidInput) as info:
        BarkerClosedForm(**params)
    assert info.value.argument == name


def test_constructor_is_keyword_only_and_checks_rcond() -> None:
    with pytest.raises(TypeError):
        BarkerClosedForm(0.6718, 0.4318, 0.15, 0.4318, 0.0203, 0.0, np.pi / 2)  # type: ignore[misc]
    params = dict(no=0.6718, es=0.4318, sn=0.15, we=0.4318, a3=0.0203, r3=0.0, alpha3=np.pi / 2)
    with pytest.raises(InvalidInput, match="rcond"):
        BarkerClosedForm(**params, rcond=0.7)
    no_f2 = BarkerClosedForm(**{**params, "sn": 0.0})
    with pytest.raises(InvalidInput, match="F2"):  # SN + R3 + CAL3 WE = 0: no reduced path
        no_f2.joint_rates(np.ones(6), np.ones(6), "reduced")
    # the wrist never divides by F2: its rates are the last three of the full path's
    full = no_f2.joint_rates(np.ones(6), np.ones(6))
    rt = no_f2.rvel_tilde(np.ones(6), full[:3], np.ones(3))
    np.testing.assert_allclose(no_f2.wrist_rates(np.ones(6), rt), full[3:], rtol=1e-14)


# -- errata (docs/errata.d/barker.md) and the report's statements ---------------------------


def test_erratum_eq35_eq36_signs(arm: Arm, regular_set) -> None:
    Q, Jp, X = regular_set
    Q, Jp, T = Q[:1000], Jp[:1000], X[:1000, :3]
    ref = np.linalg.solve(Jp[:, :3, :3], T[..., None])[..., 0]
    F = arm.cf.f_terms_batch(Q)
    det = arm.cf.det_m_batch(Q)
    T1, T2, T3 = T.T
    s1, c1 = np.sin(Q[:, 0]), np.cos(Q[:, 0])
    eq34 = (T1 * s1 - T2 * c1) * (F.f1 * F.f4 - F.f3 * F.f5) / det
    printed35 = -(F.f5 * (T1 * F.f7 + T2 * F.f6) + T3 * F.f1 * F.f4) / det
    printed36 = -F.f1 * (T1 * F.f7 - T2 * F.f6 + T3 * F.f3) / det
    corrected35 = (F.f5 * (T1 * F.f7 + T2 * F.f6) + T3 * F.f1 * F.f4) / det
    corrected36 = -F.f1 * (T1 * F.f7 + T2 * F.f6 + T3 * F.f3) / det
    assert rel(eq34, ref[:, 0]).max() < TOL  # eq. (34) is right as printed
    assert rel(corrected35, ref[:, 1]).max() < TOL
    assert rel(corrected36, ref[:, 2]).max() < TOL
    assert np.median(rel(printed35, ref[:, 1])) == pytest.approx(2.0)
    assert np.median(rel(printed36, ref[:, 2])) > 0.1


def test_erratum_eq43_m1_vanishes_at_theta1_zero(arm: Arm) -> None:
    rng = np.random.default_rng(31)
    Q = arm.sample(rng, 200)
    F = arm.cf.f_terms_batch(Q)
    s1 = np.sin(Q[:, 0])
    # printed first row factor C1 F2 - F6 is -S1 F1: det(printed M1) = S1 det M
    factor = np.cos(Q[:, 0]) * F.f2 - F.f6
    assert np.abs(factor + s1 * F.f1).max() < 1e-15
    det_m1 = factor * F.f3 * -F.f5 - factor * F.f4 * -F.f1
    assert np.abs(det_m1 - s1 * arm.cf.det_m_batch(Q)).max() < 1e-15
    # at theta_1 = 0 (the start pose among them) the printed M1 and g1 lose row 2 of eq. (25)
    Q[:, 0] = 0.0
    Q[0] = 0.0
    Q = Q[arm.regular(Q)]
    Jp = arm.jac(Q)
    T = rng.normal(size=(len(Q), 3))
    ref = np.linalg.solve(Jp[:, :3, :3], T[..., None])[..., 0]
    F = arm.cf.f_terms_batch(Q)
    T1, _T2, T3 = T.T
    factor = F.f2 - F.f6  # C1 = 1, S1 = 0
    assert np.all(factor == 0.0)
    M1 = np.stack([np.stack([factor * F.f3, factor * F.f4], -1), np.stack([-F.f1, -F.f5], -1)], 1)
    g1 = np.stack([F.f2 * T1 - F.f6 * T1, T3], axis=-1)  # eq. (42) at theta_1 = 0
    th23 = np.einsum("nij,nj->ni", np.linalg.pinv(M1, rcond=arm.cf.rcond), g1)  # eq. (44)
    th1 = (F.f3 * th23[:, 0] + F.f4 * th23[:, 1] - T1) / F.f2  # eq. (39)
    printed = np.column_stack([th1, th23])
    assert np.min(rel(printed, ref)) > 1e-3
    assert rel(arm.cf.arm_rates_batch(Q, T, method="reduced"), ref).max() < TOL


def test_erratum_eq28_f2_contains_r3() -> None:
    arm = Arm("variant")
    g = arm.cf.geometry
    assert g.f2 == pytest.approx(g.sn + g.r3 + g.cal3 * g.we, rel=1e-15)
    rng = np.random.default_rng(37)
    Q = arm.sample(rng, 100)
    Jp = arm.jac(Q)
    F = arm.cf.f_terms_batch(Q)
    s1, c1 = np.sin(Q[:, 0]), np.cos(Q[:, 0])
    for f2, good in ((g.sn + g.r3 + g.cal3 * g.we, True), (g.sn + g.cal3 * g.we, False)):
        col1 = np.column_stack([-s1 * F.f1 - c1 * f2, c1 * F.f1 - s1 * f2, 0 * s1])  # eq. (26)
        err = np.linalg.norm(col1 - Jp[:, :3, 0], axis=1)
        assert (err.max() < MODEL_TOL) if good else np.allclose(err, g.r3, rtol=1e-12, atol=0)


def test_erratum_b11_p2(arm: Arm) -> None:
    rng = np.random.default_rng(41)
    g = arm.cf.geometry
    for q in np.concatenate([arm.sample(rng, 50), special_poses(arm, rng)[1:]]):
        F = arm.spec.chain.frames(q)
        ref = F[1][:3, :3].T @ F[3][:3, :3]  # R1_2 R2_3
        s23, c23 = np.sin(q[1] + q[2]), np.cos(q[1] + q[2])
        p1 = -c23
        errs = []
        for p2 in (-s23, -s23 * g.cal3):  # corrected, printed
            B4 = np.array([[p1, -p2 * g.cal3, p2 * g.sal3],
                           [p2, p1 * g.cal3, -p1 * g.sal3], [0.0, g.sal3, g.cal3]])  # fmt: skip
            errs.append(np.abs(B4 - ref).max())
        assert errs[0] < 1e-15
        if abs(s23) > 1e-3:
            assert errs[1] > 1e-3 * abs(s23)


def test_erratum_b28_b29(arm: Arm) -> None:
    rng = np.random.default_rng(43)
    Q = arm.sample(rng, 200)
    T = rng.normal(size=(200, 3))
    ref = np.array([arm.spec.chain.frames(q)[2][:3, :3].T @ t for q, t in zip(Q, T, strict=True)])
    s1, c1, s2, c2 = np.sin(Q[:, 0]), np.cos(Q[:, 0]), np.sin(Q[:, 1]), np.cos(Q[:, 1])
    T1, T2, T3 = T.T
    printed_x2 = s2 * (c1 * T1 - s1 * T2 + c2 * T3)
    printed_y2 = c2 * (c1 * T1 - s1 * T2 - s2 * T3)
    assert np.median(np.abs(printed_x2 - ref[:, 0])) > 0.1
    assert np.median(np.abs(printed_y2 - ref[:, 1])) > 0.1
    corrected = np.column_stack([s2 * (c1 * T1 + s1 * T2) + c2 * T3,
                                 c2 * (c1 * T1 + s1 * T2) - s2 * T3])  # fmt: skip
    assert np.abs(corrected - ref[:, :2]).max() < 1e-14
    assert np.abs(arm.cf.tvel_frame2_batch(Q, T)[:, :2] - corrected).max() < 1e-15


def test_start_pose_is_singular_only_for_a3_zero() -> None:
    """'In figure 3, both singularity conditions are satisfied': only with A3 = 0."""
    puma = Arm("puma").cf
    s = puma.singularity(np.zeros(6))
    assert s.eq32 == s.eq33 == pytest.approx(0.0203, rel=1e-12)
    assert s.det_m == pytest.approx(0.4318 * 0.0203**2, rel=1e-12)  # ES A3^2
    nominal = rrc_pin.load(barker6.build(a3=0.0, name="barker6_a3_zero"))
    s = nominal.closed_form.singularity(np.zeros(6))
    assert abs(s.eq32) < 1e-16 and abs(s.eq33) < 1e-16 and s.arm_singular
    J = nominal.spec.chain.jacobian(np.zeros(6), "world_aligned")  # exact: the DH table
    sv = np.linalg.svd(J[:3, :3], compute_uv=False)
    assert sv[1] / sv[0] < 1e-15  # the double singularity: M has rank one
    # nominal values (A3 = 0, ES = WE, alpha3 = 90 deg): eq. (32) is ES (S2 + S23) = 0 and
    # eq. (33) is WE S3 = 0, as the report says
    rng = np.random.default_rng(47)
    Q = rng.uniform(-2, 2, (100, 6))
    s = nominal.closed_form.singularity_batch(Q)
    es = nominal.spec.parameters["es"]
    assert np.abs(s.eq32 - es * (np.sin(Q[:, 1]) + np.sin(Q[:, 1] + Q[:, 2]))).max() < 1e-15
    assert np.abs(s.eq33 - es * np.sin(Q[:, 2])).max() < 1e-15


def test_appendix_c_wrist_identities_hold_as_printed(arm: Arm) -> None:
    """(C36)-(C48): D1..D5 of eqs (52)-(56) against RVEL~ = W thetadot_456."""
    rng = np.random.default_rng(53)
    Q = arm.sample(rng, 200)
    w = rng.normal(size=(200, 3))
    rt = np.einsum("nij,nj->ni", arm.jac(Q)[:, 3:, 3:], w)
    g = arm.cf.geometry
    s1, c1 = np.sin(Q[:, 0]), np.cos(Q[:, 0])
    s23, c23 = np.sin(Q[:, 1] + Q[:, 2]), np.cos(Q[:, 1] + Q[:, 2])
    s4, c4, s5, c5 = np.sin(Q[:, 3]), np.cos(Q[:, 3]), np.sin(Q[:, 4]), np.cos(Q[:, 4])
    d1 = c1 * rt[:, 0] + s1 * rt[:, 1]
    d2 = s1 * rt[:, 0] - c1 * rt[:, 1]
    d3 = s23 * d1 + c23 * rt[:, 2]
    d4 = c23 * d1 - s23 * rt[:, 2]
    d5 = g.cal3 * d3 + g.sal3 * d2
    t4, t5, t6 = w.T
    sal3, cal3 = g.sal3, g.cal3
    checks = [
        (d1, s23 * sal3 * t4 - (c23 * s4 + c4 * s23 * cal3) * t5
         + ((c23 * c4 - s23 * s4 * cal3) * s5 + s23 * sal3 * c5) * t6),  # (C36)
        (d3, sal3 * (t4 + c5 * t6) - c4 * cal3 * t5 - s4 * cal3 * s5 * t6),  # (C38)
        (d2, -cal3 * (t4 + c5 * t6) - c4 * sal3 * t5 - s4 * sal3 * s5 * t6),  # (C40)
        (d4, -s4 * t5 + c4 * s5 * t6),  # (C42)
        (d5, -c4 * t5 - s4 * s5 * t6),  # (C44)
        (t5, -c4 * d5 - s4 * d4),  # (C46) = eq. (49)
        (s5 * t6, -s4 * d5 + c4 * d4),  # (C47) = eq. (50)
        (t4 + c5 * t6, sal3 * d3 - cal3 * d2),  # (C48) = eq. (51)
    ]  # fmt: skip
    for lhs, rhs in checks:
        assert np.abs(lhs - rhs).max() < MODEL_TOL
