"""``rrc-pin demo``: kinematics, closed forms and resolved-rate control in one short run."""

from __future__ import annotations

import time
from collections import Counter

import numpy as np
import numpy.typing as npt

from rrc_pin import models
from rrc_pin.loading import load
from rrc_pin.resolver import Resolver
from rrc_pin.robot import Robot
from rrc_pin.tasks import FrameTask
from solvers.closed_form.barker import BarkerClosedForm
from solvers.closed_form.quaternion import quaternion_from_matrix, rotation_vector

Array = npt.NDArray[np.float64]
DT = 0.01  # [s], control period


def kinematics_tour(names: list[str]) -> None:
    """Print, per arm and tool frame, its position and Jacobian conditioning at a named pose."""
    print(f"{'arm':12s} {'dof':>3s} {'pose':12s} {'tool frame':16s} {'position [m]':>28s} "
          f"{'cond(J)':>9s}")  # fmt: skip
    for name in names:
        arm = load(name)
        spec = models.CATALOGUE.get(name)
        pose_name, q = next(iter(spec.named_poses.items())) if spec else ("neutral", arm.neutral())
        for frame in arm.tool_frames:
            position = np.array2string(arm.fk(q, frame)[:3, 3], precision=4, suppress_small=True)
            cond = np.linalg.cond(arm.jacobian(q, frame=frame))
            print(f"{name:12s} {arm.nq:3d} {pose_name:12s} {frame:16s} {position:>28s} {cond:9.2e}")


def closed_form_check(rng: np.random.Generator) -> None:
    """Closed-form joint rates of the paper arms against a solve with Pinocchio's Jacobian.

    Barker's closed form is asked for its exact inverse: by default it damps the rates in a
    narrow band around its singularities (continuous there), where it differs from lstsq.
    """
    print(f"{'arm':12s} {'closed form':>22s} {'max rel. diff vs Pinocchio':>28s}")
    for name in ("barker6", "rrc_k1607", "kr5_3r"):
        arm = load(name)
        cf = arm.closed_form
        assert cf is not None  # every paper arm has one at its tool frame
        worst = 0.0
        for _ in range(200):
            q = arm.random_q(rng)
            x = rng.normal(size=cf.task_dim)
            J = arm.jacobian(q)[: cf.task_dim]
            if np.linalg.cond(J) > 1e6:
                continue
            reference = np.linalg.lstsq(J, x, rcond=None)[0]
            if isinstance(cf, BarkerClosedForm):
                rates = cf.joint_rates(q, x, exact=True)
            else:
                rates = cf.joint_rates(q, x)
            worst = max(worst, float(np.linalg.norm(rates - reference) / np.linalg.norm(reference)))
        print(f"{name:12s} {type(cf).__name__:>22s} {worst:28.1e}")


def teleoperate(arm: Robot, q0: Array, segments: list[tuple[str, Array, float]]) -> Array:
    """Drive ``arm`` with hand-frame twists (Barker eq. (20)), Euler-integrated (eq. (21)).

    Returns:
        The joint path, (steps + 1, nq).
    """
    resolver = Resolver(arm, dt=DT)
    q = q0.copy()
    path = [q]
    print(
        f"{'command (hand frame)':28s} {'asked':>8s} {'done':>10s} {'veer':>6s} "
        f"{'max|qdot|':>10s} {'limit excess':>12s} {'step [us]':>9s}  answers"
    )
    for label, twist, duration in segments:
        T0 = arm.fk(q)
        methods: Counter[str] = Counter()
        times, peak, excess = [], 0.0, 0.0
        for _ in range(round(duration / DT)):
            start = time.perf_counter()
            r = resolver.solve(q, twist, ref="local")
            times.append(time.perf_counter() - start)
            q = q + r.qdot * DT
            path.append(q)
            methods[r.status] += 1
            peak = max(peak, float(np.abs(r.qdot).max()))
            excess = max(
                excess,
                float(np.max(np.abs(r.qdot) - arm.velocity_limit)),
                float(np.max(q - arm.upper)),
                float(np.max(arm.lower - q)),
            )
        T1 = arm.fk(q)
        if np.any(twist[:3]):  # translation: compare displacements in base axes
            asked_vec = T0[:3, :3] @ twist[:3] * duration
            done_vec = T1[:3, 3] - T0[:3, 3]
            unit = "m  "
        else:  # rotation: compare rotation vectors in the starting hand frame
            asked_vec = twist[3:] * duration
            done_vec = rotation_vector(quaternion_from_matrix(T0[:3, :3].T @ T1[:3, :3]))
            unit = "rad"
        asked, done = float(np.linalg.norm(asked_vec)), float(np.linalg.norm(done_vec))
        cos = float(asked_vec @ done_vec) / max(asked * done, 1e-300)
        veer = float(np.rad2deg(np.arccos(np.clip(cos, -1.0, 1.0))))
        used = ", ".join(f"{m} {n}" for m, n in methods.most_common())
        print(
            f"{label:28s} {asked:6.3f} {unit} {done:6.3f} {unit} {veer:6.2f} {peak:8.3f}   "
            f"{max(excess, 0.0):12.1e} {1e6 * np.median(times):9.0f}  {used}"
        )
    return np.array(path)


