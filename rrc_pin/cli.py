"""Command line: ``rrc-pin arms | demo | check | bench | urdf | guidance | map | console``."""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from rrc_pin.errors import RrcPinError

ILLUSTRATIONS = (1, 2, 4, 5, 6, 7)
"""The Appendix II illustrations ``rrc-pin guidance`` reproduces."""
EXIT_BROKEN_PIPE = 141
"""Exit code when the reader of stdout went away (128 + SIGPIPE, as a killed process gives)."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rrc-pin`` console script; returns the exit code.

    Exit codes: 0 success, 1 a check failed, 2 bad arguments, an :class:`RrcPinError` or a
    file-system error (printed as one line on stderr, no traceback), 141 stdout closed by its reader
    (``rrc-pin check | head -1``).
    """
    args = parser().parse_args(argv)
    try:
        code = run(args)
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
    except RrcPinError as exc:
        message = " ".join(str(exc).split())
        print(f"rrc-pin {args.command}: {message}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        _discard_stdout()
        return EXIT_BROKEN_PIPE
    except OSError as exc:  # a folder that cannot be written, a path that is a file...
        print(f"rrc-pin {args.command}: {exc}", file=sys.stderr)
        return 2
    return code


DESCRIPTION = """\
Resolved-rate control of robot arms on Pinocchio: the robots it knows, a scripted
teleoperation demo, cross-checks of the paper arms, the benchmarks of a checkout, the
committed URDFs and Nadkarni's guidance illustrations. 'rrc-pin COMMAND --help' says more."""


def parser() -> argparse.ArgumentParser:
    """The argument parser of ``rrc-pin``."""
    out = argparse.ArgumentParser(
        prog="rrc-pin",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,  # DESCRIPTION's own lines
    )
    add = out.add_subparsers(dest="command", required=True).add_parser
    add("arms", help="table of the robots rrc_pin.load accepts, with their tool frames")
    _demo(add)
    check = add("check", help="cross-check every catalogue arm: DH, Pinocchio, yourdfpy")
    check.add_argument("--samples", type=int, default=200, help="configurations per arm (>= 1)")
    _bench(add)
    guidance = add(
        "guidance",
        help="Nadkarni's Appendix II: the thesis's numbers beside the computed ones, the "
        "known errata marked",
    )
    guidance.add_argument(
        "--illustration",
        type=int,
        required=True,
        choices=ILLUSTRATIONS,
        metavar="N",
        help="the illustration: " + ", ".join(map(str, ILLUSTRATIONS[:-1]))
        + f" or {ILLUSTRATIONS[-1]} (3 is 1 and 2 in one run)",
    )
    _map(add)
    _console(add)
    _urdf(add)
    return out


def _demo(add: Callable[..., argparse.ArgumentParser]) -> None:
    """``rrc-pin demo``'s arguments."""
    demo = add(
        "demo",
        help="a scripted teleoperation session on the paper arms under every singularity "
        "strategy: summary table, trajectories (CSV) and a figure (PNG) in a folder",
    )
    demo.add_argument(
        "--arm",
        default=None,
        metavar="NAME",
        help="print only the kinematics row of this arm, a name or a URDF path (DOF, tool "
        "position, cond(J) at its ready pose) instead of the tour",
    )
    demo.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder for the outputs (default: a new rrc-pin-demo-<timestamp>-* folder in the "
        "system's temporary directory, printed)",
    )
    demo.add_argument(
        "--cell",
        default=None,
        choices=("gsfc_dual", "yeh_tripod"),
        help="run this cell's scripted session instead (gsfc_dual: master-slave carrying of "
        "the held object; yeh_tripod: the walk along the beam): table, log (CSV), figure (PNG)",
    )
    demo.add_argument("--quick", action="store_true", help="shorter scripts (a smoke test)")


def _bench(add: Callable[..., argparse.ArgumentParser]) -> None:
    """``rrc-pin bench``'s arguments."""
    bench = add(
        "bench",
        help="run the benchmarks of a checkout (needs the bench extra): results to a new "
        "folder, or with --record to benchmarks/results, docs/benchmarks.md and the README",
    )
    bench.add_argument("--only", choices=BENCHMARKS, help="one benchmark")
    bench.add_argument("--quick", action="store_true", help="short runs (a smoke test)")
    bench_to = bench.add_mutually_exclusive_group()
    bench_to.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder for the results (default: a new ./rrc-pin-bench-<timestamp>)",
    )
    bench_to.add_argument(
        "--record",
        action="store_true",
        help="rewrite benchmarks/results/, docs/benchmarks.md and the README's table",
    )
    bench.add_argument(
        "--placo-python",
        default=None,
        metavar="PATH",
        help="interpreter with placo for the tasks benchmark (default: .venv-placo/bin/python "
        "of the checkout, if any; placo pins its own Pinocchio)",
    )


