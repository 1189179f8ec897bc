"""CollisionLimit held out: random starts in penetration, and clean random-command sessions.

Shared by the tests (short versions, fixed and fresh seeds: tests/test_collision_sessions.py,
tests/test_collision_starts.py) and the soak (``bench_collision.py --soak``: 200 starts and
10-minute sessions).

**Sessions** (:func:`session`): at 100 Hz, the hands driven toward random targets chosen to
collide (the panda's own base and links; under a table top; the other arm's hand), a new target
every second, at up to 0.3 m/s (and turning at random rates, with ``turn``); every tick's status
counted, every fallback tick kept with the reasons its attempts give, the largest joint rate
against its velocity limit and the one-step linearisation error of the pairs near d_s
measured.

**Starts** (:func:`panda_start`, :func:`two_pandas_start`, :func:`held_box_start`): a random
placement where one pair starts at a chosen signed distance below the safety distance (into
penetration): an obstacle of a random shape against a random link of panda; two facing pandas at
random configurations; a box held by panda's hand overlapping a link. :func:`start_trial`
then drives it, from the same start,

- *away*: a command (a twist of each hand) whose exact rates move every pair inside d_s apart,
  at :data:`AWAY` where some command can, and approach no other pair beyond its row (an LP over
  the twists, a new one every tick), until no pair is inside: the ticks that takes, against
  the time the command needs (the deepest pair's shortfall at :data:`AWAY`);
- *at random*: a random twist of each hand every 0.2 s; the largest decrease of any pair's
  distance over one tick while it is inside d_s;

and counts the fallback ticks and the largest joint rate over its velocity limit in both.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable
from typing import NamedTuple

import coal
import numpy as np
import pinocchio as pin
from scipy.optimize import linprog

import rrc_pin
from rrc_pin import CollisionLimit, CollisionModel, FrameTask, JointLimits, Resolver
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits.collision import InvariantPairWarning

DT = 0.01
SAFETY = 0.02
DETECTION = 0.10
GAIN = 0.5
SPEED = 0.3
"""[m/s] The sessions' largest hand speed."""
NEAR = 0.01
"""[m] The pairs within this of the safety distance are those whose one-step linearisation
error a session measures (the error matters where a row is about to bind)."""
AWAY = 0.05
"""[m/s] The speed at which the away command's exact rates move each pair inside d_s apart."""
SCENES = ("panda folding", "panda table", "baxter", "two pandas")
SHAPES = ("box", "sphere", "capsule", "cylinder", "halfspace", "speck")
"""Obstacle shapes of :func:`panda_start` (``speck``: a sphere of 1 um radius)."""

Targets = Callable[[np.random.Generator, dict[str, np.ndarray]], dict[str, np.ndarray]]


def two_pandas(gap: float = 1.0) -> rrc_pin.Robot:
    """Two pandas combined, the second facing the first ``gap`` [m] along x."""
    panda = rrc_pin.load("panda")
    facing = np.eye(4)
    facing[:3, :3] = np.diag([-1.0, -1.0, 1.0])
    facing[0, 3] = gap
    return rrc_pin.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})


def scene(name: str) -> tuple[CollisionModel, Targets]:
    """A session's collision model and its target rule (hand positions in, targets out)."""
    if name == "panda folding":
        cm = CollisionModel(rrc_pin.load("panda"))

        def targets(rng, hands):  # around its own base and lower links
            return {f: rng.uniform((-0.15, -0.25, 0.05), (0.25, 0.25, 0.45)) for f in hands}

    elif name == "panda table":
        cm = CollisionModel(rrc_pin.load("panda"))
        T = np.eye(4)
        T[:3, 3] = (0.55, 0.0, 0.2)
        cm.add_box(T, (0.5, 0.8, 0.04), name="table")
        cm.add_halfspace((0, 0, 1), -0.15, name="floor")  # the base on a 0.15 m plinth

        def targets(rng, hands):  # under the table top, or into the floor beside it
            return {f: rng.uniform((0.3, -0.5, -0.25), (0.8, 0.5, 0.15)) for f in hands}

    elif name in ("baxter", "two pandas"):
        cm = CollisionModel(rrc_pin.load("baxter") if name == "baxter" else two_pandas())

        def targets(rng, hands):  # each hand to where the other is
            (fa, pa), (fb, pb) = hands.items()
            mid = 0.5 * (pa + pb) + rng.normal(0.0, 0.05, 3)
            return {fa: mid + rng.normal(0.0, 0.03, 3), fb: mid + rng.normal(0.0, 0.03, 3)}

    else:
        raise ValueError(f"no scene {name!r}; scenes: {', '.join(SCENES)}")
    return cm, targets


