"""The screw of a finite displacement (Nadkarni ch. III): Illustration 1, round trips, errata."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance import (
    displacement,
    frames_from_points,
    screw_from_points,
    screw_from_poses,
    screw_of_displacement,
    screw_twist,
)

# Appendix II, Illustration 1 (Table A2-1): three positions of a body, three points each, as
# printed with two decimals (thesis units).
POSITIONS = np.array(
    [
        [[25.00, 0.00, 20.00], [30.00, 0.00, 20.00], [25.00, 0.00, 10.00]],
        [[-20.30, -7.83, -6.66], [-20.65, -8.29, -5.85], [-21.06, -7.18, -6.62]],
        [[-24.50, 5.30, 4.00], [-24.67, 5.47, 4.97], [-25.00, 6.00, 4.00]],
    ]
)
# The printed screws (u, rho_n, d, theta [deg], h), as strings to keep their digits.
PRINTED = {
    (0, 1): (
        ("0.5699", "-0.4433", "0.6918"),
        ("-1.758", "-0.762", "0.960"),
        "-40.79",
        "176.36",
        "-13.25",
    ),
    (1, 2): (
        ("0.8381", "-0.3386", "0.4276"),
        ("5.942", "6.862", "-6.212"),
        "-3.407",
        "-40.54",
        "4.815",
    ),
}
# Points within the rounding of the printed inputs (each coordinate moved by less than 0.005) from
# which every printed output follows to its last digit: found by bounded least squares
# (scipy.optimize.least_squares, 18 unknowns, residuals in half-units of the last printed digit).
WITNESS = {
    (0, 1): [
        [[0.0004484, 0.0040255, -0.0017919], [-0.0049999, 0.0004505, -0.0001687],
         [-0.0049995, -0.0003416, 0.0049982]],
        [[-0.0014601, -0.0010951, -0.001101], [0.0020212, 0.0006529, 0.0009529],
         [-0.0006361, -0.0006721, -0.0006531]],
    ],
    (1, 2): [
        [[0.0028684, 0.0037259, -8.1e-06], [0.005, 0.0008447, 7.56e-05],
         [0.0006517, 0.0010164, 0.000818]],
        [[0.0024097, 0.0014438, 0.0010448], [0.0006395, 0.0001106, -0.0049991],
         [0.0016177, -0.0030267, -1.4e-06]],
    ],
}  # fmt: skip


def flat(s):
    """u, rho, d, theta [deg], h of a screw as one vector (the printed order)."""
    scalars = np.stack([s.d, np.degrees(s.theta), s.h], axis=-1)
    return np.concatenate([s.u, s.rho, scalars], axis=-1)


def printed_vector(key):
    u, rho, d, theta, h = PRINTED[key]
    text = [*u, *rho, d, theta, h]
    values = np.array([float(t) for t in text])
    half_unit = np.array([0.5 * 10.0 ** -len(t.split(".")[1]) for t in text])
    return values, half_unit


@pytest.mark.parametrize("key", list(PRINTED))
def test_illustration_1_within_the_rounding_envelope(key):
    """Every printed number lies in the range that the inputs' rounding (+-0.005) spans, and one
    choice of points inside that rounding reproduces all of them to their last digit together."""
    a, b = key
    values, half_unit = printed_vector(key)
    nominal = flat(screw_from_points(POSITIONS[a], POSITIONS[b]))
    assert np.abs(nominal - values).max() < 0.2  # close, but not to the printed digits:
    assert np.any(np.abs(nominal - values) > half_unit)  # the rounding of the input shows
    rng = np.random.default_rng(7)
    jitter = rng.uniform(-0.005, 0.005, size=(4000, 2, 3, 3))
    cloud = flat(screw_from_points(POSITIONS[a] + jitter[:, 0], POSITIONS[b] + jitter[:, 1]))
    assert np.all(cloud.min(axis=0) <= values) and np.all(values <= cloud.max(axis=0))
    delta = np.asarray(WITNESS[key])
    assert np.abs(delta).max() <= 0.005
    witness = flat(screw_from_points(POSITIONS[a] + delta[0], POSITIONS[b] + delta[1]))
    assert np.all(np.abs(witness - values) <= half_unit), (witness - values) / half_unit


def random_rotations(rng, n):
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


def half_turns(axes):
    axes = axes / np.linalg.norm(axes, axis=-1, keepdims=True)
    return 2.0 * axes[..., :, None] * axes[..., None, :] - np.eye(3)


def special_displacements(rng, n):
    """General, pure translations, half turns, rotations about axes through the origin, identity,
    and axes in the planes u3 = 0 and u1 = u3 = 0 (eqs (3-31)-(3-36))."""
    Q = [
        random_rotations(rng, n),
        np.broadcast_to(np.eye(3), (n, 3, 3)),
        half_turns(rng.normal(size=(n, 3))),
        random_rotations(rng, n),
        np.eye(3)[None],
        half_turns(np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 2.0, 0.0]])),
    ]
    q = [rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=(n, 3)),
         np.zeros((n, 3)), np.zeros((1, 3)), rng.normal(size=(3, 3))]  # fmt: skip
    x_turn = np.array(
        [
            [[1.0, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]]
            for t in rng.uniform(-3, 3, 5)
        ]
    )
    y_turn = np.array([[[np.cos(t), 0, np.sin(t)], [0, 1.0, 0], [-np.sin(t), 0, np.cos(t)]]
                       for t in rng.uniform(-3, 3, 5)])  # fmt: skip
    Q += [x_turn, y_turn]
    q += [rng.normal(size=(5, 3)), rng.normal(size=(5, 3))]
    return np.concatenate(Q), np.concatenate(q)


def test_round_trip_random_and_special_displacements_to_1e_12(rng):
    Q, q = special_displacements(rng, 200)
    s = screw_of_displacement(Q, q)
    T = displacement(s)
    np.testing.assert_allclose(T[:, :3, :3], Q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(T[:, :3, 3], q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(s.u, axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.sum(s.u * s.rho, axis=1), 0.0, atol=1e-12)  # eq. (3-40)
    assert np.all((-np.pi < s.theta) & (s.theta <= np.pi))
    assert np.all(np.isfinite(s.rho)) and not np.any(np.isnan(s.h))
    pure = np.all(np.abs(Q - np.eye(3)) == 0.0, axis=(1, 2)) & (np.linalg.norm(q, axis=1) > 0)
    assert np.all(np.isinf(s.h[pure])) and np.all(s.d[pure] > 0)  # eq. (3-29), infinite pitch
    np.testing.assert_allclose(s.u[pure], q[pure] / np.linalg.norm(q[pure], axis=1)[:, None])
    turned = ~pure & (np.abs(s.theta) > 0)
    assert np.all(  # the thesis's sign of u: u3 > 0, else u1 > 0, else u2 > 0
        (s.u[turned, 2] > 1e-12)
        | ((np.abs(s.u[turned, 2]) <= 1e-12) & (s.u[turned, 0] > 1e-12))
        | (
            (np.abs(s.u[turned, 2]) <= 1e-12)
            & (np.abs(s.u[turned, 0]) <= 1e-12)
            & (s.u[turned, 1] > 0)
        )
    )


def test_agrees_with_pinocchio_log6(rng):
    Q, q = special_displacements(rng, 40)
    s = screw_of_displacement(Q, q)
    twist = screw_twist(s)
    for i in range(len(Q)):
        M = pin.SE3(Q[i], q[i])
        log = pin.log6(M).vector  # [v; w]
        if np.pi - abs(s.theta[i]) > 1e-6:
            np.testing.assert_allclose(twist[i], log, atol=1e-12)
        else:  # a half turn: +u and -u are the same displacement, log6 may pick either
            np.testing.assert_allclose(pin.exp6(twist[i]).homogeneous, M.homogeneous, atol=1e-12)


def test_poses_and_points_give_the_same_screw(rng):
    R = random_rotations(rng, 2)
    T = np.tile(np.eye(4), (2, 1, 1))
    T[:, :3, :3], T[:, :3, 3] = R, rng.normal(size=(2, 3))
    points = np.stack([T[:, :3, 3], T[:, :3, 3] + 2 * R[:, :, 2], T[:, :3, 3] + 3 * R[:, :, 0]], 1)
    np.testing.assert_allclose(frames_from_points(points), T, atol=1e-14)
    a, b = screw_from_poses(T[0], T[1]), screw_from_points(points[0], points[1])
    np.testing.assert_allclose(flat(a), flat(b), atol=1e-12)
    D = displacement(a)
    np.testing.assert_allclose(D @ T[0], T[1], atol=1e-12)
    c = screw_from_poses(pin.SE3(T[0]), pin.SE3(T[1]))  # pinocchio's SE3 too
    np.testing.assert_allclose(flat(c), flat(a), atol=1e-14)


def thesis_matrices(key):
    T1, T2 = frames_from_points(POSITIONS[key[0]]), frames_from_points(POSITIONS[key[1]])
    Q = T2[:3, :3] @ T1[:3, :3].T  # eq. (3-13a)
    q = T2[:3, 3] - Q @ T1[:3, 3]  # eq. (3-13b)
    return Q, q


@pytest.mark.parametrize("key", list(PRINTED))
def test_thesis_equations_3_27_3_41_3_50_3_52_hold(key):
    Q, q = thesis_matrices(key)
    s = screw_of_displacement(Q, q)
    u = s.u
    # eq. (3-27): u1' = u1/u3, u2' = u2/u3 from rows a and b; eq. (3-28) with the square root
    A = np.array([[Q[0, 0] - 1, Q[1, 0]], [Q[0, 1], Q[1, 1] - 1]])
    u1p, u2p = np.linalg.solve(A, [-Q[2, 0], -Q[2, 1]])
    u3 = 1.0 / np.sqrt(u1p**2 + u2p**2 + 1.0)
    np.testing.assert_allclose([u1p * u3, u2p * u3, u3], u, atol=1e-12)
    # eq. (3-41): the 4 x 4 system for rho_n and d
    M = np.zeros((4, 4))
    M[:3, :3], M[:3, 3], M[3, :3] = Q - np.eye(3), -u, u
    np.testing.assert_allclose(np.linalg.solve(M, [*-q, 0.0]), [*s.rho, s.d], atol=1e-10)
    # eqs (3-50), (3-51): cos(theta) three ways; eq. (3-52): sin(theta)
    for i in range(3):
        assert (Q[i, i] - u[i] ** 2) / (1 - u[i] ** 2) == pytest.approx(np.cos(s.theta), abs=1e-12)
    sin = (u[0] * u[1] * (1 - np.cos(s.theta)) - Q[0, 1]) / u[2]
    assert sin == pytest.approx(np.sin(s.theta), abs=1e-12)


def test_erratum_eq_3_28_needs_a_square_root():
    """Printed u3 = 1/(u1'^2 + u2'^2 + 1) is not a unit vector's component."""
    Q, q = thesis_matrices((0, 1))
    u = screw_of_displacement(Q, q).u
    u1p, u2p = u[0] / u[2], u[1] / u[2]
    printed_u3 = 1.0 / (u1p**2 + u2p**2 + 1.0)
    printed_u = printed_u3 * np.array([u1p, u2p, 1.0])
    assert abs(np.linalg.norm(printed_u) - 1.0) > 0.1
    assert 1.0 / np.sqrt(u1p**2 + u2p**2 + 1.0) == pytest.approx(u[2], abs=1e-14)


