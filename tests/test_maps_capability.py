"""maps.capability: bad input refused before anything changes; the maps against independent
truths (kr5_3r's analytic workspace, Barker's singular conditions, every voxel's witness
through Pinocchio); the files written."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("distributed")

import rrc_pin
from rrc_pin import maps
from rrc_pin.errors import ForeignMap, FrameNotFound, InvalidInput

pytestmark = pytest.mark.compiled

QUIET = {"progress": False, "workers": 2}


# -- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [({"voxel": 0.0}, "voxel"), ({"voxel": -0.1}, "voxel"), ({"voxel": float("nan")}, "voxel"),
     ({"voxel": "5cm"}, "voxel"), ({"voxel": 1e-4}, "voxel"), ({"samples": 0}, "samples"),
     ({"samples": -5}, "samples"), ({"samples": 1.5}, "samples"), ({"samples": True}, "samples"),
     ({"samples": 2**40}, "samples"), ({"seed": -1}, "seed"), ({"block_size": 1000}, "block_size"),
     ({"block_size": 2**3}, "block_size"), ({"blocks_per_task": 0}, "blocks_per_task"),
     ({"dexterity": 1}, "dexterity"), ({"progress": "yes"}, "progress"),
     ({"frame": "nope"}, "frame")],
)  # fmt: skip
def test_bad_arguments_are_refused_naming_them(kwargs, argument, tmp_path):
    call = {"samples": 1000, "voxel": 0.1, "out": tmp_path / "m", **QUIET, **kwargs}
    with pytest.raises(rrc_pin.RrcPinError) as err:
        maps.capability("kr5_3r", **call)
    assert isinstance(err.value, (InvalidInput, FrameNotFound))
    assert err.value.argument == argument
    assert not (tmp_path / "m").exists()


def test_an_out_path_that_is_a_file_is_refused(tmp_path):
    path = tmp_path / "file"
    path.write_text("x")
    with pytest.raises(InvalidInput) as err:
        maps.capability("kr5_3r", 1000, 0.1, out=path, **QUIET)
    assert err.value.argument == "out" and path.read_text() == "x"


def _snapshot(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_folder_holding_another_maps_blocks_is_refused_unchanged(tmp_path):
    maps.capability("kr5_3r", 3000, 0.1, out=tmp_path, seed=1, block_size=1024, **QUIET)
    before = _snapshot(tmp_path)
    for other in ({"seed": 2}, {"voxel": 0.2}, {"samples": 4000}):
        kw = {"samples": 3000, "voxel": 0.1, "seed": 1, "block_size": 1024, **other}
        with pytest.raises(ForeignMap) as err:
            maps.capability("kr5_3r", out=tmp_path, **kw, **QUIET)
        assert err.value.argument == "out" and "another map" in str(err.value)
        assert next(iter(other)) in str(err.value)  # names what differs
    with pytest.raises(ForeignMap):
        maps.capability("panda", 3000, 0.1, out=tmp_path, seed=1, block_size=1024, **QUIET)
    assert _snapshot(tmp_path) == before
    stray = tmp_path / "elsewhere" / "blocks"
    stray.mkdir(parents=True)
    (stray / "part-000000000-000000003.npz").write_bytes(b"not ours")
    with pytest.raises(ForeignMap):
        maps.capability("kr5_3r", 1000, 0.1, out=tmp_path / "elsewhere", **QUIET)


# -- kr5_3r against its analytic workspace -------------------------------------------------

A1, A2, A3 = 0.2, 0.5, 0.5
LIMITS = np.deg2rad([170.0, 135.0, 150.0])
R_MIN = np.sqrt(A2**2 + A3**2 + 2 * A2 * A3 * np.cos(LIMITS[2]))  # elbow folded to its limit
R_MAX = A2 + A3


def kr5_reachable(P: np.ndarray) -> np.ndarray:
    """The exam arm's workspace with its limits, analytically (P (N, 3) [m]).

    O1 lies on the circle of radius a1 about z0; from it the planar 2R arm (a2, a3) reaches
    the radii R_MIN..R_MAX in its vertical plane. A point is reachable when, for one of the
    two headings of joint 1 (toward the point, or away from it, within +-170 deg), the
    elbow angle from the law of cosines and the shoulder angle are within their limits.
    """
    x, y, z = P.T
    rho, phi = np.hypot(x, y), np.arctan2(y, x)
    out = np.zeros(len(P), bool)
    for q1, u in ((phi, rho), (phi - np.pi * np.sign(phi + 1e-300), -rho)):
        ok1 = np.abs(q1) <= LIMITS[0]
        dx, dz = u - A1, z
        c3 = (dx**2 + dz**2 - A2**2 - A3**2) / (2 * A2 * A3)
        ok = ok1 & (np.abs(c3) <= 1.0)
        for sign in (1.0, -1.0):
            q3 = sign * np.arccos(np.clip(c3, -1, 1))
            q2 = np.arctan2(dz, dx) - np.arctan2(A3 * np.sin(q3), A2 + A3 * np.cos(q3))
            q2 = (q2 + np.pi) % (2 * np.pi) - np.pi
            out |= ok & (np.abs(q2) <= LIMITS[1]) & (np.abs(q3) <= LIMITS[2])
    return out


def test_the_analytic_workspace_holds_the_arms_own_positions(rng):
    arm = rrc_pin.load("kr5_3r")
    Q = np.array([arm.random_q(rng) for _ in range(2000)])
    P = np.array([arm.fk(q)[:3, 3] for q in Q])
    shrunk = LIMITS * (1 - 1e-9)
    inside = np.all(np.abs(Q) <= shrunk, axis=1)
    assert kr5_reachable(P)[inside].all()
    d = np.hypot(np.hypot(P[:, 0], P[:, 1]) - A1, P[:, 2])  # distance to O1 (joint 1 toward P)
    d_away = np.hypot(np.hypot(P[:, 0], P[:, 1]) + A1, P[:, 2])
    assert np.all((d >= R_MIN - 1e-9) & (d <= R_MAX + 1e-9)
                  | (d_away >= R_MIN - 1e-9) & (d_away <= R_MAX + 1e-9))  # fmt: skip


def test_kr5_3r_reaches_its_analytic_workspace_and_nothing_else():
    """Voxels of 10 cm, 2^20 samples: every voxel wholly inside the analytic workspace (its
    125-point lattice all reachable) is reached, and every voxel reached touches it (a point
    of its lattice, dilated by a quarter voxel, is reachable)."""
    m = maps.capability("kr5_3r", 2**20, 0.1, dexterity=False, seed=2, **QUIET)
    v = m.grid.voxel
    keys = np.arange(m.grid.size)
    lows = m.grid.centres(keys) - v / 2
    t = np.linspace(0.0, 1.0, 5)
    lattice = np.stack(np.meshgrid(t, t, t, indexing="ij"), -1).reshape(-1, 3)
    inside_all = np.ones(m.grid.size, bool)
    touches = np.zeros(m.grid.size, bool)
    for f in lattice:
        inside_all &= kr5_reachable(lows + f * v)
        touches |= kr5_reachable(lows + (f * 1.5 - 0.25) * v)
    assert inside_all.sum() > 1000
    assert np.all(m.reached[inside_all]), np.flatnonzero(inside_all & ~m.reached)
    assert np.all(touches[m.reached]), np.flatnonzero(m.reached & ~touches)
    assert m.stats.outside == 0
    far = m.at([[0.0, 0.0, 1.3], [1.25, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert far.samples[0] == 0 and far.samples[1] == 0  # beyond a1 + a2 + a3 = 1.2 m


# -- barker6: the voxels flagged singular --------------------------------------------------


def test_barker6_voxels_flagged_singular_hold_the_samples_where_eqs_32_33_s5_hold():
    """Each condition's voxels are exactly those holding a sample where it holds, computed
    here apart: eq. (33) and S5 from the DH angles (Appendix D's SAL3 WE S3 + A3 C3, sin
    theta_5), eq. (32) from Pinocchio's wrist centre (F1^2 = rho^2 - F2^2: the wrist centre's
    distance to the axis of joint 1). Samples within 1e-12 of a threshold are left out."""
    arm = rrc_pin.load("barker6")
    m = maps.capability(arm, 2**16, 0.05, seed=4, block_size=2**14, **QUIET)
    g = arm.closed_form.geometry
    tol_len, _, tol_s5 = m.meta["tolerances"]
    Q = np.concatenate([
        maps_block(m, b) for b in range(m.plan.blocks)
    ])  # fmt: skip
    P = np.array([arm.fk(q)[:3, 3] for q in Q])
    values = {
        "eq32": np.sqrt(np.maximum(P[:, 0] ** 2 + P[:, 1] ** 2 - g.f2**2, 0.0)),
        "eq33": np.abs(g.sal3 * g.we * np.sin(Q[:, 2]) + g.a3 * np.cos(Q[:, 2])),
        "s5": np.abs(np.sin(Q[:, 4])),
    }
    keys = m.grid.keys_of(P)
    for name, tol in (("eq32", tol_len), ("eq33", tol_len), ("s5", tol_s5)):
        holds, near = values[name] <= tol, np.abs(values[name] - tol) < 1e-12
        sure = set(keys[holds & ~near].tolist())
        possible = set(keys[holds | near].tolist())
        flagged = set(np.flatnonzero(m.stats.arrays()[f"{name}_count"]).tolist())
        assert sure <= flagged <= possible, name
        assert len(sure) > 50
        # the witness of each flagged voxel: the condition holds there, in that voxel
        k = np.array(sorted(flagged))
        W = m.witnesses(k, f"{name}_witness")
        Pw = np.array([arm.fk(q)[:3, 3] for q in W])
        assert np.array_equal(m.grid.keys_of(Pw), k)


def maps_block(m: maps.CapabilityMap, block: int) -> np.ndarray:
    from rrc_pin.solvers.maps.sampling import block_samples

    return block_samples(m.chain, int(m.meta["seed"]), m.plan, block)


def test_barker6_eq32_voxels_lie_on_the_cylinder_about_joint_1():
    """Geometry: F1 = 0 puts the wrist centre at distance |F2| from the axis of joint 1."""
    arm = rrc_pin.load("barker6")
    m = maps.capability(arm, 2**16, 0.05, seed=4, block_size=2**14, **QUIET)
    f2, tol = arm.closed_form.geometry.f2, m.meta["tolerances"][0]
    C = m.grid.centres(np.flatnonzero(m.stats.arrays()["eq32_count"]))
    rho = np.hypot(C[:, 0], C[:, 1])
    assert np.all(rho <= np.hypot(abs(f2), tol) + np.sqrt(2) * m.grid.voxel / 2 + 1e-12)


# -- every voxel's witness, through Pinocchio ---------------------------------------------


@pytest.mark.parametrize("arm", ["panda", "rrc_k1607"])
def test_every_reached_voxel_has_a_witness_within_limits_in_it(arm):
    """The first sample of each voxel, drawn again from the seed: within the joint limits,
    and Pinocchio puts its tool frame in that voxel (all voxels, not a sample of them)."""
    robot = rrc_pin.load(arm)
    m = maps.capability(robot, 2**16, 0.05, seed=8, dexterity=False, **QUIET)
    keys = np.flatnonzero(m.reached)
    W = m.witnesses(keys)
    assert np.all((W >= robot.lower) & (W <= robot.upper))
    P = np.array([robot.fk(q)[:3, 3] for q in W])
    assert np.array_equal(m.grid.keys_of(P), keys)


# -- outputs -------------------------------------------------------------------------------


def test_outputs_summary_and_queries(tmp_path):
    m = maps.capability("panda", 2**15, 0.1, out=tmp_path, seed=1, **QUIET)
    assert (tmp_path / "map.zarr" / "checksums.json").is_file()
    text = repr(m)  # a summary, the arrays as attributes
    assert "\n" not in text and len(text) < 200 and "samples=32,768" in text
    assert f"{int(m.reached.sum()):,} voxels reached" in text
    assert len(list((tmp_path / "blocks").glob("fold-*.npz"))) == 1
    assert not list((tmp_path / "blocks").glob("part-*"))
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["samples"] == 2**15 and summary["voxels_reached"] == m.reached.sum()
    assert "| voxels_reached |" in (tmp_path / "summary.md").read_text()
    meta = m.meta
    for key in ("arm", "samples", "seed", "voxel", "block_size", "versions", "quanta", "memory"):
        assert key in meta
    assert meta["versions"]["numpy"] and meta["versions"]["dask"]
    q = m.at([[0.4, 0.1, 0.5], [5.0, 0.0, 0.0]])
    assert q.inside.tolist() == [True, False] and q.samples[1] == 0
    assert np.isnan(q.coverage[1]) and 0 < q.coverage[0] <= 1
    assert 0 < q.manipulability_mean[0] <= q.manipulability_max[0]
    assert 0 < q.sigma_min_mean[0] <= q.sigma_min_max[0]
    one = m.at([0.4, 0.1, 0.5])
    assert one.samples.shape == (1,) and one.samples[0] == q.samples[0]
    with pytest.raises(InvalidInput) as err:
        m.at([[0.0, np.nan, 0.0]])
    assert err.value.argument == "points"
    # means from the fixed-point sums: within half a quantum of the float means
    k = m.grid.keys_of([[0.4, 0.1, 0.5]])[0]
    assert m.column("count")[k] == q.samples[0]


def test_the_readmes_maps_example_runs():
    """README's maps example, with fewer samples and the progress bar off."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    block = text.split("## Capability maps", 1)[1].split("```python", 1)[1].split("```", 1)[0]
    block = block.replace("samples=10**6", "samples=2**13, progress=False")
    block = block.replace("maps.audit(m, rrc_pin.load(\"panda\"), 100)",
                          "maps.audit(m, rrc_pin.load(\"panda\"), 3)")  # fmt: skip
    namespace: dict = {}
    exec(compile(block, "README.md", "exec"), namespace)
    assert namespace["q"].samples.shape == (2,) and namespace["report"].confirmed == 1.0
    assert namespace["c"].frames == ("left/panda_hand_tcp", "right/panda_hand_tcp")