class Session(NamedTuple):
    """What one session measured (distances [m], rates relative to their limits)."""

    ticks: int
    min_distance: float
    worst_pair: tuple[str, str]
    joint_excess: float
    rate_over_limit: float
    finite: bool
    statuses: dict[str, int]
    linearisation: float
    fallbacks: list[tuple[int, float, tuple[tuple[str, str], ...]]]
    """Each fallback tick: (tick, nearest pair's distance [m], the attempts' reasons)."""


def session(name: str, seconds: float, seed: int, limit: bool = True, turn: bool = False,
            measure_steps: bool = True) -> Session:  # fmt: skip
    """One session of ``seconds`` simulated at 100 Hz (module docstring).

    Args:
        name: One of :data:`SCENES`.
        seconds: Simulated time [s].
        seed: The targets' (and turns') generator's seed.
        limit: With the collision limit (else the joint limits alone).
        turn: The hands' full twists, each turning at a random rate (0.3 rad/s a component,
            drawn with each target), not their positions alone.
        measure_steps: Measure the one-step linearisation error (a second proximity query a
            tick).
    """
    cm, targets = scene(name)
    robot = cm.robot
    frames = list(robot.tool_frames)
    limits = [JointLimits()]
    if limit:
        limits.append(CollisionLimit(cm, SAFETY, DETECTION, GAIN))
    resolver = Resolver(robot, DT, limits=limits)
    probe = CollisionLimit(cm, SAFETY, DETECTION, GAIN) if limit and measure_steps else None
    layout = Layout.of(robot)
    tasks = [FrameTask(f, rows="full" if turn else "position") for f in frames]
    rng = np.random.default_rng(seed)
    q = robot.ready()
    turning = {f: np.zeros(3) for f in frames}
    min_distance, worst, excess, over, finite, error = math.inf, ("", ""), 0.0, 0.0, True, 0.0
    statuses: dict[str, int] = {}
    fallbacks = []
    goal: dict[str, np.ndarray] = {}
    ticks = round(seconds / DT)
    for tick in range(ticks):
        hands = {f: robot.frame_pose(q, f)[:3, 3] for f in frames}
        if tick % 100 == 0:
            goal = targets(rng, hands)
            if turn:
                turning = {f: rng.normal(0.0, 0.3, 3) for f in frames}
        for task, f in zip(tasks, frames, strict=True):
            v = 2.0 * (goal[f] - hands[f])
            speed = float(np.linalg.norm(v))
            v = v * min(1.0, SPEED / speed) if speed > 0 else v
            task.set_twist(np.concatenate([v, turning[f]]) if turn else v)
        res = resolver.solve(q, [tasks], priority="strict")
        statuses[res.status] = statuses.get(res.status, 0) + 1
        qdot = np.asarray(res.qdot)
        finite &= bool(np.isfinite(qdot).all())
        over = max(over, float(np.max(np.abs(qdot) / robot.velocity_limit)))
        step = DT * qdot
        if res.status == "fallback":
            near = cm.proximity_at(q, DETECTION)
            nearest = float(near.distance.min()) if len(near.names) else math.inf
            fallbacks.append((tick, nearest, tuple(res.attempts)))
        if probe is not None:
            kin = Kinematics(robot.model, robot.model.createData(), layout, q,
                             robot.to_pinocchio(q))  # fmt: skip
            error = max(error, _step_error(probe.constraints(kin, DT, step), cm, q, step))
        q = q + step
        excess = max(excess, float(np.max(robot.lower - q)), float(np.max(q - robot.upper)))
        prox = cm.proximity_at(q, DETECTION)
        if prox.names:
            k = int(np.argmin(prox.distance))
            if prox.distance[k] < min_distance:
                min_distance, worst = float(prox.distance[k]), prox.names[k]
    return Session(ticks, min_distance, worst, excess, over, finite, statuses, float(error),
                   fallbacks)  # fmt: skip


