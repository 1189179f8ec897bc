"""DH conventions and the chain product (the second reference, independent of Pinocchio)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rrc_pin.dh import (
    DHChain,
    DHRow,
    link_transform,
    nadkarni_link,
    nadkarni_star_transform,
    rot_x,
    rot_z,
    translation,
)
from rrc_pin.errors import InvalidInput


def random_row(rng: np.random.Generator, kind: str = "revolute") -> DHRow:
    return DHRow(
        a=rng.uniform(-1, 1),
        alpha=rng.uniform(-np.pi, np.pi),
        d=rng.uniform(-1, 1),
        theta=rng.uniform(-np.pi, np.pi),
        kind=kind,
        pitch=rng.uniform(-0.2, 0.2) if kind == "screw" else 0.0,
    )


def test_standard_matrix_is_barker_eq_1(rng):
    row = random_row(rng)
    q = rng.uniform(-3, 3)
    th, a, al, r = row.theta + q, row.a, row.alpha, row.d
    barker_eq_1 = np.array(
        [
            [np.cos(th), -np.cos(al) * np.sin(th), np.sin(al) * np.sin(th), a * np.cos(th)],
            [np.sin(th), np.cos(al) * np.cos(th), -np.sin(al) * np.cos(th), a * np.sin(th)],
            [0, np.sin(al), np.cos(al), r],
            [0, 0, 0, 1],
        ]
    )
    np.testing.assert_allclose(link_transform(row, q, "standard"), barker_eq_1, atol=1e-15)


def test_modified_matrix_is_nguyen_eq_2(rng):
    row = random_row(rng)
    q = rng.uniform(-3, 3)
    th, a, al, d = row.theta + q, row.a, row.alpha, row.d
    nguyen_eq_2 = np.array(
        [
            [np.cos(th), -np.sin(th), 0, a],
            [np.sin(th) * np.cos(al), np.cos(th) * np.cos(al), -np.sin(al), -d * np.sin(al)],
            [np.sin(th) * np.sin(al), np.cos(th) * np.sin(al), np.cos(al), d * np.cos(al)],
            [0, 0, 0, 1],
        ]
    )
    np.testing.assert_allclose(link_transform(row, q, "modified"), nguyen_eq_2, atol=1e-15)


@pytest.mark.parametrize("kind", ["revolute", "prismatic", "screw"])
def test_nadkarni_eq_2_5_equals_standard_matrix_eq_2_7(rng, kind):
    for _ in range(50):
        row = random_row(rng, kind)
        q = rng.uniform(-2, 2)
        x_star, x_frame = nadkarni_link(row, q)
        np.testing.assert_allclose(x_frame, link_transform(row, q, "standard"), atol=1e-14)
        # x*(i) sits on joint axis i (the z axis of x(i-1)) and its x axis is the normal a_i.
        np.testing.assert_allclose(x_star[:2, 3], 0.0, atol=1e-15)
        np.testing.assert_allclose(
            x_frame[:3, 3] - x_star[:3, 3], row.a * x_star[:3, 0], atol=1e-14
        )


@pytest.mark.parametrize("kind", ["revolute", "prismatic", "screw"])
def test_nadkarni_eq_2_8_with_a_i_minus_1_chains_the_star_frames(rng, kind):
    """x*(i) in x*(i-1) by eq. (2-8) equals the product through x(i-1); T_i holds a_{i-1}."""
    for _ in range(50):
        previous, row = random_row(rng, "revolute"), random_row(rng, kind)
        q_prev, q = rng.uniform(-2, 2, 2)
        star_prev, x_prev = nadkarni_link(previous, q_prev)
        star, _ = nadkarni_link(row, q)
        expected = np.linalg.inv(star_prev) @ x_prev @ star
        np.testing.assert_allclose(nadkarni_star_transform(previous, row, q), expected, atol=1e-14)
        # As printed (T_i = (a_i, 0, r_i)) it is wrong whenever a_i != a_{i-1}.
        printed = nadkarni_star_transform(replace(previous, a=row.a), row, q)
        assert np.abs(printed - expected).max() > 1e-6


def test_joint_kinds_move_the_right_parameter():
    row = DHRow(a=0.1, alpha=0.2, d=0.3, theta=0.4, kind="screw", pitch=0.05)
    assert row.joint_values(2.0) == pytest.approx((2.4, 0.4))
    assert DHRow(0.1, 0.2, 0.3, 0.4, "prismatic").joint_values(2.0) == pytest.approx((0.4, 2.3))
    assert DHRow(0.1, 0.2, 0.3, 0.4).joint_values(2.0) == pytest.approx((2.4, 0.3))


@pytest.mark.parametrize("convention", ["standard", "modified", "nadkarni"])
def test_cross_product_jacobian_matches_finite_differences(rng, convention):
    kinds = ["revolute", "prismatic", "screw", "revolute", "revolute", "prismatic"]
    chain = DHChain(
        convention,
        tuple(random_row(rng, k) for k in kinds),
        base=tuple(map(tuple, rot_x(0.3) @ translation(0.1, 0.2, 0.3))),
        tool=tuple(map(tuple, rot_z(0.7) @ translation(0.0, 0.1, 0.05))),
    )
    h = 1e-6
    for _ in range(20):
        q = rng.uniform(-2, 2, chain.nq)
        T = chain.fk(q)
        J = chain.jacobian(q)
        for i in range(chain.nq):
            dq = np.zeros(chain.nq)
            dq[i] = h
            dT = (chain.fk(q + dq) - chain.fk(q - dq)) / (2 * h)
            W = dT[:3, :3] @ T[:3, :3].T
            np.testing.assert_allclose(J[:3, i], dT[:3, 3], atol=1e-8)
            np.testing.assert_allclose(J[3:, i], [W[2, 1], W[0, 2], W[1, 0]], atol=1e-8)


def test_frames_start_at_base_and_end_before_tool(rng):
    base = rot_z(0.5) @ translation(1, 2, 3)
    chain = DHChain(
        "standard",
        (random_row(rng), random_row(rng)),
        base=tuple(map(tuple, base)),
        tool=tuple(map(tuple, translation(z=0.2))),
    )
    q = rng.uniform(-1, 1, 2)
    F = chain.frames(q)
    np.testing.assert_allclose(F[0], base)
    np.testing.assert_allclose(chain.fk(q), F[-1] @ translation(z=0.2))


def test_bad_input_names_the_argument():
    chain = DHChain("standard", (DHRow(0.1, 0.0, 0.0, 0.0),))
    with pytest.raises(InvalidInput, match="^q:"):
        chain.fk([0.0, 1.0])
    with pytest.raises(InvalidInput, match="^q:.*non-finite"):
        chain.jacobian([np.nan])
    with pytest.raises(ValueError, match="^ref:"):
        chain.jacobian([0.0], ref="tool")
    with pytest.raises(InvalidInput, match="^convention:"):
        DHChain("craig", (DHRow(0.1, 0.0, 0.0, 0.0),))  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="^kind:"):
        DHRow(0.1, 0.0, 0.0, 0.0, kind="helical")  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="^pitch:"):
        DHRow(0.1, 0.0, 0.0, 0.0, kind="revolute", pitch=0.1)
