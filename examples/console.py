"""The operator's console in the browser, and the same console driven from Python.

Shows: ``rrc_pin.console.Console`` serving barker6 on a local port (open the printed address,
its token included, in a browser: the arm in 3-D, the sliders, the deadman, the readouts). A
page's controls only post commands to the console's mailbox, which its control loop reads at
every tick; this script posts the same commands itself, as a page would: latch the deadman,
command the hand along its own z axis, record, stop, retrace the record (Barker's evacuation),
and reads back where the hand went and how regularly the loop ticked. Then it serves the page
until Ctrl-C. Needs the console extra: ``pip install -e ".[console]"`` (``pip install -e .``
and viser); without viser it says so.

Run: ``python examples/console.py``
"""

import importlib.util
import os
import tempfile
import time

import numpy as np

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"  # no serving at the end (the tests)

if importlib.util.find_spec("viser") is None:
    print('The console needs viser: pip install -e ".[console]"')
    print("(rrc_pin.console.ControlLoop runs without it: the loop and its mailbox alone.)")
    print("Nothing else to show without it.")
    raise SystemExit(0)

from rrc_pin.console import Console  # noqa: E402
from rrc_pin.console import commands as cmd  # noqa: E402

console = Console("barker6", port=0, rate=100.0, out=tempfile.mkdtemp(prefix="rrc-pin-"))
console.start()
print(f"console of barker6 at {console.url} (loop {console.loop.rate:g} Hz)")
loop = console.loop
try:
    start = loop.robot_pose()
    loop.mailbox.post(cmd.Record(True))
    loop.mailbox.post(cmd.Latch(True))  # the deadman, latched (a page's checkbox)
    loop.mailbox.post(cmd.Velocity(np.array([0.0, 0.0, 0.04, 0.0, 0.0, 0.0]), "local"))
    time.sleep(1.0)  # the loop ticks in its own thread meanwhile
    loop.mailbox.post(cmd.Stop())
    time.sleep(0.2)
    moved = loop.robot_pose()[:3, 3] - start[:3, 3]
    along = moved @ start[:3, 2] / np.linalg.norm(moved)
    print(f"the hand moved {1e3 * np.linalg.norm(moved):.1f} mm, cos to its z axis {along:.4f}")
    loop.mailbox.post(cmd.Reverse(loop.snapshot.recorded))  # retrace the whole record
    while not loop.notices[-1].text.startswith("reversed"):  # computed by a worker thread
        time.sleep(0.01)
    while loop.snapshot.mode == "reverse":  # then played back at the loop's rate
        time.sleep(0.01)
    back = loop.robot_pose()[:3, 3] - start[:3, 3]
    print(f"after the reverse the hand is {1e3 * np.linalg.norm(back):.1f} mm from where it "
          f"started; last notice: {loop.notices[-1].text}")
    stats = loop.clock.stats()
    print(f"loop periods: median {1e3 * stats.median:.2f} ms, p99 {1e3 * stats.p99:.2f} ms "
          f"over {stats.n} ticks ({loop.scheduling})")
    if not QUICK:
        print("serving the page; Ctrl-C to stop")
        while True:
            time.sleep(1.0)
except KeyboardInterrupt:
    pass
finally:
    console.stop()