def _map(add: Callable[..., argparse.ArgumentParser]) -> None:
    """``rrc-pin map``'s arguments."""
    mapping = add(
        "map",
        help="capability map of an arm or a cell (needs the maps extra): reachability, "
        "orientation coverage, manipulability, singular conditions per voxel, on Dask",
    )
    mapping.add_argument("robot", metavar="ARM|CELL", help="a name or a URDF path")
    mapping.add_argument("--samples", type=int, default=10**6, help="samples per tool frame")
    mapping.add_argument("--voxel", type=float, default=0.05, help="voxel edge [m]")
    mapping.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder for the map (default: a new ./rrc-pin-map-<timestamp>); the same folder "
        "resumes an interrupted run",
    )
    mapping.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="a dask.distributed scheduler (tcp://host:8786); default: this machine",
    )
    mapping.add_argument(
        "--workers", type=int, default=None, help="threads on this machine (default: its cores)"
    )
    mapping.add_argument(
        "--dashboard",
        nargs="?",
        const="127.0.0.1:8787",
        default=None,
        metavar="[HOST:]PORT",
        help="serve Dask's dashboard of the local cluster (needs bokeh; default 127.0.0.1:8787; "
        "a port alone is on 127.0.0.1); without it, nothing listens beyond 127.0.0.1",
    )
    mapping.add_argument("--seed", type=int, default=0, help="seed of the samples")
    mapping.add_argument(
        "--no-dexterity",
        action="store_true",
        help="skip the singular values (manipulability, sigma_min): faster",
    )
    mapping.add_argument(
        "--audit",
        type=int,
        default=0,
        metavar="K",
        help="confirm K random reached voxels by resolved-rate IK through the resolver",
    )


def _console(add: Callable[..., argparse.ArgumentParser]) -> None:
    """``rrc-pin console``'s arguments."""
    console = add(
        "console",
        help="the operator's console in the browser (needs the console extra): the arm in 3-D, "
        "hand-frame commands, joint limits and singularities live",
    )
    robot = console.add_mutually_exclusive_group()
    robot.add_argument("--arm", default=None, metavar="NAME", help="arm to drive (default barker6)")
    robot.add_argument("--cell", default=None, metavar="NAME", help="a cell of several arms")
    console.add_argument("--port", type=int, default=8080, help="port (the next free one if taken)")
    console.add_argument(
        "--host",
        default="127.0.0.1",
        help="interface to serve on (default: this machine only; any other needs a token of your "
        "own, and the traffic is plain HTTP: prefer an SSH tunnel)",
    )
    console.add_argument(
        "--token",
        default=None,
        metavar="SECRET",
        help="the secret every page must show (16 characters or more of letters, digits and "
        "-_.~); default: $RRC_PIN_CONSOLE_TOKEN, else a new one at each start, printed with "
        "the address; prefer the variable: a command line is visible to every user",
    )
    console.add_argument("--rate", type=float, default=100.0, help="control loop rate [Hz]")
    console.add_argument(
        "--realtime",
        action="store_true",
        help="run the control loop under real-time scheduling (Linux, root or CAP_SYS_NICE)",
    )
    console.add_argument(
        "--out", type=Path, default=Path("."), metavar="DIR", help="folder for saved records"
    )


def _urdf(add: Callable[..., argparse.ArgumentParser]) -> None:
    """``rrc-pin urdf``'s arguments."""
    urdf = add("urdf", help="compare or rewrite the committed URDFs")
    mode = urdf.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true", help="fail if a committed file differs")
    mode.add_argument("--write", action="store_true", help="rewrite the committed files")
    urdf.add_argument(
        "--dir", type=Path, default=CHECKOUT / "urdf", help="folder of the URDFs (default: the "
        "checkout's urdf/)"
    )


