"""The SVD of a task Jacobian (rank, least-norm rates, null space) and the damping schedule."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import solvers.jacobian_svd as jacobian_svd
from solvers.errors import InputError
from solvers.jacobian_svd import RANK_TOL, Damping, JacobianSVD


def with_singular_values(
    rng: np.random.Generator, m: int, n: int, sigma: list[float]
) -> np.ndarray:
    """A random (m, n) matrix with the given singular values (the rest zero)."""
    U, _ = np.linalg.qr(rng.standard_normal((m, m)))
    V, _ = np.linalg.qr(rng.standard_normal((n, n)))
    s = np.zeros(min(m, n))
    s[: len(sigma)] = sigma
    return (U[:, : s.size] * s) @ V[:, : s.size].T


def shapes_and_ranks() -> list[tuple[int, int, int]]:
    return [(6, 7, 6), (6, 7, 4), (3, 7, 3), (6, 6, 6), (6, 6, 5), (8, 5, 5), (8, 5, 2),
            (1, 4, 1), (6, 7, 1)]  # fmt: skip


@pytest.mark.parametrize(("m", "n", "rank"), shapes_and_ranks())
def test_rates_are_the_pseudo_inverse(m: int, n: int, rank: int, rng: np.random.Generator) -> None:
    for _ in range(20):
        sigma = sorted(rng.uniform(0.1, 10.0, rank).tolist(), reverse=True)
        J = with_singular_values(rng, m, n, sigma)
        svd = JacobianSVD(J)
        assert svd.rank == rank
        assert svd.U.shape == (m, min(m, n)) and svd.Vt.shape == (n, n)
        np.testing.assert_allclose(svd.sigma[:rank], sigma, rtol=1e-12)
        assert (np.diff(svd.sigma) <= 0.0).all()
        b = rng.standard_normal(m)
        want = np.linalg.pinv(J, rtol=RANK_TOL) @ b
        np.testing.assert_allclose(svd.rates(b), want, rtol=0, atol=1e-12 * np.abs(want).max())
        # least squares: the residual is orthogonal to J's range; least norm: no null part
        residual = J @ svd.rates(b) - b
        np.testing.assert_allclose(J.T @ residual, 0.0, atol=1e-12 * 10.0 * np.abs(b).max())


@pytest.mark.parametrize(("m", "n", "rank"), shapes_and_ranks())
def test_null_basis_is_orthonormal_and_annihilated(
    m: int, n: int, rank: int, rng: np.random.Generator
) -> None:
    sigma = sorted(rng.uniform(0.1, 10.0, rank).tolist(), reverse=True)
    J = with_singular_values(rng, m, n, sigma)
    svd = JacobianSVD(J)
    null = svd.null_basis()
    assert null.shape == (n - rank, n)
    np.testing.assert_allclose(null @ null.T, np.eye(n - rank), atol=1e-14)
    np.testing.assert_allclose(J @ null.T, 0.0, atol=1e-13 * sigma[0])
    np.testing.assert_allclose(svd.Vt @ svd.Vt.T, np.eye(n), atol=1e-14)  # row + null space
    k = min(m, n)
    np.testing.assert_allclose((svd.U * svd.sigma) @ svd.Vt[:k], J, atol=1e-13 * sigma[0])
    assert np.linalg.norm(null @ svd.rates(rng.standard_normal(m))) < 1e-13 * 10.0


def test_rank_counts_singular_values_above_the_tolerance(rng: np.random.Generator) -> None:
    above = with_singular_values(rng, 6, 7, [1.0, 0.5, 0.2, 0.1, 1e-3, 10.0 * RANK_TOL])
    assert JacobianSVD(above).rank == 6
    below = with_singular_values(rng, 6, 7, [1.0, 0.5, 0.2, 0.1, 1e-3, 0.1 * RANK_TOL])
    assert JacobianSVD(below).rank == 5
    scaled = with_singular_values(rng, 6, 7, [1e6, 1e6 * 0.1 * RANK_TOL])  # relative, not absolute
    assert JacobianSVD(scaled).rank == 1
    assert JacobianSVD(1e-200 * above).rank == 6


@pytest.mark.parametrize("shape", [(6, 7), (8, 5), (1, 1)])
def test_zero_jacobian(shape: tuple[int, int]) -> None:
    m, n = shape
    svd = JacobianSVD(np.zeros(shape))
    assert svd.rank == 0
    np.testing.assert_array_equal(svd.rates(np.ones(m)), np.zeros(n))
    np.testing.assert_allclose(svd.null_basis() @ svd.null_basis().T, np.eye(n), atol=1e-15)
    assert Damping().lambda_sq(svd, np.ones(n), np.zeros(n), -np.ones(n), np.ones(n)) is None


def test_empty_jacobians() -> None:
    no_rows = JacobianSVD(np.zeros((0, 4)))
    assert no_rows.rank == 0
    np.testing.assert_array_equal(no_rows.rates(np.zeros(0)), np.zeros(4))
    np.testing.assert_array_equal(no_rows.null_basis(), np.eye(4))
    no_joints = JacobianSVD(np.zeros((3, 0)))
    assert no_joints.rank == 0 and no_joints.rates(np.ones(3)).shape == (0,)


def test_lapack_failure_is_a_linalg_error(monkeypatch: pytest.MonkeyPatch) -> None:
    def failing(J: np.ndarray, compute_uv: int, full_matrices: int) -> tuple:
        m, n = J.shape
        return np.zeros((m, m)), np.zeros(min(m, n)), np.zeros((n, n)), 3

    monkeypatch.setattr(jacobian_svd, "dgesvd", failing)
    with pytest.raises(np.linalg.LinAlgError, match="info=3"):
        JacobianSVD(np.eye(3))


def test_damped_rates_are_the_damped_least_squares(rng: np.random.Generator) -> None:
    """With one lambda^2 for every direction: J^T (J J^T + lambda^2 I)^-1 b (Nakamura)."""
    for m, n in ((6, 7), (3, 7), (6, 6)):
        J = rng.standard_normal((m, n))
        b = rng.standard_normal(m)
        svd = JacobianSVD(J)
        lam = 0.3
        want = J.T @ np.linalg.solve(J @ J.T + lam * np.eye(m), b)
        got = svd.rates(b, np.full(min(m, n), lam))
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-13)
        np.testing.assert_allclose(svd.rates(b, np.zeros(min(m, n))), svd.rates(b), rtol=1e-12)


# -- the damping schedule -------------------------------------------------------------------


def reference_lambda_sq(
    J: np.ndarray, velocity: np.ndarray, b: np.ndarray, lb: np.ndarray, ub: np.ndarray,
    ratio: float, dt: float | None = None,
) -> np.ndarray:  # fmt: skip
    """The module docstring's schedule, from numpy's SVD and a brute-force uniform scale."""
    _, s, Vt = np.linalg.svd(J)
    r = int((s > RANK_TOL * s[0]).sum())
    exact = np.linalg.pinv(J, rtol=RANK_TOL) @ b
    reach = np.array([1.0 / np.max(np.abs(Vt[i]) / velocity) for i in range(r)])
    speed = s[:r] * reach
    onset = speed.max() / ratio
    if (lb <= 0).all() and (ub >= 0).all():
        s_exact = 0.0
        for width in (1.0, 1e-3, 1e-6):  # brute force on a grid, refined twice
            t = np.minimum(s_exact + np.linspace(0.0, width, 1001), 1.0)[:, None]
            ok = ((lb <= t * exact) & (t * exact <= ub)).all(axis=1)
            s_exact = float(t[ok].max())
    else:
        s_exact = 0.0
    lam = np.zeros(s.size)
    lam[:r] = np.maximum(1.0 - (speed / onset) ** 2, 0.0) * (onset / reach) ** 2
    if dt is not None:
        U = np.linalg.svd(J)[0]
        crossing = s[0] * np.abs(U[:, :r].T @ (J @ exact)) * dt - s[:r] ** 2
        fade = np.maximum(1.0 - s[:r] / (s[0] * dt * np.linalg.norm(np.maximum(-lb, ub))), 0.0)
        lam[:r] = np.maximum(lam[:r], fade * crossing)
    return lam * (1 - s_exact)


def test_a_step_that_would_reach_the_singularity_is_damped(rng: np.random.Generator) -> None:
    """The step floor (sigma_1 |u_i^T xdot| dt - sigma_i^2, faded out where no step within
    the bounds reaches the singularity) as the reference computes it, damping steps that the
    onset alone leaves undamped."""
    checked = 0
    for _ in range(300):
        theta2 = rng.uniform(-0.2, 0.2)
        J = two_link(theta2)
        v = np.array([2.0, 3.0])
        b = rng.normal(size=2) * rng.choice([0.05, 0.5, 5.0])
        svd = JacobianSVD(J)
        exact = svd.rates(b)
        for dt in (0.001, 0.01, 0.1):
            lam = Damping().lambda_sq(svd, v, exact, -v, v, dt)
            want = reference_lambda_sq(J, v, b, -v, v, 100.0, dt)
            np.testing.assert_allclose(0.0 if lam is None else lam, want, rtol=1e-5, atol=1e-14)
            checked += lam is not None and Damping().lambda_sq(svd, v, exact, -v, v) is None
    assert checked > 20


def two_link(theta2: float, theta1: float = 0.3, l1: float = 0.5, l2: float = 0.4) -> np.ndarray:
    """Planar two-link position Jacobian; singular (stretched) at theta2 = 0."""
    s1, c1 = np.sin(theta1), np.cos(theta1)
    s12, c12 = np.sin(theta1 + theta2), np.cos(theta1 + theta2)
    return np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])


def test_no_damping_far_from_singularities(rng: np.random.Generator) -> None:
    damping = Damping()
    v = np.full(7, 2.0)
    for _ in range(50):
        J = with_singular_values(rng, 6, 7, rng.uniform(0.2, 1.0, 6).tolist())  # cond <= 5
        svd = JacobianSVD(J)
        exact = svd.rates(100.0 * rng.standard_normal(6))  # far outside the bounds
        assert damping.lambda_sq(svd, v, exact, -v, v) is None


def test_no_damping_when_the_exact_rates_fit(rng: np.random.Generator) -> None:
    damping = Damping()
    v = np.ones(7)
    J = with_singular_values(rng, 6, 7, [1.0, 0.8, 0.5, 0.3, 0.1, 1e-6])  # near singular
    svd = JacobianSVD(J)
    exact = svd.rates(1e-8 * rng.standard_normal(6))
    assert np.abs(exact).max() < 1.0  # the command is small enough to be met exactly
    assert damping.lambda_sq(svd, v, exact, -v, v) is None
    lam = damping.lambda_sq(svd, v, exact * 2.0 / np.abs(exact).max(), -v, v)  # twice too fast
    assert lam is not None and lam[5] > 0.0


def test_damping_matches_the_schedule(rng: np.random.Generator) -> None:
    """Random Jacobians, some near singular, against the formula; the early exit included."""
    damped = undamped = 0
    for trial in range(300):
        m, n = ((6, 7), (6, 6), (3, 5))[trial % 3]
        sigma = np.sort(rng.uniform(0.1, 2.0, m))[::-1]
        if trial % 2:
            sigma[-1] = 10.0 ** rng.uniform(-8.0, -1.0)  # a weak direction
        J = with_singular_values(rng, m, n, sigma.tolist())
        v = rng.uniform(0.5, 3.0, n)
        b = rng.standard_normal(m) * 10.0 ** rng.uniform(-3.0, 1.0)
        ratio = float(rng.choice([10.0, 100.0, 1000.0]))
        lb, ub = -v * rng.uniform(0.2, 1.0, n), v * rng.uniform(0.2, 1.0, n)
        svd = JacobianSVD(J)
        got = Damping(ratio).lambda_sq(svd, v, svd.rates(b), lb, ub)
        want = reference_lambda_sq(J, v, b, lb, ub, ratio)
        if got is None:
            assert (want == 0.0).all(), (trial, want)
            undamped += 1
        else:
            np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-14)  # brute-force scale
            damped += 1
    assert damped > 30 and undamped > 30


def test_damping_of_a_start_that_must_move_is_full() -> None:
    """Bounds that exclude zero: the exact rates cannot be scaled in (s_e = 0)."""
    J = two_link(1e-4)
    svd = JacobianSVD(J)
    v = np.ones(2)
    lb, ub = np.array([0.1, -1.0]), np.array([1.0, 1.0])
    lam = Damping().lambda_sq(svd, v, svd.rates(np.array([0.0, 0.1])), lb, ub)
    assert lam is not None
    reach = 1.0 / (np.abs(svd.Vt) / v).max(axis=1)
    speed = svd.sigma * reach
    onset = speed.max() / 100.0
    np.testing.assert_allclose(lam[1], (1 - (speed[1] / onset) ** 2) * (onset / reach[1]) ** 2)
    assert lam[0] == 0.0


def test_damping_grows_continuously_near_a_singularity() -> None:
    """A 2-link arm stretching out: sigma_min -> 0 on a fine log grid, then exactly 0."""
    damping = Damping()
    v = np.array([1.0, 1.5])
    b = np.array([0.3, 0.2])  # a fixed hand velocity, with a part along the weak direction
    thetas = np.concatenate([np.geomspace(0.5, 1e-14, 3000), [0.0]])
    lams, rates, bounds_sq, ranks = [], [], [], []
    for theta in thetas:
        svd = JacobianSVD(two_link(float(theta)))
        ranks.append(svd.rank)
        exact = svd.rates(b)
        lam = damping.lambda_sq(svd, v, exact, -v, v)
        rates.append(exact if lam is None else svd.rates(b, lam))
        if svd.rank == 2:
            reach = 1.0 / (np.abs(svd.Vt) / v).max(axis=1)
            onset = float((svd.sigma * reach).max()) / damping.ratio
            bounds_sq.append((onset / reach[1]) ** 2)
            lams.append(0.0 if lam is None else float(lam[1]))
            if lam is not None:
                assert lam[0] == 0.0  # only the weak direction is damped
    lams_arr, rates_arr = np.array(lams), np.array(rates)
    onset_index = int(np.argmax(lams_arr > 0.0))
    assert 0 < onset_index < 1500  # undamped far away, damped from the onset on
    assert (lams_arr[onset_index:] > 0.0).all()
    assert (lams_arr <= np.array(bounds_sq) * (1.0 + 1e-12)).all()  # at most (c_on / r)^2
    np.testing.assert_allclose(lams_arr[-1], bounds_sq[-1], rtol=1e-6)  # reached there
    # continuous: the grid steps by 1.2%; no step of lambda^2 beyond 5% of its largest value
    assert np.abs(np.diff(lams_arr)).max() < 0.05 * lams_arr.max()
    # the rates too, through the rank drop (sigma_min < RANK_TOL sigma_max, where the weak
    # direction becomes a null direction) and theta2 = 0, while the exact rates grow as
    # 1 / sigma_min; damped, they shrink from the onset on
    sizes = np.linalg.norm(rates_arr, axis=1)
    steps = np.linalg.norm(np.diff(rates_arr, axis=0), axis=1)
    assert steps.max() < 0.05 * sizes.max()
    drop = ranks.index(1)
    assert onset_index < drop < len(thetas) - 1
    # measured: 7.9e-6 rad/s, where lambda^2 (4.3e-5) is dropped with the direction
    assert np.linalg.norm(rates_arr[drop] - rates_arr[drop - 1]) < 2e-5
    assert sizes[onset_index:].max() <= sizes[onset_index] * 1.05
    assert np.linalg.norm(JacobianSVD(two_link(1e-8)).rates(b)) > 1e7


def test_damping_is_continuous_in_the_command() -> None:
    """Zero while the exact rates fit, then growing from zero as the command grows."""
    svd = JacobianSVD(two_link(1e-3))
    v = np.ones(2)
    direction = svd.rates(np.array([0.3, 0.2]))
    fit = 1.0 / np.abs(direction).max()  # the factor at which the exact rates reach a limit
    damping = Damping()
    assert damping.lambda_sq(svd, v, direction * fit * (1.0 - 1e-12), -v, v) is None
    previous = 0.0
    for excess in (1e-9, 1e-6, 1e-3, 0.1, 1.0, 10.0):
        lam = damping.lambda_sq(svd, v, direction * fit * (1.0 + excess), -v, v)
        assert lam is not None and lam[1] > previous
        previous = float(lam[1])
    lam = damping.lambda_sq(svd, v, direction * fit * (1.0 + 1e-9), -v, v)
    assert lam is not None and lam[1] < 1e-8 * previous  # from zero, no jump


def test_ratio_sets_which_directions_are_weak(rng: np.random.Generator) -> None:
    J = with_singular_values(rng, 6, 7, [1.0, 0.9, 0.7, 0.5, 0.3, 1e-3])
    svd = JacobianSVD(J)
    v = np.ones(7)
    reach = 1.0 / (np.abs(svd.Vt[:6]) / v).max(axis=1)
    speed = svd.sigma * reach
    spread = float(speed.max() / speed.min())
    exact = svd.rates(rng.standard_normal(6))
    assert np.abs(exact).max() > 1.0  # outside the bounds
    assert Damping(spread * 1.01).lambda_sq(svd, v, exact, -v, v) is None
    lam = Damping(spread * 0.99).lambda_sq(svd, v, exact, -v, v)
    assert lam is not None and lam[5] > 0.0 and (lam[:5] == 0.0).all()
    lam = Damping(1.0 + 1e-9).lambda_sq(svd, v, exact, -v, v)  # every direction but the top
    assert lam is not None
    top = int(np.argmax(speed))
    assert lam[top] == 0.0 and (np.delete(lam, top) > 0.0).all()


@pytest.mark.parametrize("ratio", [1.0, 0.5, -3.0, np.nan, np.inf, True, "100"])
def test_bad_ratio_is_refused(ratio: object) -> None:
    with pytest.raises(InputError) as info:
        Damping(ratio)  # type: ignore[arg-type]
    assert info.value.argument == "ratio"


def test_damping_is_frozen() -> None:
    damping = Damping(50.0)
    assert damping.ratio == 50.0 and Damping().ratio == 100.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        damping.ratio = 10.0  # type: ignore[misc]
