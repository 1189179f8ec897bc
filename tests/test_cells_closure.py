"""Closing a cell's chains inside the tick: the second order, the correction, the bound."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.cells import closure_kernels
from rrc_pin.cells.closure import ChainFrames, ClosureBound, close
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits.contact_limit import Closure
from rrc_pin.robot import frame_index
from rrc_pin.solvers.tick.problem import Box

FIXED = 37


def fresh() -> int:
    return int(np.random.SeedSequence().entropy % 2**63)


def kinematics(cell, q):
    """The kinematics of a tick at ``q`` (a controller's: its own Data)."""
    _, dof, q_pin = cell.positions(q)
    return Kinematics(cell.model, cell.model.createData(), Layout.of(cell), dof, q_pin)


def second_order(cell, q, qdot, contacts, grips):
    """The compiled second order of the chains (frame names) at ``q`` along ``qdot``."""
    ids = frame_index(cell.model)
    frames = ChainFrames.of(cell.model, tuple(ids[f] for f in contacts),
                            tuple((ids[a], ids[b]) for a, b in grips))  # fmt: skip
    data = kinematics(cell, q).data
    poses = np.array([data.oMf[f].homogeneous for f in frames.frames]).reshape(-1, 4, 4)
    out = np.empty(6 * (len(contacts) + len(grips)))
    closure_kernels.second_order(np.ascontiguousarray(data.J), frames.support, frames.joint,
                                 poses, frames.contacts, frames.grips, qdot, out)  # fmt: skip
    return out


def _chain_errors(cell, q, contacts, grips):
    """Each chain's pose (position [m], rotation vector [rad]) in the rows' axes, as the limits
    measure it against an identity goal: a contact's in world axes, a grip's b in a."""
    out = []
    for f in contacts:
        T = cell.fk(q, f)
        out.append(np.concatenate([T[:3, 3], pin.log3(T[:3, :3])]))
    for a, b in grips:
        rel = np.linalg.inv(cell.fk(q, a)) @ cell.fk(q, b)
        out.append(np.concatenate([rel[:3, 3], pin.log3(rel[:3, :3])]))
    return np.concatenate(out)


@pytest.mark.parametrize("seed", [FIXED, None])
@pytest.mark.parametrize("name", ["gsfc_dual", "yeh_tripod"])
def test_second_order_is_the_chains_second_derivative_along_the_step(dual, tripod, name, seed):
    """Central differences of each chain's pose along ``q + qdot t`` (integrate), against
    :func:`second_order`: contacts (a floating base on its screw) and grips (b in a)."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    cell = dual if name == "gsfc_dual" else tripod
    contacts = list(cell.tool_frames) if cell.body else []
    grips = [g.hands for g in cell.objects.values()]
    h = 1e-4
    for _ in range(5):
        q = cell.random_q(rng)
        qdot = rng.normal(size=cell.nv)
        at = [_chain_errors(cell, cell.integrate(q, qdot, t), contacts, grips)
              for t in (-h, 0.0, h)]  # fmt: skip
        numeric = (at[0] - 2.0 * at[1] + at[2]) / h**2
        # rotation vectors: their second difference is the angular acceleration near zero
        # only, so compare rotations as the rotation rate's derivative in the rows' axes
        got = second_order(cell, q, qdot, contacts, grips)
        for k in range(len(contacts) + len(grips)):
            np.testing.assert_allclose(got[6 * k : 6 * k + 3], numeric[6 * k : 6 * k + 3],
                                       atol=2e-5 * (1 + np.abs(numeric).max()),
                                       err_msg=f"seed {seed}")  # fmt: skip


@pytest.mark.parametrize("seed", [FIXED, None])
def test_second_order_rotations_against_a_finite_difference_of_the_rates(dual, tripod, seed):
    """The angular part: the derivative along the step of each chain's angular velocity in the
    rows' axes (world for a contact, a's for a grip), by central differences."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    h = 1e-6
    for cell in (dual, tripod):
        contacts = list(cell.tool_frames) if cell.body else []
        grips = [g.hands for g in cell.objects.values()]
        q, qdot = cell.random_q(rng), rng.normal(size=cell.nv)

        def rates(t, cell=cell, q=q, qdot=qdot, contacts=contacts, grips=grips):
            qt = cell.integrate(q, qdot, t)
            out = []
            for f in contacts:
                out.append(cell.jacobian(qt, "world_aligned", f)[3:] @ qdot)
            for a, b in grips:
                Ra = cell.fk(qt, a)[:3, :3]
                Ja, Jb = (cell.jacobian(qt, "world_aligned", f)[3:] for f in (a, b))
                out.append(Ra.T @ ((Jb - Ja) @ qdot))
            return np.concatenate(out)

        numeric = (rates(h) - rates(-h)) / (2 * h)
        got = second_order(cell, q, qdot, contacts, grips)
        for k in range(len(contacts) + len(grips)):
            np.testing.assert_allclose(got[6 * k + 3 : 6 * k + 6], numeric[3 * k : 3 * k + 3],
                                       atol=1e-6 * (1 + np.abs(numeric).max()),
                                       err_msg=f"seed {seed}")  # fmt: skip