def run(args: argparse.Namespace) -> int:
    """Run the parsed command; return its exit code.

    Raises:
        RrcPinError: Whatever the command refuses (``main`` prints it as one line).
    """
    if args.command == "arms":
        print(arms_table())
        return 0
    if args.command == "urdf":
        return urdf_command(args.dir, write=args.write)
    if args.command == "bench":
        return bench_command(
            args.only,
            quick=args.quick,
            out=args.out,
            record=args.record,
            placo_python=args.placo_python,
        )
    if args.command == "guidance":
        from rrc_pin.guidance.illustrations import format_report

        print(format_report(args.illustration))
        return 0
    if args.command == "console":
        return console_command(args)
    if args.command == "check":
        from rrc_pin.cross_check import run_cross_check

        return run_cross_check(samples=args.samples)
    if args.command == "map":
        return map_command(args)
    if args.cell:
        from rrc_pin.demo_cells import run_cell_demo

        return run_cell_demo(args.cell, out=args.out, quick=args.quick)
    from rrc_pin.demo import run_demo

    return run_demo(args.arm, out=args.out, quick=args.quick)


def console_command(args: argparse.Namespace) -> int:
    """Serve the console until interrupted; 2 (one line on stderr) without the console extra.

    Raises:
        RrcPinError: An arm or cell that does not load, a bad rate or port.
    """
    if not _installed("viser"):
        print('rrc-pin console: viser not installed: pip install -e ".[console]"', file=sys.stderr)
        return 2
    from rrc_pin.console import Access, Console, console_robot
    from rrc_pin.console.access import TOKEN_ENV

    token = args.token or os.environ.get(TOKEN_ENV) or None
    Access(args.host, token)  # a bad token, or none for the network: said before loading
    robot = console_robot(args.arm, args.cell)
    console = Console(robot, host=args.host, port=args.port, rate=args.rate, out=args.out,
                      realtime=args.realtime, token=token)  # fmt: skip
    console.serve_forever()
    return 0


def _discard_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's last flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # stdout is not a file (captured, replaced)
        pass


def arms_table(width: int | None = None) -> str:
    """The robots: name, DOF, joint types, tool frames, then source and assumptions below.

    Each robot's first line holds its columns (tool frames wrapped in theirs); its source and
    what is assumed or locked, and where its ready pose comes from, follow on indented lines,
    every line at most ``width`` characters (default the terminal's, else 100) where no single
    word is longer.
    """
    from rrc_pin import models
    from rrc_pin.cells import Cell
    from rrc_pin.loading import INSTALLED, arms, cells, load

    width = width or shutil.get_terminal_size((100, 24)).columns
    rows = []
    for name in arms():
        robot = load(name)
        kinds = "".join(
            robot.model.joints[j].shortname().removeprefix("JointModel")[0]
            for j in range(1, robot.model.njoints)
        )
        spec = models.CATALOGUE.get(name)
        if spec is not None:
            source, notes = spec.source, "assumed: " + "; ".join(spec.assumed)
        else:
            installed = INSTALLED[name]
            source = f"example-robot-data: {installed.path}"
            notes = f"locked: {installed.locked}; " if installed.locked else ""
            notes += f"ready pose: {installed.ready.reason}"
            if installed.ready.srdf:
                notes += f" ({installed.ready.srdf})"
        rows.append((name, str(robot.nq), kinds, ", ".join(robot.tool_frames), source, notes))
    for name in cells():
        cell = load(name)
        assert isinstance(cell, Cell)  # load gives a Cell for a cell's name
        layout = models.CELLS[name]
        dof = f"{cell.nv}" + (" (6 floating)" if cell.floating else "")
        rows.append((name, dof, "cell", ", ".join(cell.tool_frames), layout.source,
                     f"{cell.describe()}; assumed: " + "; ".join(layout.assumed)))  # fmt: skip
    return _table(("name", "dof", "joints", "tool frames"), rows, width)


