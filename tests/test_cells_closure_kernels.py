"""The closed chains' compiled correction against plain numpy and Pinocchio references.

The references are the correction as it was written before it was compiled: the second order
from Pinocchio's forward pass with the rates (``getFrameClassicalAcceleration``), the damped
least squares with numpy's solve, the null space from numpy's QR, the projection's kernel. The
compiled kernels agree with them to rounding (1e-12 relative) on random configurations, rates,
errors and boxes of both ready-made cells, the box binding or not.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.cells import closure_kernels as ck
from rrc_pin.cells.closure import TRUST, ChainFrames, close
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits.contact_limit import Closure
from rrc_pin.robot import frame_index
from rrc_pin.solvers.tick.problem import Box, Rows
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project

FIXED = 11


def fresh() -> int:
    return int(np.random.SeedSequence().entropy % 2**63)


@pytest.fixture(scope="module", params=["gsfc_dual", "yeh_tripod"])
def cell(request):
    return rrc_pin.load(request.param)


def chains_of(cell):
    """The cell's chains: the feet (contacts) of a legged cell, the grips of its objects."""
    ids = frame_index(cell.model)
    contacts = tuple(ids[f] for f in cell.tool_frames) if cell.body else ()
    grips = tuple((ids[g.hands[0]], ids[g.hands[1]]) for g in cell.objects.values())
    return contacts, grips


def reference_second_order(model, q_pin, qdot, contacts, grips):
    """The second order from Pinocchio's forward pass with the rates, no joint acceleration."""
    data = model.createData()
    pin.forwardKinematics(model, data, q_pin, qdot, np.zeros(model.nv))
    out = []
    for f in contacts:
        a = pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED)
        out.append(np.concatenate([a.linear, a.angular]))
    for fa, fb in grips:
        Ta = pin.updateFramePlacement(model, data, fa)
        Tb = pin.updateFramePlacement(model, data, fb)
        va, vb = (pin.getFrameVelocity(model, data, f, pin.LOCAL_WORLD_ALIGNED) for f in (fa, fb))
        aa, ab = (pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED)
                  for f in (fa, fb))  # fmt: skip
        d, W = Tb.translation - Ta.translation, pin.skew(va.angular)
        linear = (ab.linear - aa.linear - pin.skew(aa.angular) @ d
                  - W @ (2.0 * (vb.linear - va.linear) - W @ d))
        angular = ab.angular - aa.angular - W @ vb.angular
        Rt = Ta.rotation.T
        out.append(np.concatenate([Rt @ linear, Rt @ angular]))
    return np.concatenate(out)


def reference_damped(J, b):
    """t = (J^T J + mu I)^-1 J^T b, then t + mu (J^T J + mu I)^-1 t (zero if not definite)."""
    m, n = J.shape
    mu = max(ck.DAMPING * np.trace(J.T @ J) / max(m, 1), np.finfo(float).tiny)
    M = J.T @ J + mu * np.eye(n)
    t = np.linalg.solve(M, J.T @ b)
    return t + mu * np.linalg.solve(M, t)


def reference_close(model, q_pin, frames, closure, qdot, top, box, dt, G=None, h=None):
    """The correction in numpy: passes, lexicographic damped least squares in numpy's QR null
    space, the projection where the box or a constraint row ``G delta <= max(h - G qdot, 0)``
    binds."""
    n = qdot.size
    C = closure.C / closure.unit[:, None]
    m = C.shape[0]
    null = np.linalg.qr(C.T, mode="complete")[0][:, m:].T if top.shape[0] and m < n else None
    trust = TRUST * box.velocity
    low = np.minimum(np.maximum(box.lb - qdot, -trust), 0.0)
    high = np.maximum(np.minimum(box.ub - qdot, trust), 0.0)
    G, h = (np.zeros((0, n)), np.zeros(0)) if G is None else (G, h)
    room = np.maximum(h - G @ qdot, 0.0)
    contacts = [frames.frames[i] for i in frames.contacts]
    grips = [(frames.frames[a], frames.frames[b]) for a, b in frames.grips]
    delta = np.zeros(n)
    for _ in range(ck.PASSES):
        second = reference_second_order(model, q_pin, qdot + delta, contacts, grips)
        r = (closure.error - 0.5 * dt * dt * second) / (dt * closure.unit)
        delta = reference_damped(C, r)
        if null is not None:
            delta = delta + reference_damped(top @ null.T, -(top @ delta)) @ null
        if not (np.all((low <= delta) & (delta <= high)) and np.all(G @ delta <= room)):
            x = np.empty(n)
            M = np.vstack([C, ck.KEEP * top])
            if project(M, ck.DAMPING, delta, low, high, G, room, MARGIN, x) != SOLVED:
                x[:] = 0.0
            delta = np.clip(x, low, high)
    after = closure.error - (closure.C @ (qdot + delta) + 0.5 * dt * second) * dt
    return delta, after


def kinematics(cell, q):
    _, dof, q_pin = cell.positions(q)
    return Kinematics(cell.model, cell.model.createData(), Layout.of(cell), dof, q_pin)


