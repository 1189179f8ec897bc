"""The compiled relative rows against the plain formula (RelativeFrameTask's docstring)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rrc_pin.tasks.relative_frame_kernels import relative_rows


def _reference(Ja: np.ndarray, Jb: np.ndarray, Ta: np.ndarray, Tb: np.ndarray,
               target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    Rt = Ta[:3, :3].T
    d = Tb[:3, 3] - Ta[:3, 3]
    D = Jb - Ja
    J = np.vstack([Rt @ (D[:3] + pin.skew(d) @ Ja[3:]), Rt @ D[3:]])
    error = np.concatenate([target[:3, 3] - Rt @ d,
                            pin.log3(target[:3, :3] @ (Rt @ Tb[:3, :3]).T)])  # fmt: skip
    return J, error


def _pose(rng: np.random.Generator, angle: float) -> np.ndarray:
    axis = rng.normal(size=3)
    return pin.SE3(pin.exp3(axis / np.linalg.norm(axis) * angle), rng.normal(size=3)).homogeneous


def test_rows_and_error_as_the_formula() -> None:
    """The error's turns up to 2.5 rad: nearer pi the logarithm's conditioning turns the
    products' last bits into 1e-12 (log3 itself: tests/test_exp_log.py, to pi)."""
    rng = np.random.default_rng(11)
    for k in range(300):
        nv = 1 + k % 14
        Ja, Jb = rng.normal(size=(6, nv)), rng.normal(size=(6, nv))
        Ta, Tb = _pose(rng, rng.uniform(0.0, np.pi)), _pose(rng, rng.uniform(0.0, np.pi))
        turn = 1e-6 if k % 2 else rng.uniform(0.0, 2.5)  # held (a small error), or not
        target = np.linalg.inv(Ta) @ Tb @ _pose(rng, turn)
        J, error = np.empty((6, nv)), np.empty(6)
        relative_rows(Ja, Jb, Ta, Tb, target, J, error)
        want_J, want_error = _reference(Ja, Jb, Ta, Tb, target)
        np.testing.assert_allclose(J, want_J, rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(error, want_error, rtol=0.0, atol=1e-12)


def test_without_target_the_error_untouched() -> None:
    Ja, Jb = np.ones((6, 3)), np.zeros((6, 3))
    error = np.full(6, 7.0)
    relative_rows(Ja, Jb, np.eye(4), np.eye(4), np.zeros((0, 4)), np.empty((6, 3)), error)
    assert (error == 7.0).all()
