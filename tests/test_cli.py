"""The rrc-pin command line: arms, urdf --check, check, demo."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import rrc_pin
from rrc_pin.cli import EXIT_BROKEN_PIPE, main
from rrc_pin.urdf_export import COMMITTED_DIR


def test_arms_table_lists_tool_frames_sources_and_assumptions(capsys):
    assert main(["arms"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:5] == ["name", "dof", "joints", "tool", "frames"]
    rows: dict[str, str] = {}
    for line in lines[1:]:  # a robot's line, then its wrapped ones (indented)
        if line.startswith(" "):
            rows[next(reversed(rows))] += " " + line.strip()
        else:
            rows[line.split()[0]] = line
    assert list(rows) == rrc_pin.arms() + rrc_pin.loading.cells()
    assert rows["barker6"].split()[1:4] == ["6", "RRRRRR", "tool"]
    assert "PUMA 560 values" in rows["barker6"]
    assert rows["nadkarni_c2"].split()[1:3] == ["6", "PPPRRR"]
    assert "panda_hand_tcp" in rows["panda"] and "example-robot-data" in rows["panda"]
    assert rows["baxter"].split()[1:5] == ["15", "R" * 15, "left_gripper,", "right_gripper"]
    assert "l_gripper_tool_frame, r_gripper_tool_frame" in rows["pr2"]
    assert "locked: head, laser tilt, grippers" in rows["pr2"]
    # where each ready pose comes from (issue 33 item 2)
    assert "ready pose: the SRDF's state 'default' (panda_description/srdf/panda.srdf)" in rows[
        "panda"]  # fmt: skip
    assert "ready pose (0, 0, 90, 0, 45, 0) deg" in rows["barker6"]
    assert all("ready pose" in row for row in rows.values())
    assert rows["gsfc_dual"].split()[1:3] == ["14", "cell"] and "shoulder spacing" in rows[
        "gsfc_dual"]  # fmt: skip
    assert "24 (6 floating)" in rows["yeh_tripod"] and "leg1/flange" in rows["yeh_tripod"]


@pytest.mark.parametrize("columns", ["100", "80"])
def test_arms_lines_fit_the_terminal(columns):
    """Issue 40: lines were up to 1,066 characters; wrapped to the terminal's width (100 when
    stdout is not a terminal), words never broken."""
    env = {**os.environ, "COLUMNS": columns}
    out = subprocess.run([sys.executable, "-m", "rrc_pin.cli", "arms"], capture_output=True,
                         text=True, check=True, env=env).stdout  # fmt: skip
    lines = out.splitlines()
    assert len(lines) > 2 * len(rrc_pin.arms())
    assert max(map(len, lines)) <= int(columns), max(lines, key=len)


def test_help_loads_no_pinocchio_and_no_robot():
    """``rrc-pin --help`` imported the whole library (2.1 s): it imports the parser only."""
    code = ("import sys\nfrom rrc_pin.cli import parser\nparser().format_help()\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('pinocchio', 'numpy',"
            " 'numba', 'scipy') or m.startswith(('rrc_pin.models', 'rrc_pin.robot'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout  # fmt: skip
    assert out.strip() == "[]"


def test_help_is_plain_text_and_lists_the_illustrations(capsys):
    """Issue 33 item 8: the top-level help showed the module's reST (double backquotes); the
    guidance help did not say which illustrations exist."""
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    assert "``" not in text and ":func:" not in text and ":class:" not in text
    assert "'rrc-pin COMMAND --help' says more" in text
    with pytest.raises(SystemExit):
        main(["guidance", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--illustration N the illustration: 1, 2, 4, 5, 6 or 7" in text
    for command in ("arms", "demo", "check", "bench", "urdf"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        assert "``" not in capsys.readouterr().out


def run_console_script(*args: str, close_stdout: bool = False) -> subprocess.CompletedProcess:
    exe = shutil.which("rrc-pin", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.fail("the rrc-pin console script is not installed next to this Python")
    if not close_stdout:
        return subprocess.run([exe, *args], capture_output=True, text=True, timeout=300)
    proc = subprocess.Popen([exe, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader goes away before the first line: `rrc-pin ... | head -0`
    err = proc.stderr.read().decode()
    proc.wait(timeout=300)
    return subprocess.CompletedProcess(proc.args, proc.returncode, "", err)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["demo", "--arm", "ur55"], "rrc-pin demo: name_or_path: unknown arm 'ur55'"),
        (["check", "--samples", "0"], "rrc-pin check: samples: expected an integer >= 1, got 0"),
        (["check", "--samples", "-3"], "rrc-pin check: samples: expected an integer >= 1"),
        (["console", "--arm", "ur55"], "rrc-pin console: name_or_path: unknown arm 'ur55'"),
        (["console", "--cell", "no_such_cell"],
         "rrc-pin console: --cell: 'no_such_cell' does not load as a cell"),
        (["console", "--rate", "0"], "rrc-pin console: rate: expected a finite number > 0"),
        (["console", "--port", "70000"], "rrc-pin console: port: expected a port number"),
        (["console", "--host", "0.0.0.0"],
         "rrc-pin console: token: serving on '0.0.0.0' lets every machine that reaches it"),
        (["console", "--token", "short"], "rrc-pin console: token: expected a secret of at least"),
    ],
)
def test_errors_are_one_line_and_exit_code_2(args, message, capsys, monkeypatch):
    """Issue 7 item 7, issue 18 item 12: a traceback, or a check of nothing that passed."""
    monkeypatch.delenv("RRC_PIN_CONSOLE_TOKEN", raising=False)
    assert main(args) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(message), err


def test_the_console_takes_its_token_from_the_environment(capsys, monkeypatch):
    from rrc_pin.console.access import TOKEN_ENV

    monkeypatch.setenv(TOKEN_ENV, "too short")
    assert main(["console", "--host", "0.0.0.0"]) == 2
    assert "token: expected a secret of at least 16 characters" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["console", "--help"])
    assert f"${TOKEN_ENV}" in capsys.readouterr().out  # the help names the variable read


def test_errors_are_one_line_from_the_console_script_too():
    out = run_console_script("demo", "--arm", "ur55")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.splitlines() == [out.stderr.strip()]
    assert out.stderr.startswith("rrc-pin demo: name_or_path: unknown arm 'ur55'")


def test_a_closed_stdout_ends_quietly():
    """Issue 18 item 12: `rrc-pin check | head -1` ended in BrokenPipeError."""
    out = run_console_script("check", "--samples", "2", close_stdout=True)
    assert out.stderr == "" and out.returncode == EXIT_BROKEN_PIPE


def test_demo_help_says_what_arm_does(capsys):
    with pytest.raises(SystemExit) as info:
        main(["demo", "--help"])
    assert info.value.code == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert "--arm NAME print only the kinematics row of this arm" in help_text
    assert "at its ready pose" in help_text
    assert "instead of the tour" in help_text


def test_demo_arm_prints_a_row_per_tool_frame_of_a_two_armed_robot(capsys):
    assert main(["demo", "--arm", "baxter"]) == 0
    out = capsys.readouterr().out
    assert "left_gripper" in out and "right_gripper" in out


def test_urdf_check_passes_on_the_committed_files(capsys):
    assert main(["urdf", "--check"]) == 0
    assert "5/5 URDFs" in capsys.readouterr().out


def test_urdf_check_fails_on_a_changed_file_and_write_repairs_it(tmp_path, capsys):
    folder = tmp_path / "urdf"
    shutil.copytree(COMMITTED_DIR, folder)
    (folder / "barker6.urdf").write_text("<robot/>")
    assert main(["urdf", "--check", "--dir", str(folder)]) == 1
    assert "barker6.urdf" in capsys.readouterr().err
    assert main(["urdf", "--write", "--dir", str(folder)]) == 0
    assert main(["urdf", "--check", "--dir", str(folder)]) == 0


def scaled_numbers(text: str, factor: float, only: int | None = None) -> str:
    """``text`` with the numbers in attribute values (after the XML declaration) times ``factor``
    (all of them, or only the ``only``-th of those above 1e-3)."""
    head, body = text.split("?>", 1)
    count = iter(range(10**6))

    def scale(m: re.Match[str]) -> str:
        x = float(m.group())
        if only is None or (abs(x) > 1e-3 and next(count) == only):
            return repr(x * factor)
        return m.group()

    number = r"(?<=[\s\"])-?\d+(?:\.\d*)?(?:e[-+]?\d+)?(?=[\s\"])"
    return head + "?>" + re.sub(number, scale, body)


def test_urdf_check_compares_numbers_with_a_tolerance(tmp_path, capsys):
    folder = tmp_path / "urdf"
    shutil.copytree(COMMITTED_DIR, folder)
    for path in folder.glob("*.urdf"):
        path.write_text(scaled_numbers(path.read_text(), 1.0 + 1e-15))  # a few ulps
    assert main(["urdf", "--check", "--dir", str(folder)]) == 0
    path = folder / "rrc_k1607.urdf"
    path.write_text(scaled_numbers(path.read_text(), 1.0 + 1e-9, only=40))
    capsys.readouterr()
    assert main(["urdf", "--check", "--dir", str(folder)]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f"{path}: differs from its DH table" and len(err) == 2
    assert err[1].startswith("/robot/") and "committed" in err[1] and "generated" in err[1]


def test_urdf_with_a_bad_folder_is_one_line(tmp_path, capsys):
    assert main(["urdf", "--check", "--dir", str(tmp_path / "nothing")]) == 2
    assert main(["urdf", "--write", "--dir", str(COMMITTED_DIR / "barker6.urdf")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and all("is not a folder" in line for line in err)
    (tmp_path / "empty").mkdir()
    assert main(["urdf", "--check", "--dir", str(tmp_path / "empty")]) == 1
    assert capsys.readouterr().err.count("missing") == 5


def test_check_command_cross_validates(capsys):
    assert main(["check", "--samples", "20"]) == 0
    out = capsys.readouterr().out
    assert out.count(" ok") == 5


# ---- rrc-pin bench (issue 18 item 11) ---------------------------------------------------------

ROOT = Path(__file__).resolve().parents[1]
CHECKED_IN = [ROOT / "README.md", *sorted((ROOT / "benchmarks" / "results").glob("*"))]
if (ROOT / "docs" / "benchmarks.md").exists():
    CHECKED_IN.append(ROOT / "docs" / "benchmarks.md")


def snapshot(paths: list[Path]) -> dict[Path, bytes]:
    return {p: p.read_bytes() for p in paths}


def test_bench_without_its_extras_says_what_to_install(tmp_path, monkeypatch, capsys):
    """The README's install lacks pink: one line, exit code 2, nothing written (it rewrote the
    committed resolver.json without pink's rows, then died on matplotlib)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "pink", None)  # find_spec answers None: not installed
    before = snapshot(CHECKED_IN)
    assert main(["bench", "--only", "resolver"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "pink" in err[0] and 'pip install -e ".[bench]"' in err[0], err
    assert list(tmp_path.iterdir()) == [] and snapshot(CHECKED_IN) == before


@pytest.mark.compiled  # batches of 10^5 configurations: minutes as plain Python
def test_bench_writes_a_new_folder_by_default_and_never_the_checkout(tmp_path, monkeypatch):
    """A quick closed-form run (no pink needed) lands in ./rrc-pin-bench-<timestamp>, with its
    JSON and a benchmarks.md; --out DIR takes another folder; the checkout stays as it was."""
    import rrc_pin.cli as cli

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(cli, "_installed", lambda module: True)  # matplotlib may be absent
    before = snapshot(CHECKED_IN)
    assert main(["bench", "--only", "closed_form", "--quick"]) == 0
    (folder,) = tmp_path.iterdir()
    assert re.fullmatch(r"rrc-pin-bench-\d{8}-\d{6}", folder.name), folder.name
    results = json.loads((folder / "closed_form.json").read_text())
    assert results["quick"] is True and [a["arm"] for a in results["arms"]]
    assert "## Closed forms" in (folder / "benchmarks.md").read_text()
    mine = tmp_path / "mine" / "run"
    assert main(["bench", "--only", "closed_form", "--quick", "--out", str(mine)]) == 0
    assert (mine / "closed_form.json").exists() and (mine / "benchmarks.md").exists()
    assert snapshot(CHECKED_IN) == before


def test_bench_record_rewrites_results_docs_and_readme_and_refuses_quick(
    tmp_path, monkeypatch, capsys
):
    """--record is the only way to the checkout's results, docs/benchmarks.md and README (here a
    copy of the checkout); a smoke run cannot be recorded."""
    import rrc_pin.cli as cli

    checkout = tmp_path / "checkout"
    shutil.copytree(
        ROOT / "benchmarks", checkout / "benchmarks", ignore=shutil.ignore_patterns("__pycache__")
    )
    for path in (checkout / "benchmarks" / "results").iterdir():
        if path.name != "closed_form.json":  # the one this run "records"
            path.unlink()
    (checkout / "docs").mkdir()
    shutil.copy(ROOT / "README.md", checkout / "README.md")
    readme = checkout / "README.md"
    start, end = "<!-- performance:start -->", "<!-- performance:end -->"
    head, rest = readme.read_text().split(start, 1)
    readme.write_text(f"{head}{start}\nstale\n{end}{rest.split(end, 1)[1]}")
    monkeypatch.setattr(cli, "CHECKOUT", checkout)
    monkeypatch.setattr(cli, "_installed", lambda module: True)
    calls = []
    real = cli._run_script

    def run_script(script: Path, args: list[str]) -> int:
        calls.append((script.name, args))
        if script.name == "update_readme.py":
            return real(script, args)
        return 0  # the benchmark itself: its JSON is the copied results/closed_form.json

    monkeypatch.setattr(cli, "_run_script", run_script)
    before = snapshot(CHECKED_IN)
    assert main(["bench", "--only", "closed_form", "--record", "--quick"]) == 2
    assert "--record keeps full runs only" in capsys.readouterr().err and calls == []
    assert main(["bench", "--only", "closed_form", "--record"]) == 0
    assert calls == [("bench_closed_form.py", ["--record"]), ("update_readme.py", [])]
    assert "stale" not in readme.read_text() and "### Closed forms" in readme.read_text()
    assert "## Closed forms" in (checkout / "docs" / "benchmarks.md").read_text()
    assert snapshot(CHECKED_IN) == before


def test_readme_performance_section_is_generated_from_the_results():
    """The README's tables are what benchmarks/update_readme.py renders from the JSON files."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import update_readme
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    text = (ROOT / "README.md").read_text()
    section = text.split(update_readme.START, 1)[1].split(update_readme.END, 1)[0]
    assert section == "\n" + update_readme.render_readme(update_readme.RESULTS)
    docs = ROOT / "docs" / "benchmarks.md"
    assert docs.read_text() == update_readme.render_docs(update_readme.RESULTS, docs)


def test_file_system_errors_are_one_line_and_exit_2(tmp_path, capsys, monkeypatch):
    """A results folder that is a file, a URDF folder under a file: one line, no traceback."""
    import rrc_pin.cli as cli

    monkeypatch.setattr(cli, "_installed", lambda module: True)
    a_file = tmp_path / "a_file"
    a_file.write_text("")
    for argv in (
        ["bench", "--only", "closed_form", "--quick", "--out", str(a_file)],
        ["urdf", "--write", "--dir", str(a_file / "urdf")],
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"rrc-pin {argv[0]}: ") and err.count("\n") == 1, err


@pytest.mark.compiled
def test_map_writes_the_map_its_summary_plots_and_audit(tmp_path, monkeypatch, capsys):
    """`rrc-pin map ARM`: the Zarr store, the summary, the plots and the IK audit; by default
    in a new ./rrc-pin-map-<timestamp>; a cell (two hands) gets the cell's summary."""
    pytest.importorskip("distributed")
    out = tmp_path / "kr5"
    args = ["map", "kr5_3r", "--samples", "20000", "--voxel", "0.2", "--workers", "1"]
    assert main([*args, "--out", str(out), "--audit", "5"]) == 0
    text = capsys.readouterr().out
    assert "| voxels_reached |" in text and "audit: 100.0% of 5 reached voxels" in text
    for name in ("map.zarr", "summary.md", "summary.json", "audit.json", "blocks"):
        assert (out / name).exists(), name
    for name in ("slices.png", "view3d.png"):
        assert (out / name).stat().st_size > 10_000, name
    assert json.loads((out / "audit.json").read_text())["confirmed"] == 1.0
    monkeypatch.chdir(tmp_path)
    assert main(["map", "baxter", "--samples", "2048", "--voxel", "0.3", "--no-dexterity"]) == 0
    (folder,) = tmp_path.glob("rrc-pin-map-*")
    assert re.fullmatch(r"rrc-pin-map-\d{8}-\d{6}", folder.name)
    assert (folder / "cell_slices.png").stat().st_size > 10_000
    assert (folder / "cell_view3d.png").stat().st_size > 10_000 and (folder / "summary.md").exists()
    assert "shared_volume_m3" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--voxel", "0"], "rrc-pin map: voxel: expected a finite length > 0 [m], got 0.0"),
        (["--samples", "0"], "rrc-pin map: samples: expected 1 <= samples"),
        (["--workers", "0"], "rrc-pin map: workers: expected an int >= 1, got 0"),
        (["--seed", "5"], "rrc-pin map: out: "),
    ],
)
@pytest.mark.compiled
def test_map_errors_are_one_line_and_change_nothing(extra, message, tmp_path, capsys):
    pytest.importorskip("distributed")
    out = tmp_path / "m"
    base = ["map", "kr5_3r", "--samples", "3000", "--voxel", "0.2", "--out", str(out)]
    if extra[0] == "--seed":  # another map already in the folder
        assert main([*base, "--workers", "1"]) == 0
        capsys.readouterr()
    files = sorted(p for p in out.rglob("*") if p.is_file()) if out.exists() else []
    before = snapshot(files)
    assert main([*base, *extra]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(message), err
    after = sorted(p for p in out.rglob("*") if p.is_file()) if out.exists() else []
    assert after == files and snapshot(after) == before


def test_console_without_its_extra_says_what_to_install(monkeypatch, capsys):
    monkeypatch.setattr(rrc_pin.cli, "_installed", lambda module: module != "viser")
    assert main(["console"]) == 2
    err = capsys.readouterr().err
    assert err == 'rrc-pin console: viser not installed: pip install -e ".[console]"\n'


@pytest.mark.parametrize(
    ("cell", "label", "bound"),
    [("gsfc_dual", "max grip error [m]", 1e-5), ("yeh_tripod", "max foot slip [m]", 1e-6)],
)
def test_demo_cell_writes_the_log_and_figure_and_prints_bounded_numbers(
    cell, label, bound, tmp_path, capsys
):
    """Issue 30 item 7: ``rrc-pin demo --cell NAME`` runs the cell's scripted session."""
    assert main(["demo", "--cell", cell, "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert (tmp_path / f"{cell}.csv").is_file()
    assert (tmp_path / f"{cell}.png").stat().st_size > 5_000
    with (tmp_path / f"{cell}.csv").open() as f:
        header = f.readline().strip().split(",")
        ticks = sum(1 for _ in f)
    assert header[:3] == ["t", "mode", "status"]
    assert re.search(rf"^ticks\s+{ticks}\b", out, re.M)
    value = float(re.search(rf"^{re.escape(label)}\s+(\S+)", out, re.M).group(1))
    assert 0.0 <= value < bound
    if cell == "yeh_tripod":
        advance = float(re.search(r"^body advance \[m\]\s+(\S+)\s+planned (\S+)", out, re.M)[1])
        planned = float(re.search(r"planned (\S+)", out)[1])
        assert abs(advance - planned) < 1e-3
    else:
        assert "grip:object" in header
        moved = float(re.search(r"^object moved \[mm\]\s+(\S+)", out, re.M)[1])
        assert moved > 10.0
