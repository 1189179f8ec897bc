"""End to end: the console served on loopback, driven by Playwright in headless Debian chromium.

One console (barker6, 100 Hz) and one browser serve the whole module; the tests run in file
order on that shared state. The screenshot is kept under pytest's tmp dir and copied to
``$TMPDIR/rrc-pin-console-artifacts/`` (the test prints the path).

Every wait is on a state (the page's, the loop's), with a timeout, :data:`PATIENCE`, that a
2-core machine at a load of 10 does not reach: there a page loads in up to a minute and a
key press reaches the loop in seconds, where a quiet machine takes a second and milliseconds.
"""

from __future__ import annotations

import http.server
import io
import math
import os
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import msgspec
import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.console import Console
from rrc_pin.console.commands import AXES, Home, Latch, Record, Velocity
from rrc_pin.console.loop import ControlLoop

viser = pytest.importorskip("viser")
sync_api = pytest.importorskip("playwright.sync_api")
Image = pytest.importorskip("PIL.Image")

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--no-first-run", "--host-resolver-rules=MAP evil.example 127.0.0.1"]  # fmt: skip
ARTIFACTS = Path(tempfile.gettempdir()) / "rrc-pin-console-artifacts"
PATIENCE = 180.0
"""Longest wait [s] for any state of the page or the loop (reached only when a test fails)."""


def wait_for(condition, timeout: float = PATIENCE, what: str = "") -> None:
    deadline = time.perf_counter() + timeout
    while not condition():
        if time.perf_counter() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.02)


@pytest.fixture(scope="module")
def chromium() -> str:
    """Debian's chromium (Playwright's own download needs the network): installed if missing."""
    if not os.path.exists(CHROMIUM):
        install = ["apt-get", "install", "-y", "-q", "chromium"]
        if subprocess.run(install, capture_output=True).returncode != 0:
            subprocess.run(["apt-get", "update", "-q"], capture_output=True, check=True)
            subprocess.run(install, capture_output=True, check=True)
    return CHROMIUM


@pytest.fixture(scope="module")
def console(tmp_path_factory):
    """Under real-time scheduling where the OS grants it (else nice), as an operator runs it on
    a busy machine: at a load of 10 on 2 cores, chromium drawing in software, a nice loop made
    201 of 408 deadlines in the rate test's 2 s."""
    c = Console("barker6", port=0, out=tmp_path_factory.mktemp("records"), view_rate=20.0,
                realtime=True)  # fmt: skip
    c.start()
    yield c
    c.stop()


@pytest.fixture(scope="module")
def browser(chromium):
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, headless=True, args=ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def page(browser, console):
    context = browser.new_context(viewport={"width": 1000, "height": 700})
    context.set_default_timeout(1000 * PATIENCE)  # a page load at load 10 on 2 cores: a minute
    page = context.new_page()
    page.goto(console.url)
    page.wait_for_selector("canvas")
    page.get_by_text("hold to move").wait_for()
    page.locator(".rrc-joint").first.wait_for()
    yield page
    context.close()


def moved(loop, start: np.ndarray) -> float:
    """How far [m] the hand is from where it was at ``start`` (a pose (4, 4))."""
    return float(np.linalg.norm(loop.robot_pose()[:3, 3] - start[:3, 3]))


def jog_until(console, page, key: str, done) -> None:
    """Press a jog key until ``done()``: each press commands the jog for a quarter of a second
    from when the loop takes it; the next press once the loop has taken it and it is over."""
    loop = console.loop
    deadline = time.perf_counter() + PATIENCE
    while not done():
        if time.perf_counter() > deadline:
            raise AssertionError(f"timed out jogging with {key}")
        page.keyboard.press(key)
        wait_for(lambda: done() or jogging(loop), what=f"{key}'s jog at the loop")
        wait_for(lambda: done() or not jogging(loop), what=f"{key}'s jog over")


def jogging(loop) -> bool:
    twist = loop.snapshot.twist
    return twist is not None and bool(twist.any())