def _step_error(rows, cm: CollisionModel, q: np.ndarray, step: np.ndarray) -> float:
    """The largest one-step linearisation error of the pairs within NEAR of d_s: the lowest
    distance a pair's rows (closest points', end points') predict after the step, less the
    distance it reaches."""
    if rows.h is None:
        return 0.0
    after = cm.proximity_at(q + step, DETECTION)
    reached = dict(zip(("|".join(p) for p in after.names), after.distance, strict=True))
    predicted: dict[str, float] = {}
    for k, pair in enumerate(rows.names):
        if pair in reached and rows.distance[k] <= SAFETY + NEAR:
            d = rows.distance[k] - float(rows.G[k] @ step)
            predicted[pair] = min(predicted.get(pair, math.inf), d)
    return max((d - reached[p] for p, d in predicted.items()), default=0.0)


# -- starts in penetration ----------------------------------------------------------------------


class Start(NamedTuple):
    """A random starting placement: ``pair`` at signed distance ``distance`` [m] at ``q``."""

    model: CollisionModel
    q: np.ndarray
    pair: tuple[str, str]
    distance: float
    label: str


def panda_start(rng: np.random.Generator, distance: float) -> Start | None:
    """Panda near its ready pose and an obstacle at ``distance`` from one of its links."""
    robot = rrc_pin.load("panda")
    q = np.clip(robot.ready() + rng.uniform(-0.5, 0.5, robot.nq), robot.lower, robot.upper)
    cm = CollisionModel(robot)
    kind = str(rng.choice(SHAPES))
    body = _moving_body(rng, cm, exclude=())
    placed = _placed(rng, cm, q, body, kind, distance)
    if placed is None:
        return None
    name = _add(cm, kind, placed)
    if (cm.bodies[body], name) in cm.invariant:  # no joint moves it: not a row, no start
        return None
    return _start(cm, q, (cm.bodies[body], name), f"{kind} against {cm.bodies[body]}")


def held_box_start(rng: np.random.Generator, distance: float) -> Start | None:
    """A box held by panda's hand at ``distance`` from one of the links the hand does not
    carry (the wrist's, the forearm's)."""
    robot = rrc_pin.load("panda")
    q = np.clip(robot.ready() + rng.uniform(-0.5, 0.5, robot.nq), robot.lower, robot.upper)
    cm = CollisionModel(robot)
    hand = robot.model.frames[robot.model.getFrameId("panda_hand")].parentJoint
    body = _moving_body(rng, cm, exclude=(hand,))
    size = rng.uniform(0.02, 0.15, 3)
    placed = _placed(rng, cm, q, body, "box", distance, size=size)
    if placed is None:
        return None
    world = pin.SE3(placed["T"][:3, :3], placed["T"][:3, 3])
    hand_pose = robot.frame_pose(q, "panda_hand")
    in_hand = pin.SE3(hand_pose[:3, :3], hand_pose[:3, 3]).inverse() * world
    name = cm.attach("panda_hand", "box", in_hand.homogeneous, size=size, name="held")
    return _start(cm, q, (cm.bodies[body], name), f"held box against {cm.bodies[body]}")


