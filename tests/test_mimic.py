"""Mimic joints' own limits kept through their primaries (rrc_pin.mimic).

Before, a mimic joint's own URDF limits were dropped with the joint's coordinate: a random run
took one to 1.185 rad against its limit of 0.5. Fresh seeds at every run, printed on failure,
beside fixed ones.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin import InvalidInput, JointLimits, JointTask, Resolver, URDFError
from rrc_pin.mimic import Mimic

SEEDS = [20261209, int(np.random.SeedSequence().entropy % 2**63)]

CHAIN = """<robot name="mimic">
  <link name="base"/><link name="l0"/><link name="l1"/><link name="l2"/><link name="l3"/>
  <link name="tool"/>
  <joint name="j0" type="revolute"><parent link="base"/><child link="l0"/><axis xyz="0 0 1"/>
    <limit lower="-2.5" upper="2.5" velocity="1.5" effort="1"/></joint>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2" type="{kind}"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 1 0"/><limit lower="{lower}" upper="{upper}" velocity="{velocity}" effort="1"/>
    <mimic joint="j1" multiplier="{k}" offset="{offset}"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="l3"/><child link="tool"/>
    <origin xyz="0 0 0.2"/></joint>
</robot>"""


def chain(tmp_path, k: float, offset: float = 0.1, lower: float = -0.3, upper: float = 0.5,
          velocity: float = 0.2, kind: str = "revolute") -> rrc_pin.Robot:  # fmt: skip
    """The chain whose j2 follows j1 (``j2 = k j1 + offset``), its own limits tighter."""
    path = tmp_path / f"mimic_{k}_{offset}_{kind}.urdf"
    path.write_text(CHAIN.format(k=k, offset=offset, lower=lower, upper=upper,
                                 velocity=velocity, kind=kind))  # fmt: skip
    return rrc_pin.load(path)


@pytest.mark.parametrize("k", [0.5, -0.5, 2.0, -3.0])
def test_the_primary_is_held_where_the_mimic_stays_within_its_own_limits(tmp_path, k) -> None:
    arm = chain(tmp_path, k)
    (mimic,) = arm.mimics
    assert mimic == Mimic("j2", "j1", k, 0.1, -0.3, 0.5, 0.2)
    ends = sorted([(-0.3 - 0.1) / k, (0.5 - 0.1) / k])
    lo, hi = max(ends[0], -2.0), min(ends[1], 2.0)
    assert arm.lower[1] == pytest.approx(lo, abs=1e-15)
    assert arm.upper[1] == pytest.approx(hi, abs=1e-15)
    assert arm.velocity_limit[1] == pytest.approx(min(1.0, 0.2 / abs(k)), rel=1e-15)
    for q in (arm.lower[1], arm.upper[1]):  # the ends themselves, in floating point
        assert -0.3 <= mimic.position(q) <= 0.5
    assert abs(k) * arm.velocity_limit[1] <= 0.2
    assert (arm.lower[[0, 2]] == [-2.5, -2.0]).all()  # the other joints untouched


def test_the_formula_is_pinocchios(tmp_path) -> None:
    """``Mimic.position`` is the angle Pinocchio turns the mimic joint's link by."""
    arm = chain(tmp_path, -0.5)
    q = np.array([0.2, 0.6, -0.4])
    data = arm.model.createData()
    pin.forwardKinematics(arm.model, data, arm.to_pinocchio(q))
    j1, j2 = (arm.model.getJointId(n) for n in ("j1", "j2"))
    relative = data.oMi[j1].inverse() * data.oMi[j2]
    turned = math.atan2(relative.rotation[0, 2], relative.rotation[0, 0])  # about y
    assert turned == pytest.approx(arm.mimics[0].position(0.6), abs=1e-12)