def run_demo(arm: str | None = None) -> int:
    """Run the demo (all paper arms plus panda, or the tour of one ``arm``); exit code."""
    rng = np.random.default_rng(0)
    names = [arm] if arm else [*models.CATALOGUE, "panda"]
    print("== Forward kinematics and Jacobians (Pinocchio)\n")
    kinematics_tour(names)
    if arm:
        return 0
    print("\n== Closed forms of the papers, 200 random configurations each\n")
    closed_form_check(rng)

    print("\n== Barker's arm teleoperated in the hand frame, dt = 10 ms (QP resolver, DAQP)\n")
    barker = load("barker6")
    q0 = np.deg2rad([20.0, 30.0, 60.0, 10.0, 40.0, 0.0])
    path = teleoperate(
        barker,
        q0,
        [
            ("0.80 rad/s about -y6, 1.5 s", np.array([0, 0, 0, 0, -0.8, 0.0]), 1.5),
            ("0.10 m/s along x6, 1 s", np.array([0.1, 0, 0, 0, 0, 0.0]), 1.0),
            ("0.30 rad/s about z6, 1 s", np.array([0, 0, 0, 0, 0, 0.3]), 1.0),
            ("5 m/s along -z6, 0.5 s", np.array([0, 0, -5.0, 0, 0, 0.0]), 0.5),
        ],
    )
    theta5 = np.rad2deg(path[:151, 4])
    print(
        f"veer: angle [deg] between the commanded and the achieved motion. About -y6, theta5 "
        f"went from {theta5[0]:.1f}\nto {theta5[-1]:.1f} deg through Barker's wrist singularity "
        f"theta5 = 0 (closest {np.min(np.abs(theta5)):.2f} deg). 5 m/s exceeds the\njoint "
        "speed limits: the hand slowed down along the commanded direction (the veer left comes\n"
        "from Euler integration). answers: exact, scaled (direction kept, slower), damped\n"
        "(near a singularity)."
    )

    print("\n== Panda: an absurd command (1e6 m/s) from a start outside the joint limits\n")
    panda = load("panda")
    q = panda.neutral()
    q[0] = panda.upper[0] + 0.05
    r = Resolver(panda, dt=DT).solve(q, np.array([1e6, 0, 0, 0, 0, 0.0]))
    active = ", ".join(f"{a.name} {a.side} {a.kind}" for a in r.active[:4])
    print(
        f"{r.status}: scale {r.scale:.2e}, qdot[0] = {r.qdot[0]:+.3f} rad/s (back into "
        f"range), max|qdot|/limit = {np.max(np.abs(r.qdot) / panda.velocity_limit):.3f}"
    )
    print(f"active limits: {active}{' ...' if len(r.active) > 4 else ''}")
    two_hands()
    return 0


def two_hands() -> None:
    """Baxter's grippers with the left one commanded beyond its speed.

    Both at one priority level, they slow down together with their directions kept; with the
    right one first, it stays exact and the left one gets the least squares of what is left.
    """
    print("\n== Baxter, two grippers on one model (15 joints), strict priorities\n")
    baxter = load("baxter")
    left, right = baxter.tool_frames
    q = baxter.neutral() + 0.3
    fast, slow = np.array([2.0, 0, 0, 0, 0, 0.0]), np.array([0, 0.05, 0, 0, 0, 0.0])
    resolver = Resolver(baxter, dt=DT)
    print(f"{'levels':32s} {left + ' scale':>20s} {right + ' scale':>20s}  status")
    for label, levels in (
        ("[left, right] together", [[FrameTask(left, fast), FrameTask(right, slow)]]),
        ("[right] above [left]", [FrameTask(right, slow), FrameTask(left, fast)]),
    ):
        r = resolver.solve(q, levels, priority="strict")
        scale = {t.name: t.scale for t in r.tasks}
        print(f"{label:32s} {scale[left]:20.3f} {scale[right]:20.3f}  {r.status}")