def two_pandas_start(rng: np.random.Generator, distance: float, tries: int = 400
                     ) -> Start | None:  # fmt: skip
    """Two facing pandas at random configurations, their nearest pair across the arms within
    5 mm of ``distance`` (drawn until one is)."""
    cm = _two_pandas_model()
    robot = cm.robot
    across = np.array([a.split("/")[0] != b.split("/")[0] for a, b in cm.pairs])
    for _ in range(tries):
        q = np.clip(robot.ready() + rng.uniform(-0.9, 0.9, robot.nq), robot.lower, robot.upper)
        prox = cm.proximity_at(q, 0.2)
        if not len(prox.names):
            continue
        mask = across[prox.pair]
        if not mask.any():
            continue
        k = int(np.flatnonzero(mask)[np.argmin(prox.distance[mask])])
        if abs(prox.distance[k] - distance) <= 0.005:
            return _start(cm, q, prox.names[k], "two pandas")
    return None


@functools.cache
def _two_pandas_model() -> CollisionModel:
    """Two pandas 0.8 m apart and their collision model (no obstacle: shared as it is)."""
    return CollisionModel(two_pandas(0.8))


def _start(cm: CollisionModel, q: np.ndarray, pair: tuple[str, str], label: str) -> Start:
    prox = cm.proximity_at(q, 1.0)
    d = min((float(x) for n, x in zip(prox.names, prox.distance, strict=True) if n == pair),
            default=math.nan)  # fmt: skip
    return Start(cm, q, pair, d, f"{label} at {d * 1e3:.1f} mm")


def _moving_body(rng: np.random.Generator, cm: CollisionModel, exclude: tuple[int, ...]) -> int:
    """A random robot body moved by some joint (and not on a joint of ``exclude``)."""
    robot_bodies = [g for g in range(len(cm.bodies)) if cm.scene.joint[g] not in (0, *exclude)]
    return int(rng.choice(robot_bodies))


def _placed(rng: np.random.Generator, cm: CollisionModel, q: np.ndarray, body: int, kind: str,
            distance: float, size: np.ndarray | None = None) -> dict | None:  # fmt: skip
    """An obstacle of ``kind`` at signed ``distance`` from ``body`` at ``q`` (bisection along a
    random direction from the body's bounding-sphere centre), or None where none is found."""
    robot = cm.robot
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, robot.to_pinocchio(q))
    obj = cm.scene.geometry.geometryObjects[body]
    M = data.oMi[obj.parentJoint] * obj.placement
    mine = (obj.geometry, coal.Transform3s(M.rotation, M.translation))
    centre = data.oMi[int(cm.scene.joint[body])].act(cm.scene.bodies["centre"][body])
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    if kind == "halfspace":  # the solid u . x <= o, farther from the body as o falls
        def gap(o: float) -> float:
            return _distance(*mine, coal.Halfspace(u, o), coal.Transform3s())

        o = _bisect(gap, float(u @ centre) - 1.5, float(u @ centre) + 1.5, distance, False)
        return None if o is None else {"normal": u, "offset": o}
    shape, dims = _shape(rng, kind, size)
    R = pin.Quaternion(*(rng.normal(size=4))).normalized().toRotationMatrix()

    def apart(t: float) -> float:
        return _distance(*mine, shape, coal.Transform3s(R, centre + t * u))

    t = _bisect(apart, 0.0, 2.0, distance, True)
    if t is None:
        return None
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, centre + t * u
    return {"T": T, **dims}


def _shape(rng: np.random.Generator, kind: str, size: np.ndarray | None
           ) -> tuple[object, dict]:  # fmt: skip
    if kind == "box":
        sides = rng.uniform(0.03, 0.4, 3) if size is None else size
        return coal.Box(*sides), {"size": sides}
    if kind in ("sphere", "speck"):
        r = rng.uniform(0.01, 0.15) if kind == "sphere" else 1e-6
        return coal.Sphere(r), {"radius": r}
    r, length = rng.uniform(0.01, 0.08), rng.uniform(0.02, 0.4)
    if kind == "capsule":
        return coal.Capsule(r, length), {"radius": r, "length": length}
    return coal.Cylinder(r, length), {"radius": r, "length": length}