def _table(head: tuple[str, ...], rows: Sequence[tuple[str, ...]], width: int) -> str:
    """Columns ``head`` (the last one wrapped), then each row's two texts on indented lines."""
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head) - 1)]
    left = sum(widths) + 2 * len(widths)
    last = textwrap.TextWrapper(max(20, width - left), break_long_words=False,
                                break_on_hyphens=False)  # fmt: skip
    text = textwrap.TextWrapper(width, initial_indent="    ", subsequent_indent="      ",
                                break_long_words=False, break_on_hyphens=False)  # fmt: skip
    lines = []
    for row in [head, *rows]:
        first = "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=False)) + "  "
        wrapped = last.wrap(row[len(head) - 1]) or [""]
        lines.append((first + wrapped[0]).rstrip())
        lines += [" " * left + more for more in wrapped[1:]]
        for extra in row[len(head):]:
            lines += text.wrap(extra)
    return "\n".join(lines)


def urdf_command(directory: Path, *, write: bool) -> int:
    """Rewrite (``write``) or check the committed URDFs of the catalogue; return the exit code.

    Exit codes: 0 all match (or written), 1 some differ, 2 ``directory`` is not a folder.
    """
    from rrc_pin import models, urdf_export

    specs = list(models.CATALOGUE.values())
    if not directory.is_dir() and (directory.exists() or not write):
        print(f"rrc-pin urdf: --dir {directory} is not a folder", file=sys.stderr)
        return 2
    if write:
        for path in urdf_export.write(directory, specs):
            print(f"wrote {path}")
        return 0
    problems = urdf_export.check(directory, specs)
    for problem in problems:
        print(problem, file=sys.stderr)
    print(f"{len(specs) - len(problems)}/{len(specs)} URDFs in {directory} match their DH tables")
    return 1 if problems else 0


CHECKOUT = Path(__file__).resolve().parents[1]
"""The checkout whose ``benchmarks/`` ``rrc-pin bench`` runs (and whose ``urdf/`` it checks)."""

BENCHMARKS = (
    "closed_form",
    "resolver",
    "tasks",
    "study",
    "scaling",
    "controller",
    "control_schemes",
    "maps",
    "collision",
    "cells",
)
BENCH_MODULES = {
    "closed_form": ("matplotlib",),
    "study": ("matplotlib",),
    "scaling": ("matplotlib",),
    "resolver": ("pink", "matplotlib"),
    "tasks": ("pink", "matplotlib"),
    "controller": ("matplotlib",),
    "control_schemes": ("matplotlib",),
    "maps": ("distributed", "zarr", "matplotlib"),
    "collision": ("pink", "mink", "mujoco", "matplotlib"),
    "cells": ("matplotlib",),
}
"""What each benchmark needs from the bench extra. The resolver and tasks benchmarks also need
PlaCo, mink and Drake for a full run (they refuse without, naming what is missing); a quick run
records the absent ones as "not in this environment" (docs/benchmarks.md)."""


def bench_command(
    only: str | None,
    *,
    quick: bool = False,
    out: Path | None = None,
    record: bool = False,
    placo_python: str | None = None,
) -> int:
    """Run the checkout's ``benchmarks/bench_*.py``, then render their tables.

    The bench extra is checked first (one line on stderr naming what to install, exit code
    2, nothing written). Results go to ``out`` (default: a new ``./rrc-pin-bench-<timestamp>``
    folder) with a ``benchmarks.md`` of every table; only ``record`` rewrites the checkout's
    ``benchmarks/results/``, ``docs/benchmarks.md`` and the README's performance section.

    Args:
        only: One benchmark of :data:`BENCHMARKS`, or None for all.
        quick: Short runs (a smoke test); refused with ``record``.
        out: Folder for the results (created if missing).
        record: Write the checkout's recorded results and documents instead.
        placo_python: PlaCo's interpreter for the tasks benchmark, or None to look for it.

    Returns:
        0, or the exit code of the first script that failed; 2 for a missing extra.
    """
    folder = CHECKOUT / "benchmarks"
    if not folder.is_dir():
        print(f"rrc-pin bench runs from a checkout: no {folder}", file=sys.stderr)
        return 2
    names = [only] if only else list(BENCHMARKS)
    missing = sorted({m for name in names for m in BENCH_MODULES[name] if not _installed(m)})
    if missing:
        print(
            f'rrc-pin bench: {", ".join(missing)} not installed: pip install -e ".[bench]"',
            file=sys.stderr,
        )
        return 2
    if record and quick:
        print("rrc-pin bench: --record keeps full runs only; drop --quick", file=sys.stderr)
        return 2
    results = folder / "results" if record else (out or _new_folder(Path.cwd()))
    results.mkdir(parents=True, exist_ok=True)
    for name in names:
        args = ["--quick"] if quick else []
        args += ["--record"] if record else ["--out", str(results)]
        if name == "tasks" and placo_python:
            args += ["--placo-python", placo_python]
        print(f"rrc-pin bench: {name}", flush=True)
        code = _run_script(folder / f"bench_{name}.py", args)
        if code:
            return code
    render = (
        []
        if record
        else ["--results", str(results), "--docs", str(results / "benchmarks.md"), "--no-readme"]
    )
    code = _run_script(folder / "update_readme.py", render)
    if code == 0:
        print(f"rrc-pin bench: results in {results}")
    return code


