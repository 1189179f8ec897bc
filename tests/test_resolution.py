"""The fallback chain and the Resolution record, on Jacobians of the paper arms and panda."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from solvers.dls import Damping, damped_least_squares
from solvers.errors import InputError, ProblemError
from solvers.joint_bounds import JointLimits, VelocityBounds
from solvers.qp_backends import QPBackend, QPSolution
from solvers.resolution import ResolutionChain, uniform_scale

MODULES = {"osqp": "osqp", "daqp": "daqp", "proxqp": "proxsuite", "quadprog": "quadprog",
           "clarabel": "clarabel"}


class Broken(QPBackend):
    """A backend that raises, or reports no solution."""

    name = "broken"

    def __init__(self, mode: str) -> None:
        self.mode = mode

    def solve(self, problem: object) -> QPSolution:
        if self.mode == "raise":
            raise ProblemError("broken: crashed")
        return QPSolution(None, False, "maximum iterations reached", 4000, 0.0, 0.0, self.name)

    def reset(self) -> None:
        pass

    def warm_start_state(self) -> dict:
        return {}


def setting(rng: np.random.Generator, name: str = "panda") -> tuple:
    arm = rrc_pin.load(name)
    q = arm.random_q(rng)
    limits = JointLimits(arm.lower, arm.upper, arm.velocity_limit)
    return arm.jacobian(q), limits.bounds(q, 0.01), arm


# Without the shortcut the backend's own accuracy shows: OSQP stops at residuals of 1e-6 and
# does not polish without an active bound, which leaves up to ~1e-4 along the weakly
# curved null-space direction (curvature mu = 1e-2); the interior-point and proximal
# solvers reach about 1e-7; the active-set ones are exact.
TOL = {"osqp": 5e-4, "proxqp": 1e-6, "clarabel": 1e-6, "daqp": 1e-10, "quadprog": 1e-10}


@pytest.mark.parametrize("name", sorted(MODULES))
@pytest.mark.parametrize("shortcut", [True, False])
def test_no_active_bound_gives_damped_least_squares(
    name: str, shortcut: bool, rng: np.random.Generator
) -> None:
    pytest.importorskip(MODULES[name])
    chain = ResolutionChain(backend=name, shortcut=shortcut)
    for _ in range(20):
        J, bounds, _ = setting(rng)
        x = rng.standard_normal(6) * 0.01  # slow: no bound reached
        r = chain.resolve(J, x, bounds)
        assert r.method == "qp" and not r.active
        tol = TOL[name] if not shortcut else 1e-12
        assert np.allclose(r.qdot, damped_least_squares(J, x), atol=tol)
        assert r.status == ("unconstrained optimum" if shortcut else r.status)


def test_fallback_chain_order_and_attempts(rng: np.random.Generator) -> None:
    J, bounds, _ = setting(rng)
    x = rng.standard_normal(6) * 5.0
    for mode in ("raise", "not found"):
        r = ResolutionChain(backend=Broken(mode), shortcut=False).resolve(J, x, bounds)
        assert r.method == "dls"
        assert r.attempts[0][0] == "qp"
        assert np.all(r.qdot >= bounds.lb) and np.all(r.qdot <= bounds.ub)
    r = ResolutionChain(backend=Broken("raise"), methods=("qp", "scaling"), shortcut=False)
    out = r.resolve(J, x, bounds)
    assert out.method == "scaling" and 0.0 <= out.scale <= 1.0
    r = ResolutionChain(backend=None, methods=("hold",)).resolve(J, x, bounds)
    assert r.method == "hold"
    assert np.array_equal(r.qdot, np.clip(0.0, bounds.lb, bounds.ub))


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_numerical_trouble_never_raises(rng: np.random.Generator) -> None:
    J, bounds, _ = setting(rng)
    chain = ResolutionChain()
    for J_bad in (J * 1e300, np.zeros_like(J), J * 1e-300):
        r = chain.resolve(J_bad, np.ones(6) * 1e6, bounds, validate=False)
        assert np.all(np.isfinite(r.qdot))
        assert np.all(r.qdot >= bounds.lb) and np.all(r.qdot <= bounds.ub)


def test_direction_mode_keeps_the_direction(rng: np.random.Generator) -> None:
    chain = ResolutionChain(direction_preserving=True)
    for name in ("panda", "rrc_k1607", "barker6"):
        for _ in range(30):
            J, bounds, _ = setting(rng, name)
            x = rng.standard_normal(6) * rng.choice([0.1, 10.0, 1e6])
            r = chain.resolve(J, x, bounds)
            assert r.method == "qp_direction"
            assert 0.0 <= r.scale <= 1.0
            target = J @ damped_least_squares(J, x)
            got = J @ r.qdot
            # parallel and in the same sense: J qdot = s J qdot_dls
            assert np.allclose(got, r.scale * target, atol=1e-8 * (1 + np.abs(target).max()))


def test_strict_priority_keeps_the_task_and_serves_the_secondary(
    rng: np.random.Generator,
) -> None:
    strict = ResolutionChain(priority="strict")
    for _ in range(30):
        J, bounds, _ = setting(rng)
        x = rng.standard_normal(6) * 0.3
        z = rng.standard_normal(7)
        primary = ResolutionChain().resolve(J, x, bounds)
        both = strict.resolve(J, x, bounds, secondary=z)
        assert both.method in ("qp_priority", "qp")
        # exact for any solution of the second level, up to the clip of the backend's
        # tolerance (1e-6) into the bounds
        assert np.allclose(J @ both.qdot, J @ primary.qdot, atol=1e-5)
        assert np.linalg.norm(both.qdot - z) <= np.linalg.norm(primary.qdot - z) + 1e-6


def test_soft_secondary_leaves_a_feasible_task_unchanged(rng: np.random.Generator) -> None:
    for _ in range(30):
        J, bounds, _ = setting(rng)
        x = rng.standard_normal(6) * 0.01
        z = rng.standard_normal(7) * 0.05
        a = ResolutionChain().resolve(J, x, bounds)
        b = ResolutionChain().resolve(J, x, bounds, secondary=z)
        assert not b.active
        assert np.allclose(J @ b.qdot, J @ a.qdot, atol=1e-9)
        assert not np.allclose(b.qdot, a.qdot)


def test_uniform_scale() -> None:
    kinds = np.zeros(3, np.int8)
    b = VelocityBounds(np.array([-1.0, -1.0, 0.5]), np.array([1.0, 1.0, 1.0]), kinds, kinds)
    assert uniform_scale(np.array([2.0, -0.5, 0.7]), b) == 0.5  # the recovering joint ignored
    assert uniform_scale(np.array([0.5, -0.5, 0.7]), b) == 1.0


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"methods": ("qp", "pray")}, "fallbacks"),
        ({"priority": "lexicographic"}, "priority"),
        ({"secondary_weight": 0.0}, "secondary_weight"),
        ({"active_tol": -1.0}, "active_tol"),
        ({"damping": 0.1}, "damping"),
        ({"backend": None, "methods": ("qp",)}, "backend"),
    ],
)
def test_chain_validates_its_settings(kwargs: dict, argument: str) -> None:
    with pytest.raises(InputError) as info:
        ResolutionChain(**kwargs)
    assert info.value.argument == argument


def test_resolve_validates_input() -> None:
    chain = ResolutionChain(damping=Damping())
    kinds = np.zeros(3, np.int8)
    b = VelocityBounds(-np.ones(3), np.ones(3), kinds, kinds)
    with pytest.raises(InputError) as info:
        chain.resolve(np.eye(3), [np.nan, 0.0, 0.0], b)
    assert info.value.argument == "xdot"
    with pytest.raises(InputError) as info:
        chain.resolve(np.eye(3), np.zeros(3), b, secondary=np.zeros(2))
    assert info.value.argument == "secondary"


def test_guessed_active_set_answers_as_the_backend(rng: np.random.Generator) -> None:
    """Along a trajectory the previous active set is usually right: solved exactly without
    the backend, equal to an exact active-set solver's answer; the guess is state."""
    pytest.importorskip("daqp")
    arm = rrc_pin.load("panda")
    limits = JointLimits(arm.lower, arm.upper, arm.velocity_limit)
    fast = ResolutionChain(backend="osqp")
    exact = ResolutionChain(backend="daqp", shortcut=False)
    q = arm.neutral() + 0.2
    twist = rng.standard_normal(6)
    statuses: dict[str, int] = {}
    for k in range(300):
        if k % 30 == 0:
            twist = rng.standard_normal(6) * 1.5
        J, bounds = arm.jacobian(q), limits.bounds(q, 0.01)
        a, b = fast.resolve(J, twist, bounds), exact.resolve(J, twist, bounds)
        assert np.allclose(a.qdot, b.qdot, atol=1e-9)
        statuses[a.status] = statuses.get(a.status, 0) + 1
        q = q + 0.01 * a.qdot
    assert statuses.get("exact on the guessed active set", 0) > 100, statuses
    state = fast.warm_start_state()
    assert {"active:lower", "active:upper"} <= state.keys()
    fast.reset()
    assert fast.warm_start_state()["active:lower"].size == 0


def test_active_set_guess_survives_a_change_of_arm(rng: np.random.Generator) -> None:
    """One chain, Jacobians of different sizes: a guess naming joint 6 is not tried on six."""
    chain = ResolutionChain()
    for name in ("panda", "barker6", "panda", "barker6"):
        arm = rrc_pin.load(name)
        limits = JointLimits(arm.lower, arm.upper, arm.velocity_limit)
        for _ in range(20):
            q = arm.random_q(rng)
            bounds = limits.bounds(q, 0.01)
            r = chain.resolve(arm.jacobian(q), rng.standard_normal(6) * 3.0, bounds)
            assert np.all(r.qdot >= bounds.lb) and np.all(r.qdot <= bounds.ub)