def _add(cm: CollisionModel, kind: str, spec: dict) -> str:
    if kind == "halfspace":
        return cm.add_halfspace(spec["normal"], spec["offset"], name="obstacle")
    if kind == "box":
        return cm.add_box(spec["T"], spec["size"], name="obstacle")
    if kind in ("sphere", "speck"):
        return cm.add_sphere(spec["T"][:3, 3], spec["radius"], name="obstacle")
    add = cm.add_capsule if kind == "capsule" else cm.add_cylinder
    return add(spec["T"], spec["radius"], spec["length"], name="obstacle")


def _distance(a: object, Ta: coal.Transform3s, b: object, Tb: coal.Transform3s) -> float:
    result = coal.DistanceResult()
    coal.distance(a, Ta, b, Tb, coal.DistanceRequest(), result)
    return float(result.min_distance)


def _bisect(f: Callable[[float], float], lo: float, hi: float, target: float,
            rising: bool) -> float | None:  # fmt: skip
    """x in [lo, hi] with f(x) = target, f monotone there (rising or falling), or None."""
    below, above = (lo, hi) if rising else (hi, lo)
    if not f(below) < target < f(above):
        return None
    for _ in range(60):
        mid = 0.5 * (below + above)
        if f(mid) < target:
            below = mid
        else:
            above = mid
    return 0.5 * (below + above)


class StartReport(NamedTuple):
    """What :func:`start_trial` measured from one start."""

    fallbacks: int
    first_scale: float
    """The scale of the first away tick (NaN where no command moves every inside pair apart)."""
    first_speed: float
    """[m/s] The hands' largest speed at the first away tick."""
    first_command: float
    """[m/s] The largest hand speed the first away tick's command asked (its twists' linear
    parts: the LP's command may be slower than :data:`AWAY`, where every inside pair must move
    apart and no other come closer)."""
    exit_ticks: int | None
    """Ticks until no pair is inside d_s, commanded away (None: not within the deadline)."""
    deadline: int
    """The ticks the away command needs: the deepest pair's shortfall at the start at its
    speed, and 10 more."""
    away_ticks: int
    """Away ticks at which a command moving every inside pair apart existed."""
    away_speed: float
    """[m/s] The slowest of those commands' speeds apart, 0 where at some tick none existed (the
    speed asked where every one could go that fast: the deadline holds only then)."""
    decrease: float
    """[m] The largest decrease of an inside pair's distance over one tick, commanded at
    random."""
    rate_over_limit: float
    """The largest joint rate over its velocity limit (<= 1 where every rate is within)."""


def start_trial(start: Start, rng: np.random.Generator, random_ticks: int = 50,
                away: float = AWAY) -> StartReport:  # fmt: skip
    """Drive ``start`` away (each inside pair apart at ``away`` [m/s] where a command can),
    then at random, from the same placement (module docstring)."""
    cm, q0 = start.model, start.q
    robot = cm.robot
    with warnings.catch_warnings():  # a start may hold a pair no joint moves: known, chosen
        warnings.simplefilter("ignore", InvariantPairWarning)
        limit = CollisionLimit(cm, SAFETY, DETECTION, GAIN)
    jl = JointLimits()
    resolver = Resolver(robot, DT, limits=[jl, limit])
    frames = list(robot.tool_frames)
    tasks = [FrameTask(f) for f in frames]
    layout = Layout.of(robot)
    fallbacks, over = 0, 0.0
    deepest = min(_inside(cm, q0).values(), default=start.distance)
    deadline = math.ceil((SAFETY - deepest) / away / DT) + 10
    q, previous = q0.copy(), np.zeros(robot.nv)
    first_scale = first_speed = first_command = math.nan
    exit_ticks, away_ticks, slowest = None, 0, away
    for tick in range(deadline + 1):
        kin = Kinematics(robot.model, robot.model.createData(), layout, q, robot.to_pinocchio(q))
        rows = limit.constraints(kin, DT, previous)
        if rows.h is None or not (rows.distance < SAFETY).any():
            exit_ticks = tick
            break
        found = _away(kin, frames, rows, jl.constraints(kin, DT, previous).box, away)
        if found is None:  # no command takes every inside pair away: it does not allow it
            slowest = 0.0
            break
        twist, speed = found
        slowest = min(slowest, speed)
        away_ticks += 1
        res = _solve(resolver, tasks, twist, q)
        fallbacks += res.status == "fallback"
        over = max(over, float(np.max(np.abs(res.qdot) / robot.velocity_limit)))
        if tick == 0:
            first_scale = float(res.scale)
            first_speed = max(float(np.linalg.norm(kin.jacobian(f, "world_aligned")[:3]
                                                   @ res.qdot)) for f in frames)  # fmt: skip
            first_command = max(float(np.linalg.norm(twist[6 * k : 6 * k + 3]))
                                for k in range(len(frames)))  # fmt: skip
        previous = np.asarray(res.qdot)
        q = q + DT * previous
    decrease = 0.0
    q, twist = q0.copy(), None
    for tick in range(random_ticks):
        if tick % 20 == 0:
            twist = np.concatenate([np.concatenate([rng.normal(0, 0.15, 3), rng.normal(0, 0.5, 3)])
                                    for _ in frames])  # fmt: skip
        before = _inside(cm, q)
        res = _solve(resolver, tasks, twist, q)
        fallbacks += res.status == "fallback"
        over = max(over, float(np.max(np.abs(res.qdot) / robot.velocity_limit)))
        q = q + DT * np.asarray(res.qdot)
        after = _pair_distances(cm, q)
        for pair, d in before.items():
            decrease = max(decrease, d - after.get(pair, math.inf))
    return StartReport(fallbacks, first_scale, first_speed, first_command, exit_ticks, deadline,
                       away_ticks, slowest, decrease, over)  # fmt: skip


