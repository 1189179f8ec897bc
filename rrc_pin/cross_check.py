"""Cross-validation of an arm's kinematics against independent references (``rrc-pin check``).

For a catalogue arm and its URDF file, at seeded random configurations within the limits:
Pinocchio's forward kinematics against the DH chain product (:mod:`rrc_pin.dh`) and against
yourdfpy's; Pinocchio's Jacobian in each frame against the DH cross-product Jacobian and
against a central finite difference of Pinocchio's forward kinematics.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import numpy as np
import numpy.typing as npt

from rrc_pin import models
from rrc_pin.errors import InvalidInput
from rrc_pin.loading import load
from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.robot import Robot
from rrc_pin.solvers.spatial import REFERENCES, Reference
from rrc_pin.urdf_export import COMMITTED_DIR, TOOL_FRAME, to_urdf

FD_STEP = 1e-6  # [rad] or [m]
REFS = cast(tuple[Reference, ...], REFERENCES)  # the three frame names, typed


@dataclass
class CrossCheckReport:
    """Largest discrepancies found, in SI units (m, rad, m/s per unit rate).

    Attributes:
        arm: Arm name.
        samples: Number of configurations checked.
        fk_dh: max |T_pinocchio - T_dh| over the entries of the tool pose.
        fk_yourdfpy: max |T_pinocchio - T_yourdfpy|.
        jacobian_dh: Per frame, max |J_pinocchio - J_dh|.
        jacobian_fd: Per frame, max |J_pinocchio - J_finite_difference|.
    """

    arm: str
    samples: int
    fk_dh: float = 0.0
    fk_yourdfpy: float = 0.0
    jacobian_dh: dict[Reference, float] = field(default_factory=lambda: dict.fromkeys(REFS, 0.0))
    jacobian_fd: dict[Reference, float] = field(default_factory=lambda: dict.fromkeys(REFS, 0.0))

    def worst(self) -> tuple[float, float]:
        """(largest exact-reference error, largest finite-difference error)."""
        exact = max(self.fk_dh, self.fk_yourdfpy, *self.jacobian_dh.values())
        return exact, max(self.jacobian_fd.values())


def finite_difference_jacobians(
    robot: Robot, q: npt.NDArray[np.float64], step: float = FD_STEP, frame: str | None = None
) -> dict[Reference, npt.NDArray[np.float64]]:
    """Central finite difference of a frame's pose, as (6, nq) Jacobians in the three frames.

    With ``dT`` the derivative of the pose ``T = [R p; 0 1]``: ``world_aligned`` takes
    ``v = dp`` and ``[w]x = dR R^T``; ``world`` reads ``(v, w)`` from ``dT T^-1``; ``local`` from
    ``T^-1 dT``.

    Args:
        robot: The robot.
        q: Joint positions (nq,) [rad or m].
        step: Difference step [rad or m].
        frame: Frame to differentiate; default: the tool frame.
    """
    T = robot.fk(q, frame)
    T_inv = np.linalg.inv(T)
    out: dict[Reference, npt.NDArray[np.float64]] = {ref: np.empty((6, robot.nq)) for ref in REFS}
    for i in range(robot.nq):
        dq = np.zeros(robot.nq)
        dq[i] = step
        dT = (robot.fk(q + dq, frame) - robot.fk(q - dq, frame)) / (2.0 * step)
        world = dT @ T_inv
        twists: dict[Reference, tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]] = {
            "world_aligned": (dT[:3, 3], world[:3, :3]),
            "world": (world[:3, 3], world[:3, :3]),
            "local": ((T_inv @ dT)[:3, 3], (T_inv @ dT)[:3, :3]),
        }
        for ref, (v, W) in twists.items():
            out[ref][:3, i] = v
            out[ref][3:, i] = (
                (W[2, 1] - W[1, 2]) / 2,
                (W[0, 2] - W[2, 0]) / 2,
                (W[1, 0] - W[0, 1]) / 2,
            )
    return out


def cross_check(
    spec: ArmSpec, samples: int, rng: np.random.Generator, urdf_path: Path | None = None
) -> CrossCheckReport:
    """Compare Pinocchio (from ``urdf_path``) with the DH chain, yourdfpy and finite differences.

    Args:
        spec: The arm.
        samples: Number of random configurations within the limits.
        rng: Seeded generator.
        urdf_path: URDF file to load; default: the generated text written to a temporary file.

    Raises:
        InvalidInput: ``samples`` is not an integer >= 1 (checking nothing proves nothing).
    """
    import yourdfpy  # heavy import, only needed here

    check_samples(samples)

    with tempfile.TemporaryDirectory() as tmp:
        if urdf_path is None:
            urdf_path = Path(tmp) / f"{spec.name}.urdf"
            urdf_path.write_text(to_urdf(spec))
        robot = load(urdf_path, tool_frame=TOOL_FRAME)
        other = yourdfpy.URDF.load(
            str(urdf_path), load_meshes=False, build_collision_scene_graph=False
        )
    report = CrossCheckReport(spec.name, samples)
    for _ in range(samples):
        q = robot.random_q(rng)
        T = robot.fk(q)
        other.update_cfg(q)
        report.fk_dh = max(report.fk_dh, float(np.abs(T - spec.chain.fk(q)).max()))
        report.fk_yourdfpy = max(
            report.fk_yourdfpy,
            float(np.abs(T - other.get_transform(TOOL_FRAME, "base_link")).max()),
        )
        fd = finite_difference_jacobians(robot, q)
        for ref in REFS:
            J = robot.jacobian(q, ref)
            report.jacobian_dh[ref] = max(
                report.jacobian_dh[ref], float(np.abs(J - spec.chain.jacobian(q, ref)).max())
            )
            report.jacobian_fd[ref] = max(
                report.jacobian_fd[ref],
                float(np.abs(J - fd[ref]).max()),
            )
    return report


def check_samples(samples: int) -> int:
    """Return ``samples`` if it is an integer >= 1.

    Raises:
        InvalidInput: It is not (``0`` would check nothing and pass).
    """
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise InvalidInput("samples", f"expected an integer >= 1, got {samples!r}")
    return int(samples)


def run_cross_check(samples: int = 200, seed: int = 0, urdf_dir: Path | None = None) -> int:
    """Cross-check every catalogue arm against its committed URDF; print a table; exit code.

    Raises:
        InvalidInput: ``samples`` is not an integer >= 1.
    """
    check_samples(samples)
    folder = urdf_dir or COMMITTED_DIR
    rng = np.random.default_rng(seed)
    failed = 0
    print(f"{'arm':12s} {'exact refs':>11s} {'finite diff':>11s}  ({samples} configurations)")
    for spec in models.CATALOGUE.values():
        path = folder / f"{spec.name}.urdf"
        report = cross_check(spec, samples, rng, path if path.exists() else None)
        exact, fd = report.worst()
        ok = exact < 1e-9 and fd < 1e-6
        failed += not ok
        print(f"{spec.name:12s} {exact:11.1e} {fd:11.1e}  {'ok' if ok else 'FAILED'}")
    return 1 if failed else 0
