"""PostureTask: its rows at a configuration, per robot layout."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.tasks import PostureTask


def test_rows_follow_the_layout_and_weight_they_are_asked_with():
    """One task read with layouts of other continuous masks, in turn, and a weight replaced:
    each time the rows are those of a fresh task (its constants kept per layout and weight)."""
    panda = rrc_pin.load("panda")
    plain = Layout.of(panda)
    mask = np.zeros(panda.nv, dtype=bool)
    mask[0] = True
    wrapping = plain._replace(continuous=mask)
    q = np.clip(np.full(panda.nq, -2.5), panda.lower, panda.upper)
    q_ref = q.copy()
    q_ref[0] = q[0] + 4.0  # the short way round for a continuous joint: 4 - 2 pi rad
    task = PostureTask(q_ref, gain=2.0, weight=0.5)
    data = panda.model.createData()
    for layout in (plain, wrapping, plain, wrapping):
        kin = Kinematics(panda.model, data, layout, q, q)
        fresh = PostureTask(q_ref, gain=2.0, weight=task.weight).rows(kin)
        rows = task.rows(kin)
        np.testing.assert_array_equal(rows.b, fresh.b)
        np.testing.assert_array_equal(rows.A, np.eye(panda.nv))
        np.testing.assert_array_equal(rows.weight, fresh.weight)
        turn = 4.0 - 2 * np.pi if layout is wrapping else 4.0
        assert abs(rows.b[0] - 2.0 * turn) < 1e-12
    task.weight = 3.0
    np.testing.assert_array_equal(task.rows(kin).weight, np.full(panda.nv, 3.0))


def test_a_weight_array_is_replaced_not_written():
    """A task's weight array is its own and read-only: its rows are kept per weight, so a
    change of weights is a new array (seen at the next tick), never a write into the old."""
    panda = rrc_pin.load("panda")
    q = panda.neutral()
    task = PostureTask(q, weight=np.ones(panda.nv))
    kin = Kinematics(panda.model, panda.model.createData(), Layout.of(panda), q, q)
    assert task.rows(kin).weight is None  # all ones: the unweighted rows
    with pytest.raises(ValueError, match="read-only"):
        task.weight[0] = 2.0
    task.weight = np.full(panda.nv, 2.0)
    np.testing.assert_array_equal(task.rows(kin).weight, np.full(panda.nv, 2.0))
