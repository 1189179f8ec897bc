"""Where the time of one rrc-pin step goes, stage by stage, along a recorded trajectory.

Instrumentation, not sampling: for the duration of the profile, the functions that make up
a step are replaced by wrappers that add their ``time.perf_counter`` time to the step's
stage (cProfile's per-call hooks would cost more than the smallest stages). The wrapped
functions are the public entry points of each layer (and the pipeline's top-level helpers),
looked up by name, so that a renamed one is reported as ``missing`` rather than breaking the
benchmark:

- ``step``: the contender's whole call (the total): ``Resolver.solve(q, twist)``, or for
  tasks the FrameTasks' twists set in the call and ``Resolver.solve(q, tasks)`` (``solve``);
- ``q check``: ``Robot.positions`` and ``Robot.configuration``; ``task checks``: the tasks
  and levels checked against the robot (``Resolver._levels``, tasks only);
- ``kinematics``: every joint's Jacobian (``Kinematics``, when a tick needs more than one
  frame) and every frame's pose (when it needs a pose of another frame); ``jacobian`` is one
  frame's (``Kinematics.jacobian``);
- ``task rows``: the tasks' rows (``FrameTask.rows_at`` and every task's ``rows``);
- ``limits``: the limits' constraints (``JointLimits.constraints``: the step's box);
- ``problem``: the problem built (``rrc_pin.solvers.tick.problem.build``);
- ``numerics``: ``rrc_pin.solvers.tick.pipeline.solve``'s own code, of which ``factorization`` (the
QR
  and the SVD on demand), ``direction`` (the direction problem: the exact kernels and the
  QP's build), ``backend`` (the backend's ``solve``, its data conversion included) and
  ``lower levels`` (``rrc_pin.solvers.tick.least_squares.least_squares``);
- ``report``: building the ``Resolution``.

Times are exclusive (self time): a stage's time is what its function spent outside the
other wrapped functions it called, so the stages add up to the step. ``step``'s own time is
building the tasks in the call; ``solve``'s and ``resolve``'s own time is their control flow,
clipping, the direction problem's null space and checks; ``svd`` counts every
factorisation, the lower levels' included. Each wrapped call adds about 0.5 us, which the
recorded ``overhead_us`` (instrumented median minus the plain median, same trajectory)
and the calls per step show. The answers are checked identical to the uninstrumented ones.
"""

from __future__ import annotations

import sys
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import numpy.typing as npt

import rrc_pin.solvers.tick.pipeline as pipeline_module
from rrc_pin import kinematics as kinematics_module
from rrc_pin import tasks as tasks_module
from rrc_pin.limits import JointLimits
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.resolution import Resolution

Array = npt.NDArray[np.float64]

STAGES = {
    "step": "the call's own code: building the tasks (none for one twist)",
    "solve": "Resolver.solve's own code",
    "q check": "Robot.positions and Robot.configuration",
    "task checks": "tasks and levels checked against the robot",
    "kinematics": "every joint's Jacobian and frame's pose (several frames)",
    "jacobian": "one frame's Jacobian (Kinematics.jacobian)",
    "task rows": "the tasks' rows",
    "limits": "the limits' constraints (the step's box)",
    "problem": "rrc_pin.solvers.tick.problem.build",
    "numerics": "rrc_pin.solvers.tick.pipeline.solve's own code (status, clip, checks)",
    "factorization": "QR, least-norm rates, SVD on demand",
    "direction": "the direction problem: exact kernels, QP build",
    "backend": "the backend's solve (its data conversion included)",
    "lower levels": "strict levels (least squares in null spaces)",
    "report": "building the Resolution",
}
"""Every stage (exclusive time) and what it holds, in the order of the profile table."""


