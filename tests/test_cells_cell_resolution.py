"""CellResolution: the resolver's answer, the rates applied, each held object's hands."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cells import CellController
from rrc_pin.cells.cell_resolution import CellResolution
from rrc_pin.solvers.tick.statuses import scale_and_veer


def test_a_tick_reports_its_applied_rates_and_its_hands(dual):
    """The configuration moves by ``applied`` (the resolver's rates and the closure's
    correction); the tasks list the object, then both hands at level 0, then the posture;
    each hand's command is the object's twist carried to it, met as the object's is."""
    ctl = CellController(dual, 0.01)
    ctl.step({"object": [0.02, 0.0, 0.01, 0.0, 0.1, 0.0]})
    q = ctl.q
    step = ctl.step({"object": [0.02, 0.0, 0.01, 0.0, 0.1, 0.0]})
    r = step.resolution
    assert isinstance(r, CellResolution)
    np.testing.assert_allclose(step.q, dual.integrate(q, r.applied, 0.01), atol=1e-15)
    np.testing.assert_allclose(r.correction, r.applied - r.qdot, atol=0.0)
    assert 0.0 < np.abs(r.correction).max() < 0.1 * dual.velocity_limit.min()
    assert not r.applied.flags.writeable
    names = [(t.name, t.level) for t in r.tasks]
    assert names == [("object", 0), ("left/tool", 0), ("right/tool", 0), ("posture", 1)]
    obj = r.tasks[0]
    T_obj = dual.fk(q, "object")
    for report in r.tasks[1:3]:
        T = dual.fk(q, report.name)
        v, w = obj.commanded[:3], obj.commanded[3:]
        carried = np.concatenate([v + np.cross(w, T[:3, 3] - T_obj[:3, 3]), w])
        np.testing.assert_allclose(report.commanded, carried, atol=1e-12)
        np.testing.assert_allclose(report.achieved,
                                   dual.jacobian(q, "world_aligned", report.name) @ r.qdot,
                                   atol=1e-12)  # fmt: skip
        assert report.scale == pytest.approx(obj.scale, abs=1e-9)
        assert scale_and_veer(report.achieved, report.commanded)[1] < 1e-6


def test_free_hands_are_the_resolvers_tasks_alone(dual):
    """No held object: the report is the resolver's (each hand its own task already)."""
    cell = rrc_pin.cells.make_cell(
        {k: (a.robot, a.base) for k, a in dual.arms.items()}, name="free",
        ready={k: dual.ready()[a.q] for k, a in dual.arms.items()},
    )  # fmt: skip
    ctl = CellController(cell, 0.01)
    r = ctl.step({"left": [0.01, 0, 0, 0, 0, 0], "right": np.zeros(6)}).resolution
    assert [t.name for t in r.tasks] == ["left", "right", "posture"]
    np.testing.assert_array_equal(r.applied, r.qdot)  # no closed chain: no correction
