"""The Dask driver: bit-identical maps from 1 and 2 workers, any task grouping, an interrupted
and resumed run, and a dask.distributed cluster of two worker processes on loopback; an
address with no scheduler fails fast; a default run listens on loopback only and serves no
dashboard unless asked."""

from __future__ import annotations

import ipaddress
import json
import subprocess
import sys
import time
import urllib.error
import urllib.request

import pytest

distributed = pytest.importorskip("distributed")

from rrc_pin import maps  # noqa: E402
from rrc_pin.errors import InvalidInput, SchedulerUnreachable  # noqa: E402
from rrc_pin.maps import driver  # noqa: E402

psutil = pytest.importorskip("psutil")  # a dependency of distributed

pytestmark = pytest.mark.compiled

SMALL = {"block_size": 2**10, "progress": False}
"""Blocks of 2^10 samples keep these maps fast; one test uses the default 2^15."""


@pytest.fixture(scope="module")
def cluster():
    """A scheduler and two worker processes (one thread each) on loopback."""
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=":0",
    ) as c:  # fmt: skip
        yield c


def _same(a: maps.CapabilityMap, b: maps.CapabilityMap) -> None:
    assert a.grid == b.grid
    assert a.stats.same_as(b.stats)
    assert a.stats.count.sum() == a.meta["samples"]


@pytest.mark.parametrize("arm", ["panda", "barker6"])
def test_one_and_two_workers_and_any_grouping_give_the_same_bits(arm):
    n = 16 * 2**10 - 100  # 16 blocks, the last shorter
    one = maps.capability(arm, n, 0.08, workers=1, seed=3, **SMALL)
    two = maps.capability(arm, n, 0.08, workers=2, seed=3, **SMALL)
    _same(one, two)
    for per_task in (1, 5, 16):
        _same(one, maps.capability(arm, n, 0.08, workers=2, seed=3, blocks_per_task=per_task,
                                   **SMALL))  # fmt: skip
    other = maps.capability(arm, n, 0.08, workers=1, seed=4, **SMALL)
    assert not one.stats.same_as(other.stats)


def test_default_blocks_of_2_15_one_and_two_workers():
    kw = {"seed": 11, "dexterity": False, "progress": False}
    one = maps.capability("panda", 5 * 2**15 - 123, 0.05, workers=1, **kw)
    two = maps.capability("panda", 5 * 2**15 - 123, 0.05, workers=2, blocks_per_task=2, **kw)
    _same(one, two)
    assert one.meta["block_size"] == 2**15 and one.plan.blocks == 5


class Stop(Exception):
    pass


def test_an_interrupted_run_resumes_to_the_same_bits(tmp_path):
    kw = {"seed": 5, "voxel": 0.08, "block_size": 2**10}
    whole = maps.capability("barker6", 20 * 2**10, workers=2, progress=False, **kw)
    calls = []

    def stop_after_three(p):
        calls.append(p.done_blocks)
        if len(calls) == 3:
            raise Stop

    with pytest.raises(Stop):
        maps.capability("barker6", 20 * 2**10, workers=2, out=tmp_path, blocks_per_task=2,
                        progress=stop_after_three, **kw)  # fmt: skip
    parts = list((tmp_path / "blocks").glob("part-*.npz"))
    assert parts and not (tmp_path / "map.zarr").exists()
    resumed = maps.capability("barker6", 20 * 2**10, workers=1, out=tmp_path, blocks_per_task=5,
                              progress=False, **kw)  # fmt: skip
    _same(whole, resumed)
    assert 6 <= resumed.meta["run"]["blocks_resumed"] < 20
    again = maps.capability("barker6", 20 * 2**10, workers=1, out=tmp_path, progress=False,
                            **kw)  # nothing left to compute  # fmt: skip
    _same(whole, again)
    assert again.meta["run"]["blocks_computed"] == 0
    _same(whole, maps.load_map(tmp_path / "map.zarr"))


def test_a_distributed_cluster_gives_the_local_bits(cluster):
    kw = {"seed": 9, **SMALL}
    local = maps.capability("barker6", 16 * 2**10, 0.08, workers=2, **kw)
    remote = maps.capability("barker6", 16 * 2**10, 0.08, cluster.scheduler_address, **kw)
    _same(local, remote)
    assert remote.meta["run"]["threads"] == 2
    chain_local = maps.capability("rrc_k1607", 8 * 2**10, 0.08, workers=1, **kw)
    with distributed.Client(cluster.scheduler_address) as client:  # a Client passed in
        chain_remote = maps.capability("rrc_k1607", 8 * 2**10, 0.08, client, **kw)
    _same(chain_local, chain_remote)


