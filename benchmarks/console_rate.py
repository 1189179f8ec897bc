"""The console's control loop with a browser connected: tick periods at 100 Hz and 1 kHz.

Run from a checkout with the console and test extras and Debian's chromium installed:
``python benchmarks/console_rate.py [--seconds S] [--out DIR]``. Not part of ``rrc-pin bench``:
it needs a browser (the test suite's, headless, software WebGL), which the benchmark
smoke run of ``.ci/run`` does not install.

For each case a :class:`rrc_pin.console.Console` serves one arm on a loopback port, headless
chromium opens the page (Playwright), the deadman is latched and the sliders command a slow
hand-frame twist (the arm moves all along, the view sends every change), and after a settling
second the loop's tick periods (start to start) and work times (the tick itself) are taken for
``--seconds``. The view's own update time (scene and readouts) is sampled too. Cases: panda at
100 Hz and at 1 kHz with the console's thread switch interval (0.2 ms), and panda at 1 kHz with
Python's default (5 ms), which shows what the setting buys, and panda at 1 kHz with the loop
under real-time scheduling (``--realtime``: ``SCHED_FIFO``, root here); the gsfc_dual cell at
1 kHz (its ``CellController``, the held object commanded), with and without real-time
scheduling. Then the cost of
moving the arm in the scene (``Scene.update`` inside ``server.atomic()``, browser connected)
against viser's ``ViserUrdf.update_cfg`` on the same panda.

Writes ``console_rate.json`` into ``--out`` (default: a temporary folder) and prints a table.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import load_average, machine_info

from rrc_pin.console import Console
from rrc_pin.console import commands as cmd
from rrc_pin.console.app import SWITCH_INTERVAL

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--no-first-run"]  # fmt: skip
CASES = (
    ("panda", 100.0, SWITCH_INTERVAL, False),
    ("panda", 1000.0, SWITCH_INTERVAL, False),
    ("panda", 1000.0, SWITCH_INTERVAL, True),
    ("panda", 1000.0, 5e-3, False),
    ("gsfc_dual", 1000.0, SWITCH_INTERVAL, False),
    ("gsfc_dual", 1000.0, SWITCH_INTERVAL, True),
)
"""(arm or cell, loop rate [Hz], thread switch interval [s], real-time scheduling)."""


def ms(values: np.ndarray) -> dict[str, float]:
    """Median, p99 and max of ``values`` [s], in milliseconds."""
    median, p99 = np.percentile(values, [50.0, 99.0])
    return {"median": 1e3 * median, "p99": 1e3 * p99, "max": 1e3 * float(np.max(values))}


def run_case(
    browser: Any, arm: str, rate: float, switch: float, realtime: bool, seconds: float
) -> dict[str, Any]:
    """One console, one page, the arm moving; the loop's periods and work times."""
    import rrc_pin.console.app as app

    app.SWITCH_INTERVAL = switch  # the console sets it at start
    console = Console(arm, port=0, rate=rate, out=tempfile.mkdtemp(), realtime=realtime)
    console.start()
    try:
        page = browser.new_page(viewport={"width": 1000, "height": 700})
        page.set_default_timeout(120_000)
        page.goto(console.url)
        page.locator(".rrc-joint").first.wait_for()
        loop = console.loop
        loop.mailbox.post(cmd.Latch(True))
        loop.mailbox.post(cmd.Velocity(np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.05])))  # a slow roll
        time.sleep(1.0)
        loop.clock.reset()
        skipped, ticks = loop.skipped, loop.clock.ticks
        views = []
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            time.sleep(0.1)
            views.append(console.view.cost)
        elapsed = time.perf_counter() - start
        periods, work = loop.clock.periods(), loop.clock.work()
        out = {
            "arm": arm, "rate": rate, "switch_interval": switch, "seconds": elapsed,
            "scheduling": loop.scheduling,
            "ticks": loop.clock.ticks - ticks, "expected": round(elapsed * rate),
            "skipped": loop.skipped - skipped, "period_ms": ms(periods), "work_ms": ms(work),
            "view_ms": ms(np.array(views)), "view_updates": console.view.updates,
            "status": loop.snapshot.resolution.status if loop.snapshot.resolution else None,
        }  # fmt: skip
        page.close()
        return out
    finally:
        console.stop()