def moved_at_once(r: StartReport) -> bool:
    """Whether the hands moved at the first away tick's command: its scale met, and the hands
    faster than 1 cm/s or at the command's own hand speed where that is slower (a command
    that moves every inside pair apart without bringing any other closer may have to turn the
    hand more than move it)."""
    return r.first_scale >= 0.99 and (r.first_speed > 0.01
                                      or r.first_speed >= 0.99 * r.first_command > 0.0)


def _solve(resolver: Resolver, tasks: list[FrameTask], twist: np.ndarray, q: np.ndarray):
    for k, task in enumerate(tasks):
        task.set_twist(twist[6 * k : 6 * k + 6])
    return resolver.solve(q, [tasks], priority="strict")


def _pair_distances(cm: CollisionModel, q: np.ndarray) -> dict[tuple[str, str], float]:
    """Each pair's distance within the detection distance (its closest points' row)."""
    prox = cm.proximity_at(q, DETECTION)
    out: dict[tuple[str, str], float] = {}
    for name, d in zip(prox.names, prox.distance, strict=True):
        out.setdefault(name, float(d))
    return out


def _inside(cm: CollisionModel, q: np.ndarray) -> dict[tuple[str, str], float]:
    return {p: d for p, d in _pair_distances(cm, q).items() if d < SAFETY}


def _away(kin: Kinematics, frames: list[str], rows, box, speed: float
          ) -> tuple[np.ndarray, float] | None:  # fmt: skip
    """Twists of the hands whose exact (least-norm) rates move every pair inside d_s apart at
    the largest speed up to ``speed`` (its closest points' row), keep every row and the box,
    and are small (an LP); with that speed [m/s], or None where no twist moves them apart."""
    A = np.vstack([kin.jacobian(f, "world_aligned") for f in frames])
    P = np.linalg.pinv(A)  # the exact rates w = P b of a command b
    m = A.shape[0]
    own = np.array([k == 0 or rows.names[k] != rows.names[k - 1] for k in range(rows.h.size)])
    inside = own & (rows.distance < SAFETY)
    GP = rows.G @ P
    lb, ub = np.maximum(box.lb, -1e3), np.minimum(box.ub, 1e3)
    # z = (b+, b-, speed): max speed - 1e-3 |b|_1
    cost = np.concatenate([np.full(2 * m, 1e-3), [-1.0]])
    A_ub = np.vstack([
        np.hstack([GP, -GP, np.zeros((GP.shape[0], 1))]),
        np.hstack([GP[inside], -GP[inside], np.ones((int(inside.sum()), 1))]),
        np.hstack([P, -P, np.zeros((P.shape[0], 1))]),
        np.hstack([-P, P, np.zeros((P.shape[0], 1))]),
    ])  # fmt: skip
    b_ub = np.concatenate([rows.h, np.zeros(int(inside.sum())), 0.999 * ub, -0.999 * lb])
    bounds = [(0.0, 0.5)] * (2 * m) + [(0.0, speed)]
    result = linprog(cost, A_ub=A_ub, b_ub=b_ub, bounds=bounds, method="highs")
    if result.status != 0 or result.x[-1] < 1e-4:
        return None
    return np.asarray(result.x[:m] - result.x[m : 2 * m]), float(result.x[-1])


