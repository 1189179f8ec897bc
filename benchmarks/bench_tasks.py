"""Several tasks on one robot: rrc-pin against pink and PlaCo on baxter's two grippers.

Run from a checkout: ``python benchmarks/bench_tasks.py --out DIR`` (``--record`` writes
``benchmarks/results/``, ``--quick`` a short smoke run, ``--steps N`` the trajectory
length, ``--placo-python PATH`` PlaCo's interpreter; with neither ``--out`` nor ``--record``
nothing is written). ``rrc-pin bench`` runs it. Issue 19's comparison.

The robot: ``rrc_pin.load("baxter")``, 15 joints (head pan and both 7-joint arms, the
fingers fixed at zero). The tasks, the same for every contender: a frame task per gripper
(``left_gripper``, ``right_gripper``) following its own random piecewise-constant twist (new
every 50 steps, about 0.4 m/s and 0.6 rad/s, world axes) and a posture task toward the
neutral configuration with gain k = 1/s. The costs are pink's (frame tasks 1 for position
and orientation, posture 0.1); pink squares them (its objective is ``|W (J Δq + e)|^2``,
W = diag(cost)), rrc-pin's weights and PlaCo's multiply the squared residual, so both are
given cost squared (frame 1, posture 0.01): the same objective. Limits: velocity and
one-step position (pink ``ConfigurationLimit(gain=1)`` and ``VelocityLimit``; PlaCo's joint
and velocity limits).

A trajectory of configurations is recorded with rrc-pin (weighted) from a seeded random
start, dt = 10 ms; then every contender computes the joint rates at every recorded
configuration, as its users call it, the whole call timed:

- rrc-pin weighted: ``solve(q, [FrameTask(left, v_l), FrameTask(right, v_r), posture])``
  (one least squares of the costs); rrc-pin strict: ``solve(q, [[both frame tasks],
  posture], priority="strict")`` (the hands first, one common direction-preserving scale;
  the posture in their null space: a different problem, timed, not compared). The two
  FrameTasks are built in the call, as the README writes it;
- pink: ``configuration.update(q)``, each FrameTask target set to the frame's pose moved by
  ``twist * dt``, the PostureTask (gain ``k dt``) toward neutral, ``solve_ik`` with every
  qpsolvers backend pink accepts; failures (pink raises) count, rates taken as zero;
- PlaCo (:mod:`placo_peer`: its own Pinocchio, in its own interpreter when it cannot share
  ours): two frame tasks with the targets moved by ``twist * dt`` and a joints task;
- the weighted floor (:func:`floor`): rrc-pin weighted's problem with nothing but the
  numerics, what plain Python reaches on it.

Modes (:mod:`timing`): the tight loop and the interleaved one (every contender at every
step, shuffled). When PlaCo runs as a worker process, its call is timed by the worker's
clock and the two processes are pinned to one core for the whole benchmark, so that the
interleaved calls share caches as in one process (and the tight loops are measured under
the same pinning).

Same answers where nothing is constrained: at the steps where no contender's answer is
within 1e-6 rad/s of a bound, rrc-pin weighted and PlaCo solve the same problem (PlaCo's
target errors are exactly ``v dt`` and ``w dt``), compared to 1e-6 rad/s; pink does not:
its frame task's error is ``log6`` of the pose difference in the frame's axes and its
Jacobian carries ``Jlog6``, the same to first order in dt. So pink is compared at smaller
steps as well (the targets moved by ``twist * h``, posture gain ``k h``, for h from 10 ms
to 1 us): its difference from rrc-pin falls as O(h), recorded with the fitted order.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import logging  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
from bench_resolver import BACKEND_MODULES, rrc_statistics, step_box  # noqa: E402
from machine import load_average, machine_info, source_state  # noqa: E402
from placo_peer import PlacoPeer, Worker, placo_checks, placo_python, placo_urdf  # noqa: E402
from render_tasks import FLOOR, MODES, PLACO, STRICT, WEIGHTED, plot, readme_table  # noqa: E402
from render_tasks import docs_section as docs_section  # noqa: E402 (update_readme.py)
from script import make_parser, write  # noqa: E402
from stage_profile import profile_steps  # noqa: E402
from timing import (  # noqa: E402
    MODE_TITLES,
    REPEATS,
    Contender,
    add_peer_ratios,
    combine_rounds,
    fastest_of,
    one_core,
    progress,
    quiet_stdout,
    run_mode,
    summarise,
)

import rrc_pin  # noqa: E402
from rrc_pin import FrameTask, PostureTask  # noqa: E402
from rrc_pin.control.drift import advance  # noqa: E402

ROBOT = "baxter"
SEED = 20261122
DT = 0.01
SEGMENT = 50
STEPS, QUICK_STEPS = 2000, 100
FRAME_COST = 1.0
"""pink's position and orientation cost of each frame task (rrc-pin and PlaCo: its square)."""
POSTURE_COST = 0.1
"""pink's posture cost (rrc-pin and PlaCo: its square)."""
POSTURE_GAIN = 1.0
"""k [1/s]: the posture asks for k (q_ref - q) (pink's gain: k dt)."""
FREE = 1e-6
"""[rad/s] An answer this far inside every bound is unconstrained (equivalence check)."""
SAME = 1e-6
"""[rad/s] Largest difference between answers to the same problem."""
STEP_SIZES = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
"""[s] Steps h at which pink's pose-target answers are compared with the velocity ones."""

