"""Generate docs/benchmarks.md and the README's performance section from the recorded results.

Run from a checkout after the benchmarks: ``python benchmarks/update_readme.py``. Every
number comes from ``benchmarks/results/<name>.json``, rendered by the benchmark script's own
``docs_section`` (every table, for docs/benchmarks.md) and ``readme_table`` (the short
tables between the README's markers ``<!-- performance:start -->`` and
``<!-- performance:end -->``); nothing is typed. ``--results DIR --docs FILE --no-readme``
renders another run (what ``rrc-pin bench --out DIR`` does) without touching the checkout.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # the scripts import their shared modules (machine, timing...)
ROOT = HERE.parent
README = ROOT / "README.md"
DOCS = ROOT / "docs" / "benchmarks.md"
RESULTS = HERE / "results"
START, END = "<!-- performance:start -->", "<!-- performance:end -->"
BENCHMARKS = {
    "closed_form": ("bench_closed_form.py", "Closed forms against Pinocchio + numpy"),
    "resolver": (
        "bench_resolver.py",
        "One frame in the limits: rrc-pin, PlaCo, Drake, pink and mink in one process",
    ),
    "tasks": ("bench_tasks.py", "Two grippers and a posture on baxter: rrc-pin and its peers"),
    "study": (
        "bench_study.py",
        "Sampling time and velocity conversions (Nguyen & Zhou section 5)",
    ),
    "scaling": ("bench_scaling.py", "Scaling: batch size and degrees of freedom"),
    "controller": ("bench_controller.py", "Teleoperation controller: tick time and sessions"),
    "control_schemes": (
        "bench_control_schemes.py",
        "Control schemes on Pinocchio dynamics (Nguyen & Zhou section 6)",
    ),
    "maps": ("bench_maps.py", "Capability maps: samples per second per core, workers, queries"),
    "collision": (
        "bench_collision.py",
        "Collision avoidance on two facing pandas: rrc-pin, mink, pink",
    ),
    "cells": ("bench_cells.py", "Multi-arm cells: one controller tick on gsfc_dual and yeh_tripod"),
}
"""Benchmark name: (script, title), in the order of the documents."""
DOCS_ONLY = ("study", "scaling", "control_schemes")
"""Rendered in docs/benchmarks.md only, not in the README's performance section."""
SCHEMES_DOC = ROOT / "docs" / "control_schemes.md"
SCHEMES_START, SCHEMES_END = "<!-- control-schemes:start -->", "<!-- control-schemes:end -->"
"""docs/control_schemes.md's results section: ``bench_control_schemes.markdown`` of the JSON."""

MODES_TEXT = """\
A step's time is the whole call a user makes (a library, a backend, a set of options: a
*contender*), timed with `time.perf_counter` along a recorded trajectory, every contender in
the same process, in up to three modes (`benchmarks/timing.py`), each from fresh contenders
(warm starts carry from step to step within a mode, as in a control loop; one untimed call at
the first step before timing):

- **tight loop**: one contender at a time, every step back to back: caches, branch
  predictors and the CPU clock stay hot for that contender (what a micro-benchmark measures);
- **interleaved**: at every step every contender is called once, in an order drawn at random
  at each step, so each call finds the caches its peers left (one process running several
  libraries);
- **1 ms of other work between calls** (the peers comparison): one contender at a time, and
  after each call 1 ms of numpy products and Pinocchio kinematics of another model, as a
  controller does between ticks: each call finds its caches cooled, on a busy core.

In the tight and other-work modes the contenders take turns of 250 steps, in an order
rotated at every turn, so that the machine's load drifting over the run meets every
contender alike. The first calls of a turn find the caches of the previous contender
(rrc-pin's panda tick: 128 us on the first call after other work, 18 on the second, 11 on
the third, 8-10 after): the tight mode leaves the first 5 calls of every turn out of its
statistics, for every contender; the other two modes measure calls with cooled caches. The
collision and cells benchmarks run closed loops (each contender its own state) in the tight
and interleaved modes the same way. Statistics per contender and mode: median, 10th, 90th
and 99th percentiles and mean [us]; ratios to a peer measured in the same run, mode and
round (the peer's time over the contender's: above 1, the contender is faster); the largest
excess over the velocity limits and over the position limits after one Euler step; failures
(the library raised; its rates taken as zero). BLAS threads are pinned to one for every
library (the matrices are tiny). The machine is shared: the load average (1 minute) at the
start and end of each benchmark is recorded. It counts the benchmark's own process too: a
benchmark that runs right after another one starts at about 1 on its own, and ends near 1
plus what other processes add; those inflate the tails more than the medians. On a machine
with more runnable processes than cores, a call that loses its core waits a scheduler time
slice (about 4 ms): the p99 then measures the machine, not the library."""

