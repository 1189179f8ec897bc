"""Command line: ``rrc-pin arms | demo | check | bench | urdf --check|--write``."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from rrc_pin import models, urdf_export
from rrc_pin.errors import RrcPinError
from rrc_pin.loading import INSTALLED, arms, load

EXIT_BROKEN_PIPE = 141
"""Exit code when the reader of stdout went away (128 + SIGPIPE, as a killed process gives)."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rrc-pin`` console script; returns the exit code.

    Exit codes: 0 success, 1 a check failed, 2 bad arguments or an :class:`RrcPinError`
    (printed as one line on stderr, no traceback), 141 stdout closed by its reader
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
    return code


def parser() -> argparse.ArgumentParser:
    """The argument parser of ``rrc-pin``."""
    out = argparse.ArgumentParser(prog="rrc-pin", description=__doc__)
    sub = out.add_subparsers(dest="command", required=True)
    sub.add_parser("arms", help="table of the robots rrc_pin.load accepts, with their tool frames")
    demo = sub.add_parser(
        "demo",
        help="a short tour: kinematics, closed forms and resolved-rate control (paper arms, panda)",
    )
    demo.add_argument(
        "--arm",
        default=None,
        metavar="NAME",
        help="print only the kinematics row of this arm (DOF, tool position, cond(J) at a "
        "named pose) instead of the tour",
    )
    check = sub.add_parser("check", help="cross-check every catalogue arm: DH, Pinocchio, yourdfpy")
    check.add_argument("--samples", type=int, default=200, help="configurations per arm (>= 1)")
    bench = sub.add_parser("bench", help="run, record and tabulate the benchmarks")
    bench.add_argument("--only", choices=["closed_form", "resolver"], help="one benchmark")
    urdf = sub.add_parser("urdf", help="compare or rewrite the committed URDFs")
    mode = urdf.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true", help="fail if a committed file differs")
    mode.add_argument("--write", action="store_true", help="rewrite the committed files")
    urdf.add_argument(
        "--dir", type=Path, default=urdf_export.COMMITTED_DIR, help="folder of the URDFs"
    )
    return out


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
        return bench_command(args.only)
    if args.command == "check":
        from rrc_pin.cross_check import run_cross_check

        return run_cross_check(samples=args.samples)
    from rrc_pin.demo import run_demo

    return run_demo(args.arm)


def _discard_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's last flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # stdout is not a file (captured, replaced)
        pass


def arms_table() -> str:
    """Name, DOF, joint types, tool frames, source, and assumed values or locked joints."""
    rows = [("name", "dof", "joints", "tool frames", "source", "assumed / locked")]
    for name in arms():
        robot = load(name)
        kinds = "".join(
            robot.model.joints[j].shortname().removeprefix("JointModel")[0]
            for j in range(1, robot.model.njoints)
        )
        spec = models.CATALOGUE.get(name)
        if spec is not None:
            source, notes = spec.source, "; ".join(spec.assumed)
        else:
            installed = INSTALLED[name]
            source = f"example-robot-data: {installed.path}"
            notes = f"locked: {installed.locked}" if installed.locked else "-"
        tools = ", ".join(robot.tool_frames)
        rows.append((name, str(robot.nq), kinds, tools, source, notes))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    return "\n".join(
        "  ".join(cell.ljust(w) for cell, w in zip(r[:5], widths, strict=True)) + "  " + r[5]
        for r in rows
    )


def urdf_command(directory: Path, *, write: bool) -> int:
    """Rewrite (``write``) or check the committed URDFs of the catalogue; return the exit code.

    Exit codes: 0 all match (or written), 1 some differ, 2 ``directory`` is not a folder.
    """
    specs = list(models.CATALOGUE.values())
    if (directory.exists() and not directory.is_dir()) or not (write or directory.is_dir()):
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


def bench_command(only: str | None) -> int:
    """Run ``benchmarks/bench_*.py`` of the checkout, then regenerate the README's table."""
    folder = urdf_export.COMMITTED_DIR.parent / "benchmarks"
    if not folder.is_dir():
        print(f"rrc-pin bench runs from a checkout: no {folder}", file=sys.stderr)
        return 2
    names = [only] if only else ["closed_form", "resolver"]
    for name in names:
        code = subprocess.call([sys.executable, str(folder / f"bench_{name}.py")])
        if code:
            return code
    return subprocess.call([sys.executable, str(folder / "update_readme.py")])


if __name__ == "__main__":
    raise SystemExit(main())
