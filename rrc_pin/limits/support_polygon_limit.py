r"""SupportPolygonLimit: the centre of mass kept over the feet in support.

The support region is the convex hull of the feet's contact patches on the ground (each
foot's origin plus its ``sole``, horizontal offsets in base axes), shrunk by ``margin``: an
edge :math:`n_k^T x \le o_k` of the hull (outward unit normal :math:`n_k`) becomes
:math:`n_k^T x \le o_k - \text{margin}`. One row per edge keeps the horizontal projection
:math:`c_{xy}` of the centre of mass in it for the step, as the joint limits keep a position
limit (a fraction :math:`\gamma` of the distance left, per step):

.. math:: n_k^T J_{c,xy}\,\dot q \le \gamma\,\frac{g_k - 2\beta}{\Delta t}, \qquad
    g_k = o_k - \text{margin} - n_k^T c_{xy},

with :math:`\beta` = :data:`BUFFER`, held (0) for :math:`\beta \le g_k \le 2\beta` and
:math:`\gamma (g_k - \beta) / \Delta t` below. Linearised over the step, :math:`c_{xy}` then
covers at most :math:`\gamma` of its distance to the buffer per step, and the buffer absorbs
the second-order terms: it stays inside (measured: docs/api.md). The feet in support are taken
as fixed (hold them with a :class:`~rrc_pin.limits.ContactLimit` on the same frames): the
hull's own motion is not in the rows. A hull without area (two point feet, or one) keeps the
centre of mass on its segment or point; with a margin that is infeasible, and the resolver
answers by least squares (a start outside the region moves back in the same way).

A body command that would carry the centre of mass out of the region is then scaled (the
resolver's direction problem): never obeyed.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.center_of_mass import center_of_mass, check_mass
from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import finite_number, names, real_array
from rrc_pin.solvers.tick.problem import Constraints

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]

BUFFER = 5e-5
"""[m] The centre of mass approaches an edge up to twice this distance inside it, is held
(h = 0) between twice and once this distance inside, and is asked back nearer than that. The
steps' second-order terms and the contacts' slip (a few um a step) drift a held centre of
mass outward; asked back from inside the region, it settles where the drift and the way back
balance (the drift over gamma), still inside. Held, the command stays direction-preserving
instead of turning the top level into least squares."""


class SupportPolygonLimit(Limit):
    """The centre of mass over the support region (module docstring).

    Args:
        feet: Frames in support (e.g. a cell's feet); changed with :meth:`set_feet`.
        sole: Each foot's contact patch: offsets (k, 2) [m] on the ground around the foot's
            origin, in base axes (e.g. a rectangle's corners); default the origin alone.
        points: Fixed points (p, 2) [m] of the ground also in the region (the footprint of
            a robot whose feet are not in its model: an upper body), or None.
        margin: Distance [m] >= 0 kept from the region's edges.
        gain: gamma in (0, 1]: the fraction of the distance to an edge allowed per step.
        name: Name in the report; rows are named ``name:edge<k>``.

    Raises:
        InvalidInput: Bad feet, sole, points, margin, gain or name.
    """

    def __init__(
        self,
        feet: Sequence[str] = (),
        *,
        sole: npt.ArrayLike | None = None,
        points: npt.ArrayLike | None = None,
        margin: float = 0.02,
        gain: float = 0.5,
        name: str = "support",
    ) -> None:
        if not isinstance(name, str) or not name:
            raise InvalidInput("name", f"expected a non-empty string, got {name!r}")
        self.name = name
        self.sole = _offsets(np.zeros((1, 2)) if sole is None else sole, "sole")
        self.points = np.zeros((0, 2)) if points is None else _offsets(points, "points")
        self.margin = finite_number(margin, "margin", 0.0)
        self.gain = finite_number(gain, "gain", 0.0, inclusive=False)
        if self.gain > 1.0:
            raise InvalidInput("gain", f"expected a number in (0, 1], got {self.gain}")
        self._layout: Layout | None = None
        self.set_feet(feet)

    def set_feet(self, feet: Sequence[str]) -> None:
        """The frames in support from now on (a foot lifted or landed).

        Raises:
            InvalidInput: Not distinct frame names; the limit is then unchanged.
            FrameNotFound: A frame the robot (of the resolver holding it) does not have.
        """
        items = names(feet, "feet")
        if len(set(items)) != len(items):
            raise InvalidInput("feet", f"expected distinct frame names, got {feet!r}")
        if self._layout is not None:
            _check_frames(items, self._layout)
        self.feet: tuple[str, ...] = items

    def check(self, layout: Layout) -> None:
        """Refuse feet the robot does not have.

        Raises:
            FrameNotFound: Naming ``feet`` and listing the robot's frames.
        """
        _check_frames(self.feet, layout)
        self._layout = layout

    def region(self, kin: Kinematics) -> tuple[Array, Array]:
        """The shrunk region's edges: outward normals (k, 2) and offsets (k,) [m].

        ``normals @ x <= offsets`` for a point x (2,) of the ground inside it.
        """
        ground = [kin.pose(f)[:2, 3] + self.sole for f in self.feet]
        normals, offsets = hull_edges(np.vstack([*ground, self.points]))
        return normals, offsets - self.margin

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """One row per edge of the shrunk region (module docstring)."""
        if not self.feet and not self.points.size:
            return Constraints()
        check_mass(kin.model)
        normals, offsets = self.region(kin)
        com = center_of_mass(kin)
        G = normals @ com.jacobian[:2]
        gap = offsets - normals @ com.position[:2]
        held = np.maximum(gap - 2.0 * BUFFER, 0.0)
        h = self.gain * np.where(gap < BUFFER, gap - BUFFER, held) / dt
        names = tuple(f"{self.name}:edge{k}" for k in range(h.size))
        return Constraints(G=G, h=h, names=names)


def hull_edges(points: Array) -> tuple[Array, Array]:
    """The convex hull of ``points`` (n, 2) as edges: outward unit normals (k, 2), offsets (k,).

    Andrew's monotone chain (1979). A hull without area is its segment (its line both ways
    and its two ends) or its point (four sides of it).
    """
    pts = np.unique(np.round(points, 12), axis=0)  # sorted by x, then y
    if len(pts) == 1:
        normals = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
        return normals, normals @ pts[0]
    lower = _chain(pts)
    upper = _chain(pts[::-1])
    ring = np.array(lower[:-1] + upper[:-1])
    if len(ring) < 3:  # collinear: a segment
        a, b = pts[0], pts[-1]
        t = (b - a) / np.linalg.norm(b - a)
        n = np.array([t[1], -t[0]])
        normals = np.array([n, -n, t, -t])
        return normals, np.array([n @ a, -n @ a, t @ b, -t @ a])
    edges = np.roll(ring, -1, axis=0) - ring  # counter-clockwise
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    return normals, np.einsum("ij,ij->i", normals, ring)


def _chain(pts: Array) -> list[Array]:
    out: list[Array] = []
    for p in pts:
        while len(out) >= 2 and _turn(out[-2], out[-1], p) <= 1e-15:
            out.pop()
        out.append(p)
    return out


def _turn(o: Array, a: Array, b: Array) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _offsets(value: npt.ArrayLike, name: str) -> Array:
    x: Array = np.array(real_array(value, name), dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 2 or not len(x) or not np.isfinite(x).all():
        raise InvalidInput(name, f"expected finite offsets (k, 2) [m], got shape {x.shape}")
    return x


def _check_frames(frames: tuple[str, ...], layout: Layout) -> None:
    for frame in frames:
        if frame not in layout.frames:
            raise FrameNotFound(frame, sorted(layout.frames), "feet")