PEERS_TEXT = """\
PlaCo 0.10 pins `pin==3.8.0`, so the comparison of rrc-pin with PlaCo, pink, mink and Drake
(`bench_resolver.py`, `bench_tasks.py`) runs in an environment of its own where all of them
and rrc-pin import together (rrc-pin needs `pin>=3.0`: pip resolves it to PlaCo's 3.8.0).
From a checkout, with Python 3.11 (the versions recorded below):

```
python3.11 -m venv .venv-peers
.venv-peers/bin/pip install -e ".[bench]" "placo==0.10.2" "drake==1.51.1"
.venv-peers/bin/python -c "import placo, pink, mink, mujoco, pydrake, numba, daqp, rrc_pin"
.venv-peers/bin/rrc-pin bench --only resolver --out peers-run
.venv-peers/bin/rrc-pin bench --only tasks --out peers-run
```

`--record` instead of `--out DIR` rewrites `benchmarks/results/`. Run without `-e` install, the
scripts take the checkout from `PYTHONPATH=.`: `PYTHONPATH=. .venv-peers/bin/python
benchmarks/bench_resolver.py --out DIR`. A full run refuses to start where a peer does not
import, naming it and what to install; `--quick` (the smoke run the CI makes in the bench
extra, where PlaCo and Drake are absent) runs without them and records each as "not in this
environment", never as run. Each run prints its seed (fresh unless `--seed S` is given) and
records it.

How to read the comparison: every ratio is PlaCo's time over the contender's, taken within
one round and mode on the same trajectory (above 1: faster than PlaCo); the median's range
over the rounds shows how far the shared machine moved the numbers. Read the medians and
their ratios first: on a machine with more runnable processes than its 2 cores (the load
average recorded), a p99 of several milliseconds is a call that lost its core for a
scheduler time slice, whoever the contender. The answers' tables say what each library
does with the same command: PlaCo, pink and mink solve a least squares of the pose error (a
command they cannot meet is traded against the limits: it veers), rrc-pin's default and
Drake keep its direction and scale its speed; the LP maximum scale along the command
(`benchmarks/quality.py`) is the best speed any answer could reach in the step's box."""


def load_module(name: str) -> ModuleType:
    """The benchmark script ``name`` imported as a module (for its renderers)."""
    script = BENCHMARKS[name][0]
    spec = importlib.util.spec_from_file_location(f"_bench_{name}", HERE / script)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot import {HERE / script}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def recorded(results: Path) -> dict[str, dict[str, Any]]:
    """The results found in ``results`` (name -> the JSON's content)."""
    out = {}
    for name in BENCHMARKS:
        path = results / f"{name}.json"
        if path.exists():
            out[name] = json.loads(path.read_text())
    return out


def render_readme(results: Path) -> str:
    """The README's performance section (between the markers)."""
    found = recorded(results)
    parts = []
    for name, (script, title) in BENCHMARKS.items():
        if name in DOCS_ONLY:
            continue
        if name not in found:
            parts.append(f"### {title}\n\nNot recorded yet: run `rrc-pin bench --record`.\n")
            continue
        table = load_module(name).readme_table(found[name]).strip()
        parts.append(f"### {title}\n\n{table}\n\nRecorded by `benchmarks/{script}`.\n")
    parts.append(
        "Every table, the modes, the profile of a step and the machine: `docs/benchmarks.md`.\n"
    )
    return "\n".join(parts)


