"""The resolver against pink's ``solve_ik``: step time as users run it, and limit compliance.

Run from a checkout: ``python benchmarks/bench_resolver.py --out DIR`` (``--record`` writes
``benchmarks/results/`` instead, ``--quick`` a short smoke run, ``--steps N`` the trajectory
length; with neither ``--out`` nor ``--record`` nothing is written). ``rrc-pin bench`` runs it.

One arm at a time (rrc_k1607, panda), one trajectory of joint configurations is recorded
first: from a seeded random start, piecewise-constant random twists (new every 50 steps,
about 0.4 m/s and 0.6 rad/s) are resolved by rrc-pin in tracking mode
(``Resolver(arm, dt, direction_preserving=False)``, DAQP) and integrated with dt = 10 ms, so
that position and velocity limits become active along the way. Then every contender
computes joint rates at every recorded configuration q_k with its twist. A step's time is
the whole call, as its users make it:

- rrc-pin: ``Resolver.solve(q, twist)`` (Pinocchio Jacobian, bounds, one SVD, the QP when
  the box-free optimum leaves the bounds, the Resolution): the default (DAQP,
  direction-preserving), tracking (DAQP, ``direction_preserving=False``), OSQP and every
  other installed backend (direction-preserving);
- pink (``pink.solve_ik``): ``configuration.update(q)``, the FrameTask target set to the
  pose moved by ``twist * dt``, ``solve_ik(..., limits=[ConfigurationLimit(gain=1),
  VelocityLimit])`` with every qpsolvers backend pink accepts. pink raises when its QP has
  no solution (a failure, rates taken as zero);
- mink (``mink.solve_ik``, :mod:`mink_peer`): the arm's URDF loaded into MuJoCo (meshes
  stripped; its tool pose and Jacobian checked against Pinocchio's first, the benchmark
  stops if they differ), the same target pose as pink's, ``ConfigurationLimit`` and
  ``VelocityLimit``, every qpsolvers backend; absent when mink is not installed;
- Pinocchio + numpy, the unconstrained step and physical floor (no limits):
  ``computeFrameJacobian`` then ``numpy.linalg.solve`` on ``J J^T``, ``lstsq``, or damped
  least squares;
- the floor within the limits (:data:`LIMITS_FLOOR`): the least a direction-preserving step
  in the limits does in Python, rrc-pin's default without its damping, checks, fallbacks
  and report (:func:`limits_floor`), what pure Python can reach on this problem.

Each contender is timed in the three modes of :mod:`timing` (tight loop, 1 kHz loop with
``time.sleep`` to the next tick, interleaved with its peers in an order shuffled at each
step), each mode from fresh contenders, :data:`timing.REPEATS` rounds of the three modes
(one with ``--quick``), combined by their medians (:func:`timing.combine_rounds`). Per
contender and mode: median, p10, p90, p99 and mean [us], the ratio to pink's fastest
backend of that mode (its median over the contender's, its p99 over the contender's: above
1, faster than pink), the largest
velocity and position excess, failures; per rrc-pin contender how its steps were answered
(status, method, backend share, active bounds). Then where the default's step time goes:
:mod:`stage_profile` (``time.perf_counter`` wrappers around each stage). BLAS threads are
pinned to one (set before numpy is imported) for both libraries, so that the tiny matrix
products do not pay for thread hand-offs; OSQP's C-level prints are sent to /dev/null.
Results: ``resolver.json`` and ``resolver.png``; :func:`docs_section` and
:func:`readme_table` render them (``update_readme.py``).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import logging  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from collections import Counter  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import mink_peer  # noqa: E402
import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
from machine import load_average, machine_info, source_state  # noqa: E402
from scipy.linalg.lapack import dgesvd  # noqa: E402
from script import QUICK_NOTE, is_quick, make_parser, write  # noqa: E402
from stage_profile import profile_steps, profile_table  # noqa: E402
from timing import (  # noqa: E402
    MODE_TITLES,
    MODES,
    PERIOD,
    REPEATS,
    Contender,
    add_peer_ratios,
    combine_rounds,
    fastest_of,
    mode_table,
    progress,
    quiet_stdout,
    record_trajectory,
    rounds_note,
    run_mode,
    summarise,
    timing_chart,
    us,
)

import rrc_pin  # noqa: E402
from rrc_pin.control.drift import advance  # noqa: E402
from rrc_pin.robot import frame_id  # noqa: E402
from solvers.kernels import joint_box, line_scale, uniform_scale  # noqa: E402
from solvers.qp_backends import installed_backends  # noqa: E402

ARMS = ("rrc_k1607", "panda")
SEED = 20261122
DT = 0.01
SEGMENT = 50
STEPS, QUICK_STEPS = 2000, 100
DEFAULT = "rrc-pin default (daqp, direction)"
TRACKING = "rrc-pin tracking (daqp)"
BACKEND_MODULES = ("daqp", "osqp", "proxsuite", "quadprog", "clarabel")
"""Modules of the QP backends, for the versions recorded."""
FLOOR_DAMPING = 0.01
"""Damping ``lambda`` of the Pinocchio + numpy DLS row (``J^T (J J^T + lambda^2 I)^-1 x``)."""
FLOOR = "Pinocchio + numpy solve (J J^T)"
"""The physical floor: one Pinocchio Jacobian and one small dense solve, no limits."""
LIMITS_FLOOR = "Pinocchio + SVD + exact scale in the limits"
"""The floor within the limits (:func:`limits_floor`)."""

Array = np.ndarray


def rrc_options() -> dict[str, dict[str, Any]]:
    """The rrc-pin contenders: label to Resolver keyword arguments."""
    out: dict[str, dict[str, Any]] = {
        DEFAULT: {},
        TRACKING: {"direction_preserving": False},
    }
    for name in installed_backends():
        if name != "daqp":
            out[f"rrc-pin {name} (direction)"] = {"qp": rrc_pin.QPOptions(backend=name)}
    return out


def rrc_contenders(arm: Any) -> list[Contender]:
    """Fresh rrc-pin resolvers, each calling ``solve(q, twist)``, keeping the Resolutions."""
    out = []
    for label, kwargs in rrc_options().items():
        resolver = rrc_pin.Resolver(arm, dt=DT, **kwargs)
        out.append(Contender(label, resolver.solve, rates=lambda r: r.qdot, keep=True))
    return out


def pink_backends() -> list[str]:
    """The qpsolvers backends pink is run with (every one installed), or [] without pink."""
    try:
        import pink  # noqa: F401
        import qpsolvers
    except ImportError:
        return []
    return list(qpsolvers.available_solvers)


def pink_contenders(arm: Any) -> list[Contender]:
    """pink.solve_ik with every qpsolvers backend, on the same task and limits."""
    if not pink_backends():
        return []
    import pink
    from pink.limits import ConfigurationLimit, VelocityLimit
    from pink.tasks import FrameTask

    logging.getLogger().setLevel(logging.ERROR)  # pink logs every near-limit configuration
    model, frame = arm.model, arm.tool_frame
    out = []
    for solver in pink_backends():
        configuration = pink.Configuration(model, model.createData(), arm.neutral())
        task = FrameTask(frame, position_cost=1.0, orientation_cost=1.0)
        limits = [ConfigurationLimit(model, config_limit_gain=1.0), VelocityLimit(model)]

        def step(
            q: Array,
            x: Array,
            configuration: Any = configuration,
            task: Any = task,
            limits: Any = limits,
            solver: str = solver,
        ) -> Array:
            configuration.update(q)
            T = configuration.get_transform_frame_to_world(frame)
            task.set_target(advance(T, x, DT, local=False))
            return pink.solve_ik(
                configuration, [task], DT, solver=solver, limits=limits, safety_break=False
            )

        out.append(Contender(f"pink {solver}", step))
    return out


def floor_contenders(arm: Any) -> list[Contender]:
    """Pinocchio + numpy, the unconstrained step (no limits): ``computeFrameJacobian``
    (LOCAL_WORLD_ALIGNED) then the minimum-norm rates by ``numpy.linalg.solve`` on
    ``J J^T`` (6 x 6), by ``numpy.linalg.lstsq``, or damped least squares."""
    model = arm.model
    fid = frame_id(model, arm.tool_frame)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    eye = np.eye(6) * FLOOR_DAMPING**2
    d1, d2, d3 = (model.createData() for _ in range(3))  # one workspace per contender

    def jacobian(q: Array, data: Any) -> Array:
        return pin.computeFrameJacobian(model, data, q, fid, lwa)

    def solve(q: Array, x: Array, data: Any = d1) -> Array:
        J = jacobian(q, data)
        return J.T @ np.linalg.solve(J @ J.T, x)

    def lstsq(q: Array, x: Array, data: Any = d2) -> Array:
        return np.linalg.lstsq(jacobian(q, data), x, rcond=None)[0]

    def dls(q: Array, x: Array, data: Any = d3) -> Array:
        J = jacobian(q, data)
        return J.T @ np.linalg.solve(J @ J.T + eye, x)

    return [
        Contender(FLOOR, solve),
        Contender("Pinocchio + numpy lstsq", lstsq),
        Contender(f"Pinocchio + numpy DLS (lambda {FLOOR_DAMPING:g})", dls),
        limits_floor(arm),
    ]


def limits_floor(arm: Any) -> Contender:
    """The least work of a direction-preserving step within the limits, in Python: the
    Jacobian, rrc-pin's step bounds (:func:`solvers.kernels.joint_box`), the SVD's exact
    rates, and where they leave the bounds the largest scale along them, exactly, with one
    null direction (:func:`solvers.kernels.line_scale`) or none (the uniform scale).
    rrc-pin's default answers the same wherever it does not damp; what it does beyond this
    (input checks, the damping near singularities, the fallbacks, the Resolution) is its
    gap to this floor."""
    model = arm.model
    fid = frame_id(model, arm.tool_frame)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    data = model.createData()
    b = step_box(arm)

    def step(q: Array, x: Array) -> Array:
        J = pin.computeFrameJacobian(model, data, q, fid, lwa)
        b.at(q)
        U, s, Vt, _ = dgesvd(J, full_matrices=1)
        m = s.size  # six rows: the rest of Vt spans the null space
        w = (x @ U / s) @ Vt[:m]
        if ((b.lb <= w) & (w <= b.ub)).all():
            return w
        if Vt.shape[0] == m + 1:
            u, y = line_scale(w, Vt[m], b.lb, b.ub)
            return np.minimum(np.maximum(u * w + y * Vt[m], b.lb), b.ub)
        return uniform_scale(w, b.lb, b.ub) * w

    return Contender(LIMITS_FLOOR, step)


class step_box:
    """The step's joint box of ``arm`` (rrc-pin's kernel), its ``lb`` and ``ub`` refreshed by
    :meth:`at`."""

    def __init__(self, arm: Any) -> None:
        n = arm.nq
        self.arm, self.lb, self.ub = arm, np.empty(n), np.empty(n)
        self.kind = np.empty((2, n), np.int8)
        self.none, self.zero = np.array([np.inf]), np.zeros(n)

    def at(self, q: Array) -> None:
        arm = self.arm
        joint_box(q, arm.lower, arm.upper, arm.velocity_limit, 0.0, 1.0, DT, self.zero, self.none,
                  self.lb, self.ub, self.kind)  # fmt: skip


def floor_agreement(default: Any, floor: Any) -> dict[str, Any]:
    """The largest difference [rad/s] between rrc-pin's default and the floor in the limits
    over the steps the default did not damp (there they solve the same problem)."""
    undamped = np.array([r.status != "damped" for r in default.kept])
    diff = np.abs(default.rates - floor.rates)[undamped]
    return {
        "steps": int(undamped.sum()),
        "max_difference": float(diff.max()) if diff.size else None,
    }


def tracking_errors(arm: Any, Q: Array, X: Array, rates: Array) -> dict[str, float]:
    """Relative twist error ``|J(q_k) qdot_k - x_k| / |x_k|`` (rows [v; w], m/s and rad/s
    summed as one vector) along the trajectory: median, p99 and largest."""
    J = np.array([arm.jacobian(q) for q in Q])
    err = np.linalg.norm(np.einsum("kij,kj->ki", J, rates) - X, axis=1)
    rel = err / np.maximum(np.linalg.norm(X, axis=1), 1e-12)
    p50, p99 = np.percentile(rel, [50, 99])
    return {
        "tracking_median": float(p50),
        "tracking_p99": float(p99),
        "tracking_max": float(rel.max()),
    }


def rrc_statistics(resolutions: list[Any]) -> dict[str, Any]:
    """How a contender's steps were answered: status, method and backend counts, active bounds,
    the resolver's own build time (median over every step [us]) and backend solve time
    (median over the steps that called the backend [us]), the largest clip [rad/s]."""
    n = len(resolutions)
    backends = Counter(r.backend for r in resolutions if r.backend)
    solves = [r.solve_time for r in resolutions if r.backend]
    return {
        "steps": n,
        "status": dict(Counter(r.status for r in resolutions).most_common()),
        "method": dict(Counter(r.method for r in resolutions).most_common()),
        "backend_share": sum(backends.values()) / n if n else 0.0,
        "backends": dict(backends.most_common()),
        "active_fraction": sum(bool(r.active) for r in resolutions) / n if n else 0.0,
        "with_attempts": sum(bool(r.attempts) for r in resolutions),
        "build_time_median_us": float(np.median([r.build_time for r in resolutions]) * 1e6),
        "backend_solve_median_us": float(np.median(solves) * 1e6) if solves else 0.0,
        "max_clip": float(max((r.clip for r in resolutions), default=0.0)),
    }


def bench_arm(name: str, steps: int, repeats: int) -> dict[str, Any]:
    """Every contender in every mode along one trajectory of arm ``name``, ``repeats`` rounds
    (:func:`timing.combine_rounds`), then the profile."""
    arm = rrc_pin.load(name)
    progress(f"{name}: recording {steps} steps (rrc-pin tracking)")
    Q, X = record_trajectory(arm, steps, np.random.default_rng(SEED), DT, SEGMENT)
    limits = (arm.lower, arm.upper, arm.velocity_limit)
    shuffle = np.random.default_rng(SEED + 1)
    modes: dict[str, Any] = {}
    rrc: dict[str, Any] = {}
    with_mink = mink_peer.available()
    gap = mink_peer.kinematics_gap(arm) if with_mink else None
    if gap is not None and max(gap.values()) > mink_peer.KINEMATICS_TOL:
        # mink would solve another arm's problem: the comparison would be void.
        raise SystemExit(f"{name}: MuJoCo's kinematics differ from Pinocchio's: {gap}")
    rounds: dict[str, list[dict[str, Any]]] = {mode: [] for mode in MODES}
    for round_ in range(repeats):
        for mode in MODES:
            contenders = rrc_contenders(arm) + pink_contenders(arm)
            if with_mink:
                contenders += mink_peer.mink_contenders(arm, DT)
            contenders += floor_contenders(arm)
            progress(f"{name}: {MODE_TITLES[mode]}, {len(contenders)} contenders, "
                     f"round {round_ + 1} of {repeats}")  # fmt: skip
            with quiet_stdout():  # OSQP's C code prints "Polishing not needed"
                runs = run_mode(mode, contenders, Q, X, shuffle, PERIOD)
            rows = summarise(runs, Q, limits, DT)
            for label, run in runs.items():
                rows[label].update(tracking_errors(arm, Q, X, run.rates))
            add_peer_ratios(rows, "pink ", "baseline")
            add_peer_ratios(rows, "mink ", "mink")
            add_peer_ratios(rows, FLOOR, "floor")
            rounds[mode].append(rows)
            if round_ == 0:  # the answers are the same in every round
                rrc[mode] = {
                    c.label: rrc_statistics(runs[c.label].kept) for c in contenders if c.keep
                }
                agreement = floor_agreement(runs[DEFAULT], runs[LIMITS_FLOOR])
    for mode in MODES:
        rows = combine_rounds(rounds[mode])
        modes[mode] = {
            "pink_fastest": fastest_of(rows, "pink "),
            "mink_fastest": fastest_of(rows, "mink "),
            "floor": FLOOR,
            "contenders": rows,
        }
    progress(f"{name}: profile of the default")
    profile = profile_default(arm, Q, X)
    recorded = rrc["tight"].get(TRACKING, {})
    return {
        "arm": name,
        "nq": arm.nq,
        "tool_frame": arm.tool_frame,
        "trajectory": {
            "steps": steps,
            "recorded_by": "rrc_pin.Resolver(arm, dt, direction_preserving=False) (DAQP)",
            "active_fraction": recorded.get("active_fraction"),
        },
        "mink_kinematics_gap": gap,
        "floor_agreement": agreement,
        "modes": modes,
        "rrc_pin": rrc,
        "profile": profile,
    }


def profile_default(arm: Any, Q: Array, X: Array) -> dict[str, Any]:
    """The default's stage profile (:mod:`stage_profile`), with the plain tight-loop median
    of the same trajectory and the instrumentation's overhead [us]."""
    reference = rrc_pin.Resolver(arm, dt=DT)
    rates = np.array([reference.solve(q, x).qdot for q, x in zip(Q, X, strict=True)])
    plain = rrc_pin.Resolver(arm, dt=DT)
    run = run_mode("tight", [Contender(DEFAULT, plain.solve, lambda r: r.qdot)], Q, X)
    resolver = rrc_pin.Resolver(arm, dt=DT)
    profile = profile_steps(lambda q, x: resolver.solve(q, x), resolver, Q, X, rates)
    profile["plain_median_us"] = float(np.median(run[DEFAULT].seconds) * 1e6)
    profile["overhead_us"] = (
        profile["stages"]["all"]["total"]["median_us"] - profile["plain_median_us"]
    )
    return profile


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write JSON and PNG to --out or (--record) benchmarks/results."""
    parser = make_parser(__doc__, "resolver", f"{QUICK_STEPS} steps per arm")
    parser.add_argument("--steps", type=int, default=None, help=f"trajectory length ({STEPS})")
    parser.add_argument("--arms", nargs="+", default=list(ARMS), help="arms (rrc_k1607 panda)")
    args = parser.parse_args(argv)
    steps = args.steps or (QUICK_STEPS if args.quick else STEPS)
    if steps < 2:
        parser.error("--steps: at least 2")
    if args.record and (
        args.quick
        or steps != STEPS
        or args.arms != list(ARMS)
        or not pink_backends()
        or not mink_peer.available()
    ):
        parser.error(
            f"--record keeps full runs only ({STEPS} steps, every arm, pink and mink installed)"
        )
    warnings.simplefilter("ignore")
    repeats = 1 if args.quick else REPEATS
    start = load_average()
    results: dict[str, Any] = {
        "benchmark": "resolver",
        "machine": machine_info("qpsolvers", "pink", "mink", "mujoco", *BACKEND_MODULES),
        "source": source_state(),
        "settings": {
            "dt": DT,
            "steps": steps,
            "segment": SEGMENT,
            "seed": SEED,
            "period_s": PERIOD,
            "khz_wait": "time.sleep to the next tick",
            "rounds": repeats,
            "quick": bool(args.quick),
            "pink_backends": pink_backends(),
        },
        "notes": [] if pink_backends() else ["pink is not installed: its rows are absent"],
        "arms": [bench_arm(a, steps, repeats) for a in args.arms],
    }
    results["load_average"] = {"start": start, "end": load_average()}
    write(args, "resolver", results, lambda path: plot(results, path))
    print(readme_table(results))
    return 0


# ---- rendering (update_readme.py) -------------------------------------------------------------


def readme_table(results: dict[str, Any]) -> str:
    """The README's table: for each arm, rrc-pin default and tracking against pink's fastest
    backend, median and p99 in each mode, and the ratios (pink's time over rrc-pin's)."""
    head = "| arm | contender |"
    rule = "| --- | --- |"
    for mode in MODES:
        head += f" {MODE_TITLES[mode]}: median / p99 [us] | vs pink |"
        rule += " ---: | ---: |"
    lines = [head, rule]
    for arm in results["arms"]:
        modes = arm["modes"]
        for label in [DEFAULT, TRACKING, "pink fastest", LIMITS_FLOOR]:
            cells = f"| {arm['arm']} | {label} |"
            if label == "pink fastest":
                names = [modes[m]["pink_fastest"] or "-" for m in MODES]
                cells = f"| {arm['arm']} | pink fastest ({', '.join(_short(n) for n in names)}) |"
            for mode in MODES:
                rows = modes[mode]["contenders"]
                key = modes[mode]["pink_fastest"] if label == "pink fastest" else label
                row = rows.get(key) if key else None
                if row is None:
                    cells += " - | - |"
                    continue
                ratio = (
                    "1"
                    if label == "pink fastest"
                    else (
                        f"{row.get('vs_baseline_median', float('nan')):.1f}x / "
                        f"{row.get('vs_baseline_p99', float('nan')):.1f}x"
                    )
                )
                cells += f" {us(row['median_us'])} / {us(row['p99_us'])} | {ratio} |"
            lines.append(cells)
    lines += ["", _setup_line(results)]
    return "\n".join(lines)


def _short(label: str) -> str:
    return label.removeprefix("pink ")


def _setup_line(results: dict[str, Any]) -> str:
    s, m = results["settings"], results["machine"]
    load = results.get("load_average", {})
    arms = ", ".join(
        f"{a['arm']} ({a['nq']} joints, a bound active at "
        f"{100 * (a['trajectory']['active_fraction'] or 0):.0f}% of the steps)"
        for a in results["arms"]
    )
    text = (
        f"{s['steps']} steps of a seeded random teleoperation ({arms}), dt = {1000 * s['dt']:g} "
        "ms. rrc-pin default: `Resolver(arm)` (DAQP, direction-preserving); tracking: "
        "`direction_preserving=False`; pink: `solve_ik` with the same frame task and limits, "
        "its fastest qpsolvers backend in each mode. The floor in the limits: Pinocchio's "
        "Jacobian, rrc-pin's step bounds, the SVD's exact rates and, where they leave the "
        "bounds, their largest scale with the null direction, exactly; no damping, checks, "
        f"fallbacks or report: what plain Python reaches on this problem{_agreement(results)}. "
        "Ratios: pink's time over rrc-pin's or the floor's (above 1: faster), median / p99; "
        f"{rounds_note(s)}. Measured on "
        f"{m['cpu']} ({m['cores']} cores), Python {m['python']}, Pinocchio {m['pinocchio']}, "
        f"pink {m.get('pink')}"
    )
    if load:
        text += (
            f", load average {load['start'][0]:.2f} at the start, {load['end'][0]:.2f} at the end"
        )
    return text + "."


def _agreement(results: dict[str, Any]) -> str:
    """The recorded agreement of the default and the floor, for the setup line ("" if none)."""
    parts = [
        f"{a['arm']} {a['floor_agreement']['max_difference']:.0e} rad/s over "
        f"{a['floor_agreement']['steps']} steps"
        for a in results["arms"]
        if (a.get("floor_agreement") or {}).get("max_difference") is not None
    ]
    return f" (rrc-pin's default where it does not damp: {', '.join(parts)})" if parts else ""


def docs_section(results: dict[str, Any]) -> str:
    """Every table of the resolver benchmark, for docs/benchmarks.md."""
    s = results["settings"]
    lines = [
        f"Trajectories: {s['steps']} steps, dt = {1000 * s['dt']:g} ms, twists new every "
        f"{s['segment']} steps (seed {s['seed']}), recorded by rrc-pin in tracking mode. The "
        "1 kHz loop waits with `time.sleep` until the next 1 ms tick. Ratios: pink's fastest "
        "backend of the same mode (by median) over the contender: its median over the "
        "contender's median, its p99 over the contender's p99 (above 1: faster than pink); "
        f"{rounds_note(s)}.",
        "",
    ]
    for note in results.get("notes", []):
        lines += [f"- {note}", ""]
    for arm in results["arms"]:
        t = arm["trajectory"]
        lines += [
            f"### {arm['arm']} ({arm['nq']} joints, tool frame `{arm['tool_frame']}`)",
            "",
            f"A bound is active in rrc-pin tracking's answer at "
            f"{100 * (t['active_fraction'] or 0):.1f}% of the {t['steps']} steps.",
            "",
        ]
        for mode in MODES:
            baselines = {"pink": "baseline"}
            if arm["modes"][mode].get("mink_fastest"):
                baselines["mink"] = "mink"
            lines += mode_table(arm["modes"][mode], mode, baselines)
        lines += _summary(arm) + _floor_table(arm) + _routes_table(arm)
        lines += profile_table(arm["profile"], "the default")
    return "\n".join(lines)


def _summary(arm: dict[str, Any]) -> list[str]:
    """One sentence per mode: rrc-pin's default and tracking against pink's and mink's
    fastest backends and the floor (ratios, median / p99), and where rrc-pin is behind."""
    out = []
    for mode in MODES:
        m = arm["modes"][mode]
        rows = m["contenders"]
        parts, behind = [], []
        for label in (DEFAULT, TRACKING):
            r = rows.get(label)
            if r is None:
                continue
            cells = []
            for key, who in (("baseline", m.get("pink_fastest")), ("mink", m.get("mink_fastest"))):
                if who and f"vs_{key}_median" in r:
                    med, p99 = r[f"vs_{key}_median"], r[f"vs_{key}_p99"]
                    cells.append(f"{med:.2f}x / {p99:.2f}x {who}'s time")
                    short = "default" if label == DEFAULT else "tracking"
                    stats = [n for n, v in (("median", med), ("p99", p99)) if v < 1]
                    behind += [f"{short} {' and '.join(stats)} vs {who}"] if stats else []
            if "vs_floor_median" in r:
                cells.append(f"the floor is {1 / r['vs_floor_median']:.1f}x faster (median)")
            parts.append(f"{label}: " + ", ".join(cells))
        if not parts:
            continue
        tail = "behind: " + "; ".join(behind) if behind else "ahead of every peer's fastest"
        out.append(f"- {MODE_TITLES[mode]}: " + "; ".join(parts) + f" ({tail}).")
    if not out:
        return []
    return [
        "Summary (ratios: the peer's time over rrc-pin's, median / p99; above 1 rrc-pin is "
        "faster):",
        "",
        *out,
        "",
    ]


def _floor_table(arm: dict[str, Any]) -> list[str]:
    """Tight loop: each contender's gap to the physical floor and its tracking error."""
    m = arm["modes"]["tight"]
    rows = m["contenders"]
    if m.get("floor") not in rows:
        return []
    gap = arm.get("mink_kinematics_gap")
    lines = [
        f"Tight loop against the physical floor ({m['floor']}: one Pinocchio Jacobian and one "
        "6 x 6 solve, no limits): the floor's median over the contender's (below 1: slower "
        "than the floor), and the tracking error |J qdot - x| / |x| (rows [v; w] as one "
        "vector; the limits and the direction-preserving scale make it nonzero by design).",
        "",
        "| contender | median [us] | floor / contender (median) | floor / contender (p99) | "
        "tracking error, median | p99 | max |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for label, r in sorted(rows.items(), key=lambda kv: kv[1]["median_us"]):
        lines.append(
            f"| {label} | {us(r['median_us'])} | {r.get('vs_floor_median', float('nan')):.2f}x | "
            f"{r.get('vs_floor_p99', float('nan')):.2f}x | {r.get('tracking_median', 0):.2g} | "
            f"{r.get('tracking_p99', 0):.2g} | {r.get('tracking_max', 0):.2g} |"
        )
    if gap:
        lines += [
            "",
            "mink runs on the arm's URDF loaded into MuJoCo (meshes stripped); its kinematics "
            f"against Pinocchio's at 50 random configurations: tool position {gap['position']:.1g} "
            f"m, rotation {gap['rotation']:.1g} rad, Jacobian entries {gap['jacobian']:.1g}.",
        ]
    return [*lines, ""]


def _routes_table(arm: dict[str, Any]) -> list[str]:
    stats = arm["rrc_pin"]["tight"]
    statuses = sorted({s for r in stats.values() for s in r["status"]})
    lines = [
        "How rrc-pin's steps were answered (tight loop; the same in every mode): status counts, "
        "share answered by the backend (the rest: the box-free optimum, or a closed-form scale), "
        "steps with a failed attempt (then a fallback answered), the resolver's own times: "
        "its build time (everything but the backend, median over all steps) and the backend's "
        "solve time (median over the steps that called it).",
        "",
        "| contender | " + " | ".join(statuses) + " | backend share | bound active | "
        "failed attempts | build [us] | backend solve [us] |",
        "| --- |" + " ---: |" * (len(statuses) + 5),
    ]
    for label, r in stats.items():
        counts = " | ".join(str(r["status"].get(s, 0)) for s in statuses)
        lines.append(
            f"| {label} | {counts} | {100 * r['backend_share']:.1f}% | "
            f"{100 * r['active_fraction']:.1f}% | {r['with_attempts']} | "
            f"{r['build_time_median_us']:.1f} | {r.get('backend_solve_median_us', 0.0):.1f} |"
        )
    return [*lines, ""]


def plot(results: dict[str, Any], path: Path) -> bool:
    """Median step time per contender, mode and arm (bars), p99 as a tick; False without
    matplotlib (nothing written)."""
    arms = results["arms"]
    panels = [
        ({mode: arm["modes"][mode]["contenders"] for mode in MODES},
         f"{arm['arm']}: one resolved-rate step")
        for arm in arms
    ]  # fmt: skip
    note = QUICK_NOTE if is_quick(results) else None
    return timing_chart(panels, path, (7.5 * len(arms), 6), note=note)


if __name__ == "__main__":
    sys.exit(main())