@pytest.mark.parametrize("seed", [FIXED, None])
def test_second_order_is_pinocchios_forward_pass(cell, seed):
    """From the world Jacobian's columns, the same as Pinocchio's forward pass with the rates
    (contacts: a floating base on its screw; grips: b in a), to rounding."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    contacts, grips = chains_of(cell)
    frames = ChainFrames.of(cell.model, contacts, grips)
    for _ in range(10):
        q = cell.random_q(rng)
        qdot = rng.normal(size=cell.nv) * rng.uniform(0.01, 3.0)
        data = kinematics(cell, q).data
        poses = np.array([data.oMf[f].homogeneous for f in frames.frames])
        got = np.empty(6 * (len(contacts) + len(grips)))
        ck.second_order(np.ascontiguousarray(data.J), frames.support, frames.joint, poses,
                        frames.contacts, frames.grips, qdot, got)  # fmt: skip
        want = reference_second_order(cell.model, cell.to_pinocchio(q), qdot, contacts, grips)
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12 * (1 + np.abs(want).max()),
                                   err_msg=f"seed {seed}")  # fmt: skip


def test_chain_frames_hold_each_frames_joints(cell):
    """Each frame's support is the rates of the joints on its chain: the columns where its
    world Jacobian is not zero at a random configuration, and the joints' own columns."""
    contacts, grips = chains_of(cell)
    frames = ChainFrames.of(cell.model, contacts, grips)
    assert len(frames.frames) == len(set(frames.frames)) == len(contacts) + 2 * len(grips)
    kin = kinematics(cell, cell.random_q(np.random.default_rng(FIXED)))
    names = {v: k for k, v in kin.layout.frames.items()}
    for i, f in enumerate(frames.frames):
        moving = np.abs(kin.jacobian(names[f], "world")).max(axis=0) > 0.0
        np.testing.assert_array_equal(frames.support[i], moving)
    for j in range(1, cell.model.njoints):
        start, nv = cell.model.joints[j].idx_v, cell.model.joints[j].nv
        assert np.all(frames.joint[start : start + nv] == j)


@pytest.mark.parametrize("seed", [FIXED, None])
def test_damped_is_its_formula(seed):
    """Against numpy's solves; its residual within the two damped steps' bound."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    for m, n in ((6, 14), (18, 24), (6, 6), (9, 5), (1, 3)):  # the rows' side, M's
        J, b = rng.normal(size=(m, n)), rng.normal(size=m)
        got = np.empty(n)
        ck.damped(J, b, got)
        np.testing.assert_allclose(got, reference_damped(J, b), rtol=1e-9, atol=1e-12,
                                   err_msg=f"seed {seed}")  # fmt: skip
        if m > n:  # more rows than rates: a least squares' residual
            continue
        # Two damped steps leave (mu / (sigma^2 + mu))^2 of b along each singular direction.
        mu, sigma = ck.DAMPING * np.trace(J.T @ J) / m, np.linalg.svd(J, compute_uv=False)[-1]
        left = (mu / (sigma**2 + mu)) ** 2 * np.linalg.norm(b)
        assert np.linalg.norm(J @ got - b) <= 1.01 * left + 1e-12, f"seed {seed}"
    for m, n in ((2, 3), (3, 2), (0, 3)):  # no rows, or all zero: zero
        got = np.ones(n)
        ck.damped(np.zeros((m, n)), np.ones(m), got)
        np.testing.assert_array_equal(got, 0.0)


@pytest.mark.parametrize("seed", [FIXED, None])
def test_damped_factors_serve_every_right_hand_side(seed):
    """:func:`damped_factor` once, :func:`damped_solve` for several rates: :func:`damped`'s
    answers, bit for bit; and the kept rows' null space is numpy's, to rounding."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    for m, n in ((6, 14), (18, 24), (9, 5)):
        J = rng.normal(size=(m, n))
        L = np.empty((min(m, n), min(m, n)))
        mu = ck.damped_factor(J, L)
        assert mu > 0.0
        for _ in range(3):
            b, got, want = rng.normal(size=m), np.empty(n), np.empty(n)
            ck.damped_solve(J, L, mu, b, got)
            ck.damped(J, b, want)
            np.testing.assert_array_equal(got, want, err_msg=f"seed {seed}")
        top = rng.normal(size=(6, n))
        null, keep = ck.kept(J, top)
        if m >= n:
            assert null.shape == (0, n) and keep.shape == (6, 0)
            continue
        want_null = np.linalg.qr(J.T, mode="complete")[0][:, m:].T
        # the same subspace, orthonormal rows: the same projector
        np.testing.assert_allclose(null.T @ null, want_null.T @ want_null, atol=1e-13,
                                   err_msg=f"seed {seed}")  # fmt: skip
        np.testing.assert_allclose(null @ null.T, np.eye(n - m), atol=1e-13)
        np.testing.assert_allclose(keep, top @ null.T, atol=1e-13)