Array = np.ndarray


def record_trajectory(robot: Any, steps: int, rng: np.random.Generator) -> tuple[Array, Array]:
    """Configurations (steps, 15) and the two grippers' twists (steps, 12) of an rrc-pin run."""
    resolver = rrc_pin.Resolver(robot, dt=DT)
    posture = _posture(robot)
    left, right = robot.tool_frames
    q = robot.random_q(rng)
    Q = np.empty((steps, robot.nq))
    X = np.empty((steps, 12))
    x = np.zeros(12)
    for k in range(steps):
        if k % SEGMENT == 0:
            x = np.concatenate(
                [
                    np.concatenate([rng.normal(size=3) * 0.23, rng.normal(size=3) * 0.35])
                    for _ in range(2)
                ]
            )
        Q[k], X[k] = q, x
        tasks = [_frame(left, x[:6]), _frame(right, x[6:]), posture]
        q = q + resolver.solve(q, tasks).qdot * DT
    return Q, X


def _posture(robot: Any) -> PostureTask:
    return PostureTask(robot.neutral(), gain=POSTURE_GAIN, weight=POSTURE_COST**2)


def _frame(frame: str, twist: Array) -> FrameTask:
    return FrameTask(frame, twist, weight=FRAME_COST**2)


def rrc_contenders(robot: Any) -> list[Contender]:
    """rrc-pin weighted and strict, fresh, keeping their Resolutions, and the weighted floor."""
    return [rrc_contender(robot, WEIGHTED)[0], rrc_contender(robot, STRICT)[0], floor(robot)]


