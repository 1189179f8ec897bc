"""Batch kinematics of the maps: Barker's closed form and the compiled chain agree on barker6,
the evaluator is chosen by the arm, the chain is read off any robot's model."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.errors import FrameNotFound, InvalidInput, ToolFrameRequired
from rrc_pin.maps.kinematics import arm_kinematics, chain_of, placed, z_to
from rrc_pin.maps.voxels import chain_grid, quanta
from rrc_pin.solvers.maps.batch import Rows
from rrc_pin.solvers.maps.kinematics import BarkerKinematics, ChainKinematics, task_rows
from rrc_pin.solvers.maps.sampling import Plan, block_samples

pytestmark = pytest.mark.compiled


def test_the_evaluator_follows_the_arm():
    assert isinstance(arm_kinematics(rrc_pin.load("barker6")), BarkerKinematics)
    variant = arm_kinematics(rrc_pin.load("barker6", alpha3=np.deg2rad(88), a3=0.02))
    assert isinstance(variant, BarkerKinematics)
    flange = arm_kinematics(rrc_pin.load("barker6", tool_frame="flange"))
    assert isinstance(flange, ChainKinematics) and flange.rows == 6
    kr5 = arm_kinematics(rrc_pin.load("kr5_3r"))  # a closed form, but not Barker's: the chain
    assert isinstance(kr5, ChainKinematics) and kr5.rows == 3
    assert task_rows(7) == task_rows(6) == 6 and task_rows(5) == 3


def test_barkers_closed_form_and_the_chain_give_the_same_rows():
    """On the same block: voxels, directions and margins equal (but for a sample on a voxel
    or bin boundary, where the two computations may round apart), the singular values to
    1e-12; Barker's flags agree with his conditions computed from the closed form's own
    singularity_batch."""
    arm = rrc_pin.load("barker6")
    closed = arm_kinematics(arm)
    chain = ChainKinematics(closed.chain, 6)
    grid = chain_grid(closed.chain, 0.05)
    plan = Plan(4096, 4096)
    Q = block_samples(closed.chain, 1, plan, 0)
    q = quanta(closed.chain, 6)
    a, b = Rows.empty(4096, 3), Rows.empty(4096, 0)
    closed.block_rows(Q, grid.arrays, True, q, 0, a)
    chain.block_rows(Q, grid.arrays, True, q, 0, b)
    assert np.mean(a.keys == b.keys) > 0.999 and np.mean(a.dirs == b.dirs) > 0.999
    assert np.array_equal(a.fmax[:, 2], b.fmax[:, 2])
    assert np.abs(a.fmax[:, :2] - b.fmax[:, :2]).max() < 1e-12
    assert np.abs(a.isum[:, :2] - b.isum[:, :2]).max() <= 1  # one quantum at most
    s = arm.closed_form.singularity_batch(Q)
    tol = np.asarray(closed.tolerances)
    flags = np.abs(np.stack([s.eq32, s.eq33, s.s5], axis=1)) <= tol
    assert np.array_equal(a.isum[:, 2:] == 1, flags)
    assert closed.conditions == ("eq32", "eq33", "s5")
    g = arm.closed_form.geometry
    assert tol[0] == pytest.approx(0.01 * g.reach) and tol[2] == 0.01


def test_manipulability_of_barker6_is_det_j(rng):
    """prod(sigma) of the wrist-centre Jacobian is |det J| = |ES F1 eq33 S5| (eq. D9)."""
    arm = rrc_pin.load("barker6")
    kin = arm_kinematics(arm)
    grid = chain_grid(kin.chain, 0.05)
    Q = block_samples(kin.chain, 3, Plan(500, 512), 0)
    rows = Rows.empty(500, 3)
    kin.block_rows(Q, grid.arrays, True, quanta(kin.chain, 6), 0, rows)
    s = arm.closed_form.singularity_batch(Q)
    det = np.abs(s.det_m * s.s5)
    assert np.allclose(rows.fmax[:, 0], det, rtol=1e-10, atol=1e-14)


def test_chain_of_errors_name_the_argument():
    with pytest.raises(ToolFrameRequired) as err:
        chain_of(rrc_pin.load("baxter"))
    assert err.value.argument == "frame"
    with pytest.raises(FrameNotFound) as err2:
        chain_of(rrc_pin.load("panda"), "nope")
    assert err2.value.argument == "frame"
    with pytest.raises(InvalidInput) as err3:
        chain_of(rrc_pin.load("panda"), "universe")
    assert err3.value.argument == "frame"


def test_placed_chain_moves_the_tool_by_the_placement(rng):
    chain, _ = chain_of(rrc_pin.load("panda"))
    T = np.eye(4)
    T[:3, :3] = z_to([0.3, -0.2, 0.9])
    T[:3, 3] = (1.0, -0.5, 0.2)
    moved = placed(chain, T)
    for _ in range(20):
        q = chain.lower + (chain.upper - chain.lower) * rng.random(chain.n)
        R, p = chain.pose(q)
        R2, p2 = moved.pose(q)
        assert np.allclose(R2, T[:3, :3] @ R, atol=1e-14)
        assert np.allclose(p2, T[:3, :3] @ p + T[:3, 3], atol=1e-14)


def test_z_to_takes_z_to_the_axis(rng):
    for a in [*np.eye(3), -np.eye(3)[2], *rng.normal(size=(20, 3))]:
        A = z_to(a)
        assert np.allclose(A @ A.T, np.eye(3), atol=1e-14) and np.isclose(np.linalg.det(A), 1)
        assert np.allclose(A[:, 2], a / np.linalg.norm(a), atol=1e-14)