def screenshot(page) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)


def bluish(rgb: np.ndarray) -> np.ndarray:
    """Pixels of the paper arms' blue (rrc_pin.console.visuals.PAPER_COLOR, shaded)."""
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return (b - r > 50) & (b - g > 30)


def test_the_page_shows_the_arm(console, page, tmp_path):
    shots = []  # a software renderer's first frames come slowly: look until the arm is there

    def drawn() -> bool:
        shots.append(screenshot(page)[:, :590])  # the panel sits on the right from x = 600
        return bluish(shots[-1]).sum() > 1000

    wait_for(drawn, what="the arm drawn")
    canvas = shots[-1]
    arm = int(bluish(canvas).sum())
    console.scene.robot_root.visible = False
    hidden = []

    def gone() -> bool:
        hidden.append(screenshot(page)[:, :590])
        return bluish(hidden[-1]).sum() < 0.3 * arm

    wait_for(gone, what="the arm hidden")
    console.scene.robot_root.visible = True
    changed = (np.abs(canvas - hidden[-1]).sum(axis=2) > 60).mean()
    path = tmp_path / "console.png"
    Image.fromarray(screenshot(page).astype(np.uint8)).save(path)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    kept = shutil.copy(path, ARTIFACTS / "console.png")
    print(f"\nscreenshot of the console: {kept} ({arm} arm pixels, {changed:.2%} changed hidden)")
    assert canvas.std() > 10  # not a blank canvas
    gone_pixels = (bluish(canvas) & ~bluish(hidden[-1])).sum()  # the arm's: gone when hidden
    assert gone_pixels > 1000 and gone_pixels > 0.7 * arm  # (the rest: the gizmo's blue)
    assert changed > 0.002


def test_a_slider_moved_by_the_keyboard_moves_the_hand_along_its_axis(console, page):
    loop = console.loop
    start = loop.robot_pose()
    vx = page.get_by_role("slider").nth(AXES.index("vx"))
    vx.focus()
    for _ in range(4):
        page.keyboard.press("ArrowRight")  # 4 steps of 5 mm/s
    wait_for(lambda: loop.operator.velocity[0] == pytest.approx(0.02), what="vx = 0.02 m/s")
    assert console.panel.sliders[0].value == pytest.approx(0.02)
    assert np.allclose(loop.robot_pose(), start)  # nothing moves before the deadman
    page.get_by_label("deadman latched").focus()
    page.keyboard.press(" ")
    wait_for(lambda: loop.snapshot.enabled, what="the latched deadman")
    wait_for(lambda: moved(loop, start) > 0.01, what="the hand 1 cm along")  # 20 mm/s
    d = loop.robot_pose()[:3, 3] - start[:3, 3]
    assert d @ start[:3, 0] / np.linalg.norm(d) > 0.99  # along the hand's x axis (hand frame)
    deadman = page.locator('[data-field="deadman"]')
    wait_for(lambda: deadman.inner_text() == "held", what="the page's deadman readout")