def floor(robot: Any) -> Contender:
    """The least work of the weighted problem in Python: one Pinocchio pass, the two frame
    Jacobians and the posture rows stacked with the square roots of their weights, rrc-pin's
    step bounds, the normal equations' optimum, and DAQP on the same costs where it leaves the
    bounds. rrc-pin weighted solves the same problem (with a 1e-6 least-norm term in its QP);
    what it does beyond this (the tasks' objects and checks, the fallbacks, the Resolution)
    is its gap to this floor."""
    import daqp

    model, data = robot.model, robot.model.createData()
    frames = [model.getFrameId(f) for f in robot.tool_frames]
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    s = step_box(robot)
    n, target = robot.nq, robot.neutral()
    A = np.zeros((12 + n, n))
    A[12:] = np.eye(n) * POSTURE_COST
    sense = np.zeros(n, dtype=np.intc)

    def step(q: Array, x: Array) -> Array:
        q, q_pin = robot.configuration(q)
        pin.computeJointJacobians(model, data, q_pin)
        pin.updateFramePlacements(model, data)
        for k, frame in enumerate(frames):
            A[6 * k : 6 * k + 6] = pin.getFrameJacobian(model, data, frame, lwa)
        b = np.concatenate([x, POSTURE_COST * POSTURE_GAIN * (target - q)])
        P, c = A.T @ A, b @ A
        w = np.linalg.solve(P, c)
        s.at(q)
        if ((s.lb <= w) & (w <= s.ub)).all():
            return w
        return daqp.solve(P, -c, np.zeros((0, n)), s.ub, s.lb, sense)[0]

    return Contender(FLOOR, step)


def rrc_contender(robot: Any, label: str) -> tuple[Contender, Any]:
    """A fresh rrc-pin contender (weighted or strict) and its Resolver."""
    left, right = robot.tool_frames
    posture = _posture(robot)
    resolver = rrc_pin.Resolver(robot, dt=DT)

    def one_qp(q: Array, x: Array) -> Any:
        return resolver.solve(q, [_frame(left, x[:6]), _frame(right, x[6:]), posture])

    def levels(q: Array, x: Array) -> Any:
        stack: list[Any] = [[_frame(left, x[:6]), _frame(right, x[6:])], posture]
        return resolver.solve(q, stack, priority="strict")

    call = one_qp if label == WEIGHTED else levels
    return Contender(label, call, lambda r: r.qdot, keep=True), resolver


def profile(robot: Any, label: str, Q: Array, X: Array) -> dict[str, Any]:
    """Stage profile of an rrc-pin contender (:mod:`stage_profile`), with its plain tight-loop
    median on the same trajectory and the instrumentation's overhead [us]."""
    reference, _ = rrc_contender(robot, label)
    rates = np.array([reference.call(q, x).qdot for q, x in zip(Q, X, strict=True)])
    plain, _ = rrc_contender(robot, label)
    run = run_mode("tight", [plain], Q, X)[label]
    contender, resolver = rrc_contender(robot, label)
    out = profile_steps(contender.call, resolver, Q, X, rates, tasks=True)
    out["plain_median_us"] = float(np.median(run.seconds) * 1e6)
    out["overhead_us"] = out["stages"]["all"]["total"]["median_us"] - out["plain_median_us"]
    return out


def pink_backends() -> list[str]:
    """The qpsolvers backends pink is run with (every one installed), or [] without pink."""
    try:
        import pink  # noqa: F401
        import qpsolvers
    except ImportError:
        return []
    return list(qpsolvers.available_solvers)


def pink_step(robot: Any, solver: str, h: float = DT) -> Any:
    """One pink solver of the same problem: ``step(q, x)`` -> rates, with step ``h`` [s]."""
    import pink
    from pink.limits import ConfigurationLimit, VelocityLimit
    from pink.tasks import FrameTask as PinkFrameTask
    from pink.tasks import PostureTask as PinkPostureTask

    model = robot.model
    configuration = pink.Configuration(model, model.createData(), robot.neutral())
    frames = list(robot.tool_frames)
    hands = [
        PinkFrameTask(f, position_cost=FRAME_COST, orientation_cost=FRAME_COST) for f in frames
    ]
    posture = PinkPostureTask(cost=POSTURE_COST, gain=POSTURE_GAIN * h)
    posture.set_target(robot.neutral())
    tasks = [*hands, posture]
    limits = [ConfigurationLimit(model, config_limit_gain=1.0), VelocityLimit(model)]

    def step(q: Array, x: Array) -> Array:
        configuration.update(q)
        for i, (frame, task) in enumerate(zip(frames, hands, strict=True)):
            T = configuration.get_transform_frame_to_world(frame)
            task.set_target(advance(T, x[6 * i : 6 * i + 6], h, local=False))
        return pink.solve_ik(
            configuration, tasks, h, solver=solver, limits=limits, safety_break=False
        )

    return step


