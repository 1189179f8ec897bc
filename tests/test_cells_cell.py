"""Cells: loading by name, parts, base placements, bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.cells import make_cell
from rrc_pin.errors import InvalidInput, UnknownArm


def test_ready_made_cells_load_by_name_with_their_parts(dual, tripod):
    assert dual.tool_frames == ("left/tool", "right/tool") and set(dual.objects) == {"object"}
    assert (dual.nq, dual.nv, dual.floating) == (14, 14, False)
    assert (tripod.nq, tripod.nv, tripod.floating, tripod.body) == (25, 24, True, "body")
    assert rrc_pin.loading.cells() == ["gsfc_dual", "yeh_tripod"]
    for cell in (dual, tripod):
        assert cell.cell_spec is not None and cell.cell_spec.assumed


def test_the_tripod_stands_its_feet_on_z_zero(tripod):
    q = tripod.ready()
    for foot in tripod.tool_frames:
        assert abs(tripod.fk(q, foot)[2, 3]) < 1e-12


def test_world_frame_jacobians_are_each_arms_own_at_its_base_placement(dual, tripod):
    """A world-frame twist of a hand reaches each arm as its own Jacobian seen from its base."""
    rng = np.random.default_rng(30)
    for cell in (dual, tripod):
        for _ in range(5):
            q = cell.random_q(rng)
            if cell.floating:  # a random body pose too
                q[:3] = rng.normal(size=3)
                quat = rng.normal(size=4)
                q[3:7] = quat / np.linalg.norm(quat)
            T_body = cell.fk(q, cell.body) if cell.body else np.eye(4)
            for arm in cell.arms.values():
                qa = q[arm.q]
                base = T_body @ arm.base
                R = base[:3, :3]
                J_own = arm.robot.jacobian(qa, "world_aligned")  # in the arm's base axes
                J_cell = cell.jacobian(q, "world_aligned", arm.hand)[:, arm.v]
                np.testing.assert_allclose(J_cell[:3], R @ J_own[:3], atol=1e-12)
                np.testing.assert_allclose(J_cell[3:], R @ J_own[3:], atol=1e-12)
                np.testing.assert_allclose(cell.fk(q, arm.hand), base @ arm.robot.fk(qa),
                                           atol=1e-12)  # fmt: skip
                others = np.ones(cell.nv, dtype=bool)
                others[arm.v] = False
                others[:6] = others[:6] & (not cell.floating)
                assert not cell.jacobian(q, "world_aligned", arm.hand)[:, others].any()


def test_the_object_frame_is_fixed_to_the_first_hand_by_the_grasp(dual):
    q = dual.random_q(1)
    g = dual.objects["object"]
    np.testing.assert_allclose(dual.fk(q, "object"), dual.fk(q, g.hands[0]) @ g.in_hand,
                               atol=1e-12)  # fmt: skip


def test_an_unknown_cell_lists_the_cells_and_arms():
    with pytest.raises(UnknownArm, match="gsfc_dual.*yeh_tripod"):
        rrc_pin.load("gsfc_triple")


def test_a_non_rigid_base_placement_is_refused_naming_it():
    arm = rrc_pin.load("barker6")
    T = np.eye(4)
    T[0, 0] = 2.0
    with pytest.raises(InvalidInput, match=r"^arms\['b'\]"):
        make_cell({"a": (arm, np.eye(4)), "b": (arm, T)}, name="bad")


def test_an_object_naming_an_unknown_arm_lists_the_arms():
    arm = rrc_pin.load("barker6")
    with pytest.raises(InvalidInput, match="no arm 'c'; arms: a, b"):
        make_cell({"a": (arm, np.eye(4)), "b": (arm, pin.SE3(np.eye(3), np.ones(3)).homogeneous)},
                  name="x", objects={"box": ("a", "c")})  # fmt: skip


def test_an_unknown_arm_of_a_cell_lists_them(dual):
    with pytest.raises(InvalidInput, match="^key: no arm 'middle'.*left, right"):
        dual.arm("middle")