def test_erratum_eq_3_36_is_the_transpose():
    """For u = (0, 1, 0), Q = [[c, 0, s], [0, 1, 0], [-s, 0, c]]; the printed (3-36) has the
    signs of sin(theta) swapped, which contradicts eq. (3-53), sin(theta) = q13/u2."""
    theta = 0.7
    c, s_ = np.cos(theta), np.sin(theta)
    printed = np.array([[c, 0, -s_], [0, 1, 0], [s_, 0, c]])
    screw = screw_of_displacement(printed, np.zeros(3))
    assert screw.u == pytest.approx([0, 1, 0]) and screw.theta == pytest.approx(-theta)
    corrected = printed.T
    screw = screw_of_displacement(corrected, np.zeros(3))
    assert screw.u == pytest.approx([0, 1, 0]) and screw.theta == pytest.approx(theta)
    assert corrected[0, 2] / screw.u[1] == pytest.approx(np.sin(screw.theta))  # eq. (3-53)


def test_bad_input_names_the_argument():
    good = POSITIONS[0]
    cases = [
        ([[0, 0, 0], [0, 0, 1], [0, 0, 2]], "points_1"),  # collinear
        ([[1, 1, 1], [1, 1, 1], [0, 0, 2]], "points_1"),  # coincident
        ([[0, 0, 0], [0, 0, 1], [np.nan, 0, 2]], "points_1"),  # non-finite
        ([[0, 0, 0], [0, 0, 1]], "points_1"),  # shape
    ]
    for bad, name in cases:
        with pytest.raises(InvalidInput, match=f"^{name}:"):
            screw_from_points(bad, good)
    with pytest.raises(InvalidInput, match="^points_2:"):
        screw_from_points(good, [[0, 0, 0], [0, 0, 0], [1, 0, 0]])
    with pytest.raises(InvalidInput, match="^T2:"):
        screw_from_poses(np.eye(4), 2 * np.eye(4))
    with pytest.raises(InvalidInput, match="^T1:"):
        screw_from_poses(np.full((4, 4), np.inf), np.eye(4))
    with pytest.raises(InvalidInput, match="^Q:"):
        screw_of_displacement(np.ones((3, 3)), np.zeros(3))
    with pytest.raises(InvalidInput, match="^q:"):
        screw_of_displacement(np.eye(3), np.zeros(2))


def test_eqs_3_18_and_3_45_read_as_dot_product_and_norm(rng):
    """The OCR prints (3-18) 'u - X_HO1 = u - X_HO2' and (3-45) 'X_HO1 = X_HO2': they are
    u . X_HO1 = u . X_HO2 (a line of the body keeps its angle with the axis) and
    |X_HO1| = |X_HO2| (the rotation keeps lengths); X_HO1 = X_HO2 holds only on the axis."""
    Q = random_rotations(rng, 1)[0]
    u = screw_of_displacement(Q, np.zeros(3)).u
    x1 = rng.normal(size=3)
    x2 = Q @ x1  # eq. (3-14)
    assert u @ x1 == pytest.approx(u @ x2, abs=1e-12)
    assert np.linalg.norm(x1) == pytest.approx(np.linalg.norm(x2), abs=1e-12)
    assert np.linalg.norm(x1 - x2) > 1e-3
