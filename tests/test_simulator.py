"""The simulator: Pinocchio's dynamics of the generated URDFs, the integrator, payload, contact."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.dynamics import ContactPlane, Drives, Simulator, drives_of
from rrc_pin.errors import InvalidInput
from rrc_pin.models.inertia import make

ARMS = ("barker6", "rrc_k1607")


@pytest.fixture(scope="module", params=ARMS)
def arm(request):
    return rrc_pin.load(request.param)


def test_rnea_and_aba_are_inverse_and_match_the_mass_matrix(arm, rng):
    """M(q) qdd + h(q, v) = tau for qdd = ABA(q, v, tau), and RNEA(q, v, qdd) = tau."""
    model = arm.model.copy()
    model.armature[:] = drives_of(arm.name, arm.nq).armature
    data = model.createData()
    for _ in range(10):
        q, v, tau = arm.random_q(rng), rng.normal(size=arm.nq), rng.normal(size=arm.nq) * 10
        qdd = pin.aba(model, data, q, v, tau)
        assert np.allclose(pin.rnea(model, data, q, v, qdd), tau, atol=1e-9)
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.nonLinearEffects(model, data, q, v)
        assert np.allclose(M @ qdd + h, tau, atol=1e-9)
        assert np.all(np.linalg.eigvalsh(M) > 0.0)


def energy_error(arm, dt: float, seconds: float = 0.3) -> float:
    sim = Simulator(arm, dt, torque_limit=np.full(arm.nq, 1e9))
    sim.reset(np.full(arm.nq, 0.3))
    e0 = sim.energy()
    worst = 0.0
    for _ in range(round(seconds / dt)):
        sim.step(np.zeros(arm.nq))
        worst = max(worst, abs(sim.energy() - e0))
    return worst


def test_unforced_frictionless_energy_is_conserved_to_first_order(arm):
    """Semi-implicit Euler is first order: halving dt halves the energy error.

    Measured over 0.3 s of free fall from q = 0.3 rad everywhere, at 1 kHz and 2 kHz:
    barker6 0.0138 J -> 0.0069 J, rrc_k1607 0.0616 J -> 0.0308 J (ratio 2.00).
    """
    coarse, fine = energy_error(arm, 1e-3), energy_error(arm, 5e-4)
    assert coarse < 0.1  # [J] at 1 kHz
    assert 1.8 < coarse / fine < 2.2


def test_payload_adds_its_weight_at_the_tool(arm, rng):
    q = arm.random_q(rng)
    sim = Simulator(arm)
    bare = pin.computeGeneralizedGravity(sim.model, sim.data, q).copy()
    sim.set_payload(make(2.0, np.zeros(3), np.eye(3) * 1e-3))
    loaded = pin.computeGeneralizedGravity(sim.model, sim.data, q)
    weight = np.array([0.0, 0.0, 2.0 * 9.81])
    assert np.allclose(loaded - bare, arm.jacobian(q)[:3].T @ weight, atol=1e-9)
    sim.set_payload(None)
    assert np.allclose(pin.computeGeneralizedGravity(sim.model, sim.data, q), bare, atol=1e-12)


def test_plane_pushes_along_its_normal_in_proportion_to_the_penetration(arm, rng):
    q = arm.random_q(rng)
    p = arm.fk(q)[:3, 3]
    normal = np.array([0.0, 0.6, 0.8])
    plane = ContactPlane(p + 0.002 * normal, normal, stiffness=5e3, damping=10.0)
    sim = Simulator(arm, plane=plane, torque_limit=np.full(arm.nq, 1e9))
    sim.reset(q)
    tau = rng.normal(size=arm.nq)
    sim.step(tau)
    assert np.allclose(sim.report.contact, 10.0 * normal)  # 5e3 N/m x 2 mm
    assert np.allclose(sim.state().force, -10.0 * normal)  # what the tool exerts
    model = sim.model
    expected = pin.aba(
        model,
        model.createData(),
        q,
        np.zeros(arm.nq),
        tau + arm.jacobian(q)[:3].T @ (10.0 * normal),
    )
    assert np.allclose(sim.v, 1e-3 * expected)
    far = ContactPlane(p - 0.01 * normal, normal, stiffness=5e3)
    assert not far.force_on_tool(p, np.zeros(3)).any()


def test_torques_are_clipped_at_the_limits_and_reported(arm):
    sim = Simulator(arm)
    sim.step(np.full(arm.nq, 1e4))
    assert sim.report.clipped
    assert np.allclose(sim.report.tau, arm.model.effortLimit)


def test_friction_dissipates(arm):
    sim = Simulator(arm, friction=True, torque_limit=np.full(arm.nq, 1e9))
    sim.reset(np.full(arm.nq, 0.3), v=np.full(arm.nq, 1.0))
    e0 = sim.energy()
    free = Simulator(arm, torque_limit=np.full(arm.nq, 1e9))
    free.reset(np.full(arm.nq, 0.3), v=np.full(arm.nq, 1.0))
    for _ in range(100):
        sim.step(np.zeros(arm.nq))
        free.step(np.zeros(arm.nq))
    assert sim.energy() < free.energy() < e0 + 0.1


def test_bad_input_is_refused_by_name_before_any_change(arm):
    sim = Simulator(arm)
    q = sim.q.copy()
    bad = np.zeros(arm.nq)
    bad[0] = np.nan
    with pytest.raises(InvalidInput, match="tau"):
        sim.step(bad)
    assert np.array_equal(sim.q, q) and sim.t == 0.0
    with pytest.raises(InvalidInput, match="normal"):
        ContactPlane(np.zeros(3), np.array([0.0, 0.0, 2.0]), 1e3)
    with pytest.raises(InvalidInput, match="stiffness"):
        ContactPlane(np.zeros(3), np.array([0.0, 0.0, 1.0]), 0.0)
    with pytest.raises(InvalidInput, match="torque_limit"):
        Simulator(arm, torque_limit=-np.ones(arm.nq))
    with pytest.raises(InvalidInput, match="dt"):
        Simulator(arm, dt=0.0)
    with pytest.raises(InvalidInput, match="payload"):
        sim.set_payload(2.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="viscous"):
        Drives(np.ones(arm.nq), np.ones(2), np.ones(arm.nq))
    with pytest.raises(InvalidInput, match="coulomb"):
        Drives(np.ones(arm.nq), np.ones(arm.nq), -np.ones(arm.nq))
    with pytest.raises(InvalidInput, match="drives"):
        Simulator(arm, drives=Drives(np.ones(3), np.ones(3), np.ones(3)))


def test_dynamics_exports_exist_and_are_sorted():
    import rrc_pin.dynamics as dynamics

    namespace: dict = {}
    exec("from rrc_pin.dynamics import *", namespace)
    assert set(dynamics.__all__) <= set(namespace)
    assert dynamics.__all__ == sorted(dynamics.__all__)