def pink_contenders(robot: Any) -> list[Contender]:
    """pink.solve_ik with every qpsolvers backend, fresh."""
    logging.getLogger().setLevel(logging.ERROR)  # pink logs every near-limit configuration
    return [Contender(f"pink {s}", pink_step(robot, s)) for s in pink_backends()]


# ---- PlaCo ------------------------------------------------------------------------------------


def placo_peer(robot: Any, where: str, urdf: Path) -> Any:
    """A fresh PlaCo peer, in-process or in a worker."""
    config = {
        "urdf": str(urdf),
        "joints": list(robot.joint_names),
        "frames": list(robot.tool_frames),
        "dt": DT,
        "frame_weight": FRAME_COST**2,
        "posture_weight": POSTURE_COST**2,
        "posture_gain": POSTURE_GAIN,
        "q_ref": robot.neutral().tolist(),
    }
    return PlacoPeer(**config) if where == "in-process" else Worker(where, config)


# ---- the benchmark ----------------------------------------------------------------------------


def limit_slack(Q: Array, rates: Array, robot: Any) -> Array:
    """Per step, how far inside every bound the answer is (rad/s; negative: outside)."""
    vmax = robot.velocity_limit
    up = np.minimum(vmax, (robot.upper - Q) / DT)
    low = np.maximum(-vmax, (robot.lower - Q) / DT)
    return np.minimum(up - rates, rates - low).min(axis=1)


def equivalence(
    robot: Any,
    Q: Array,
    X: Array,
    rates: dict[str, Array],
    resolutions: list[Any],
    regularization: float | None,
) -> dict[str, Any]:
    """Where nothing is constrained: each peer's rates against rrc-pin weighted's (module
    docstring), PlaCo's also against rrc-pin with PlaCo's regularisation as a DampingTask,
    and pink's at smaller steps h."""
    ours = rates[WEIGHTED]
    free = (limit_slack(Q, ours, robot) > FREE) & np.array(
        [r.method == "qp" and not r.backend for r in resolutions]
    )
    out: dict[str, Any] = {
        "free_steps": int(free.sum()),
        "free_margin": FREE,
        "tolerance": SAME,
        "peers": {},
    }
    for label, theirs in rates.items():
        if label in (WEIGHTED, STRICT):
            continue
        with np.errstate(invalid="ignore"):  # NaN rates: a failed step, never "inside"
            both = free & (limit_slack(Q, theirs, robot) > FREE)
        out["peers"][label] = {"steps": int(both.sum()), **_differences(theirs, ours, both)}
        out["peers"][label]["same_problem"] = label in (PLACO, FLOOR)
        if label == PLACO and regularization and both.any():
            damped = _with_damping(robot, Q, X, both, regularization)
            out["peers"][label]["with_damping_task"] = {
                "weight": regularization,
                **_differences(theirs, damped, both),
            }
    steps = np.flatnonzero(free)
    picks = np.linspace(0, steps.size - 1, min(40, steps.size)).astype(int)
    chosen = steps[picks] if steps.size else steps
    convergence: dict[str, Any] = {}
    with quiet_stdout():
        for solver in pink_backends():
            worst = []
            for h in STEP_SIZES:
                step = pink_step(robot, solver, h)
                d = 0.0
                for k in chosen:
                    try:
                        d = max(d, float(np.abs(step(Q[k], X[k]) - ours[k]).max()))
                    except Exception:  # pink raised: no comparison at this step
                        d = float("nan")
                worst.append(d)
            order = _order(STEP_SIZES[:3], worst[:3])
            convergence[f"pink {solver}"] = {"max_difference": worst, "order": order}
    out["pink_step_sizes"] = {"steps": len(chosen), "h": list(STEP_SIZES), "pink": convergence}
    return out


