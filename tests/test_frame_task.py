"""rrc_pin.tasks.frame_task: the selected rows of a frame's Jacobian.

Against ``J[list(selected)]`` (bitwise, the same layout) for every named selection and index
lists consecutive or not, on C- and Fortran-ordered Jacobians.
"""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin import FrameTask
from rrc_pin.tasks.frame_task import ROWS


@pytest.mark.parametrize("rows", [*ROWS, (0, 2, 4), (1, 2), (5,), (4, 3)])
@pytest.mark.parametrize("order", ["C", "F"])
def test_rows_from_are_the_selected_rows_of_the_jacobian(rows, order):
    J = np.asarray(np.random.default_rng(7).normal(size=(6, 9)), order=order)
    task = FrameTask("tool", rows=rows)
    got = task.rows_from(J, np.zeros(len(task.selected)), 1.5).A
    want = J[list(task.selected)] if len(task.selected) != 6 else J
    np.testing.assert_array_equal(got, want)
    assert got.strides == want.strides
    if len(task.selected) != 6:
        assert not np.shares_memory(got, J)
