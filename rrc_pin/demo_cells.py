"""``rrc-pin demo --cell NAME``: a scripted session of a multi-arm cell.

``gsfc_dual``: a synthetic hand controller (a 3 cm circle with a wrist roll, position scale
2, clutch released for 10 % of the session) drives the object both arms hold
(:class:`rrc_pin.cells.MasterSlave`), as ``examples/dual_arm_master_slave.py``.
``yeh_tripod``: the tripod walks along its beam, one leg swinging at a time, then the body
moves, as ``examples/tripod_walk.py``. A summary table is printed; the
:class:`~rrc_pin.cells.CellController` log is written as ``<cell>.csv`` and a figure as
``<cell>.png`` (needs matplotlib) into the output folder (``--out``, or a new folder under the
system's temporary directory).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.cells import Cell, CellController, MasterSlave
from rrc_pin.demo_figure import draw_cell
from rrc_pin.loading import load

Array = npt.NDArray[np.float64]
DT = 0.01  # [s]
CELLS = ("gsfc_dual", "yeh_tripod")
SLIP_BOUND = 1e-6  # [m], the largest slip of a supporting foot the walk may show


def ctl_cell(name: str) -> Cell:
    """The ready-made cell ``name``."""
    cell = load(name)
    assert isinstance(cell, Cell)
    return cell


def master_pose(t: float) -> Array:
    """The master's synthetic pose (4, 4): a 3 cm circle with a slow wrist roll."""
    T = np.eye(4)
    T[:3, :3] = pin.exp3(np.array([0.2 * np.sin(t), 0.0, 0.0]))
    T[:3, 3] = [0.03 * np.cos(2.0 * t), 0.03 * np.sin(2.0 * t), 0.01 * np.sin(t)]
    return T


def dual(quick: bool) -> tuple[CellController, list[tuple[str, str, str]]]:
    """The master-slave session of ``gsfc_dual``; the controller and its summary rows."""
    cell = ctl_cell("gsfc_dual")
    ctl = CellController(cell, dt=DT)
    master = MasterSlave(scale=2.0, rotation=np.eye(3), dt=DT)
    ticks = round((1.0 if quick else 8.0) / DT)
    start = cell.fk(ctl.q, "object")[:3, 3]
    for k in range(ticks):
        clutch = not (0.45 * ticks <= k < 0.55 * ticks)
        ctl.step({"object": master.update(master_pose(k * DT), clutch)})
    grip = max(rec.grip["object"] for rec in ctl.log)
    moved = float(np.linalg.norm(cell.fk(ctl.q, "object")[:3, 3] - start))
    return ctl, [
        ("ticks", str(len(ctl.log)), f"{1 / DT:.0f} Hz"),
        ("object moved [mm]", f"{moved * 1e3:.1f}", "from its start"),
        ("max grip error [m]", f"{grip:.2e}", f"bound {ctl.closure.position:.0e}"
         if ctl.closure else ""),
        *_chains(ctl),
    ]


def _chains(ctl: CellController) -> list[tuple[str, str, str]]:
    """The summary's rows on the closed chains (errors at the ticks' start, lost ticks)."""
    chain = ctl.log.column("chain")
    statuses = [rec.status for rec in ctl.log]
    lost = sum(s in ("grip_lost", "contact_lost") for s in statuses)
    bound = ctl.closure
    return [
        ("max chain error [m]", f"{chain[:, 0].max():.2e}", f"bound {bound.position:.0e}"
         if bound else ""),
        ("max chain error [rad]", f"{chain[:, 1].max():.2e}", f"bound {bound.rotation:.0e}"
         if bound else ""),
        ("chain lost [ticks]", str(lost), "held still until a command closed it"),
        ("statuses", " ".join(sorted(set(statuses))), ""),
    ]


def _move(ctl: CellController, name: str, displacement: Array, speed: float) -> None:
    ticks = max(1, round(float(np.linalg.norm(displacement)) / speed / ctl.dt))
    twist = np.r_[displacement / (ticks * ctl.dt), np.zeros(3)]
    for _ in range(ticks):
        ctl.step({name: twist})
    for _ in range(5):
        ctl.step({name: np.zeros(6)})


def tripod(quick: bool) -> tuple[CellController, list[tuple[str, str, str]]]:
    """The walk of ``yeh_tripod``; the controller and its summary rows."""
    stride, lift, speed, cycles = (0.03, 0.02, 0.1, 1) if quick else (0.1, 0.05, 0.1, 2)
    cell = ctl_cell("yeh_tripod")
    ctl = CellController(cell, dt=DT)
    body0 = cell.fk(ctl.q, "body")[:3, 3]
    slip = 0.0

    def slipped(support: dict[str, Array]) -> float:
        return max(float(np.linalg.norm(cell.fk(ctl.q, f)[:3, 3] - p)) for f, p in support.items())

    for _ in range(cycles):
        for leg in cell.arms:
            ctl.swing(leg)
            support = {f: cell.fk(ctl.q, f)[:3, 3] for f in ctl.support}
            for d in ([0.0, 0.0, lift], [stride, 0.0, 0.0], [0.0, 0.0, -lift]):
                _move(ctl, leg, np.array(d), speed)
            ctl.land(leg)
            slip = max(slip, slipped(support))
        support = {f: cell.fk(ctl.q, f)[:3, 3] for f in ctl.support}
        _move(ctl, "body", np.array([stride, 0.0, 0.0]), speed)
        slip = max(slip, slipped(support))
    advance = cell.fk(ctl.q, "body")[:3, 3] - body0
    return ctl, [
        ("ticks", str(len(ctl.log)), f"{1 / DT:.0f} Hz, {cycles} cycles"),
        ("body advance [m]", f"{advance[0]:.6f}", f"planned {cycles * stride:.3f}"),
        ("max foot slip [m]", f"{slip:.2e}", f"bound {SLIP_BOUND:.0e}"),
        *_chains(ctl),
    ]


def run_cell_demo(name: str, out: Path | None = None, quick: bool = False) -> int:
    """The scripted session of cell ``name``; table printed, CSV and PNG in ``out``."""
    from rrc_pin.demo import default_out

    out = default_out() if out is None else out
    out.mkdir(parents=True, exist_ok=True)
    print(f"== {name} session, dt = {DT * 1e3:g} ms{' (quick)' if quick else ''} -> {out}\n")
    ctl, rows = (dual if name == "gsfc_dual" else tripod)(quick)
    for label, value, note in rows:
        print(f"{label:20s} {value:>14s}  {note}".rstrip())
    ctl.save(out / f"{name}.csv")
    figure = draw_cell(ctl, out / f"{name}.png")
    skipped = f"; {name}.png skipped: matplotlib is not installed"
    print(f"\nwritten to {out}: {name}.csv" + (f", {name}.png" if figure else skipped))
    return 0
