"""The paper arms' collision capsules, sized from their DH tables.

Each link of a catalogue arm is the chain of its DH offsets: in its URDF link frame (see
:mod:`rrc_pin.urdf_export`) the fixed part of the link transform walks from the link's joint
to the next joint, one straight segment per non-zero offset (``d_i`` along the joint axis, then
``a_i`` along the common normal, standard and Nadkarni conventions; ``a_i`` then ``d_{i+1}`` in
the modified one). Every segment is a capsule of the link's radius
(:attr:`~rrc_pin.models.arm_spec.ArmSpec.collision_radii`, assumed values recorded with the
arm); a link with no offset (a wrist link) is a sphere of that radius at its joint. The last
link goes on to the tool frame and from the tool to each extra frame (Barker's ``flange``: his
hand). The base placement (a paper's world frame) is not a link and carries no capsule.

So the capsule axes pass through every joint origin of the DH chain, at every configuration:
the capsules contain the chain's skeleton, and :func:`always_touching` names the link pairs
that overlap whatever the joints do (a spherical wrist's links 4 and 6), which a collision
check must leave out.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.dh import DHRow, rot_x, rot_z, translation
from rrc_pin.models.arm_spec import ArmSpec

Matrix4 = npt.NDArray[np.float64]
BASE_LINK = "base_link"
SEGMENT_TOL = 1e-12
"""[m] Offsets at most this long make no segment."""


class LinkCapsule(NamedTuple):
    """One collision capsule of a link, in the link's URDF frame.

    Attributes:
        link: URDF link name (``link1`` ... ``link<n>``).
        start: One end of the axis (3,) [m]; the link's joint origin for its first capsule.
        end: The other end (3,) [m]; equal to ``start`` for a sphere.
        radius: Radius [m].
    """

    link: str
    start: tuple[float, float, float]
    end: tuple[float, float, float]
    radius: float

    @property
    def length(self) -> float:
        """Length of the axis [m] (0 for a sphere)."""
        return float(np.linalg.norm(np.subtract(self.end, self.start)))


def link_name(index: int) -> str:
    """URDF name of link ``index`` (1-based; 0 is the base link)."""
    return BASE_LINK if index == 0 else f"link{index}"


def link_paths(spec: ArmSpec) -> list[list[Matrix4]]:
    """Per link 1..n, the factors of its fixed transform, joint to next joint, in order.

    The last link's list ends with the tool pose; the extra frames are not in it (see
    :func:`link_capsules`).
    """
    rows = spec.chain.rows
    paths: list[list[Matrix4]] = []
    for i, row in enumerate(rows):
        if spec.chain.convention == "modified":
            factors = _modified_pre(rows[i + 1]) if i + 1 < len(rows) else []
        else:
            factors = [rot_z(row.theta), translation(z=row.d), translation(x=row.a),
                       rot_x(row.alpha)]  # fmt: skip
        paths.append(factors)
    paths[-1].append(np.asarray(spec.chain.tool, dtype=float))
    return paths


def _modified_pre(row: DHRow) -> list[Matrix4]:
    """Factors of ``Rx(alpha) Tx(a) Rz(theta0) Tz(d0)`` (modified DH, the next row's)."""
    return [rot_x(row.alpha), translation(x=row.a), rot_z(row.theta), translation(z=row.d)]


def _segments(
    factors: list[Matrix4], start: Matrix4
) -> tuple[list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]], Matrix4]:
    """Segments (from, to) walked by ``factors`` from ``start``, and the pose reached."""
    T = start
    out = []
    for F in factors:
        nxt = T @ F
        if np.linalg.norm(nxt[:3, 3] - T[:3, 3]) > SEGMENT_TOL:
            out.append((T[:3, 3].copy(), nxt[:3, 3].copy()))
        T = nxt
    return out, T


def link_capsules(spec: ArmSpec) -> tuple[LinkCapsule, ...]:
    """Every link's capsules (module docstring), link by link; empty without radii.

    Returns:
        Capsules in link order, each in its link's URDF frame; a link without offsets has
        one capsule of zero length (a sphere at its joint).
    """
    radii = spec.collision_radii
    if not radii:
        return ()
    out: list[LinkCapsule] = []
    paths = link_paths(spec)
    for i, factors in enumerate(paths):
        segments, tool = _segments(factors, np.eye(4))
        if i == len(paths) - 1:
            for _, extra in spec.chain.extra_frames:
                segments += _segments([np.asarray(extra, dtype=float)], tool)[0]
        if not segments:
            segments = [(np.zeros(3), np.zeros(3))]
        out += [
            LinkCapsule(link_name(i + 1), _point(a), _point(b), float(radii[i]))
            for a, b in segments
        ]
    return tuple(out)


def _point(p: npt.NDArray[np.float64]) -> tuple[float, float, float]:
    return float(p[0]), float(p[1]), float(p[2])


def always_touching(spec: ArmSpec) -> tuple[tuple[str, str], ...]:
    """Link pairs whose capsules overlap at every configuration: to leave out of a check.

    Links i < j (not adjacent: j > i + 1) both hold a point of the chain between them: link i
    the next joint's origin, link j its own joint's origin. Those points are at most the
    lengths of the links between them apart, plus the travel of the prismatic joints between
    them, so when that bound is no more than the sum of the two radii the capsules touch
    whatever the joints do (Barker's links 4 and 6 meet at the wrist centre).

    Returns:
        ``(link_i, link_j)`` URDF link names, i < j.
    """
    radii = spec.collision_radii
    if not radii:
        return ()
    lengths = [sum(float(np.linalg.norm(b - a)) for a, b in _segments(f, np.eye(4))[0])
               for f in link_paths(spec)[:-1]] + [0.0]  # fmt: skip
    travel = [
        max(abs(lo), abs(hi)) if row.kind != "revolute" else 0.0
        for row, lo, hi in zip(spec.chain.rows, spec.lower, spec.upper, strict=True)
    ]
    n = spec.nq
    pairs = []
    for i in range(n):
        for j in range(i + 2, n):
            bound = sum(lengths[i + 1 : j]) + sum(travel[i + 1 : j + 1])
            if bound <= radii[i] + radii[j]:
                pairs.append((link_name(i + 1), link_name(j + 1)))
    return tuple(pairs)