def render_docs(results: Path, docs: Path) -> str:
    """docs/benchmarks.md: how the benchmarks measure, the machine, every table."""
    found = recorded(results)
    plots = Path(os.path.relpath(results, docs.parent))
    lines = [
        "# Benchmarks",
        "",
        "Generated by `python benchmarks/update_readme.py` from "
        f"`{_shown(results)}/*.json`; do not edit by hand. Rerun on your machine with "
        "`rrc-pin bench` (writes a new folder, never the recorded results) or "
        "`rrc-pin bench --record` (rewrites `benchmarks/results/`, this file and the "
        "README's table); `--only " + "|".join(BENCHMARKS) + "`, `--quick` for a smoke run.",
        "",
        "## How a step is timed",
        "",
        MODES_TEXT,
        "",
    ]
    lines += ["## The peers' environment", "", PEERS_TEXT, ""]
    if found:
        lines += ["## Machine, versions, load", "", *_machine_table(found), ""]
        lines += ["## Closing note", "", *closing_note(found), ""]
    for name, (script, title) in BENCHMARKS.items():
        lines += [f"## {title}", ""]
        if name not in found:
            lines += [f"Not recorded: run `python benchmarks/{script}`.", ""]
            continue
        module = load_module(name)
        doc = (module.__doc__ or "").strip().split("\n\n")
        lines += [
            f"Recorded by `benchmarks/{script}`: {doc[0].rstrip('.')}.",
            "",
            module.docs_section(found[name]).strip(),
            "",
        ]
        if (results / f"{name}.png").exists():
            lines += [f"![{title}]({(plots / f'{name}.png').as_posix()})", ""]
    return "\n".join(lines).rstrip() + "\n"


def closing_note(found: dict[str, dict[str, Any]]) -> list[str]:
    """The recorded ratios in a few lines: closed forms against Pinocchio + numpy, batch
    against loop, the resolver against pink's and mink's fastest, the study's conclusion,
    the largest gap to the physical floor (each from its own JSON; "not recorded" if absent)."""
    out = []
    cf = found.get("closed_form")
    if cf:
        out.append(
            "- Closed forms against Pinocchio + numpy (one call, median): "
            + ", ".join(f"{a['arm']} {a['scalar']['speedup']:.2f}x" for a in cf["arms"])
            + "; batch against a Python loop (N = "
            + f"{cf['sizes']['n_batch']:,}): "
            + ", ".join(f"{a['arm']} {a['batch']['speedup']:.0f}x" for a in cf["arms"])
            + "."
        )
    for name, key in (("resolver", "arms"), ("tasks", None)):
        res = found.get(name)
        if not res or res.get("schema", 1) < 3:
            continue
        for part in res[key] if key else [res]:
            rows = part["modes"]
            cells = []
            for mode in rows:
                for label, r in rows[mode]["contenders"].items():
                    if label.startswith("rrc-pin") and "vs_placo_median" in r:
                        cells.append(f"{label}, {mode}: {r['vs_placo_median']:.2f}x / "
                                     f"{r['vs_placo_p99']:.2f}x")  # fmt: skip
            what = part.get("arm") or part.get("robot")
            out.append(
                f"- {what}, PlaCo's time over rrc-pin's (median / p99; above 1 rrc-pin is "
                "faster): " + ("; ".join(cells) or "PlaCo not in this recording") + "."
            )
    study = found.get("study")
    if study:
        match = next((r for r in study["by_speed"] if r.get("report_match")), None)
        if match:
            out.append(
                "- Sampling-time study (Nguyen & Zhou section 5): the errors are first order in "
                "the sampling time (a half-sample lag); the report's 0.5 in/s at 10 ms is a path "
                f"with a peak tool acceleration of {match['accel']:.1f} m/s^2, and 10 ms is the "
                "longest period only for such paths: dt <= 2 e_max / a_max."
            )
    scaling = found.get("scaling")
    if scaling:
        worst = max(scaling["dof"], key=lambda r: r["median_us"] / r["floor_median_us"])
        out.append(
            "- Largest ratio to the unconstrained reference (one Pinocchio Jacobian and one "
            f"numpy solve, no limits, same run): {worst['arm']} ({worst['nq']} joints), the "
            "resolver's "
            f"{worst['median_us']:.0f} us against {worst['floor_median_us']:.0f} us "
            f"({worst['median_us'] / worst['floor_median_us']:.1f}x); every arm: "
            + ", ".join(
                f"{r['arm']} {r['median_us'] / r['floor_median_us']:.1f}x" for r in scaling["dof"]
            )
            + "."
        )
    mp = found.get("maps")
    if mp:
        panda = [c for c in mp["cases"] if c["arm"] == "panda"]
        out.append(
            "- Capability maps, samples per CPU-second of one thread: "
            + ", ".join(
                f"{c['label']} {c['per_core_per_s'] / 1e3:,.0f} k ({c['vs_pinocchio_loop']:.1f}x "
                "Pinocchio in a loop)"
                for c in panda
            )
            + f"; 1 -> 2 workers {mp['scaling']['speedup']:.2f}x."
        )
    ctl = found.get("controller")
    if ctl:
        target = 100 * ctl["settings"]["target_overhead"]
        out.append(
            "- Teleoperation controller: its overhead over a bare `Resolver.solve` + Euler loop "
            "(interleaved, share of the controller's median step): "
            + ", ".join(f"{a['arm']} {100 * a['overhead_median']:.0f} %" for a in ctl["arms"])
            + f" (issue 8's target: under {target:.0f} %)."
        )
    return out or ["Nothing recorded yet."]


