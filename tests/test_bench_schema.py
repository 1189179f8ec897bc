"""The benchmarks' JSON schema (benchmarks/schema.py), on the recorded results and on a fresh
quick run of rrc-pin's own study through ``rrc-pin bench`` (no peer library needed).

The whole ``rrc-pin bench --quick`` with the peers (pink, mink) runs in .ci/run with the
bench extra installed; the README and docs/benchmarks.md against the JSON:
tests/test_cli.py::test_readme_performance_section_is_generated_from_the_results.
"""

from __future__ import annotations

import copy
import json
import sys
from pathlib import Path

import pytest

from rrc_pin.cli import main

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
try:
    import schema
finally:
    sys.path.remove(str(ROOT / "benchmarks"))

RECORDED = sorted((ROOT / "benchmarks" / "results").glob("*.json"))


@pytest.mark.parametrize("path", RECORDED, ids=[p.stem for p in RECORDED])
def test_recorded_results_follow_the_schema(path):
    assert schema.problems(json.loads(path.read_text())) == []


def test_every_benchmark_of_the_cli_has_a_schema_and_a_recorded_result():
    import rrc_pin.cli as cli

    assert set(cli.BENCHMARKS) <= set(schema.KNOWN)
    assert {p.stem for p in RECORDED} == set(cli.BENCHMARKS)


def test_schema_names_what_is_missing():
    """The schema can fail: a timing row without its ratio, a closed form without p99."""
    resolver = json.loads((ROOT / "benchmarks" / "results" / "resolver.json").read_text())
    broken = copy.deepcopy(resolver)
    row = next(iter(broken["arms"][0]["modes"]["tight"]["contenders"].values()))
    for key in [k for k in row if k.startswith("vs_")]:
        del row[key]
    del row["p99_us"]
    found = schema.problems(broken)
    assert any("p99_us" in p for p in found) and any("no ratio" in p for p in found), found
    cf = json.loads((ROOT / "benchmarks" / "results" / "closed_form.json").read_text())
    cf = {**cf, "schema": 2}
    cf["arms"][0]["scalar"].pop("closed_form_p99_us", None)
    assert any("closed_form_p99_us" in p for p in schema.problems(cf))
    assert schema.problems({"benchmark": "nope"})[0].startswith("benchmark:")


@pytest.mark.parametrize("name", ["resolver", "tasks"])
def test_schema_holds_the_peers_comparison_to_what_ran(name):
    """Issue 27: every peer ran in a full recording, each peer that ran has its rows and its
    kinematics checked, a peer that did not run has no row and is said "not in this
    environment" (a quick run only), and every contender's answers are judged."""
    recorded = json.loads((ROOT / "benchmarks" / "results" / f"{name}.json").read_text())
    assert schema.problems(recorded) == []
    assert set(recorded["peers"].values()) == {"ran"}
    part = recorded["arms"][0] if name == "resolver" else recorded

    missing_gap = copy.deepcopy(recorded)
    (missing_gap["arms"][0] if name == "resolver" else missing_gap)["kinematics_gaps"].pop("mink")
    assert any("kinematics_gaps.mink" in p for p in schema.problems(missing_gap))

    quick = copy.deepcopy(recorded)
    quick["quick"] = True
    quick["peers"]["PlaCo"] = "not in this environment: ModuleNotFoundError: placo"
    found = schema.problems(quick)
    assert found and all("rows of PlaCo, which did not run" in p for p in found), found
    for part_ in quick["arms"] if name == "resolver" else [quick]:
        for m in part_["modes"].values():
            for label in [k for k in m["contenders"] if k.startswith("PlaCo")]:
                del m["contenders"][label]
    assert schema.problems(quick) == []
    quick["quick"] = False  # a full run without PlaCo: refused
    assert any("a full run needs every peer" in p for p in schema.problems(quick))
    quick["peers"]["PlaCo"] = "passed"
    assert any("peers.PlaCo: expected 'ran'" in p for p in schema.problems(quick))

    unjudged = copy.deepcopy(recorded)
    target = unjudged["arms"][0] if name == "resolver" else unjudged
    label = next(iter(part["modes"]["tight"]["contenders"]))
    del target["quality"][label]
    assert any(f"quality.{label}" in p for p in schema.problems(unjudged))


