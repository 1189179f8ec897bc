"""What every benchmark script shares: its arguments, where its results go, matplotlib.

A script ``bench_<name>.py`` takes ``--quick`` (a short smoke run), and ``--out DIR`` or
``--record`` (``benchmarks/results/``, full runs only); it writes ``<name>.json`` and, with
matplotlib, ``<name>.png``. ``rrc-pin bench`` calls the scripts that way.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from machine import load_average, machine_info, source_state
from timing import progress

RESULTS = Path(__file__).resolve().parent / "results"


def make_parser(doc: str | None, name: str, quick: str = "short run") -> argparse.ArgumentParser:
    """The parser of a script (``doc``: its module docstring) with ``--quick`` and ``--out`` or
    ``--record``; add the script's own options, then read them with :func:`arguments`."""
    out = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    out.add_argument("--quick", action="store_true", help=quick)
    where = out.add_mutually_exclusive_group()
    where.add_argument("--out", type=Path, help=f"folder for {name}.json and .png")
    where.add_argument("--record", action="store_true", help="write benchmarks/results/")
    return out


def arguments(parser: argparse.ArgumentParser, argv: Sequence[str] | None) -> argparse.Namespace:
    """Parse ``argv``; a quick run is never recorded (exit code 2, argparse's message)."""
    args = parser.parse_args(argv)
    if args.record and args.quick:
        parser.error("--record keeps full runs only")
    return args


def measure(
    name: str, quick: bool, run: Callable[[], dict[str, Any]], *packages: str
) -> dict[str, Any]:
    """The JSON of benchmark ``name``: what ran it (the machine, with the versions of
    ``packages`` too; the code measured), ``quick``, what ``run()`` returns, and the load
    average at the start and end."""
    start = load_average()
    results: dict[str, Any] = {
        "benchmark": name,
        "machine": machine_info(*packages),
        "source": source_state(),
        "quick": bool(quick),
        **run(),
    }
    results["load_average"] = {"start": start, "end": load_average()}
    return results


def write(
    args: argparse.Namespace,
    name: str,
    results: dict[str, Any],
    plot: Callable[[Path], bool],
    indent: int = 2,
) -> Path | None:
    """Write ``<name>.json`` and (``plot(path)``, False without matplotlib) ``<name>.png`` to
    ``--out`` or, with ``--record``, the recorded results; the folder, or None for neither."""
    out: Path | None = RESULTS if args.record else args.out
    if out is None:
        return None
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{name}.json").write_text(json.dumps(results, indent=indent) + "\n")
    drawn = plot(out / f"{name}.png")
    what = f" and {name}.png" if drawn else " (matplotlib not installed: no plot)"
    progress(f"wrote {out / f'{name}.json'}{what}")
    return out


QUICK_NOTE = "quick run (a smoke test, not a result)"
"""What a figure of a ``--quick`` run says above its panels."""


def is_quick(results: dict[str, Any]) -> bool:
    """Whether ``results`` come from a quick run (the flag at the top, or in the settings)."""
    settings = results.get("settings")
    return bool(results.get("quick") or (isinstance(settings, dict) and settings.get("quick")))


def mark_quick(fig: Any, results: dict[str, Any]) -> None:
    """Title ``fig`` with :data:`QUICK_NOTE` when ``results`` come from a quick run."""
    if is_quick(results):
        fig.suptitle(QUICK_NOTE, color="firebrick")


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend (files only), or None without matplotlib."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