def test_an_address_without_a_scheduler_fails_fast(tmp_path):
    start = time.perf_counter()
    with pytest.raises(SchedulerUnreachable) as err:
        maps.capability("kr5_3r", 1000, 0.1, "tcp://127.0.0.1:9", out=tmp_path / "m",
                        progress=False)  # fmt: skip
    assert time.perf_counter() - start < driver.CONNECT_TIMEOUT + 3.0
    assert err.value.argument == "scheduler" and "127.0.0.1:9" in str(err.value)
    assert not (tmp_path / "m").exists()


@pytest.mark.parametrize(
    ("scheduler", "workers", "argument"),
    [(42, None, "scheduler"), ("", None, "scheduler"), ("tcp://a b:1", None, "scheduler"),
     ("tcp://127.0.0.1:9", 2, "workers"), (None, 0, "workers"), (None, 1.5, "workers"),
     (None, True, "workers")],
)  # fmt: skip
def test_scheduler_and_workers_arguments_are_checked(scheduler, workers, argument):
    with pytest.raises(InvalidInput) as err:
        maps.capability("kr5_3r", 1000, 0.1, scheduler, workers=workers, progress=False)
    assert err.value.argument == argument


@pytest.mark.parametrize("dashboard", [8787, "", "abc", ":99999", "tcp://host:1", "a b:1"])
def test_a_bad_dashboard_address_is_refused(dashboard):
    with pytest.raises(InvalidInput) as err:
        maps.capability("kr5_3r", 1000, 0.1, dashboard=dashboard, progress=False)
    assert err.value.argument == "dashboard"
    with pytest.raises(InvalidInput) as err:
        maps.capability("kr5_3r", 1000, 0.1, "tcp://127.0.0.1:9", dashboard="8787")
    assert err.value.argument == "dashboard"


def test_dashboard_addresses_default_to_loopback():
    assert driver.dashboard_address("8787") == "127.0.0.1:8787"
    assert driver.dashboard_address(":0") == "127.0.0.1:0"
    assert driver.dashboard_address("0.0.0.0:8787") == "0.0.0.0:8787"  # named: every interface


SOCKETS = """
import json, sys, threading, psutil
from rrc_pin.cli import main
seen, done = set(), threading.Event()

def sample():  # this process and its children, every 20 ms while the map runs
    while not done.is_set():
        me = psutil.Process()
        for p in (me, *me.children(recursive=True)):
            try:
                for c in p.net_connections(kind="inet"):
                    seen.add((c.laddr.ip if c.laddr else "", c.status))
            except psutil.Error:
                pass
        done.wait(0.02)

threading.Thread(target=sample, daemon=True).start()
code = main(["map", "kr5_3r", "--samples", "60000", "--voxel", "0.1", "--out", sys.argv[1]])
done.set()
print("SOCKETS " + json.dumps([code, sorted(seen)]))
"""


def test_a_default_map_run_listens_on_loopback_only(tmp_path):
    """``rrc-pin map`` with no scheduler, in a fresh interpreter: every socket of the process
    and its children, sampled while the map runs, is on 127.0.0.1 (distributed 2026.8 with
    ``dashboard_address=None`` listened on 0.0.0.0:8787 and a second port)."""
    done = subprocess.run([sys.executable, "-c", SOCKETS, str(tmp_path / "m")],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    line = next(x for x in done.stdout.splitlines() if x.startswith("SOCKETS "))
    code, seen = json.loads(line.removeprefix("SOCKETS "))
    assert code == 0
    listening = [ip for ip, status in seen if status == psutil.CONN_LISTEN]
    assert len(listening) >= 1  # the servers were seen up
    assert all(ipaddress.ip_address(ip).is_loopback for ip, _ in seen if ip), seen


def _status(port: int, path: str) -> int:
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=5) as r:
            return int(r.status)
    except urllib.error.HTTPError as e:
        return e.code


def test_the_servers_serve_nothing_unless_the_dashboard_is_asked_for():
    def ports() -> set[int]:
        return {c.laddr.port for c in psutil.Process().net_connections(kind="inet")
                if c.status == psutil.CONN_LISTEN}  # fmt: skip

    before = ports()
    for dashboard, expected in ((None, {404}), (":0", {200, 404})):
        answers: set[int] = set()

        def probe(_p, answers=answers):
            for port in ports() - before:
                answers.add(_status(port, "/health"))

        maps.capability("kr5_3r", 4 * 2**10, 0.1, workers=1, dashboard=dashboard,
                        progress=probe, block_size=2**10)  # fmt: skip
        assert answers == expected, dashboard  # 200: the scheduler's routes, once asked