# -- the soak ---------------------------------------------------------------------------------

STARTS = {"panda": panda_start, "held box": held_box_start, "two pandas": two_pandas_start}
"""The starts' kinds, drawn in turn."""


def soak(starts: int, minutes: float, seed: int = 0,
         progress: Callable[[str], None] = print) -> dict:  # fmt: skip
    """``starts`` random starts (the kinds in turn, from touching to 8 cm deep) and each scene's
    sessions of ``minutes``, positions (seed 7) and turning (seed 8): the soak's JSON body."""
    rng = np.random.default_rng(seed)
    rows = []
    kinds = list(STARTS)
    while len(rows) < starts:
        kind = kinds[len(rows) % len(kinds)]
        start = STARTS[kind](rng, float(rng.uniform(-0.08, 0.0)))
        if start is None:
            continue
        r = start_trial(start, rng)
        rows.append({"kind": kind, "label": start.label, "distance_m": start.distance,
                     **{k: _plain(v) for k, v in r._asdict().items()},
                     "moved_at_once": moved_at_once(r)})  # fmt: skip
        progress(f"start {len(rows)}: {start.label}: {r}")
    sessions = []
    for name in SCENES:
        for turn, session_seed in ((False, 7), (True, 8)):
            s = session(name, 60.0 * minutes, session_seed, turn=turn)
            sessions.append({
                "scene": name, "turning": turn, "seed": session_seed, "ticks": s.ticks,
                "min_distance_m": s.min_distance, "worst_pair": list(s.worst_pair),
                "joint_excess": s.joint_excess, "rate_over_limit": s.rate_over_limit,
                "finite": s.finite, "statuses": s.statuses,
                "linearisation_m": s.linearisation, "fallback_ticks": len(s.fallbacks),
                "fallbacks": [{"tick": t, "nearest_m": d, "attempts": [list(a) for a in why]}
                              for t, d, why in s.fallbacks[:50]],
            })  # fmt: skip
            progress(f"session {name}{' turning' if turn else ''}: {sessions[-1]}")
    away = [r for r in rows if r["away_ticks"]]
    timed = [r for r in away if r["away_speed"] >= AWAY - 1e-9]
    summary = {
        "starts": len(rows),
        "locked": sum(r["fallbacks"] > 0 for r in rows),
        "commanded_away": len(away),
        "moved_at_first_tick": sum(r["moved_at_once"] for r in away),
        "at_full_speed_apart": len(timed),
        "out_within_deadline": sum(r["exit_ticks"] is not None for r in timed),
        "largest_decrease_m": max((r["decrease"] for r in rows), default=0.0),
        "largest_rate_over_limit": max([r["rate_over_limit"] for r in rows]
                                       + [s["rate_over_limit"] for s in sessions]),
        "session_fallback_ticks": sum(s["fallback_ticks"] for s in sessions),
    }
    settings = {"starts": starts, "minutes": minutes, "seed": seed, "dt": DT, "safety": SAFETY,
                "detection": DETECTION, "gain": GAIN, "away_speed": AWAY}  # fmt: skip
    return {"settings": settings, "summary": summary, "starts": rows, "sessions": sessions}


def _plain(value: object) -> object:
    """A JSON value: NaN as None."""
    if isinstance(value, float) and math.isnan(value):
        return None
    return value
