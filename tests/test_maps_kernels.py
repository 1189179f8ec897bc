"""The maps' compiled kernels (solvers/maps/kernels.py through solvers/maps/batch.py) against
independent references: Pinocchio for the chain's pose and Jacobian, numpy's SVD for the
singular values, numpy's scatter reductions for the accumulation; and the same source as
plain Python (NUMBA_DISABLE_JIT=1) giving the same bits."""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import numpy as np
import pytest

import rrc_pin
from rrc_pin.maps.kinematics import chain_of
from rrc_pin.solvers.maps import kernels as map_kernels
from rrc_pin.solvers.maps.batch import BINS, NONE, Rows, VoxelTable, direction_bins, singular_values

ROOT = Path(__file__).resolve().parents[1]
JIT = not numba.config.DISABLE_JIT
CONFIGS = 2000 if JIT else 200
"""Random configurations per arm (fewer when the kernels run as plain Python)."""

UNALIGNED_URDF = """<?xml version="1.0"?>
<robot name="odd_axes">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0.1 0 0.3" rpy="0.1 0.2 0.3"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0.2 0.1" rpy="0 0.5 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.3" upper="0.4" velocity="1" effort="1"/></joint>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.3 0 0" rpy="0 0 0.4"/><axis xyz="0 1 0"/>
    <limit velocity="1" effort="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0 0 0.25" rpy="-0.3 0 0"/><axis xyz="0 0 -1"/>
    <limit lower="-1" upper="1.5" velocity="1" effort="1"/></joint>
  <joint name="j5" type="prismatic"><parent link="l4"/><child link="tip"/>
    <origin xyz="0.05 0.02 0.1" rpy="0 0 0"/><axis xyz="0.3 -0.4 0.866"/>
    <limit lower="0" upper="0.2" velocity="1" effort="1"/></joint>
</robot>
"""


