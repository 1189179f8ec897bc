"""synthetic_stream: the recording has the rate, noise, dropouts and jumps asked."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.control.synthetic_stream import Jump, device_pose, synthetic_stream


def test_the_recording_is_what_was_asked():
    rec = synthetic_stream(5.0, 90.0, seed=4, noise=1e-3, dropouts=[(1.0, 1.5)],
                           jumps=[Jump(2.0, (0.3, 0.0, 0.0), 3), Jump(4.0, (0.0, 0.1, 0.0))])
    gaps = np.diff(rec.times)
    assert gaps.min() == pytest.approx(1 / 90) and gaps.max() == pytest.approx(0.5 + 1 / 90,
                                                                                abs=1 / 90)
    assert not ((rec.times >= 1.0) & (rec.times < 1.5)).any()
    offset = rec.poses[:, :3, 3] - rec.truth[:, :3, 3]
    glitch = np.flatnonzero(np.abs(offset[:, 0] - 0.3) < 0.01)
    assert len(glitch) == 3 and rec.times[glitch[0]] >= 2.0
    assert (np.abs(offset[rec.times >= 4.0, 1] - 0.1) < 0.01).all()
    quiet = rec.times < 1.0
    assert offset[quiet].std() == pytest.approx(1e-3, rel=0.1)
    for truth, t in zip(rec.truth[:5], rec.times[:5], strict=True):
        np.testing.assert_allclose(truth, device_pose(t), atol=1e-15)
    turned = [np.linalg.norm(pin.log3(p[:3, :3] @ q[:3, :3].T)) for p, q in zip(
        rec.poses, rec.truth, strict=True)]  # fmt: skip
    assert 0.0 < np.median(turned) < 0.01
    again = synthetic_stream(5.0, 90.0, seed=4, noise=1e-3, dropouts=[(1.0, 1.5)],
                             jumps=[Jump(2.0, (0.3, 0.0, 0.0), 3), Jump(4.0, (0.0, 0.1, 0.0))])
    np.testing.assert_array_equal(again.poses, rec.poses)  # seeded


def test_bad_arguments_are_refused_by_name():
    for kwargs, argument in [({"seconds": 0.0}, "seconds"), ({"rate": -1.0}, "rate"),
                             ({"noise": -1.0}, "noise")]:  # fmt: skip
        with pytest.raises(rrc_pin.InvalidInput) as info:
            synthetic_stream(**{"seconds": 1.0, **kwargs})
        assert info.value.argument == argument
    with pytest.raises(rrc_pin.InvalidInput):
        synthetic_stream(1.0, jumps=[Jump(0.5, (0.1, 0.0))])  # type: ignore[arg-type]
