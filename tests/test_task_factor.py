"""The per-step factorisation: the Cholesky route against the SVD, and when each is taken."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from solvers.dls import Damping, TaskSVD, task_svd, weight_factor
from solvers.joint_bounds import VelocityBounds
from solvers.qp_problem import tracking_free, tracking_problem_from
from solvers.task_factor import TaskInverse, factor_task

ARMS = ("panda", "rrc_k1607", "barker6")


def wide(n: int) -> VelocityBounds:
    return VelocityBounds(np.full(n, -1e9), np.full(n, 1e9))


def jacobians(rng: np.random.Generator, count: int) -> list[np.ndarray]:
    arms = [rrc_pin.load(name) for name in ARMS]
    return [arms[k % 3].jacobian(arms[k % 3].random_q(rng)) for k in range(count)]


def test_inverse_route_agrees_with_the_svd(rng: np.random.Generator) -> None:
    inverse = 0
    for k, J in enumerate(jacobians(rng, 300)):
        m, n = J.shape
        factor = weight_factor(rng.uniform(0.5, 2.0, m), m) if k % 2 else None
        task = factor_task(J, factor, Damping())
        if not isinstance(task, TaskInverse):
            continue
        inverse += 1
        svd = task_svd(J, factor, Damping())
        assert svd.lambda_sq == 0.0 and svd.rank == m == task.rank
        assert np.array_equal(task.J, svd.J)
        x = rng.standard_normal(m)
        z = rng.standard_normal(n)
        scale = 1.0 + np.abs(svd.dls(x)).max()
        assert np.allclose(task.dls(x), svd.dls(x), atol=1e-12 * scale)
        assert np.allclose(task.null_project(z), svd.null_project(z), atol=1e-12)
        assert np.allclose(task.row_project(z), svd.row_project(z), atol=1e-12)
        for mu in (1e-2, 0.5):  # P of the tracking problem, both routes
            p_inv = tracking_problem_from(task, tracking_free(task, x, z, mu), wide(n))
            p_svd = tracking_problem_from(svd, tracking_free(svd, x, z, mu), wide(n))
            assert np.allclose(p_inv.P, p_svd.P, atol=1e-12 * np.abs(p_svd.P).max())
            assert np.allclose(p_inv.q, p_svd.q, atol=1e-12 * (1 + np.abs(p_svd.q).max()))
            assert np.allclose(p_inv.x_free, p_svd.x_free, atol=1e-11 * scale)
        basis = task.null_basis()
        assert basis.shape == (n - m, n)
        assert np.allclose(basis @ basis.T, np.eye(n - m), atol=1e-12)
        assert np.allclose(task.J @ basis.T, 0.0, atol=1e-12)
    assert inverse > 150  # most random configurations are away from singularities


def test_certificate_is_within_a_factor_sqrt_m_of_sigma_min(rng: np.random.Generator) -> None:
    """Certified only when sigma_min >= eps; always when sigma_min >= sqrt(m) eps."""
    damping = Damping(threshold=0.05)
    seen = {"certified": 0, "refused": 0}
    for _ in range(3000):
        m, n = 6, int(rng.integers(6, 9))
        U, _ = np.linalg.qr(rng.standard_normal((m, m)))
        V, _ = np.linalg.qr(rng.standard_normal((n, n)))
        sigma = np.sort(rng.uniform(0.01, 2.0, m))[::-1]
        sigma[-1] = rng.choice([rng.uniform(0.0, 0.05), rng.uniform(0.04, 0.2)])
        J = U @ np.diag(sigma) @ V[:m]
        certified = isinstance(factor_task(J, None, damping), TaskInverse)
        seen["certified" if certified else "refused"] += 1
        if certified:
            assert sigma.min() >= 0.05 * (1 - 1e-12)
        if sigma.min() >= np.sqrt(m) * 0.05 * (1 + 1e-12):
            assert certified
    assert min(seen.values()) > 500


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_svd_route_where_the_certificate_cannot_hold() -> None:
    k1607 = rrc_pin.load("rrc_k1607")
    J = k1607.jacobian(np.zeros(7))  # exactly singular: damped, rank 5
    task = factor_task(J, None, Damping())
    assert isinstance(task, TaskSVD) and task.lambda_sq > 0.0 and task.rank == 5
    panda = rrc_pin.load("panda")
    J = panda.jacobian(panda.neutral() + 0.3)
    assert isinstance(factor_task(J, None, Damping()), TaskInverse)
    for damping in (Damping(floor=1e-3), Damping(measure="manipulability"), None):
        assert isinstance(factor_task(J, None, damping), TaskSVD)  # schedules it cannot settle
    assert isinstance(factor_task(J[:, :3], None, Damping()), TaskSVD)  # more rows than joints
    for bad in (J * 1e300, J * 1e-300, np.zeros_like(J)):
        assert isinstance(factor_task(bad, None, Damping()), TaskSVD)


def test_null_basis_of_several_directions_comes_from_the_svd(rng: np.random.Generator) -> None:
    panda = rrc_pin.load("panda")
    J = panda.jacobian(panda.random_q(rng))[:3]  # position task: four null directions
    task = factor_task(J, None, Damping())
    assert isinstance(task, TaskInverse)
    basis = task.null_basis()
    assert basis.shape == (4, 7)
    assert np.allclose(basis @ basis.T, np.eye(4), atol=1e-12)
    assert np.allclose(J @ basis.T, 0.0, atol=1e-12)
