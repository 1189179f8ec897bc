"""Draw a benchmark's PNG again from its JSON, without running it.

``python benchmarks/replot.py NAME... [--results DIR]`` reads ``DIR/NAME.json`` (default
``benchmarks/results/``) and writes ``DIR/NAME.png`` with the benchmark's ``plot``: for a
change of the figure alone, the recorded numbers stay as they were measured.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
MODULES = {
    "closed_form": "bench_closed_form",
    "resolver": "bench_resolver",
    "tasks": "bench_tasks",
    "scaling": "bench_scaling",
    "controller": "bench_controller",
    "control_schemes": "bench_control_schemes",
    "collision": "bench_collision",
    "cells": "bench_cells",
}
"""Benchmark -> the module whose ``plot(result, path)`` draws it (the study's figure needs its
sampled runs, not only the JSON: rerun ``rrc-pin bench --only study``)."""
NAMES = tuple(MODULES)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="+", choices=NAMES, metavar="NAME", help=", ".join(NAMES))
    parser.add_argument("--results", type=Path, default=RESULTS, help="folder of the JSON files")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(HERE))
    for name in args.names:
        result = json.loads((args.results / f"{name}.json").read_text())
        module = importlib.import_module(MODULES[name])
        path = args.results / f"{name}.png"
        if not module.plot(result, path):
            print("matplotlib is not installed: pip install -e '.[bench]'", file=sys.stderr)
            return 2
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