def _shown(path: Path) -> str:
    try:
        return path.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return str(path)


def _machine_table(found: dict[str, dict[str, Any]]) -> list[str]:
    keys = [
        ("cpu", "CPU"),
        ("cores", "cores"),
        ("python", "Python"),
        ("numpy", "numpy"),
        ("pinocchio", "Pinocchio"),
        ("placo", "PlaCo"),
        ("pink", "pink"),
        ("mink", "mink"),
        ("mujoco", "MuJoCo"),
        ("pydrake", "Drake"),
        ("qpsolvers", "qpsolvers"),
        ("daqp", "daqp"),
        ("osqp", "osqp"),
        ("proxsuite", "proxsuite"),
        ("quadprog", "quadprog"),
        ("clarabel", "clarabel"),
        ("numba", "numba"),
        ("dask", "Dask"),
        ("zarr", "zarr"),
        ("blas_threads", "BLAS threads"),
    ]
    names = list(found)
    lines = ["| | " + " | ".join(names) + " |", "| --- |" + " --- |" * len(names)]
    for key, title in keys:
        values = [found[n]["machine"].get(key, "-") for n in names]
        if all(v in (None, "-") for v in values):
            continue
        lines.append(
            f"| {title} | " + " | ".join("-" if v is None else str(v) for v in values) + " |"
        )
    loads = []
    for n in names:
        load = found[n].get("load_average") or found[n]["machine"].get("load_average")
        if isinstance(load, dict):
            loads.append(f"{load['start'][0]:.2f} -> {load['end'][0]:.2f}")
        elif load:
            loads.append(f"{load[0]:.2f} -> {load[1]:.2f}")
        else:
            loads.append("-")
    lines.append("| load average (1 min), start -> end | " + " | ".join(loads) + " |")
    code = []
    for n in names:
        s = found[n].get("source", {})
        text = f"{s.get('commit') or '-'}"
        if s.get("uncommitted_changes"):
            text += " + uncommitted: " + ", ".join(s.get("changed_files") or ["some files"])
        code.append(f"{text} (sources {s.get('source_sha256', '-')})" if s else "-")
    lines.append("| code measured (rrc_pin/, solvers/) | " + " | ".join(code) + " |")
    return lines


def render_schemes(results: Path) -> str | None:
    """docs/control_schemes.md's results section, or None when not recorded."""
    found = recorded(results).get("control_schemes")
    return None if found is None else load_module("control_schemes").markdown(found)


def update_readme(readme: Path, section: str, start: str = START, end: str = END) -> bool:
    """Rewrite ``readme`` between the markers; False if the file or the markers are missing."""
    if not readme.is_file():
        return False
    text = readme.read_text()
    if start not in text or end not in text:
        return False
    head, rest = text.split(start, 1)
    _, tail = rest.split(end, 1)
    readme.write_text(f"{head}{start}\n{section}{end}{tail}")
    return True


def main(argv: list[str] | None = None) -> int:
    """Write the docs (and the README's section and docs/control_schemes.md's results); exit
    code 1 if the markers are missing."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, default=RESULTS, help="folder of the JSON files")
    parser.add_argument("--docs", type=Path, default=DOCS, help="the Markdown file to write")
    parser.add_argument("--readme", type=Path, default=README, help="the README to update")
    parser.add_argument(
        "--no-readme",
        action="store_true",
        help="leave the README and docs/control_schemes.md alone",
    )
    args = parser.parse_args(argv)
    args.docs.parent.mkdir(parents=True, exist_ok=True)
    args.docs.write_text(render_docs(args.results, args.docs))
    print(f"wrote {args.docs}")
    if args.no_readme:
        return 0
    if not update_readme(args.readme, render_readme(args.results)):
        print(f"{args.readme}: markers {START} ... {END} not found", file=sys.stderr)
        return 1
    print(f"updated {args.readme}")
    schemes = render_schemes(args.results)
    if schemes is not None:
        if not update_readme(SCHEMES_DOC, schemes, SCHEMES_START, SCHEMES_END):
            print(f"{SCHEMES_DOC}: markers {SCHEMES_START} ... not found", file=sys.stderr)
            return 1
        print(f"updated {SCHEMES_DOC}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