def _problem(cell, rng, box_scale=1.0):
    """A grip or contact closure at a random configuration: rows, a small error, a box.

    Returns q, the chains' rows and errors, their frames, the box, rates inside it."""
    q = cell.random_q(rng)
    ids = frame_index(cell.model)
    if cell.body:
        frames = list(cell.tool_frames)
        C = np.vstack([cell.jacobian(q, "world_aligned", f) for f in frames])
        chains = ChainFrames.of(cell.model, tuple(ids[f] for f in frames), ())
        unit = np.tile([1.99] * 3 + [1.0] * 3, len(frames))
    else:
        a, b = cell.objects["object"].hands
        task = rrc_pin.tasks.RelativeFrameTask(a, b)
        C = rrc_pin.Resolver(cell, 0.01).rows_of(task, q).A
        chains = ChainFrames.of(cell.model, (), ((ids[a], ids[b]),))
        unit = np.array([1.5] * 3 + [1.0] * 3)
    error = rng.normal(size=C.shape[0]) * 1e-5
    n = cell.nv
    lb = -cell.velocity_limit * box_scale * rng.uniform(0.0, 1.0, n)
    ub = cell.velocity_limit * box_scale * rng.uniform(0.0, 1.0, n)
    box = Box(lb, ub, np.zeros((2, n), np.int8), True, False, cell.velocity_limit.copy())
    qdot = box.clip(rng.normal(size=n) * 0.3)
    return q, Closure(C, error, unit), chains, box, qdot


@pytest.mark.parametrize("seed", [FIXED, None])
def test_the_correction_stays_in_the_box_left_and_its_trust_region(dual, tripod, seed):
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    for cell in (dual, tripod):
        for _ in range(20):
            q, closure, chains, box, qdot = _problem(cell, rng)
            top = rng.normal(size=(6, cell.nv))
            delta, _, _ = close(kinematics(cell, q), chains, closure, qdot, top, box, None, 0.01)
            assert np.all(np.isfinite(delta)), seed
            applied = qdot + delta
            assert np.all(applied >= box.lb - 1e-12) and np.all(applied <= box.ub + 1e-12), seed
            assert np.all(np.abs(delta) <= 0.1 * box.velocity * (1 + 1e-12)), seed


@pytest.mark.parametrize("seed", [FIXED, None])
def test_an_unbounded_correction_closes_the_chains_and_keeps_the_top_level(dual, seed):
    """Box wide open, rows well conditioned: the chains' rates are met (their error and
    their second order along the step taken out) and the top level's rows do not move (the
    correction in their null space), both to the damping's second order."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    checked = 0
    while checked < 10:
        q, closure, chains, box, _ = _problem(dual, rng, box_scale=1e3)
        C = closure.C
        null = np.linalg.svd(C)[2][6:]
        qdot = null.T @ rng.normal(size=null.shape[0]) * 0.3  # the grip's rows kept, C qdot = 0
        top = dual.jacobian(q, "world_aligned", "object")
        top[:3] /= 1.5
        sigma = np.linalg.svd(top @ null.T, compute_uv=False)
        if sigma[0] > 10 * sigma[-1] or np.linalg.svd(C, compute_uv=False)[-1] < 0.1:
            continue  # nearer a singular configuration: the damping takes its share
        box = box._replace(velocity=box.velocity * 1e3)
        delta, after, _ = close(kinematics(dual, q), chains, closure, qdot, top, box, None, 0.01)
        size = np.abs(closure.error).max()  # what the chains' rows must take out
        # exact to second order in the damping (1e-4 of the rows' mean squared singular value)
        np.testing.assert_allclose(top @ delta, 0.0, atol=1e-3 * size / 0.01,
                                   err_msg=f"seed {seed}")  # fmt: skip
        np.testing.assert_allclose(after, 0.0, atol=1e-3 * size, err_msg=f"seed {seed}")
        checked += 1


def test_a_singular_chain_is_corrected_by_bounded_rates(dual):
    """Both arms within 1e-4 rad of straight up (every joint near zero): the grip's rows
    nearly lose a direction (a singular chain). The correction is damped: the least squares'
    rates, some 1e-5 / (0.01 sigma_min), would reach tens of rad/s."""
    rng = np.random.default_rng(FIXED)
    q = rng.normal(size=dual.nq) * 1e-4
    a, b = dual.objects["object"].hands
    C = rrc_pin.Resolver(dual, 0.01).rows_of(rrc_pin.tasks.RelativeFrameTask(a, b), q).A
    sigma = np.linalg.svd(C, compute_uv=False)
    assert 1e-12 < sigma[-1] < 1e-3 * sigma[0]  # nearly singular
    ids = frame_index(dual.model)
    chains = ChainFrames.of(dual.model, (), ((ids[a], ids[b]),))
    for _ in range(10):
        error = rng.normal(size=6) * 1e-5
        closure = Closure(C, error, np.array([1.5] * 3 + [1.0] * 3))
        wide = np.full(dual.nv, 1e3)
        box = Box(-wide, wide, np.zeros((2, dual.nv), np.int8), True, False, wide)
        delta, _, _ = close(kinematics(dual, q), chains, closure, np.zeros(dual.nv),
                         np.zeros((0, dual.nv)), box, None, 0.01)  # fmt: skip
        assert np.all(np.isfinite(delta))
        assert np.abs(delta).max() < 0.1, np.abs(delta).max()


def test_the_bound_is_checked_and_reads_each_chain(dual):
    bound = ClosureBound(1e-5, 2e-5)
    e = np.zeros(12)
    e[0], e[9] = 0.5e-5, 3e-5  # chain 1 within; chain 2's rotation beyond (1.5)
    assert bound.level(e) == pytest.approx(1.5)
    assert bound.level(np.zeros(0)) == 0.0
    for bad in ({"position": 0.0}, {"rotation": -1.0}, {"position": np.nan}):
        with pytest.raises(InvalidInput, match=next(iter(bad))):
            ClosureBound(**bad)