def map_command(args: argparse.Namespace) -> int:
    """``rrc-pin map``: the map of an arm (one tool frame) or a cell (several) into a folder.

    Writes ``map.zarr`` (per frame for a cell), ``summary.md``/``.json``, the plots (with
    matplotlib) and, with ``--audit K``, ``audit.json``; prints the summary table.

    Raises:
        RrcPinError: Bad arguments (named), an unreachable scheduler, another map's blocks
            in the folder, the maps extra missing.
    """
    import json

    from rrc_pin import maps
    from rrc_pin.loading import load

    robot = load(args.robot)
    out: Path = args.out if args.out is not None else _fresh(Path.cwd(), "rrc-pin-map")
    dexterity = not args.no_dexterity
    if len(robot.tool_frames) > 1:
        cell = maps.cell_map(robot, args.samples, args.voxel, args.scheduler, seed=args.seed,
                             out=out, workers=args.workers, dexterity=dexterity,
                             dashboard=args.dashboard)  # fmt: skip
        maps.plot_cell(cell, out)
        print(cell.summary_table())
    else:
        m = maps.capability(robot, args.samples, args.voxel, args.scheduler, seed=args.seed,
                            out=out, workers=args.workers, dexterity=dexterity,
                            dashboard=args.dashboard)  # fmt: skip
        maps.plot_map(m, out)
        print(m.summary_table())
        if args.audit > 0:
            report = maps.audit(m, robot, args.audit, seed=args.seed)
            record = {
                "voxels": int(report.keys.size),
                "confirmed": report.confirmed,
                "failures": report.failures.tolist(),
                "seconds": report.seconds,
                "steps": report.steps_total,
            }
            (out / "audit.json").write_text(json.dumps(record, indent=1) + "\n")
            print(
                f"audit: {report.confirmed:.1%} of {report.keys.size} reached voxels confirmed "
                f"by IK through the resolver ({report.seconds:.1f} s)"
            )
    print(f"rrc-pin map: wrote {out} (resume with --out {out})")
    return 0


def _installed(module: str) -> bool:
    """Whether ``module`` can be imported (a None entry in sys.modules counts as missing)."""
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def _fresh(parent: Path, prefix: str) -> Path:
    """A path ``<prefix>-<timestamp>`` in ``parent`` that does not exist (not created)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for k in range(1000):
        path = parent / (f"{prefix}-{stamp}" + (f"-{k}" if k else ""))
        if not path.exists():
            return path
    raise FileExistsError(f"{parent}: no free {prefix}-{stamp}-N name")


def _new_folder(parent: Path, prefix: str = "rrc-pin-bench") -> Path:
    """A folder ``<prefix>-<timestamp>`` in ``parent`` that did not exist (created)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for k in range(1000):
        path = parent / (f"{prefix}-{stamp}" + (f"-{k}" if k else ""))
        try:
            path.mkdir(parents=True)
        except FileExistsError:
            continue
        return path
    raise FileExistsError(f"{parent}: no free {prefix}-{stamp}-N folder")


def _run_script(script: Path, args: list[str]) -> int:
    """Run a benchmark script with this interpreter; its exit code."""
    return subprocess.call([sys.executable, str(script), *args])


if __name__ == "__main__":
    raise SystemExit(main())