def scene_cost(browser: Any, n: int) -> dict[str, Any]:
    """``Scene.update`` against ``ViserUrdf.update_cfg`` on panda, a page connected to each."""
    import viser
    import yourdfpy
    from viser.extras import ViserUrdf

    import rrc_pin
    from rrc_pin.console.scene import Scene
    from rrc_pin.console.visuals import _filename, visuals_of

    arm = rrc_pin.load("panda")
    rng = np.random.default_rng(0)
    Q = np.array([arm.random_q(rng) for _ in range(n)])
    out: dict[str, Any] = {}
    for name in ("Scene.update", "ViserUrdf.update_cfg"):
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        if name == "Scene.update":
            scene = Scene(server, arm, visuals_of(arm))
            move = scene.update
        else:
            path = Path(arm.source)
            urdf = yourdfpy.URDF.load(str(path),
                                      filename_handler=partial(_filename, directory=path.parent))
            viewer = ViserUrdf(server, urdf, root_node_name="/robot")
            fingers = len(viewer.get_actuated_joint_names()) - arm.nq

            def move(q: np.ndarray, viewer: Any = viewer, fingers: int = fingers) -> None:
                viewer.update_cfg(np.r_[q, np.zeros(fingers)])

        page = browser.new_page(viewport={"width": 1000, "height": 700})
        page.set_default_timeout(120_000)
        page.goto(f"http://127.0.0.1:{server.get_port()}/")
        page.wait_for_selector("canvas")
        time.sleep(1.0)
        times = []
        for q in Q:
            t = time.perf_counter()
            with server.atomic():
                move(q)
            times.append(time.perf_counter() - t)
            time.sleep(0.02)
        out[name] = ms(np.array(times))
        page.close()
        server.stop()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="measured time per case")
    parser.add_argument("--out", type=Path, default=None, help="folder for console_rate.json")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    record: dict[str, Any] = {"machine": machine_info("viser", "playwright"),
                              "load_start": load_average()}  # fmt: skip
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=ARGS)
        record["cases"] = [run_case(browser, *case, args.seconds) for case in CASES]
        record["scene"] = scene_cost(browser, 200)
        browser.close()
    record["load_end"] = load_average()
    out = args.out or Path(tempfile.mkdtemp(prefix="rrc-pin-console-rate-"))
    out.mkdir(parents=True, exist_ok=True)
    (out / "console_rate.json").write_text(json.dumps(record, indent=1))
    print("| arm | rate | loop thread | switch interval | period median / p99 / max [ms] | tick "
          "work median / p99 [ms] | ticks / expected | skipped | view update median / p99 [ms] |")
    print("| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for c in record["cases"]:
        p_, w, v = c["period_ms"], c["work_ms"], c["view_ms"]
        print(f"| {c['arm']} | {c['rate']:g} Hz | {c['scheduling']} | "
              f"{1e3 * c['switch_interval']:g} ms | "
              f"{p_['median']:.2f} / {p_['p99']:.2f} / {p_['max']:.1f} | {w['median']:.3f} / "
              f"{w['p99']:.2f} | {c['ticks']} / {c['expected']} | {c['skipped']} | "
              f"{v['median']:.1f} / {v['p99']:.1f} |")  # fmt: skip
    for name, s in record["scene"].items():
        print(f"{name}: median {s['median']:.2f} ms, p99 {s['p99']:.2f} ms")
    print(f"load average {record['load_start']} -> {record['load_end']}")
    print(f"recorded in {out / 'console_rate.json'}")


if __name__ == "__main__":
    main()