def random_case(cell, frames, rng, k):
    """A random tick's inputs to :func:`close`: chains' errors, rates, a wide box (k odd) or a
    tight one (the trust region binds), a top level (k % 4 < 2) and constraint rows (k % 3 ==
    0, one of them held at zero room where k % 6 == 0)."""
    names = {v: k for k, v in frame_index(cell.model).items()}
    contacts = [frames.frames[i] for i in frames.contacts]
    grips = [(frames.frames[a], frames.frames[b]) for a, b in frames.grips]
    q = cell.random_q(rng)
    kin = kinematics(cell, q)
    C = np.vstack([kin.jacobian(names[f]) for f in contacts]
                  + [rrc_pin.tasks.RelativeFrameTask(names[a], names[b]).rows(kin).A
                     for a, b in grips])  # fmt: skip
    unit = np.tile([1.7, 1.7, 1.7, 1.0, 1.0, 1.0], C.shape[0] // 6)
    closure = Closure(C, rng.normal(size=C.shape[0]) * 1e-5, unit)
    scale = 1e3 if k % 2 else 1e-3  # wide, or the correction's trust region binds
    lb = -cell.velocity_limit * rng.uniform(0.0, 1.0, cell.nv)
    ub = cell.velocity_limit * rng.uniform(0.0, 1.0, cell.nv)
    box = Box(lb, ub, np.zeros((2, cell.nv), np.int8), True, False,
              cell.velocity_limit * scale)  # fmt: skip
    qdot = box.clip(rng.normal(size=cell.nv) * 0.3)
    top = rng.normal(size=(6, cell.nv)) if k % 4 < 2 else np.zeros((0, cell.nv))
    rows = None
    if k % 3 == 0:
        G = rng.normal(size=(4, cell.nv))
        h = G @ qdot + np.abs(rng.normal(size=4)) * 1e-4
        if k % 6 == 0:
            h[0] = G[0] @ qdot  # held: no room
        rows = Rows(G, h, ("row",) * 4)
    return q, kin, closure, qdot, top, box, rows


@pytest.mark.parametrize("seed", [FIXED, None])
def test_the_correction_is_the_numpy_reference(cell, seed):
    """:func:`close` (one compiled call) against the numpy reference on random chains'
    errors, rates, boxes and constraint rows: a wide box (the least squares) and a tight one
    (the projection), rows with room and a row held."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    frames = ChainFrames.of(cell.model, *chains_of(cell))
    projected = 0
    for k in range(24):
        q, kin, closure, qdot, top, box, rows = random_case(cell, frames, rng, k)
        got, after, applied = close(kin, frames, closure, qdot, top, box, rows, 0.01)
        G, h = (None, None) if rows is None else (rows.G, np.asarray(rows.h))
        want, want_after = reference_close(cell.model, cell.to_pinocchio(q), frames, closure,
                                           qdot, top, box, 0.01, G, h)  # fmt: skip
        if k % 2 == 0:  # the trust region binds: the projection's answer, on it
            on = np.isclose(np.abs(got), TRUST * box.velocity, rtol=1e-9, atol=0.0)
            # or none, as the reference finds: a row held at no room, which the projection
            # keeps with its margin to spare, may leave it no point (seed
            # 3002881855625045783, case 6; both zero)
            held = k % 6 == 0 and not want.any()
            assert on.any() or held, f"seed {seed}, case {k}"
            projected += int(on.any())
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12 * (1 + np.abs(want).max()),
                                   err_msg=f"seed {seed}, case {k}")  # fmt: skip
        np.testing.assert_allclose(after, want_after, rtol=0.0, atol=1e-15,
                                   err_msg=f"seed {seed}, case {k}")  # fmt: skip
        trust = TRUST * box.velocity  # inside the box and the trust region
        low = np.minimum(np.maximum(box.lb - qdot, -trust), 0.0)
        high = np.maximum(np.minimum(box.ub - qdot, trust), 0.0)
        assert np.all((low <= got) & (got <= high)), f"seed {seed}"
        assert np.array_equal(applied, box.clip(qdot + got)), f"seed {seed}"
        if rows is not None:
            room = np.maximum(h - G @ qdot, 0.0)
            assert np.all(G @ got <= room + 1e-12 * (1 + np.abs(room))), f"seed {seed}"
    assert projected >= 8  # of 12: the 4 with a row held may have none


@pytest.mark.parametrize("seed", [FIXED, None])
def test_largest_is_numpys_norms(seed):
    """Each chain's position and rotation lengths, the largest: numpy's floats, bit for bit."""
    seed = fresh() if seed is None else seed
    rng = np.random.default_rng(seed)
    assert ck.largest(np.zeros(0)) == (0.0, 0.0)
    for k in (1, 2, 3, 5):
        for _ in range(50):
            error = rng.normal(size=6 * k) * 10.0 ** rng.uniform(-9, 1)
            e = error.reshape(-1, 6)
            want = (float(np.max(np.linalg.norm(e[:, :3], axis=1))),
                    float(np.max(np.linalg.norm(e[:, 3:], axis=1))))  # fmt: skip
            assert ck.largest(error) == want, f"seed {seed}"