def test_keyboard_jogs_and_stop(console, page):
    loop = console.loop
    page.evaluate("document.activeElement && document.activeElement.blur()")
    page.keyboard.press(" ")  # STOP
    wait_for(lambda: not loop.operator.latched and loop.snapshot.stops == 1, what="STOP")
    assert console.guard.urgents == 1  # taken as its message came, ahead of every queue
    wait_for(lambda: console.panel.sliders[0].value == 0.0, what="sliders back at zero")
    wait_for(lambda: not page.get_by_label("deadman latched").is_checked(), what="unchecked")
    wait_for(lambda: not loop.snapshot.enabled, what="released")
    page.get_by_label("deadman latched").focus()
    page.keyboard.press(" ")
    wait_for(lambda: loop.operator.latched, what="latched again")
    console.panel.sync(loop.snapshot)  # the loop's count of the page's own STOP: not a second
    assert console.panel.latch.value  # release (it unlatched an operator who latched at once)
    page.evaluate("document.activeElement.blur()")
    start = loop.robot_pose()
    for client in console.server.get_clients().values():  # the view the arrow keys moved
        client.camera.position = console.server.initial_camera.position
        client.camera.look_at = console.server.initial_camera.look_at
    jog_until(console, page, "u", lambda: moved(loop, start) > 0.01)  # +vz, half the range
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=ARTIFACTS / "console_moving.png")  # the twist arrows at the hand
    d = loop.robot_pose()[:3, 3] - start[:3, 3]
    assert d @ start[:3, 2] / np.linalg.norm(d) > 0.99  # along the hand's z axis
    R = loop.robot_pose()[:3, :3]

    def turn() -> np.ndarray:
        return pin.log3(R.T @ loop.robot_pose()[:3, :3])

    jog_until(console, page, "Shift+U", lambda: np.linalg.norm(turn()) > 0.05)  # +wz
    assert turn()[2] / np.linalg.norm(turn()) > 0.99  # about the hand's z axis
    # the latch unchecked and the STOP button, as the page sends them: ahead of every queue too
    page.get_by_label("deadman latched").uncheck()
    wait_for(lambda: not loop.operator.latched, what="the latch let go")
    page.get_by_role("button", name="STOP (space)").click()
    wait_for(lambda: loop.snapshot.stops == 2, what="the STOP button")
    assert console.guard.urgents == 3


def test_readouts_show_the_joints_against_their_limits(console, page):
    rows = page.locator(".rrc-joint")
    assert rows.count() == 6
    assert rows.first.get_attribute("data-joint") == "joint1"
    wait_for(lambda: page.locator('[data-field="status"]').inner_text() in ("exact", "scaled"),
             what="the resolver's status")  # fmt: skip
    assert page.locator('[data-field="singularity"]').inner_text() == "none"
    assert "100 Hz" in page.locator('[data-field="loop"]').inner_text()


def test_a_page_without_the_token_is_refused(console, browser):
    context = browser.new_context()  # another browser profile: no cookie
    context.set_default_timeout(1000 * PATIENCE)
    stranger = context.new_page()
    refused = console.guard.refused
    answer = stranger.goto(console.url.split("?")[0])
    assert answer.status == 403 and "needs its token" in stranger.content()
    assert stranger.locator("canvas").count() == 0
    assert console.guard.refused > refused  # the page (and the icon it asks for)
    assert "needs its token" in console.guard.last_refused
    assert len(console.server.get_clients()) == 1  # the operator's page only
    context.close()


OPENER = """<html><head><title>waiting</title></head><body><script>
const ws = new WebSocket("{target}", ["{protocol}"]);
ws.onopen = () => {{ document.title = "opened"; }};
ws.onerror = () => {{ if (document.title === "waiting") document.title = "refused"; }};
</script></body></html>"""


class OtherSite(http.server.BaseHTTPRequestHandler):
    """Another site's page, served from this machine: it opens a websocket to ``target``."""

    target = ""

    def do_GET(self) -> None:
        body = OPENER.format(target=self.target, protocol=f"viser-v{viser.__version__}").encode()
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args) -> None:
        pass


def test_a_page_of_another_origin_cannot_open_the_websocket(console, page):
    """In the operator's own browser, its cookie set, pages of other origins served from this
    machine (chromium itself refuses a public site's page the loopback): another site's
    (``evil.example``, which the browser resolves to 127.0.0.1), and another port's of this
    machine (the same site: the browser sends the cookie along). The Origin check refuses
    both."""
    OtherSite.target = console.url.split("/?")[0].replace("http://", "ws://") + "/"
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), OtherSite)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        for host in ("evil.example", "127.0.0.1"):
            origin = f"http://{host}:{server.server_port}"
            refused = console.guard.refused
            other = page.context.new_page()
            other.goto(f"{origin}/")
            other.wait_for_function("document.title !== 'waiting'")
            assert other.title() == "refused", origin
            assert console.guard.refused == refused + 1
            assert console.guard.last_refused == f"a page of {origin!r} may not use this console"
            other.close()
    finally:
        server.shutdown()
    assert len(console.server.get_clients()) == 1  # the operator's page only