def _differences(theirs: Array, ours: Array, where: Array) -> dict[str, float | None]:
    """Largest and median (over the steps) of the largest joint-rate difference [rad/s]."""
    if not where.any():
        return {"max_difference": None, "median_difference": None}
    diff = np.abs(theirs[where] - ours[where]).max(axis=1)
    return {"max_difference": float(diff.max()), "median_difference": float(np.median(diff))}


def _with_damping(robot: Any, Q: Array, X: Array, where: Array, weight: float) -> Array:
    """rrc-pin weighted's rates with a DampingTask of ``weight`` added, at the steps ``where``.

    PlaCo's regularisation ``r |Δq|^2`` is, in rates (Δq = qdot dt, every term of its
    objective scaled by dt^2 alike), a DampingTask of weight r: the same problem exactly.
    """
    left, right = robot.tool_frames
    tasks = [_posture(robot), rrc_pin.DampingTask(weight)]
    out = np.zeros_like(Q)
    for k in np.flatnonzero(where):
        resolver = rrc_pin.Resolver(robot, dt=DT)
        out[k] = resolver.solve(
            Q[k], [_frame(left, X[k, :6]), _frame(right, X[k, 6:]), *tasks]
        ).qdot
    return out


def _order(h: tuple[float, ...], d: list[float]) -> float | None:
    """Slope of log(difference) against log(h) (least squares), None where undefined."""
    x, y = np.log(h), np.log(np.asarray(d, dtype=float))
    if not np.isfinite(y).all():
        return None
    return float(np.polyfit(x, y, 1)[0])