@pytest.mark.parametrize("seed", SEEDS)
def test_primary_bounds_keep_the_mimic_inside_in_floating_point(seed: int) -> None:
    """Random multipliers (both signs, tiny to large) and offsets: the ends, rounded, inside."""
    rng = np.random.default_rng(seed)
    for _ in range(2000):
        k = float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-3, 3))
        lower = float(rng.uniform(-2, 1))
        m = Mimic("m", "p", k, float(rng.normal()), lower, lower + float(rng.uniform(0, 2)),
                  float(rng.uniform(0.01, 5)))  # fmt: skip
        lo, hi, speed = m.primary_bounds()
        assert lo <= hi, (seed, m)
        for q in (lo, hi, 0.5 * (lo + hi)):
            assert m.lower <= m.position(q) <= m.upper, (seed, m, q)
        assert abs(k) * speed <= m.velocity and speed > 0.0, (seed, m)
        assert hi - lo == pytest.approx((m.upper - m.lower) / abs(k), rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("k", [0.5, -0.5, -3.0])
def test_limits_hold_over_a_random_run(tmp_path, seed: int, k: float) -> None:
    """Random commands from random starts, 800 steps of the resolver (each command held 1 s:
    a twist up to 1e3 m/s, or a rate of the primary up to 10 rad/s) and 200 of the
    controller: the mimic joint never leaves its own limits, nor its speed limit."""
    rng = np.random.default_rng(seed)
    arm = chain(tmp_path, k, velocity=2.0)
    (mimic,) = arm.mimics
    resolver = Resolver(arm, dt=0.01)
    for step in range(800):
        if step % 200 == 0:
            q = arm.random_q(rng)
        if step % 100 == 0:  # each command held: the arm runs into its limits
            twist = rng.normal(size=6) * 10.0 ** rng.uniform(-1, 3)
            rate = JointTask("j1", float(rng.uniform(-10.0, 10.0))) if step % 200 else None
        r = resolver.solve(q, twist) if rate is None else resolver.solve(q, [rate])
        q = q + r.qdot * 0.01
        assert -0.3 <= mimic.position(q[1]) <= 0.5, (seed, step, q)
        assert abs(k * r.qdot[1]) <= 2.0, (seed, step, r)
    ends = set()
    for speed in (10.0, -10.0):  # then the primary driven to each end, wherever the run left it
        for _ in range(450):  # 4.5 s: the longest way across at the tightened speed is 4 s
            r = resolver.solve(q, [JointTask("j1", speed)])
            q = q + r.qdot * 0.01
            assert -0.3 <= mimic.position(q[1]) <= 0.5 and abs(k * r.qdot[1]) <= 2.0, seed
        ends.add(round(float(mimic.position(q[1])), 9))
    assert ends == {-0.3, 0.5}, (seed, ends)  # the mimic's own limits reached, not passed
    ctl = rrc_pin.Controller(arm, dt=0.01, q0=arm.ready())
    for _ in range(200):
        q, r = ctl.step(rng.normal(size=6) * 2.0, ref="local")
        assert -0.3 <= mimic.position(q[1]) <= 0.5 and abs(k * r.qdot[1]) <= 2.0, seed


def test_a_velocity_override_and_a_cell_keep_the_mimic_limits(tmp_path) -> None:
    arm = chain(tmp_path, -0.5)
    override = JointLimits(velocity=[5.0, 5.0, 5.0])
    q = arm.ready()
    r = Resolver(arm, limits=[override]).solve(q, [0.0, 0.0, -50.0, 0.0, 0.0, 0.0])
    assert abs(r.qdot[1]) <= 0.4 and r.box.ub[1] == 0.4
    cell = rrc_pin.combine({"a": (arm, np.eye(4)), "b": (arm, np.eye(4))})
    assert [m.name for m in cell.mimics] == ["a/j2", "b/j2"]
    np.testing.assert_array_equal(cell.lower, np.r_[arm.lower, arm.lower])
    np.testing.assert_array_equal(cell.mimic_velocity, np.r_[arm.mimic_velocity,
                                                             arm.mimic_velocity])  # fmt: skip


def test_limits_no_primary_position_keeps_are_refused_by_name(tmp_path) -> None:
    with pytest.raises(URDFError, match="mimic joint 'j2'.*j1's own limits"):
        chain(tmp_path, 0.1, offset=0.5, lower=0.9, upper=1.0)  # j1 in [4, 5]: outside [-2, 2]
    with pytest.raises(URDFError, match="held at its offset 0.7"):
        chain(tmp_path, 0.0, offset=0.7)
    arm = chain(tmp_path, 0.0, offset=0.2)  # held inside: j1 free
    assert arm.lower[1] == -2.0 and arm.upper[1] == 2.0
    path = tmp_path / "continuous.urdf"  # a continuous mimic of a continuous joint
    path.write_text(CHAIN.format(k=-0.5, offset=0.1, lower=0, upper=0, velocity=0.2,
                                 kind="continuous").replace('"revolute"><parent link="l0"',
                                                            '"continuous"><parent link="l0"'))
    free = rrc_pin.load(path)  # its speed kept; it has no position limits
    assert free.continuous[1] and free.velocity_limit[1] == 0.4
    with pytest.raises(URDFError, match="follows the continuous joint 'j1'"):
        rrc_pin.Robot(free.model, "tool", name="m", source="t",
                      mimic_limits={"j2": (-0.3, 0.5, 0.2)})  # fmt: skip


def test_mimic_limits_are_checked(tmp_path) -> None:
    arm = chain(tmp_path, 0.5)
    for bad in ({"j9": (0.0, 1.0, 1.0)}, {"j2": (1.0, 0.0, 1.0)}, {"j2": (0.0, 1.0, 0.0)},
                {"j2": (0.0, math.nan, 1.0)}, {"j2": "abc"}, [("j2", (0, 1, 1))]):  # fmt: skip
        with pytest.raises(InvalidInput) as info:
            rrc_pin.Robot(arm.model, "tool", name="m", source="test", mimic_limits=bad)
        assert info.value.argument == "mimic_limits"