def test_the_loop_keeps_its_rate_with_a_browser_connected(console, page):
    loop = console.loop
    loop.mailbox.post(Latch(True))
    loop.clock.reset()
    start, ticks = time.perf_counter(), loop.clock.ticks
    wait_for(lambda: loop.clock.ticks > ticks + 200, what="200 ticks")  # 2 s at 100 Hz
    stats = loop.clock.stats()
    deadlines = (time.perf_counter() - start) * loop.rate
    print(f"\n100 Hz ({loop.scheduling}) with a browser: median {1e3 * stats.median:.2f} ms, "
          f"p99 {1e3 * stats.p99:.2f} ms, max {1e3 * stats.max:.1f} ms over {stats.n} periods "
          f"({loop.clock.ticks - ticks} ticks of {deadlines:.0f} deadlines), "
          f"view update {1e3 * console.view.cost:.1f} ms")  # fmt: skip
    # The median holds whatever the machine does; the count of ticks has a margin for the
    # stalls a loaded shared machine causes (docs/api.md: the tail moves with the load).
    assert stats.median == pytest.approx(0.01, rel=0.1)
    assert loop.clock.ticks - ticks > 0.5 * deadlines
    assert console.view.errors == 0


def raw_socket(console):
    """A hostile page: viser's protocol by hand (a page counts once it reports its camera)."""
    from websockets.sync.client import connect

    url = console.url.replace("http://", "ws://")
    before = set(console.server.get_clients())
    ws = connect(url, subprotocols=[f"viser-v{viser.__version__}"], max_size=None, proxy=None)
    ws.send(message("ViewerCameraMessage", wxyz=[1, 0, 0, 0], position=[1, 1, 1], fov=1.0,
                    near=0.01, far=100.0, image_height=100, image_width=100,
                    look_at=[0, 0, 0], up_direction=[0, 0, 1]))  # fmt: skip
    wait_for(lambda: set(console.server.get_clients()) - before, what="the raw page")
    (ws.client_id,) = set(console.server.get_clients()) - before
    return ws


def gone(console, ws) -> bool:
    return ws.client_id not in console.server.get_clients()


def message(kind: str, **fields) -> bytes:
    return msgspec.msgpack.encode({"type": kind, **fields})


