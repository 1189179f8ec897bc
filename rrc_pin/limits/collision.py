r"""CollisionLimit: every pair of bodies kept apart, and tool frames inside their walls.

One velocity-damper row per pair closer than the detection distance (Kanehiro et al. 2008,
:mod:`rrc_pin.solvers.collision.damper_kernels`), and one per capsule end point within it of the
other body
(:mod:`rrc_pin.solvers.collision.narrow_kernels`: near-parallel capsules' closest points jump from
end to end,
and the end about to become the closest is then already constrained; a capsule against a
box also gets rows for the box's features that may take over within the step,
:mod:`rrc_pin.solvers.collision.box_kernels`; an end-point row
may lose :data:`END` of its margin a step, a pair's own row the damper's share):

.. math:: -n^T (J_b - J_a)\,\dot q \le \xi \frac{d - d_s}{d_i - d_s}

``d`` the pair's signed distance (negative in penetration), ``n`` the unit normal from A to B
(kept in penetration), ``J_a``, ``J_b`` the witness points' linear Jacobians, ``d_s`` the
safety distance, ``d_i`` the detection distance and :math:`\xi` [m/s] the approach speed
allowed at ``d_i`` (the row is not felt there by a slower approach: activation is smooth).
Below ``d_s``, in penetration too, the row asks only that the distance not decrease
(:mod:`rrc_pin.solvers.collision.damper_kernels`): standing still is always allowed, so a start
inside never locks the arm, and a command that moves the pair apart is met as it is (the
distance then grows at the command's pace). A pair at most :data:`BAND` below ``d_s`` (what
one step's linearisation loses) is pushed back out, restoring :data:`RECOVERY` of its shortfall
a step, less and less deeper down, nothing from twice :data:`BAND` on.
Linearised over one step of ``dt``, the distance after the step is at least
:math:`d_s + (d - d_s)(1 - \xi\,dt / (d_i - d_s))`, so :math:`\xi` is capped at
:math:`(d_i - d_s)/dt` (never crossing :math:`d_s` in one step). The true distance differs
from the linearised one by second-order terms (the witness points' accelerations over a step,
and their motion along curved surfaces): docs/api.md states the tolerance measured.

A virtual wall (:meth:`~rrc_pin.geometry.CollisionModel.add_workspace`, ``add_wall``) gives
the same row for its frame's origin :math:`p` at distance :math:`o - n^T p` from the wall,
with the wall itself as the safety distance (``d_s = 0``): :math:`n^T J_p \dot q \le
\xi (o - n^T p) / d_i`.

Every row is marked ``slide`` (:class:`~rrc_pin.solvers.tick.problem.Constraints`): the resolver's
direction-preserving top level loses only the command's component into a pair, and slides
along it (:mod:`rrc_pin.solvers.tick.pipeline`, ``sliding``). Rows are named ``"body_a|body_b"``
(walls
``"frame|wall"``) and carry their distance, so ``Resolution.active_rows`` names the pairs
that bound the answer and how close they are.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.geometry import CollisionModel, Wall
from rrc_pin.geometry.proximity import Proximity, gather, measure, proximity_of
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.collision.collision_pass import pair_rows
from rrc_pin.solvers.collision.damper_kernels import damper_bound
from rrc_pin.solvers.collision.records import SETTINGS
from rrc_pin.solvers.tick.problem import Constraints

if TYPE_CHECKING:
    from rrc_pin.geometry.scene import Scene
    from rrc_pin.kinematics import Layout

Array = npt.NDArray[np.float64]

SAFETY = 0.02
"""[m] Default safety distance d_s."""

DETECTION = 0.10
"""[m] Default detection distance d_i."""

GAIN = 0.5
"""[m/s] Default approach speed xi allowed at the detection distance."""

BAND = 1e-3
"""[m] The shortfall below d_s that a pair's row pushes back out (the one-step linearisation's
tolerance, docs/api.md); deeper, the push falls linearly to nothing at twice this: a start the
user chose inside is left to the command
(:func:`~rrc_pin.solvers.collision.damper_kernels.damper_bound`)."""

RECOVERY = 0.5
"""Fraction of a shortfall within :data:`BAND` below d_s restored per step (at most at the
gain)."""

END = 0.5
"""Fraction of its margin above d_s an end-point row may lose in one step (its xi is
``END * (d_i - d_s) / dt``): it only has to keep the end from crossing d_s unseen, and the
pair's own damper would slow a capsule sliding along another as its overhanging end comes in
(tangential progress 0.75 of the command with the pair's xi on two pandas' hands)."""

BLEND = 0.005
"""[m] An end point's row takes the pair's own xi where the end is as close as the pair's
closest points, and :data:`END`'s only where it is this much farther, linearly between. Two
capsules near parallel have their closest points at either end, from one tick to the next:
with the end's looser xi, turning about the pair's middle looked free to the row of the closest
end and was taken (the far end may approach faster), the closest end then swapped; two pandas'
hands held against each other had their wrists flip back and forth at 0.3-0.6 rad/s a tick."""

STILL = 1e-9
"""[m/s per rad/s] A row whose every entry is below this is dropped: at this configuration no
joint changes the pair's distance to first order (a pair no joint ever moves is left out of the
model's pairs: :func:`~rrc_pin.geometry.pairs.invariant`), so the row constrains nothing, and
could not be met where it asks the pair out."""


class InvariantPairWarning(UserWarning):
    """A pair that no joint can move is inside the safety distance: it is no constraint."""


class CollisionLimit(Limit):
    """Keeps the pairs of a :class:`~rrc_pin.geometry.CollisionModel` apart (module docstring).

    Args:
        model: The collision model (the resolver's robot's; obstacles may be added later).
        safety: Safety distance d_s [m], >= 0 and below ``detection``.
        detection: Detection distance d_i [m]: pairs closer than it get a row.
        gain: xi [m/s] > 0, the approach speed allowed at ``detection`` (capped at
            ``(detection - safety) / dt`` each tick).
        pairs: Only these pairs ``(body_a, body_b)`` (names of ``model.bodies``, either
            order), or None for every pair of the model.
        name: Name in the report.

    Attributes:
        last: The :class:`~rrc_pin.geometry.Proximity` of the last tick (the rows' pairs, a
            pair's end-point rows after its own), built when read; None before the first.

    Raises:
        InvalidInput: ``model`` not a CollisionModel, a distance or gain out of range, a pair
            naming a body the model does not have or that is not one of its pairs; nothing is
            kept.

    One limit holds one query state (a resolver's ticks run one at a time): give each
    resolver its own.
    """

    def __init__(
        self,
        model: CollisionModel,
        safety: float = SAFETY,
        detection: float = DETECTION,
        gain: float = GAIN,
        *,
        pairs: Sequence[tuple[str, str]] | None = None,
        name: str = "collision",
    ) -> None:
        if not isinstance(model, CollisionModel):
            raise InvalidInput("model", f"expected a CollisionModel, got {type(model).__name__}")
        d_s = finite_number(safety, "safety", 0.0)
        d_i = finite_number(detection, "detection", 0.0, inclusive=False)
        if d_s >= d_i:
            raise InvalidInput("safety", f"expected below the detection distance {d_i} m, got "
                               f"{d_s} m")  # fmt: skip
        xi = finite_number(gain, "gain", 0.0, inclusive=False)
        if not isinstance(name, str):
            raise InvalidInput("name", f"expected a string, got {name!r}")
        chosen = None if pairs is None else _pairs(model, pairs)
        self.model, self.safety, self.detection, self.gain, self.name = model, d_s, d_i, xi, name
        self.pairs = chosen
        self._data = model.create_data()
        self._rows: int | None = None  # the last tick's rows in self._data, None before one
        self._last: Proximity | None = None
        self._settings: tuple[float, npt.NDArray[np.void]] = (math.nan, np.zeros(1, SETTINGS))
        self._kept: tuple[Scene | None, npt.NDArray[np.bool_]] = (None, np.zeros(0, np.bool_))
        self._seen: Scene | None = None
        self._slide = np.ones(0, dtype=np.bool_)
        self._named: tuple[tuple[Scene | None, bytes], tuple[str, ...]] = ((None, b""), ())
        self._warn_invariant(model.scene)

    def check(self, layout: Layout) -> None:
        """Refuse a resolver whose robot is not the model's.

        Raises:
            InvalidInput: ``model`` of a robot with other joints or frames.
        """
        robot = self.model.robot
        if layout.nv != robot.model.nv or list(layout.joints) != list(robot.dof_names):
            raise InvalidInput("model", f"a collision model of {robot.name} (rates "
                               f"{list(robot.dof_names)}), not of this robot's rates "
                               f"{list(layout.joints)}")  # fmt: skip
        self._compile(layout)

    def _compile(self, layout: Layout) -> None:
        """Run the collision pass once now: no tick compiles it or loads it.

        From numba's cache or compiled, on the arrays a tick passes (its q read-only or not);
        nothing is kept.
        """
        robot, scene = self.model.robot, self.model.scene
        _, dof, q_pin = robot.positions(robot.ready())
        cdata, settings = self.model.create_data(), self._damper(1.0)
        kin = Kinematics(robot.model, robot.model.createData(), layout, dof, q_pin)
        for writeable in (True, False):
            q = np.array(dof)
            q.flags.writeable = writeable
            measure(scene, robot.model, q, lambda: kin.data, cdata, settings, scene.every)
        pair_rows(cdata.J, scene.support, scene.bodies, scene.first, scene.second, settings,
                  cdata.found, 0, cdata.G, cdata.h)  # fmt: skip

    @property
    def last(self) -> Proximity | None:
        """The :class:`~rrc_pin.geometry.Proximity` of the last tick (class docstring)."""
        if self._last is None and self._rows is not None:
            self._last = proximity_of(self._data, self._rows)
        return self._last

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """The damper rows of the pairs within the detection distance, and of the walls."""
        model = self.model
        if kin.model is not model.robot.model:
            raise InvalidInput("kin", f"kinematics of another model than {model.robot.name}'s")
        scene, data = model.scene, self._data
        if scene is not self._seen:  # an obstacle added since: its pairs no joint moves
            self._warn_invariant(scene)
        keep = scene.every if self.pairs is None else self._keep(scene)
        rows, unmoved = measure(scene, kin.model, kin.q, lambda: kin.data, data,
                                self._damper(dt), keep)  # fmt: skip
        self._rows, self._last = rows, None
        walls = model.walls()
        if not rows and not walls:
            return _NONE
        G, h, distance, pair = data.copies(rows)
        names = self._names(scene, pair)
        if walls or unmoved:
            G, h, distance, names = self._trimmed(kin, walls, G, h, distance, names,
                                                  data.found["moved"][:rows], dt)  # fmt: skip
            if not h.size:
                return _NONE
        return Constraints(G=G, h=h, names=names, slide=self._sliding(h.size),
                           distance=distance)  # fmt: skip

    def _sliding(self, rows: int) -> npt.NDArray[np.bool_]:
        """Every one of ``rows`` rows slides (module docstring): a read-only view of one array
        kept, grown where more rows come."""  # noqa: D205, D209
        if self._slide.size < rows:
            self._slide = np.ones(max(rows, 2 * self._slide.size), dtype=np.bool_)
            self._slide.flags.writeable = False
        return self._slide[:rows]

    def _names(self, scene: Scene, pair: npt.NDArray[np.int64]) -> tuple[str, ...]:
        """The rows' names (``"body_a|body_b"``) of the pairs ``pair`` (rows,) of ``scene``:
        those of the last tick again where its rows were the same pairs'."""  # noqa: D205, D209
        key = (scene, pair.tobytes())
        if self._named[0] != key:
            self._named = (key, gather(scene.labels, pair))
        return self._named[1]

    def _trimmed(
        self, kin: Kinematics, walls: Sequence[Wall], G: Array, h: Array, distance: Array,
        names: tuple[str, ...], moved: npt.NDArray[np.bool_], dt: float,
    ) -> tuple[Array, Array, Array, tuple[str, ...]]:  # fmt: skip
        """The pairs' rows with the walls' after them, less those no joint moves."""
        listed = list(names)
        if walls:
            G, h, distance = self._walls(kin, walls, G, h, listed, distance, dt)
            moved = np.abs(G).max(axis=1) > STILL
        if not moved.all():  # a pair no joint can move apart or together has no row
            G, h, distance = G[moved], h[moved], distance[moved]
            listed = [n for n, m in zip(listed, moved.tolist(), strict=True) if m]
        return G, h, distance, tuple(listed)

    def _damper(self, dt: float) -> npt.NDArray[np.void]:
        """The pass's settings (1,) at step ``dt`` [s] (kept while ``dt`` is the same)."""
        if self._settings[0] != dt:
            span = self.detection - self.safety
            settings = np.zeros(1, dtype=SETTINGS)
            settings["detection"], settings["ends"], settings["rows"] = self.detection, True, True
            settings["safety"], settings["xi"] = self.safety, min(self.gain, span / dt)
            settings["xi_end"], settings["blend"], settings["band"] = END * span / dt, BLEND, BAND
            settings["recovery"], settings["still"] = RECOVERY / dt, STILL
            self._settings = (dt, settings)
        return self._settings[1]

    def _walls(
        self, kin: Kinematics, walls: Sequence[Wall], G: Array, h: Array, names: list[str],
        distance: Array, dt: float,
    ) -> tuple[Array, Array, Array]:  # fmt: skip
        """The rows of the walls whose frame is within the detection distance of them."""
        xi = min(self.gain, self.detection / dt)
        rows, bounds, gaps = [G], [h], [distance]
        for wall in walls:
            p = kin.pose(wall.frame)[:3, 3]
            gap = wall.offset - float(wall.normal @ p)
            if gap >= self.detection:
                continue
            J = kin.jacobian(wall.frame, "world_aligned")[:3]
            rows.append((wall.normal @ J)[None, :])
            bounds.append(np.array([damper_bound(gap, self.detection, xi, BAND, RECOVERY / dt)]))
            gaps.append(np.array([gap]))
            names.append(f"{wall.frame}|{wall.name}")
        return np.vstack(rows), np.concatenate(bounds), np.concatenate(gaps)

    def _warn_invariant(self, scene: Scene) -> None:
        """Warn of the pairs of ``scene`` that no joint moves and that are inside d_s."""
        self._seen = scene
        inside = [f"{a}|{b} ({d * 1e3:.1f} mm)" for (a, b), d in scene.invariant.items()
                  if d < self.safety and (self.pairs is None or (a, b) in self.pairs)]  # fmt: skip
        if inside:
            warnings.warn(
                f"{self.name}: {', '.join(inside)} inside the safety distance "
                f"{self.safety * 1e3:.1f} mm, and no joint changes their distance: not "
                "constrained (the robot cannot move them apart)", InvariantPairWarning,
                stacklevel=3,
            )  # fmt: skip

    def _keep(self, scene: Scene) -> npt.NDArray[np.bool_]:
        """Whether each pair of ``scene`` is one of :attr:`pairs` (kept per scene)."""
        if self._kept[0] is not scene:
            chosen = self.pairs or frozenset()
            self._kept = (scene, np.array([p in chosen for p in scene.pair_names], dtype=np.bool_))
        return self._kept[1]


_NONE = Constraints()


def _pairs(model: CollisionModel, pairs: Sequence[tuple[str, str]]) -> frozenset[tuple[str, str]]:
    """``pairs`` as the model orders them, each checked."""
    bodies = set(model.bodies)
    known = set(model.pairs)
    out = set()
    if isinstance(pairs, (str, bytes)) or not isinstance(pairs, Sequence):
        raise InvalidInput("pairs", f"expected a sequence of (body_a, body_b), got {pairs!r}")
    for pair in pairs:
        if not (isinstance(pair, (tuple, list)) and len(pair) == 2
                and all(isinstance(x, str) for x in pair)):  # fmt: skip
            raise InvalidInput("pairs", f"expected (body_a, body_b) names, got {pair!r}")
        for body in pair:
            if body not in bodies:
                raise InvalidInput("pairs", f"no body {body!r} in the collision model; bodies: "
                                   f"{', '.join(model.bodies)}")  # fmt: skip
        a, b = pair
        if (a, b) in known:
            out.add((a, b))
        elif (b, a) in known:
            out.add((b, a))
        else:
            raise InvalidInput("pairs", f"({a!r}, {b!r}) is not a pair of the model (left out: "
                               f"{model.excluded.get((a, b), model.excluded.get((b, a)))})")
    return frozenset(out)

