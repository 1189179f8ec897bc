"""Paper arms: Pinocchio (committed URDF) == DH == yourdfpy; Jacobians == cross products == FD."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cross_check import cross_check, finite_difference_jacobians, run_cross_check
from rrc_pin.errors import InvalidInput
from rrc_pin.models import CATALOGUE, barker6
from rrc_pin.urdf_export import COMMITTED_DIR

SAMPLES = 1000


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_committed_urdf_agrees_with_dh_yourdfpy_and_finite_differences(name):
    report = cross_check(
        CATALOGUE[name], SAMPLES, np.random.default_rng(7), COMMITTED_DIR / f"{name}.urdf"
    )
    assert report.samples == SAMPLES
    assert report.fk_dh < 1e-9 and report.fk_yourdfpy < 1e-9, report
    for ref in ("world_aligned", "local", "world"):
        assert report.jacobian_dh[ref] < 1e-9, (ref, report)
        assert report.jacobian_fd[ref] < 1e-6, (ref, report)


def test_barker_variant_alpha3_88_passes_the_same_checks():
    spec = barker6.build(alpha3=np.deg2rad(88), a3=0.02, r3=0.01, name="barker6_variant")
    report = cross_check(spec, SAMPLES, np.random.default_rng(8))
    exact, fd = report.worst()
    assert exact < 1e-9 and fd < 1e-6, report
    # The variant really differs from the nominal arm.
    q = np.full(6, 0.4)
    assert np.abs(spec.chain.fk(q) - CATALOGUE["barker6"].chain.fk(q)).max() > 1e-3


def test_exam_jacobians_at_0_pi4_minus_pi4():
    """Robotics I exam, eq. (2): J_L and J_A at theta = (0, pi/4, -pi/4), to 4 decimals."""
    J = rrc_pin.load("kr5_3r").jacobian([0.0, np.pi / 4, -np.pi / 4])
    J_L = [[0, -0.3536, 0], [1.0536, 0, 0], [0, 0.8536, 0.5]]
    J_A = [[0, 0, 0], [0, -1, -1], [1, 0, 0]]
    np.testing.assert_allclose(J[:3], J_L, atol=5e-5)
    np.testing.assert_allclose(J[3:], J_A, atol=5e-5)


@pytest.mark.parametrize("name", ["panda", "ur5", "kinova", "baxter_left"])
def test_installed_arm_jacobians_match_finite_differences(name, rng):
    arm = rrc_pin.load(name)
    for _ in range(50):
        q = arm.random_q(rng)
        fd = finite_difference_jacobians(arm, q)
        for ref, J_fd in fd.items():
            np.testing.assert_allclose(arm.jacobian(q, ref), J_fd, atol=1e-6)


def test_a_check_of_nothing_is_refused():
    """Issue 18 item 12: ``samples=0`` checked nothing and passed."""
    for samples in (0, -1, 2.5, True):
        with pytest.raises(InvalidInput, match="^samples: expected an integer >= 1"):
            cross_check(CATALOGUE["kr5_3r"], samples, np.random.default_rng(0))
        with pytest.raises(InvalidInput, match="^samples: expected an integer >= 1"):
            run_cross_check(samples)


def test_finite_differences_of_any_frame(rng):
    arm = rrc_pin.load("barker6")
    q = arm.random_q(rng)
    fd = finite_difference_jacobians(arm, q, frame="flange")
    for ref, J_fd in fd.items():
        np.testing.assert_allclose(arm.jacobian(q, ref, frame="flange"), J_fd, atol=1e-6)
    assert (
        np.abs(fd["world_aligned"] - finite_difference_jacobians(arm, q)["world_aligned"]).max()
        > 1e-3
    )