def test_bad_input_from_pages_never_stops_or_corrupts_the_loop(console, page, browser):
    loop, panel = console.loop, console.panel
    errors, ticks = panel.errors, loop.clock.ticks
    vx, speed = panel.sliders[0]._impl.uuid, panel.speed._impl.uuid  # viser keeps ids private
    frame = panel.frame._impl.uuid
    second = page.context.new_page()  # a second page at the same time (its cache: the first's)
    second.goto(console.url)
    second.get_by_text("hold to move").wait_for()
    wait_for(lambda: len(console.server.get_clients()) == 2, what="two pages")
    # Values of the right kind out of range, or not numbers: refused by the panel.
    ws = raw_socket(console)
    for value in (math.nan, math.inf, 1e9, -5.0):
        ws.send(message("GuiUpdateMessage", uuid=vx, updates={"value": value}))
    ws.send(message("GuiUpdateMessage", uuid=speed, updates={"value": 5000}))
    ws.send(message("GuiUpdateMessage", uuid=frame, updates={"value": "sideways"}))
    for position, wxyz in (([math.nan, 0, 0], [1, 0, 0, 0]), ([0, 0, 0], [0, 0, 0, 0])):
        ws.send(message("TransformControlsUpdateMessage", name="/target", wxyz=wxyz,
                        position=position))  # fmt: skip
    # (each refusal puts the controls back: how many arrive refused depends on the threads)
    wait_for(lambda: panel.errors > errors and console.scene.refused > 0,
             what=f"refusals ({panel.errors - errors}, {console.scene.refused})")  # fmt: skip
    # Garbage: values viser cannot cast, unknown ids and messages, bytes that are not msgpack.
    ws.send(message("GuiUpdateMessage", uuid=vx, updates={"value": "garbage"}))
    ws.send(message("GuiUpdateMessage", uuid="no-such-id", updates={"value": 1}))
    ws.send(message("NoSuchMessage", anything=[1, 2, 3]))  # the guard closes this connection
    wait_for(lambda: gone(console, ws), what="the page of unknown messages dropped")
    garbage = raw_socket(console)
    garbage.send(b"\x00\xff garbage \x13")  # and this one
    wait_for(lambda: gone(console, garbage), what="the page of garbage dropped")
    # A flood, then a socket closed without the closing handshake.
    ws = raw_socket(console)
    for _ in range(1000):
        ws.send(message("GuiUpdateMessage", uuid=speed, updates={"value": 50}))
        ws.send(message("GuiUpdateMessage", uuid=speed, updates={"value": 55}))
    ws.socket.close()
    second.close()
    wait_for(lambda: gone(console, ws), what="the flooding page gone")
    wait_for(lambda: len(console.server.get_clients()) == 1, what="one page left")
    wait_for(lambda: loop.clock.ticks > ticks + 50, what="the loop ticking on")
    print(
        f"\nrefused: {panel.errors - errors} page values, {console.scene.refused} gizmo poses; "
        f"mailbox: {loop.mailbox.dropped} commands dropped of {loop.mailbox.posted}"
    )
    assert loop.alive and loop.errors == 0
    q = loop.snapshot.q
    robot = console.robot
    assert np.all(np.isfinite(q)) and np.all(q >= robot.lower) and np.all(q <= robot.upper)
    s = loop.operator.settings
    v = loop.operator.velocity
    assert np.all(np.abs(v[:3]) <= s.max_linear) and np.all(np.abs(v[3:]) <= s.max_angular)
    assert loop.operator.frame in ("local", "world_aligned") and loop.operator.target is None
    assert loop.ctl.speed in (0.5, 0.55)  # the flood's last values, in range
    assert len(loop.mailbox) < loop.mailbox.capacity
    assert loop.operator.latched  # a page is still there: the deadman is not released
    assert page.locator(".rrc-joint").count() == 6  # and it still shows the console


def test_a_record_uploaded_by_the_page_is_replayed(console, page, tmp_path):
    """A record of three parts (viser uploads in parts of 512 kiB): the intake takes each."""
    loop = console.loop
    recorder = ControlLoop(console.robot, rate=100.0)
    for command in (Record(True), Latch(True), Velocity(np.array([0.01, 0, 0, 0, 0, 0]))):
        recorder.mailbox.post(command)
    for k in range(2500):
        recorder.tick(k * recorder.dt)
    path = recorder.ctl.log.save(tmp_path / "record.csv")
    assert path.stat().st_size > 2 * 2**19
    closed = dict(console.guard.closed)
    page.get_by_text("Trajectory").click()
    page.locator("input[type=file]").set_input_files(path)
    wait_for(lambda: loop.snapshot.mode == "replay", what="the uploaded record replayed")
    assert console.guard.closed == closed
    page.evaluate("document.activeElement && document.activeElement.blur()")
    page.keyboard.press(" ")  # STOP ends the replay
    wait_for(lambda: loop.snapshot.mode == "teleop", what="the replay stopped")


