"""The IK audit: voxels the map reports reached are reached by resolved-rate IK through the
resolver (within the joint limits), from random starts; on a 7-joint arm too.

The suite audits a seeded choice of 40 voxels per arm to keep its time small; the benchmark
(benchmarks/bench_maps.py) and ``rrc-pin map --audit 1000`` run the 1,000-voxel audit."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("distributed")

import rrc_pin
from rrc_pin import maps
from rrc_pin.errors import InvalidInput
from rrc_pin.maps.audit import AuditReport, boundary

pytestmark = pytest.mark.compiled


@pytest.mark.parametrize(("arm", "voxel"), [("panda", 0.05), ("rrc_k1607", 0.05),
                                            ("kr5_3r", 0.1)])  # fmt: skip
def test_audited_voxels_are_reached_by_ik(arm, voxel):
    robot = rrc_pin.load(arm)
    m = maps.capability(robot, 2**16, voxel, seed=2, dexterity=False, progress=False, workers=2)
    report = maps.audit(m, robot, 40, seed=4)
    assert report.keys.size == 40 and report.confirmed == 1.0, report.failures
    assert np.all(report.distance == 0.0)
    assert repr(report).startswith("AuditReport(40 voxels tried, 40 reached (100.0%), failures []")


def test_a_reports_repr_is_a_one_line_summary_its_arrays_attributes():
    n = 1000
    keys = 3 * np.arange(n, dtype=np.int64)
    reached = np.ones(n, bool)
    reached[[7, 500, 501, 502, 503, 504, 999]] = False
    report = AuditReport(keys, reached, np.arange(n) % 4 + 1, np.full(n, 40), np.zeros(n), 26.0,
                         41_752)  # fmt: skip
    text = repr(report)
    assert "\n" not in text and len(text) < 200
    assert text == ("AuditReport(1,000 voxels tried, 993 reached (99.3%), failures [21, 1500, "
                    "1503, 1506, 1509, ...], starts 2.5 mean, 4 most, 41,752 resolver steps, "
                    "26.0 s)")  # fmt: skip
    assert report.keys is keys and report.failures.tolist() == keys[~reached].tolist()


def test_refine_tries_the_boundary_and_arguments_are_checked():
    robot = rrc_pin.load("kr5_3r")
    m = maps.capability(robot, 2**14, 0.1, seed=2, dexterity=False, progress=False, workers=2)
    edge = boundary(m)
    assert edge.size and not m.reached[edge].any()
    refined = maps.refine(m, robot, 15, seed=1, starts=3, max_steps=60)
    assert refined.keys.size == 15 and set(refined.keys) <= set(edge)
    with pytest.raises(InvalidInput) as err:
        maps.audit(m, rrc_pin.load("panda"), 5)
    assert err.value.argument == "robot"
    with pytest.raises(InvalidInput) as err:
        maps.audit(m, robot, 0)
    assert err.value.argument == "voxels"
