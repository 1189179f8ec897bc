"""Regenerate the README's performance section from the recorded benchmark results.

Run from a checkout after the benchmarks: ``python benchmarks/update_readme.py``. Each
benchmark script records ``benchmarks/results/<name>.json`` and renders it with its own
``markdown_table``; this script puts those tables between the README's markers.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # the scripts import their shared machine.py
README = HERE.parent / "README.md"
START, END = "<!-- performance:start -->", "<!-- performance:end -->"
BENCHMARKS = {
    "closed_form": ("bench_closed_form.py", "Closed forms against Pinocchio + numpy"),
    "resolver": ("bench_resolver.py", "Resolver step time against qpsolvers backends and pink"),
}


def render() -> str:
    """Markdown of every recorded benchmark, in a fixed order."""
    parts = []
    for name, (script, title) in BENCHMARKS.items():
        results_path = HERE / "results" / f"{name}.json"
        if not results_path.exists():
            parts.append(f"### {title}\n\nNot recorded yet: run `python benchmarks/{script}`.\n")
            continue
        spec = importlib.util.spec_from_file_location(name, HERE / script)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        results = json.loads(results_path.read_text())
        parts.append(
            f"### {title}\n\n{module.markdown_table(results).strip()}\n\n"
            f"Recorded by `benchmarks/{script}`; plot: `benchmarks/results/{name}.png`.\n"
        )
    return "\n".join(parts)


def main() -> int:
    """Rewrite the README between the markers; exit code 1 if the markers are missing."""
    text = README.read_text()
    if START not in text or END not in text:
        print(f"{README}: markers {START} ... {END} not found", file=sys.stderr)
        return 1
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    README.write_text(f"{head}{START}\n{render()}{END}{tail}")
    print(f"updated {README}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