def test_dragging_the_gizmo_servoes_the_hand_to_it(console, page):
    """From home: the flood above leaves the arm wherever its timing took it."""
    loop = console.loop
    loop.mailbox.post(Home())
    wait_for(lambda: np.array_equal(loop.snapshot.q, loop.start_q), what="the arm at home")
    # going home is a stop: latched only once the page shows it released (latched before, the
    # page's release came after and unlatched the servo half a second in)
    latch = page.get_by_label("deadman latched")
    wait_for(lambda: not latch.is_checked(), what="the page's latch released")
    latch.check()
    wait_for(lambda: loop.operator.latched, what="the deadman latched")
    start = loop.robot_pose()
    target = start.copy()
    target[:3, 3] += 0.03 * start[:3, 1]  # 3 cm along the hand's y axis
    x, y, z, w = pin.Quaternion(target[:3, :3]).coeffs().tolist()
    ws = raw_socket(console)  # the page's gizmo, by its message
    ws.send(message("TransformControlsUpdateMessage", name="/target", wxyz=[w, x, y, z],
                    position=target[:3, 3].tolist()))  # fmt: skip
    wait_for(lambda: loop.snapshot.mode == "target", what="the servo to the target")
    wait_for(lambda: np.linalg.norm(loop.robot_pose()[:3, 3] - target[:3, 3]) < 2e-3,
             what="the hand at the target")  # fmt: skip
    d = loop.robot_pose()[:3, 3] - start[:3, 3]
    assert d @ start[:3, 1] / np.linalg.norm(d) > 0.99
    ws.socket.close()
    wait_for(lambda: gone(console, ws), what="the gizmo's page gone")
    page.get_by_role("button", name="drop the target").click()
    wait_for(lambda: loop.operator.target is None, what="the target dropped")


def test_the_last_page_closing_releases_the_deadman(console, page):
    loop = console.loop
    assert loop.operator.latched
    page.close()
    wait_for(
        lambda: not loop.operator.latched,
        what=f"the released deadman ({len(console.server.get_clients())} pages)",
    )
    assert "no page connected" in loop.notices[-1].text
    assert loop.alive


def test_a_cells_console_at_1_khz_drives_the_object_and_a_pages_stop_holds_it(browser, tmp_path):
    """gsfc_dual served at 1 kHz: the page shows the cell and names its held object; latched,
    the object goes up (20 mm/s) with the grip held; the page's STOP is taken out of band
    (the guard's urgents) and the cell then holds still to 1e-6 m over 100 more ticks."""
    c = Console("gsfc_dual", port=0, rate=1000.0, out=tmp_path)
    c.start()
    context = browser.new_context(viewport={"width": 1000, "height": 700})
    context.set_default_timeout(1000 * PATIENCE)
    try:
        page = context.new_page()
        page.goto(c.url)
        page.get_by_text("hold to move").wait_for()
        loop = c.loop
        assert loop.hands == ("object",) and loop.dt == pytest.approx(1e-3, abs=1e-15)
        wait_for(lambda: c.panel.status.content.count('data-field="hand" style="color:inherit">'
                                                      "object<") == 1, what="the object named")
        start = loop.robot_pose()
        loop.mailbox.post(Latch(True))
        loop.mailbox.post(Velocity(np.array([0.0, 0.0, 0.02, 0.0, 0.0, 0.0]), "world_aligned"))
        wait_for(lambda: moved(loop, start) > 0.005, what="the object 5 mm up")
        d = loop.robot_pose()[:3, 3] - start[:3, 3]
        assert np.linalg.norm(d[:2]) < 1e-3 * np.linalg.norm(d) + 1e-6
        page.evaluate("document.activeElement && document.activeElement.blur()")
        page.keyboard.press(" ")  # STOP
        wait_for(lambda: not loop.operator.latched and loop.snapshot.stops == 1, what="STOP")
        assert c.guard.urgents == 1
        wait_for(lambda: not loop.snapshot.enabled, what="released")
        held, ticks = loop.robot_pose(), loop.clock.ticks
        wait_for(lambda: loop.clock.ticks > ticks + 100, what="100 more ticks")
        assert moved(loop, held) < 1e-6
        position, rotation = loop.cell_ctl.chain_error
        assert loop.snapshot.lost is None and max(position, rotation) <= 2e-5
        assert loop.errors == 0 and c.view.errors == 0, c.view.last_error
    finally:
        context.close()
        c.stop()