def test_quick_study_through_the_cli_writes_json_that_follows_the_schema(tmp_path, monkeypatch):
    import rrc_pin.cli as cli

    monkeypatch.setattr(cli, "_installed", lambda module: True)  # matplotlib may be absent
    out = tmp_path / "run"
    assert main(["bench", "--only", "study", "--quick", "--out", str(out)]) == 0
    results = json.loads((out / "study.json").read_text())
    assert results["quick"] is True and schema.problems(results) == []
    assert "## Sampling time and velocity conversions" in (out / "benchmarks.md").read_text()


def test_schema_names_what_the_controller_and_control_schemes_miss():
    """A controller tick row without its ratio, a session without its tick times or with a
    NaN drift, a control-scheme step row without p99: each named."""
    ctl = json.loads((ROOT / "benchmarks" / "results" / "controller.json").read_text())
    assert schema.problems(ctl) == []
    rows = ctl["arms"][0]["contenders"]
    for key in [k for row in rows.values() for k in list(row) if k.startswith("vs_")]:
        for row in rows.values():
            row.pop(key, None)
    del ctl["sessions"][0]["tick"]
    ctl["sessions"][1]["drift_max_mm"] = float("nan")
    found = schema.problems(ctl)
    assert any("no ratio" in p for p in found), found
    assert any(p.startswith("sessions.") and "tick.p99_us" in p for p in found), found
    assert any("drift_max_mm" in p for p in found), found
    scaling = json.loads((ROOT / "benchmarks" / "results" / "scaling.json").read_text())
    scaling["dof"][0]["controller"] = {"median_us": 200.0, "p10_us": 150.0, "p90_us": 300.0}
    assert any("dof." in p and "controller.p99_us" in p for p in schema.problems(scaling))
    cs = json.loads((ROOT / "benchmarks" / "results" / "control_schemes.json").read_text())
    assert schema.problems(cs) == []
    del next(iter(cs["timing"][0]["contenders"].values()))["p99_us"]
    assert any(p.startswith("timing.") and "p99_us" in p for p in schema.problems(cs))


def test_control_schemes_doc_is_generated_from_the_results():
    """docs/control_schemes.md's results section is what update_readme.py renders."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import update_readme
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    text = (ROOT / "docs" / "control_schemes.md").read_text()
    section = text.split(update_readme.SCHEMES_START, 1)[1].split(update_readme.SCHEMES_END)[0]
    assert section == "\n" + update_readme.render_schemes(update_readme.RESULTS)


def test_the_cells_schema_wants_each_cell_with_and_without_collision():
    """Issue 30: each cell's tick without collision constraints, and with them or the
    refusal said in not_run."""
    recorded = json.loads((ROOT / "benchmarks" / "results" / "cells.json").read_text())
    assert schema.problems(recorded) == []
    assert {r["cell"] for r in recorded["rows"]} == set(schema.CELLS)
    dropped = copy.deepcopy(recorded)
    dropped["rows"] = [r for r in dropped["rows"]
                       if not (r["cell"] == "yeh_tripod" and r["collision"])]  # fmt: skip
    assert schema.problems(dropped) == [
        "rows.yeh_tripod: no tick with collision constraints, and no reason in not_run"]
    dropped["not_run"] = [{"cell": "yeh_tripod", "limits": "collision", "reason": "refused"}]
    assert schema.problems(dropped) == []
    slow = copy.deepcopy(recorded)
    del slow["rows"][0]["rate_hz_p99"]
    assert any("rate_hz_p99" in p for p in schema.problems(slow))
