"""Denavit-Hartenberg conventions of the papers, and a chain product independent of Pinocchio.

Three conventions, each a 4x4 link transform from frame i to frame i-1:

- ``standard`` (Barker eq. (1), the 3R exam): ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``; joint i
  moves about/along ``z_{i-1}``.
- ``modified`` (Craig; Nguyen eq. (2)): ``Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)``;
  joint i moves about/along ``z_i``.
- ``nadkarni`` (Nadkarni eqs. (2-1) to (2-9)): ``X_{x(i-1)} = U_i (V_i X_{x(i)} + S_i)`` with the
  intermediate frame ``x*(i)`` (origin on joint axis i, x along normal i). Its matrix (2-7) is
  the standard one; it adds the ``x*`` frames and screw joints.

Joint kinds: ``revolute`` (theta = theta0 + q), ``prismatic`` (d = d0 + q) and ``screw``
(theta = theta0 + q, d = d0 + pitch q; Nadkarni chapter II).

The chain product gives forward kinematics and the geometric (cross-product, Nguyen
eqs. (13)-(17)) Jacobian: the project's second reference, beside Pinocchio.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_vector
from rrc_pin.solvers.spatial import Reference, check_reference, from_world_aligned

Convention = Literal["standard", "modified", "nadkarni"]
JointKind = Literal["revolute", "prismatic", "screw"]
CONVENTIONS: tuple[str, ...] = ("standard", "modified", "nadkarni")
JOINT_KINDS: tuple[str, ...] = ("revolute", "prismatic", "screw")

Matrix4 = npt.NDArray[np.float64]


def rot_x(angle: float) -> Matrix4:
    """Homogeneous rotation about x by ``angle`` [rad]."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def rot_z(angle: float) -> Matrix4:
    """Homogeneous rotation about z by ``angle`` [rad]."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def translation(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Matrix4:
    """Homogeneous translation by (x, y, z) [m]."""
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


@dataclass(frozen=True)
class DHRow:
    """One joint of a DH table, in SI units.

    Attributes:
        a: Common normal length [m] (``a_i``; ``a_{i-1}`` in the modified convention).
        alpha: Twist [rad] (``alpha_i``; ``alpha_{i-1}`` in the modified convention).
        d: Offset along the joint axis at q = 0 [m] (Barker's and Nadkarni's ``r_i``).
        theta: Angle about the joint axis at q = 0 [rad] (Barker's ``theta'_i - theta_i``).
        kind: ``revolute``, ``prismatic`` or ``screw``.
        pitch: Screw pitch [m/rad]; only for ``screw`` joints.
    """

    a: float
    alpha: float
    d: float
    theta: float
    kind: JointKind = "revolute"
    pitch: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in JOINT_KINDS:
            raise InvalidInput(
                "kind", f"expected one of {', '.join(JOINT_KINDS)}, got {self.kind!r}"
            )
        if self.kind != "screw" and self.pitch != 0.0:
            raise InvalidInput("pitch", f"only screw joints have a pitch, this is {self.kind}")

    def joint_values(self, q: float) -> tuple[float, float]:
        """Return (theta, d) at joint position ``q`` [rad or m]."""
        if self.kind == "revolute":
            return self.theta + q, self.d
        if self.kind == "prismatic":
            return self.theta, self.d + q
        return self.theta + q, self.d + self.pitch * q


def link_transform(row: DHRow, q: float, convention: Convention) -> Matrix4:
    """Transform from frame i to frame i-1 (a point in frame i to frame i-1), shape (4, 4).

    Barker eq. (1) / Nadkarni eq. (2-7) for ``standard`` and ``nadkarni``; Nguyen eq. (2) for
    ``modified``.
    """
    theta, d = row.joint_values(q)
    if convention == "modified":
        return rot_x(row.alpha) @ translation(x=row.a) @ rot_z(theta) @ translation(z=d)
    if convention == "standard":
        return rot_z(theta) @ translation(z=d) @ translation(x=row.a) @ rot_x(row.alpha)
    return nadkarni_link(row, q)[1]


def nadkarni_link(row: DHRow, q: float) -> tuple[Matrix4, Matrix4]:
    """Nadkarni's frames of link i in frame x(i-1): (x*(i), x(i)), each (4, 4).

    ``x*(i) = [U_i | (0, 0, r_i)]`` by eq. (2-3) and ``x(i) = x*(i) [V_i | (a_i, 0, 0)]`` by
    eq. (2-1); together eq. (2-5), ``X_{x(i-1)} = U_i (V_i X_{x(i)} + S_i)``.
    """
    theta, r = row.joint_values(q)
    c, s = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(row.alpha), np.sin(row.alpha)
    U = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # eq. (2-4)
    V = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])  # eq. (2-2)
    x_star = np.eye(4)
    x_star[:3, :3] = U
    x_star[:3, 3] = (0.0, 0.0, r)
    x_frame = np.eye(4)
    x_frame[:3, :3] = U @ V
    x_frame[:3, 3] = U @ np.array([row.a, 0.0, r])  # U_i S_i, eq. (2-6)
    return x_star, x_frame


def nadkarni_star_transform(previous: DHRow, row: DHRow, q: float) -> Matrix4:
    """Pose (4, 4) of x*(i) in x*(i-1): Nadkarni eq. (2-8), ``V_{i-1} [U_i X + T_i]``.

    ``T_i = (a_{i-1}, 0, r_i)``: the printed eq. (2-9) reads ``a_i`` (docs/errata.md). The
    normal length in T must be the previous link's, because x*(i-1) and x(i-1) are a_{i-1}
    apart along their common x axis (eq. (2-1)), and ``V_{i-1}`` leaves that axis fixed.

    Args:
        previous: Row i-1 (its ``alpha`` and ``a`` place x(i-1) in x*(i-1)).
        row: Row i.
        q: Position of joint i [rad or m].
    """
    theta, r = row.joint_values(q)
    c, s = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(previous.alpha), np.sin(previous.alpha)
    U = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    V = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    T = np.eye(4)
    T[:3, :3] = V @ U
    T[:3, 3] = V @ np.array([previous.a, 0.0, r])
    return T


@dataclass(frozen=True)
class DHChain:
    """A serial arm as a DH table plus fixed base and tool transforms.

    Attributes:
        convention: ``standard``, ``modified`` or ``nadkarni``.
        rows: One :class:`DHRow` per joint, base to tip.
        base: (4, 4) pose of DH frame 0 in the base frame.
        tool: (4, 4) pose of the tool frame in the last DH frame.
        extra_frames: Named (4, 4) poses fixed to the tool frame (e.g. Barker's ``flange``).
    """

    convention: Convention
    rows: tuple[DHRow, ...]
    base: tuple[tuple[float, ...], ...] = field(default_factory=lambda: _as_tuple(np.eye(4)))
    tool: tuple[tuple[float, ...], ...] = field(default_factory=lambda: _as_tuple(np.eye(4)))
    extra_frames: tuple[tuple[str, tuple[tuple[float, ...], ...]], ...] = ()

    def __post_init__(self) -> None:
        if self.convention not in CONVENTIONS:
            raise InvalidInput(
                "convention", f"expected one of {', '.join(CONVENTIONS)}, got {self.convention!r}"
            )
        if not self.rows:
            raise InvalidInput("rows", "a chain needs at least one joint")

    @property
    def nq(self) -> int:
        """Number of joints."""
        return len(self.rows)

    def frames(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Poses of DH frames 0..n in the base frame, shape (n + 1, 4, 4).

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        q = as_vector(q, "q", self.nq)
        out = np.empty((self.nq + 1, 4, 4))
        out[0] = np.asarray(self.base)
        for i, row in enumerate(self.rows):
            out[i + 1] = out[i] @ link_transform(row, q[i], self.convention)
        return out

    def fk(self, q: npt.ArrayLike) -> Matrix4:
        """Tool pose in the base frame, shape (4, 4)."""
        T: Matrix4 = self.frames(q)[-1] @ np.asarray(self.tool)
        return T

    def joint_axes(
        self, q: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Unit axis and a point on the axis of every joint, base frame: two (nq, 3) arrays."""
        F = self.frames(q)
        # standard/nadkarni: joint i moves about z_{i-1}; modified: about z_i.
        on_axis = F[1:] if self.convention == "modified" else F[:-1]
        return on_axis[:, :3, 2].copy(), on_axis[:, :3, 3].copy()

    def jacobian(
        self, q: npt.ArrayLike, ref: Reference = "world_aligned"
    ) -> npt.NDArray[np.float64]:
        """Geometric Jacobian of the tool frame by cross products (Nguyen eqs. (13)-(17)).

        Column i is ``[b_i x (p - o_i) + pitch_i b_i; b_i]`` for revolute and screw joints and
        ``[b_i; 0]`` for prismatic ones, with ``b_i`` the joint axis and ``o_i`` a point on it.

        Args:
            q: Joint positions (nq,).
            ref: ``world_aligned``, ``local`` or ``world`` (see :mod:`rrc_pin.solvers.spatial`).

        Returns:
            (6, nq) array, rows [v; w].
        """
        ref = check_reference(ref)
        axes, points = self.joint_axes(q)
        T = self.fk(q)
        p = T[:3, 3]
        J = np.zeros((6, self.nq))
        for i, row in enumerate(self.rows):
            if row.kind == "prismatic":
                J[:3, i] = axes[i]
            else:
                J[:3, i] = np.cross(axes[i], p - points[i]) + row.pitch * axes[i]
                J[3:, i] = axes[i]
        return from_world_aligned(J, T[:3, :3], p, ref)

    def extra_frame(self, name: str) -> Matrix4:
        """Pose (4, 4) of a named extra frame in the tool frame."""
        for frame_name, pose in self.extra_frames:
            if frame_name == name:
                return np.asarray(pose)
        raise InvalidInput(
            "name", f"no extra frame {name!r}; have {[n for n, _ in self.extra_frames]}"
        )


def _as_tuple(T: npt.ArrayLike) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(x) for x in r) for r in np.asarray(T, dtype=float))


def pose(T: npt.ArrayLike) -> tuple[tuple[float, ...], ...]:
    """Freeze a (4, 4) array into nested tuples for a frozen :class:`DHChain` field."""
    return _as_tuple(T)
