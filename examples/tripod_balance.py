"""Balance: Yeh's tripod keeps its centre of mass over its feet while it is pushed and walks.

Shows: ``rrc_pin.SupportPolygonLimit`` (the centre of mass's ground projection kept in the
convex hull of the feet's contact patches, shrunk by a margin) with ``rrc_pin.ContactLimit``
for the feet in support and a body ``FrameTask``, through the ``Resolver``: random body
commands that would carry the centre of mass out are scaled; then each foot in turn is
lifted and set down 5 cm forward after ``rrc_pin.ComTask`` moved the centre of mass over the
two other feet, the body pushed toward the lifted foot meanwhile. Prints the centre of
mass's closest approach to the region's edge, checked with scipy's convex hull. Needs only
``pip install -e .``.

Run: ``python examples/tripod_balance.py``
"""

from __future__ import annotations

import os

import numpy as np
from scipy.spatial import ConvexHull

import rrc_pin
from rrc_pin.center_of_mass import center_of_mass
from rrc_pin.kinematics import Kinematics, Layout

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
DT = 0.01
SOLE = 0.3 * np.array([[1.0, 1.0], [1.0, -1.0], [-1.0, 1.0], [-1.0, -1.0]])  # [m] patches


class Tripod:
    """The tripod through a Resolver: a top level, a posture below, contacts and support."""

    def __init__(self, margin: float) -> None:
        self.cell = rrc_pin.load("yeh_tripod")
        self.feet = list(self.cell.tool_frames)
        self.margin, self.layout = margin, Layout.of(self.cell)
        self.contact = rrc_pin.ContactLimit(self.feet)
        self.support = rrc_pin.SupportPolygonLimit(self.feet, sole=SOLE, margin=margin)
        self.resolver = rrc_pin.Resolver(self.cell, dt=DT, limits=[
            rrc_pin.JointLimits(), self.contact, self.support])  # fmt: skip
        self.posture = rrc_pin.PostureTask(self.cell.dof_positions(self.cell.ready()),
                                           gain=0.1, weight=1e-3)  # fmt: skip
        self.q = self.cell.ready()
        self.closest, self.scaled = np.inf, 0

    def kinematics(self) -> Kinematics:
        """The kinematics now."""
        _, dof, q_pin = self.cell.positions(self.q)
        return Kinematics(self.cell.model, self.cell.model.createData(), self.layout, dof, q_pin)

    def com(self) -> np.ndarray:
        """The centre of mass's ground projection (2,) [m] now."""
        return center_of_mass(self.kinematics()).position[:2]

    def tick(self, *levels: list) -> None:
        """Resolve ``levels`` (the posture below), integrate, check against scipy's hull."""
        r = self.resolver.solve(self.q, [*levels, [self.posture]], priority="strict")
        held = any(row.name.startswith("support") for row in r.active_rows)
        self.scaled += held and r.scale < 0.999
        self.q = self.cell.integrate(self.q, r.qdot, DT)
        hull = ConvexHull(np.vstack([self.cell.fk(self.q, f)[:2, 3] + SOLE
                                     for f in self.support.feet]))  # fmt: skip
        inside = -(hull.equations[:, :2] @ self.com() + hull.equations[:, 2]).max()
        self.closest = min(self.closest, inside - self.margin)  # >= 0: in the shrunk region

    def in_support(self, feet: list[str]) -> None:
        """The feet in support from now on (contacts and region)."""
        self.contact.set_frames(feet)
        self.support.set_feet(feet)


def pushed(seconds: float) -> Tripod:
    """Random horizontal body commands on three feet, the region shrunk by 0.65 m."""
    tripod, rng = Tripod(margin=0.65), np.random.default_rng(0)
    for k in range(round(seconds / DT)):
        if k % 100 == 0:
            twist = np.r_[rng.normal(size=2) * 0.15, 0.0, 0.0, 0.0, rng.normal() * 0.1]
        tripod.tick([rrc_pin.FrameTask("body", twist)])
    return tripod


def over(tripod: Tripod, feet: list[str]) -> np.ndarray:
    """A point 5 cm inside the region of ``feet`` nearest the centre of mass."""
    normals, offsets = rrc_pin.SupportPolygonLimit(feet, sole=SOLE, margin=0.08).region(
        tripod.kinematics())  # fmt: skip
    target = tripod.com()
    for _ in range(20):
        excess = normals @ target - offsets
        if excess.max() <= 0.0:
            break
        target = target - (excess.max() + 1e-3) * normals[excess.argmax()]
    return target


def walk(legs: int) -> Tripod:
    """Each of ``legs`` feet in turn: the CoM over the others, the foot stepped 5 cm."""
    tripod = Tripod(margin=0.03)
    middle = tripod.com()
    for leg in tripod.feet[:legs]:
        rest = [f for f in tripod.feet if f != leg]
        shift(tripod, over(tripod, rest))
        tripod.in_support(rest)
        start = tripod.cell.fk(tripod.q, leg)
        away = (start[:2, 3] - tripod.com()) / np.linalg.norm(start[:2, 3] - tripod.com())
        for k in range(500):
            s = min(k, 200) / 200.0
            goal = start.copy()
            goal[0, 3] += 0.05 * s
            goal[2, 3] += 0.05 * np.sin(np.pi * s)
            foot = rrc_pin.FrameTask(leg, target=goal)
            body = rrc_pin.FrameTask("body", np.r_[0.1 * away, 0.0] if k < 200 else np.zeros(3),
                                     rows="position")  # fmt: skip
            tripod.tick([foot, body] if k < 200 else [foot], [body])
        tripod.in_support(tripod.feet)
        shift(tripod, middle)
    return tripod


def shift(tripod: Tripod, target: np.ndarray) -> None:
    """The centre of mass to ``target`` (2,) [m], the body's height and attitude held."""
    body = tripod.cell.fk(tripod.q, "body")
    for _ in range(300):
        tripod.tick([rrc_pin.ComTask(axes="xy", target=target, gain=2.0),
                     rrc_pin.FrameTask("body", rows=(2, 3, 4, 5), target=body)])  # fmt: skip


def main() -> None:
    """Pushed, then walking."""
    run = pushed(8.0 if QUICK else 15.0)
    print(f"pushed: the CoM's closest approach to the shrunk region's edge "
          f"{1e3 * run.closest:.3f} mm (inside); {run.scaled} commands scaled by the region")
    run = walk(1 if QUICK else 3)
    print(f"walking, one foot lifted at a time: closest approach {1e3 * run.closest:.3f} mm; "
          f"{run.scaled} ticks of the push toward the lifted foot scaled")
    print(f"feet in support at the end: {', '.join(run.support.feet)}")


if __name__ == "__main__":
    main()