def _with_ratios(rows: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """``rows`` of one round with every row's ratios to pink's fastest and to PlaCo."""
    add_peer_ratios(rows, "pink ")
    add_peer_ratios(rows, PLACO, "placo")
    return rows


def bench(steps: int, placo_where: str | None, placo_why: str, repeats: int) -> dict[str, Any]:
    """Every contender in every mode along one baxter trajectory, ``repeats`` rounds
    (:func:`timing.combine_rounds`), then the checks."""
    robot = rrc_pin.load(ROBOT)
    progress(f"{ROBOT}: recording {steps} steps (rrc-pin weighted)")
    Q, X = record_trajectory(robot, steps, np.random.default_rng(SEED))
    limits = (robot.lower, robot.upper, robot.velocity_limit)
    shuffle = np.random.default_rng(SEED + 1)
    folder = Path(tempfile.mkdtemp(prefix="rrc-pin-placo-"))
    placo: dict[str, Any] = {"where": placo_where, "note": placo_why}
    modes: dict[str, Any] = {}
    rrc: dict[str, Any] = {}
    kept_rates: dict[str, Array] = {}
    kept_resolutions: list[Any] = []
    urdf = placo_urdf(robot, folder) if placo_where else None
    try:
        peer = placo_peer(robot, placo_where, urdf) if placo_where and urdf else None
        if peer is not None:
            placo["info"] = peer.info()
            placo["checks"] = placo_checks(robot, peer, np.random.default_rng(SEED + 2))
        pids = [peer.process.pid] if isinstance(peer, Worker) else []
        with one_core(pids) as cpu:
            placo["pinned_to_cpu"] = cpu
            rounds: dict[str, list[dict[str, Any]]] = {mode: [] for mode in MODES}
            for round_ in range(repeats):
                for mode in MODES:
                    contenders = rrc_contenders(robot) + pink_contenders(robot)
                    if peer is not None:
                        if round_ or mode != MODES[0]:  # a fresh peer per mode, as the others
                            _close(peer)
                            peer = placo_peer(robot, placo_where, urdf)  # type: ignore[arg-type]
                            if isinstance(peer, Worker) and cpu is not None:
                                os.sched_setaffinity(peer.process.pid, {cpu})
                        contenders.append(
                            Contender(PLACO, peer.timed_step, remote=True, loop=peer.loop)
                        )
                    progress(f"{ROBOT}: {MODE_TITLES[mode]}, {len(contenders)} contenders, "
                             f"round {round_ + 1} of {repeats}")  # fmt: skip
                    with quiet_stdout():
                        runs = run_mode(mode, contenders, Q, X, shuffle)
                    rounds[mode].append(_with_ratios(summarise(runs, Q, limits, DT)))
                    if round_:
                        continue  # the answers are the same in every round
                    rrc[mode] = {
                        c.label: rrc_statistics(runs[c.label].kept) for c in contenders if c.keep
                    }
                    if mode == "tight":  # rates NaN where the call failed (not compared)
                        kept_rates = {
                            label: np.where(run.failed[:, None], np.nan, run.rates)
                            for label, run in runs.items()
                        }
                        kept_resolutions = runs[WEIGHTED].kept
            for mode in MODES:
                rows = combine_rounds(rounds[mode])
                modes[mode] = {"pink_fastest": fastest_of(rows, "pink "), "contenders": rows}
        if peer is not None:
            _close(peer)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    progress(f"{ROBOT}: profiles of rrc-pin weighted and strict")
    profiles = {label: profile(robot, label, Q, X) for label in (WEIGHTED, STRICT)}
    progress(f"{ROBOT}: equivalence where nothing is constrained")
    return {
        "robot": ROBOT,
        "nq": robot.nq,
        "frames": list(robot.tool_frames),
        "trajectory": {
            "steps": steps,
            "recorded_by": "rrc-pin weighted",
            "active_fraction": rrc["tight"][WEIGHTED]["active_fraction"],
        },
        "modes": modes,
        "rrc_pin": rrc,
        "placo": placo,
        "equivalence": equivalence(
            robot,
            Q,
            X,
            kept_rates,
            kept_resolutions,
            placo.get("info", {}).get("regularization"),
        ),
        "profiles": profiles,
    }


def _close(peer: Any) -> None:
    if isinstance(peer, Worker):
        peer.close()


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write JSON and PNG to --out or (--record) benchmarks/results."""
    parser = make_parser(__doc__, "tasks", f"{QUICK_STEPS} steps")
    parser.add_argument("--steps", type=int, default=None, help=f"trajectory length ({STEPS})")
    parser.add_argument("--placo-python", default=None, help="PlaCo's interpreter")
    args = parser.parse_args(argv)
    steps = args.steps or (QUICK_STEPS if args.quick else STEPS)
    if steps < 2:
        parser.error("--steps: at least 2")
    if args.record and (args.quick or steps != STEPS or not pink_backends()):
        parser.error(f"--record keeps full runs only ({STEPS} steps, pink installed)")
    warnings.simplefilter("ignore")
    placo_where, placo_why = placo_python(args.placo_python)
    progress(f"PlaCo: {placo_why}")
    repeats = 1 if args.quick else REPEATS
    start = load_average()
    notes = [] if pink_backends() else ["pink is not installed: its rows are absent"]
    if placo_where is None:
        notes.append(placo_why)
    results: dict[str, Any] = {
        "benchmark": "tasks",
        "machine": machine_info("qpsolvers", "pink", *BACKEND_MODULES),
        "source": source_state(),
        "settings": {
            "dt": DT,
            "steps": steps,
            "segment": SEGMENT,
            "seed": SEED,
            "frame_cost": FRAME_COST,
            "posture_cost": POSTURE_COST,
            "posture_gain": POSTURE_GAIN,
            "weights": {"frame": FRAME_COST**2, "posture": POSTURE_COST**2},
            "quick": bool(args.quick),
            "rounds": repeats,
            "pink_backends": pink_backends(),
        },
        "notes": notes,
        **bench(steps, placo_where, placo_why, repeats),
    }
    results["load_average"] = {"start": start, "end": load_average()}
    write(args, "tasks", results, lambda path: plot(results, path))
    print(readme_table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