def configurations(robot: rrc_pin.Robot, rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` configurations (n, nq) uniform within the limits ([-pi, pi] if continuous), as
    ``Robot.random_q`` draws them, in one call."""
    lo = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    return lo + (hi - lo) * rng.random((n, robot.nq))


def _robots(tmp_path: Path) -> list[tuple[str, rrc_pin.Robot, str | None]]:
    urdf = tmp_path / "odd_axes.urdf"
    urdf.write_text(UNALIGNED_URDF)
    T = np.eye(4)
    T[:3, :3] = rrc_pin.load("barker6").fk(np.full(6, 0.3))[:3, :3]
    T[:3, 3] = (0.4, -1.2, 0.1)
    cell = rrc_pin.combine({"a": (rrc_pin.load("panda"), np.eye(4)),
                            "b": (rrc_pin.load("kr5_3r"), T)})  # fmt: skip
    names = ("panda", "rrc_k1607", "kr5_3r", "barker6", "ur5", "z1", "kinova", "nadkarni_c2")
    out = [(n, rrc_pin.load(n), None) for n in names]
    out += [("odd_axes", rrc_pin.load(str(urdf)), None)]
    out += [("baxter", rrc_pin.load("baxter"), "left_gripper"), ("cell", cell, "b/tool")]
    return out


def test_chain_pose_and_jacobian_equal_pinocchio(tmp_path, rng):
    """Thousands of random configurations per arm: revolute about x, y, z, -z and an
    unaligned axis, prismatic (aligned and not), continuous joints, a tree (baxter's left
    arm) and a placed arm of a combined cell; pose and world-aligned Jacobian to 1e-12."""
    for name, robot, frame in _robots(tmp_path):
        chain, index = chain_of(robot, frame)
        assert chain.n == len(index)
        rows = 6 if chain.n >= 6 else 3
        Q = configurations(robot, rng, CONFIGS)
        R, P, J = chain.batch(Q[:, index], rows)
        T = np.array([robot.fk(q, frame) for q in Q])
        Jp = np.array([robot.jacobian(q, frame=frame)[:rows][:, index] for q in Q])
        worst = max(np.abs(R - T[:, :3, :3]).max(), np.abs(P - T[:, :3, 3]).max(),
                    np.abs(J - Jp).max())  # fmt: skip
        assert worst < 1e-12, (name, worst)
        R1, p1 = chain.pose(Q[0, index])  # one configuration: the same kernel
        assert np.array_equal(R1, R[0]) and np.array_equal(p1, P[0])
        assert np.array_equal(chain.jacobian(Q[0, index], rows), J[0])


def test_chain_of_continuous_and_prismatic_ranges(tmp_path):
    urdf = tmp_path / "odd_axes.urdf"
    urdf.write_text(UNALIGNED_URDF)
    chain, _ = chain_of(rrc_pin.load(str(urdf)))
    assert chain.kind.tolist() == [0, 1, 0, 0, 1]
    assert chain.bounded.tolist() == [True, True, False, True, True]
    assert chain.lower[2] == -np.pi and chain.upper[2] == np.pi
    assert chain.span[2] == 0.0 and chain.span[1] == pytest.approx(0.7)


def test_reach_and_jacobian_bounds_hold(rng):
    for name in ("panda", "nadkarni_c2", "kr5_3r"):
        robot = rrc_pin.load(name)
        chain, _ = chain_of(robot)
        rows = 6 if chain.n >= 6 else 3
        _, P, J = chain.batch(configurations(robot, rng, 3000), rows)
        assert np.linalg.norm(P - chain.trans[0], axis=1).max() <= chain.reach() + 1e-12
        assert np.linalg.norm(J, axis=(1, 2)).max() <= chain.jacobian_bound(rows) + 1e-12


@pytest.mark.parametrize("shape", [(6, 7), (6, 6), (3, 3), (3, 5), (2, 9)])
def test_singular_values_equal_numpy_svd(shape, rng):
    for k in range(300):
        J = rng.normal(size=shape) * rng.uniform(0.01, 3.0, size=(1, shape[1]))
        if k % 3 == 0:  # rank deficient: one row a combination of two others
            J[-1] = 0.3 * J[0] - 2.0 * J[1]
        if k % 7 == 0:
            J[0] = 0.0
        ref = np.linalg.svd(J, compute_uv=False)
        got = singular_values(J)
        assert np.abs(got - ref).max() <= 1e-12 * max(ref[0], 1.0), (J, got, ref)
        assert np.all(np.diff(got) <= 0)


def test_singular_values_of_pinocchio_jacobians(rng):
    robot = rrc_pin.load("panda")
    for q in configurations(robot, rng, 500):
        J = robot.jacobian(q)
        ref = np.linalg.svd(J, compute_uv=False)
        assert np.abs(singular_values(J) - ref).max() <= 1e-12 * ref[0]


def _bin_reference(d: np.ndarray) -> int:
    """The cube-map bin as the docstring reads: face, then three equal angles per axis."""
    axis = int(np.argmax(np.abs(d)))
    face = 2 * axis + (0 if d[axis] >= 0 else 1)
    u, v = (d[a] / abs(d[axis]) for a in range(3) if a != axis)
    cell = [int(np.clip(np.floor((np.degrees(np.arctan(x)) + 45.0) / 30.0), 0, 2)) for x in (u, v)]
    return face * 9 + cell[0] * 3 + cell[1]


def test_direction_bins(rng):
    Z = rng.normal(size=(20000, 3))
    Z /= np.linalg.norm(Z, axis=1)[:, None]
    bins = direction_bins(Z)
    assert [_bin_reference(d) for d in Z[:3000]] == bins[:3000].tolist()
    counts = np.bincount(bins, minlength=BINS)
    assert counts.size == BINS == 54 and counts.min() > 0
    assert counts.max() / counts.min() < 1.5  # near equal solid angles (1.26 at 2e5 samples)
    for axis in np.eye(3):
        assert direction_bins(axis)[0] == direction_bins(axis * (1 - 1e-9))[0]


def test_voxel_key_matches_numpy_floor(rng):
    start, voxel, shape = np.array([-14, -7, 3]), 0.07, np.array([30, 20, 12])
    P = rng.uniform(-1.3, 2.0, size=(5000, 3))
    idx = np.floor(P / voxel).astype(np.int64) - start
    inside = np.all((idx >= 0) & (idx < shape), axis=1)
    ref = np.where(inside, (idx[:, 0] * shape[1] + idx[:, 1]) * shape[2] + idx[:, 2], -1)
    got = [map_kernels.voxel_key(x, y, z, start, voxel, shape) for x, y, z in P]
    assert got == ref.tolist()
    assert inside.any() and not inside.all()


def _random_rows(rng, n: int, conditions: int = 2) -> Rows:
    rows = Rows.empty(n, conditions)
    rows.keys[:] = rng.integers(-1, 400, n)
    rows.count[:] = 1
    rows.dirs[:] = np.uint64(1) << rng.integers(0, BINS, n).astype(np.uint64)
    rows.fmax[:] = rng.uniform(0, 1, (n, 3))
    rows.fmax[rng.random(n) < 0.1, :2] = -np.inf
    rows.isum[:] = rng.integers(0, 2**31, rows.isum.shape)
    rows.imin[:] = rng.integers(0, 10**9, rows.imin.shape)
    rows.imin[rng.random(rows.imin.shape) < 0.5] = NONE
    return rows


def _reference(rows: Rows) -> dict[int, tuple]:
    keys = rows.keys
    out = {}
    for k in np.unique(keys[keys >= 0]):
        sel = keys == k
        out[int(k)] = (int(rows.count[sel].sum()), int(np.bitwise_or.reduce(rows.dirs[sel])),
                       rows.fmax[sel].max(axis=0).tolist(), rows.isum[sel].sum(axis=0).tolist(),
                       rows.imin[sel].min(axis=0).tolist())  # fmt: skip
    return out


def _as_dict(table: VoxelTable) -> dict[int, tuple]:
    s = table.sparse()
    return {int(k): (int(c), int(d), f.tolist(), i.tolist(), m.tolist())
            for k, c, d, f, i, m in zip(s.keys, s.count, s.dirs, s.fmax, s.isum, s.imin,
                                         strict=True)}  # fmt: skip


def test_accumulate_equals_numpy_reductions_in_any_grouping(rng):
    rows = _random_rows(rng, 6000)
    ref = _reference(rows)
    whole = VoxelTable(4, 3, capacity=2)  # grows several times
    whole.add(rows)
    assert _as_dict(whole) == ref
    assert whole.outside == int(np.count_nonzero(rows.keys < 0))
    # random chunks, in a shuffled order, through two tables merged
    cuts = np.sort(rng.choice(np.arange(1, 6000), size=9, replace=False))
    chunks = np.split(np.arange(6000), cuts)
    rng.shuffle(chunks)
    a, b = VoxelTable(4, 3), VoxelTable(4, 3, capacity=1 << 14)
    for i, idx in enumerate(chunks):
        part = Rows(*(getattr(rows, f)[idx] for f in ("keys", "count", "dirs", "fmax", "isum",
                                                        "imin")))  # fmt: skip
        (a if i % 2 else b).add(part)
    a.add_sparse(b.sparse())
    assert _as_dict(a) == ref and a.outside == whole.outside


JIT_FREE = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    import rrc_pin
    from rrc_pin.maps.kinematics import arm_kinematics
    from rrc_pin.solvers.maps.sampling import Plan, block_samples
    from rrc_pin.maps.voxels import chain_grid, quanta
    from rrc_pin.solvers.maps.batch import Rows, VoxelTable
    out = {}
    for name in ("panda", "barker6"):
        kin = arm_kinematics(rrc_pin.load(name))
        plan = Plan(40, 32)
        grid = chain_grid(kin.chain, 0.05)
        table = VoxelTable(2 + len(kin.conditions), 1 + len(kin.conditions))
        for b in range(plan.blocks):
            Q = block_samples(kin.chain, 7, plan, b)
            rows = Rows.empty(32, len(kin.conditions)).head(len(Q))
            kin.block_rows(Q, grid.arrays, True, quanta(kin.chain, kin.rows), plan.first(b), rows)
            table.add(rows)
        s = table.sparse()
        order = np.argsort(s.keys)
        out[name] = [a[order].tolist() for a in (s.keys, s.count, s.dirs.astype(str),
                     s.fmax.view(np.int64), s.isum, s.imin)]
    print(json.dumps(out))
    """
)


def test_the_same_source_runs_without_the_jit():
    """NUMBA_DISABLE_JIT=1 runs the kernels as Python: the same bits as compiled (a few
    blocks of panda's chain and barker6's closed form, every statistic)."""
    env = {**os.environ, "NUMBA_DISABLE_JIT": "0" if not JIT else "1"}
    done = subprocess.run([sys.executable, "-c", JIT_FREE], capture_output=True, text=True,
                          env=env, cwd=ROOT, check=True)  # fmt: skip
    here = io.StringIO()
    with contextlib.redirect_stdout(here):
        exec(JIT_FREE, {"__name__": "jit_free"})
    assert json.loads(done.stdout) == json.loads(here.getvalue())
    assert len(json.loads(here.getvalue())["panda"][0]) > 5