class _Stages:
    """Per-step exclusive time of each stage [s], kept with a stack of the running stages."""

    def __init__(self) -> None:
        self.totals: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self._children: list[float] = []  # time spent in wrapped callees, per running stage

    def clear(self) -> None:
        """Start a new step."""
        self.totals.clear()
        self.calls.clear()

    def wrap(self, stage: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        totals, calls, children, clock = self.totals, self.calls, self._children, time.perf_counter

        def timed(*args: Any, **kwargs: Any) -> Any:
            calls[stage] += 1
            children.append(0.0)
            t0 = clock()
            try:
                return fn(*args, **kwargs)
            finally:
                elapsed = clock() - t0
                totals[stage] += elapsed - children.pop()
                if children:
                    children[-1] += elapsed

        return timed


@contextmanager
def _patched(targets: list[tuple[Any, str, str]], stages: _Stages) -> Iterator[list[str]]:
    """Replace ``owner.name`` by its timed wrapper for each (owner, name, stage) present;
    yield the targets that are missing; restore everything on exit."""
    saved: list[tuple[Any, str, Any, bool]] = []
    missing: list[str] = []
    try:
        for owner, name, stage in targets:
            own = name in getattr(owner, "__dict__", {})
            original = (
                owner.__dict__[name]
                if own and isinstance(owner, type)
                else getattr(owner, name, None)
            )
            if original is None:
                where = getattr(owner, "__name__", type(owner).__name__)
                missing.append(f"{stage}: {where}.{name}")
                continue
            saved.append((owner, name, original, own))
            setattr(owner, name, stages.wrap(stage, getattr(owner, name)))
        yield missing
    finally:
        for owner, name, original, own in reversed(saved):
            if own:
                setattr(owner, name, original)
            else:  # an instance attribute shadowing a method: remove it
                delattr(owner, name)


def _targets(resolver: Any, tasks: bool) -> list[tuple[Any, str, str]]:
    """What to wrap: (owner, attribute, stage)."""
    resolver_module = sys.modules[type(resolver).__module__]
    out: list[tuple[Any, str, str]] = [
        (resolver, "solve", "solve"),
        (resolver.robot, "positions", "q check"),
        (resolver.robot, "configuration", "q check"),
        (resolver.backend, "solve", "backend"),
        (kinematics_module.Kinematics, "_compute_joints", "kinematics"),
        (kinematics_module.Kinematics, "_compute_frames", "kinematics"),
        (kinematics_module.Kinematics, "jacobian", "jacobian"),
        (JointLimits, "constraints", "limits"),
        (resolver_module, "build", "problem"),
        (resolver_module, "solve", "numerics"),
        (Factorization, "__init__", "factorization"),
        (Factorization, "least_norm", "factorization"),
        (Factorization, "rates", "factorization"),
        (pipeline_module, "along", "direction"),
        (pipeline_module, "direction_qp", "direction"),
        (pipeline_module, "least_squares", "lower levels"),
        (Resolution, "of", "report"),
    ]
    if not tasks:
        return [*out, (tasks_module.FrameTask, "rows_at", "task rows")]
    out.append((resolver, "_levels", "task checks"))
    for name in sorted(getattr(tasks_module, "__all__", ())):
        kind = getattr(tasks_module, name)
        if isinstance(kind, type) and "rows" in kind.__dict__ and name != "Task":
            out.append((kind, "rows", "task rows"))
    return out


def profile_steps(
    call: Callable[[Array, Array], Any],
    resolver: Any,
    Q: Array,
    X: Array,
    reference: Array,
    *,
    tasks: bool = False,
) -> dict[str, Any]:
    """Stage times of ``call(q, x)`` (which calls ``resolver.solve``) at every step of (Q, X).

    Args:
        call: One step, as the benchmark's contender makes it, returning the Resolution.
        resolver: The fresh :class:`rrc_pin.Resolver` that ``call`` uses.
        Q: Configurations (steps, n) [rad].
        X: Commands (steps, m).
        reference: The rates the same contender gave uninstrumented (steps, n), to check that
            the instrumentation changes nothing.
        tasks: ``call`` passes tasks (else one twist).

    Returns:
        Per route (``all`` steps; ``no backend``: answered without calling the backend, by
        the box-free optimum or a closed-form scale; ``backend``: steps that called it) and
        per stage: mean and median [us] over the steps, the mean's share of the mean step,
        the steps the stage ran in; the routes' step counts, the missing targets, and
        whether the answers are identical to ``reference``.
    """
    stages = _Stages()
    timed_call = stages.wrap("step", call)
    per_step: list[dict[str, float]] = []
    calls: list[dict[str, int]] = []
    routes: list[str] = []
    rates = np.empty_like(reference)
    with _patched(_targets(resolver, tasks), stages) as missing:
        for k, (q, x) in enumerate(zip(Q, X, strict=True)):
            stages.clear()
            r = timed_call(q, x)
            per_step.append(dict(stages.totals))
            calls.append(dict(stages.calls))
            rates[k] = r.qdot
            routes.append("backend" if r.backend else "no backend")
    table = {"all": _table(per_step, calls)}
    for route in ("no backend", "backend"):
        chosen = [k for k, r in enumerate(routes) if r == route]
        if chosen:
            table[route] = _table([per_step[k] for k in chosen], [calls[k] for k in chosen])
    return {
        "method": "time.perf_counter wrappers around each stage's function",
        "steps": {route: routes.count(route) for route in ("no backend", "backend")},
        "stages": table,
        "missing": missing,
        "identical_answers": bool(np.array_equal(rates, reference)),
    }


def _table(
    per_step: list[dict[str, float]], calls: list[dict[str, int]]
) -> dict[str, dict[str, float]]:
    """Mean and median [us] of every stage over the steps (0 where it did not run), its mean's
    share of the mean step, the steps it ran in, its calls per step (mean); ``total`` is the
    whole step."""
    names = sorted({name for step in per_step for name in step})
    columns = {name: np.array([step.get(name, 0.0) for step in per_step]) for name in names}
    columns["total"] = np.sum(list(columns.values()), axis=0)
    total = float(columns["total"].mean())
    out: dict[str, dict[str, float]] = {}
    for name, values in columns.items():
        out[name] = {
            "mean_us": float(values.mean() * 1e6),
            "median_us": float(np.median(values) * 1e6),
            "share": float(values.mean() / total) if total else float("nan"),
            "ran_in": int((values > 0.0).sum()),
            "calls": float(np.mean([c.get(name, 0) for c in calls])),
        }
    out["total"]["calls"] = float(np.mean([sum(c.values()) for c in calls]))
    return out


def profile_table(profile: dict[str, Any], who: str) -> list[str]:
    """Markdown lines of a profile (as :func:`profile_steps` returns it, plus ``plain_median_us``
    and ``overhead_us``): one row per stage, mean [us] and share per route."""
    stages = profile["stages"]
    routes = [r for r in ("all", "no backend", "backend") if r in stages]
    steps = profile["steps"]
    lines = [
        f"Where {who}'s step goes ({profile['method']}, exclusive times; "
        f"{steps.get('no backend', 0)} steps answered without the backend, "
        f"{steps.get('backend', 0)} through it): mean [us] per step and share of the mean "
        f"step, and calls per step (each costs about 0.5 us of instrumentation). "
        f"Uninstrumented median {profile['plain_median_us']:.1f} us, instrumented "
        f"{stages['all']['total']['median_us']:.1f} us (overhead {profile['overhead_us']:.1f} "
        f"us); answers identical: {'yes' if profile['identical_answers'] else 'NO'}."
        + (f" Not found: {', '.join(profile['missing'])}." if profile["missing"] else ""),
        "",
        "| stage | what | calls | " + " | ".join(f"{r}: mean [us] | share" for r in routes) + " |",
        "| --- | --- | ---: |" + " ---: | ---: |" * len(routes),
    ]
    for name, what in [*STAGES.items(), ("total", "the whole call")]:
        if not any(name in stages[r] for r in routes):
            continue
        count = stages["all"].get(name, {}).get("calls", 0.0)
        cells = f"| {'**total**' if name == 'total' else name} | {what} | {count:.2g} |"
        for r in routes:
            row = stages[r].get(name)
            cells += f" {row['mean_us']:.1f} | {100 * row['share']:.0f}% |" if row else " 0 | 0% |"
        lines.append(cells)
    return [*lines, ""]
