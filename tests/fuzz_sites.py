"""The public call sites the fuzz of tests/test_fuzz.py drives, each with valid arguments.

Every class of ``rrc_pin.__all__`` (its constructor and public methods) and function, and the
documented entry points of the submodules: guidance, maps, the control strategies, cells. A
site is a callable made fresh for each call where a call that succeeds with a strange value
could change what the next one sees (a controller's configuration; a collision model that
only gains shapes serves all calls of a site), and the valid value of each argument the fuzz
replaces, one at a time. Records (``NamedTuple``: ``TaskRows``, ``Constraints``, guidance's
``Command``...) are data: they are checked where a call takes them, and the fuzz passes bad
ones there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import rrc_pin
from rrc_pin import guidance, maps
from rrc_pin.cells.closure import ClosureBound
from rrc_pin.control import strategies
from rrc_pin.solvers.tick.damping import Damping


@dataclass
class Site:
    """A call site: ``call()(**valid, **fixed)`` succeeds.

    Attributes:
        name: How the report names it.
        call: Makes the callable (a fresh object's method where the object holds state: an
            error must leave that object as it was).
        valid: The valid value of each argument the fuzz replaces (passed by keyword).
        fixed: Arguments passed as they are (not fuzzed).
        aliases: Other names an error may give an argument (``command`` is a ``twist``).
    """

    name: str
    call: Callable[[], Callable[..., Any]]
    valid: dict[str, Any]
    fixed: dict[str, Any] = field(default_factory=dict)
    aliases: dict[str, tuple[str, ...]] = field(default_factory=dict)


class World:
    """The objects the sites call on, built once (read only for the sites).

    Args:
        tmp: A folder the sites may write in (also the working folder of the fuzz).
    """

    def __init__(self, tmp: Path) -> None:
        self.tmp = tmp
        self.panda = rrc_pin.load("panda")
        self.barker = rrc_pin.load("barker6")
        self.cell = rrc_pin.load("gsfc_dual")
        self.tripod = rrc_pin.load("yeh_tripod")
        self.q = self.panda.ready()
        self.qb = self.barker.ready()
        self.tool = "panda_hand_tcp"
        self.twist = np.array([0.05, 0.0, 0.0, 0.0, 0.0, 0.1])
        self.T = np.eye(4)
        self.T[:3, 3] = [0.5, 0.0, 0.3]
        ctl = rrc_pin.Controller(self.panda)
        for _ in range(3):
            ctl.step(self.twist, ref="local")
        self.log_path = ctl.log.save(tmp / "run.csv")
        self.map = maps.capability(self.barker, samples=256, voxel=0.2, workers=1,
                                   progress=False, block_size=64)
        self.map_path = maps.save_map(self.map, tmp / "map.zarr")

    def controller(self) -> rrc_pin.Controller:
        ctl = rrc_pin.Controller(self.panda)
        ctl.step(self.twist, ref="local")
        return ctl

    def collision(self) -> rrc_pin.CollisionModel:
        model = rrc_pin.CollisionModel(self.panda)
        model.add_box(self.T, [0.1, 0.1, 0.1], name="box")
        return model

    def cell_controller(self, stepped: bool = False) -> Any:
        ctl = rrc_pin.CellController(self.cell)
        if stepped:
            ctl.step({"object": np.array([0.01, 0.0, 0.0, 0.0, 0.0, 0.0])})
        return ctl


def sites(w: World) -> list[Site]:
    """Every site of the fuzz, on the objects of ``w``."""
    return [*_robot(w), *_resolver(w), *_tasks(w), *_limits(w), *_collision(w),
            *_controller(w), *_cells(w), *_guidance(w), *_maps(w), *_strategies(w),
            *_teleoperation(w)]


def _robot(w: World) -> list[Site]:
    p = w.panda
    return [
        Site("load", lambda: rrc_pin.load, {"name_or_path": "panda", "tool_frame": None}),
        Site("arms", lambda: rrc_pin.arms, {}),
        Site("Robot", lambda: rrc_pin.Robot, {
            "model": p.model, "tool_frames": w.tool, "name": "p", "source": "s", "spec": None,
            "poses": None, "mimic_limits": None},
            aliases={"tool_frames": ("tool_frame",)}),  # named as load names it
        Site("Robot.fk", lambda: p.fk, {"q": w.q, "frame": None}),
        Site("Robot.jacobian", lambda: p.jacobian, {"q": w.q, "ref": "local", "frame": None}),
        Site("Robot.frame_pose", lambda: p.frame_pose, {"q": w.q, "frame": w.tool}),
        Site("Robot.integrate", lambda: p.integrate, {"q": w.q, "qdot": np.zeros(7), "dt": 0.01}),
        Site("Robot.configuration", lambda: p.configuration, {"q": w.q}),
        Site("Robot.to_pinocchio", lambda: p.to_pinocchio, {"q": w.q}),
        Site("Robot.dof_positions", lambda: p.dof_positions, {"q": w.q}),
        Site("Robot.positions", lambda: p.positions, {"q": w.q}),
        Site("Robot.check_q", lambda: p.check_q, {"q": w.q, "name": "q"}),
        Site("Robot.random_q", lambda: p.random_q, {"rng": 0}),
        Site("combine", lambda: rrc_pin.combine,
             {"arms": {"a": (p, np.eye(4)), "b": (w.barker, w.T)}, "name": None}),
        Site("load(parameters)", lambda: rrc_pin.load, {"name_or_path": "barker6", "a3": 0.02},
             aliases={"name_or_path": ("a3",)}),  # geometry is for catalogue names only
        Site("Robot.ready", lambda: p.ready, {}),
        Site("Robot.neutral", lambda: p.neutral, {}),
        *_closed_form(w),
    ]


def _closed_form(w: World) -> list[Site]:
    cf = w.barker.closed_form
    Q = np.array([w.qb, w.qb + 0.1])
    twist = np.array([0.1, 0.0, 0.0, 0.0, 0.0, 0.2])
    return [
        Site("ClosedForm.jacobian", lambda: cf.jacobian, {"q": w.qb}),
        Site("ClosedForm.joint_rates", lambda: cf.joint_rates,
             {"q": w.qb, "xdot": twist, "method": "full", "exact": False}),
        Site("ClosedForm.jacobian_batch", lambda: cf.jacobian_batch, {"Q": Q}),
        Site("ClosedForm.joint_rates_batch", lambda: cf.joint_rates_batch,
             {"Q": Q, "X": np.array([twist, twist]), "method": "full", "exact": False}),
        Site("ClosedForm.singularity", lambda: cf.singularity, {"q": w.qb}),
    ]


def _resolver(w: World) -> list[Site]:
    p = w.panda
    return [
        Site("Resolver", lambda: rrc_pin.Resolver, {
            "robot": p, "dt": 0.01, "task": None, "limits": None, "qp": None,
            "damping": Damping(), "direction_preserving": True, "use_closed_form": False}),
        Site("Resolver.solve", lambda: rrc_pin.Resolver(p).solve, {
            "q": w.q, "command": w.twist, "ref": None, "priority": "weighted", "dt": None,
            "qdot_prev": None}, aliases={"command": ("twist",)}),
        Site("Resolver.solve(tasks)", lambda: rrc_pin.Resolver(p).solve,
             {"q": w.q, "command": [rrc_pin.FrameTask(w.tool, w.twist)], "priority": "strict"},
             aliases={"command": ("twist",)}),
        Site("Resolver.rows_of", lambda: rrc_pin.Resolver(p).rows_of,
             {"task": rrc_pin.FrameTask(w.tool, w.twist), "q": w.q}),
        Site("Resolver.reset", lambda: rrc_pin.Resolver(p).reset, {}),
        Site("Resolver.warm_start_state", lambda: rrc_pin.Resolver(p).warm_start_state, {}),
        Site("Resolver.mask", lambda: rrc_pin.Resolver(p).mask, {"joints": ["panda_joint2"]}),
        Site("Resolver.unmask", lambda: rrc_pin.Resolver(p).unmask, {"joints": "panda_joint2"}),
        Site("QPOptions", lambda: rrc_pin.QPOptions,
             {"backend": "daqp", "options": {}, "fallbacks": ("scipy",), "time_limit": 0.05},
             aliases={k: (f"qp.{k}",) for k in ("backend", "options", "fallbacks")}),
        Site("Damping", lambda: rrc_pin.Damping, {"threshold": 100.0}),
        Site("Damping.lambda_sq", lambda: Damping().lambda_sq, {
            "sigma": np.array([2.0, 1.0, 1e-4]), "rank": 3, "scale": 0.5, "along": np.ones(3),
            "dt": 0.01}),
    ]


def _tasks(w: World) -> list[Site]:
    return [
        Site("FrameTask", lambda: rrc_pin.FrameTask, {
            "frame": w.tool, "twist": w.twist, "ref": "world_aligned", "rows": "full",
            "weight": 1.0, "name": None, "target": None, "gain": 1.0}),
        Site("FrameTask.set_twist", lambda: rrc_pin.FrameTask(w.tool).set_twist,
             {"twist": w.twist}),
        Site("FrameTask.set_target", lambda: rrc_pin.FrameTask(w.tool).set_target,
             {"target": w.T}),
        Site("FrameTask.check_twist", lambda: rrc_pin.FrameTask(w.tool).check_twist,
             {"twist": w.twist}),
        Site("FrameTask.check_ref", lambda: rrc_pin.FrameTask(w.tool).check_ref,
             {"ref": "local"}),
        Site("RelativeFrameTask", lambda: rrc_pin.RelativeFrameTask, {
            "frame_a": w.tool, "frame_b": "panda_link0", "twist": w.twist, "rows": "full",
            "weight": 1.0, "target": None, "gain": 1.0, "name": None}),
        Site("RelativeFrameTask.set_twist",
             lambda: rrc_pin.RelativeFrameTask(w.tool, "panda_link0").set_twist,
             {"twist": w.twist}),
        Site("RelativeFrameTask.set_target",
             lambda: rrc_pin.RelativeFrameTask(w.tool, "panda_link0").set_target,
             {"target": w.T}),
        Site("PostureTask", lambda: rrc_pin.PostureTask,
             {"q_ref": w.q, "gain": 1.0, "weight": 1.0, "name": "posture"}),
        Site("JointTask", lambda: rrc_pin.JointTask,
             {"joint": "panda_joint1", "rate": 0.1, "weight": 1.0, "name": None}),
        Site("DampingTask", lambda: rrc_pin.DampingTask, {"weight": 1e-3, "name": "damping"}),
    ]


def _limits(w: World) -> list[Site]:
    return [
        Site("JointLimits", lambda: rrc_pin.JointLimits, {
            "margin": 0.01, "acceleration": None, "velocity": None, "position_gain": 1.0,
            "name": "joint limits"}),
        Site("ContactLimit", lambda: rrc_pin.ContactLimit,
             {"frames": ["left/tool"], "name": "contact"}),
        Site("ContactLimit.set_frames", lambda: rrc_pin.ContactLimit(["a"]).set_frames,
             {"frames": ["left/tool"]}),
        Site("GripLimit", lambda: rrc_pin.GripLimit,
             {"pairs": [("left/tool", "right/tool")], "name": "grip"}),
        Site("GripLimit.set_pairs", lambda: rrc_pin.GripLimit().set_pairs,
             {"pairs": [("left/tool", "right/tool")]}),
        Site("CollisionLimit", lambda: rrc_pin.CollisionLimit, {
            "model": w.collision(), "safety": 0.02, "detection": 0.1, "gain": 0.5,
            "pairs": None, "name": "collision"}, aliases={"detection": ("safety",)}),
    ]


def _collision(w: World) -> list[Site]:
    T = w.T
    tetrahedron = np.array([[0.0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]])
    return [
        Site("CollisionModel", lambda: rrc_pin.CollisionModel,
             {"robot": w.panda, "geometry": None}),
        Site("CollisionModel.add_box", _shared(w, "add_box"),
             {"T": T, "size": [0.1, 0.2, 0.3], "name": None}),
        Site("CollisionModel.add_capsule", _shared(w, "add_capsule"),
             {"T": T, "radius": 0.05, "length": 0.2, "name": None}),
        Site("CollisionModel.add_cylinder", _shared(w, "add_cylinder"),
             {"T": T, "radius": 0.05, "length": 0.2, "name": None}),
        Site("CollisionModel.add_sphere", _shared(w, "add_sphere"),
             {"center_or_T": [0.5, 0.0, 0.3], "radius": 0.05, "name": None}),
        Site("CollisionModel.add_convex", _shared(w, "add_convex"),
             {"T": T, "points": tetrahedron, "name": None}),
        Site("CollisionModel.add_halfspace", _shared(w, "add_halfspace"),
             {"normal": [0.0, 0.0, 1.0], "offset": -0.5, "name": None}),
        Site("CollisionModel.add_wall", _shared(w, "add_wall"),
             {"normal": [0.0, 0.0, 1.0], "offset": -0.5, "frame": None, "name": None}),
        Site("CollisionModel.add_workspace", _shared(w, "add_workspace"),
             {"T": T, "size": [2.0, 2.0, 2.0], "frame": None, "name": None}),
        Site("CollisionModel.attach", _shared(w, "attach"), {
            "link": "panda_link7", "kind": "sphere", "T_link_shape": np.eye(4), "name": None,
            "radius": 0.03}),
        Site("CollisionModel.remove", lambda: w.collision().remove, {"name": "box"}),
        Site("CollisionModel.create_data", _shared(w, "create_data"), {}),
        Site("CollisionModel.walls", _shared(w, "walls"), {"frame": None}),
        Site("CollisionModel.proximity_at", _shared(w, "proximity_at"),
             {"q": w.q, "detection": 0.1, "data": None, "ends": False}),
    ]


def _shared(w: World, method: str) -> Callable[[], Callable[..., Any]]:
    """A method of a collision model of the site's own, built once (a model costs 6 ms): the
    shapes the odd value that succeeds adds stay, a few."""
    model = w.collision()
    model.add_wall([0.0, 0.0, 1.0], -0.5, name="floor")  # walls(frame=...) compares frames
    bound = getattr(model, method)
    return lambda: bound


def _controller(w: World) -> list[Site]:
    return [
        Site("Controller", lambda: rrc_pin.Controller, {
            "robot": w.panda, "dt": 0.01, "q0": None, "strategy": None, "limits": None,
            "qp": None, "damping": Damping(), "deadman": rrc_pin.Deadman(),
            "drift": rrc_pin.DriftCorrection(), "speed": 1.0, "near": 0.05, "smoothing": None}),
        Site("Controller.step", lambda: w.controller().step, {"twist": w.twist, "ref": "local"}),
        Site("Controller.stream", lambda: w.controller().stream, {"name": None, "options": None}),
        Site("Controller.close_stream", lambda: _streaming(w.controller()).close_stream,
             {"name": None}),
        Site("SmoothingOptions", lambda: rrc_pin.SmoothingOptions,
             {"acceleration": 20.0, "jerk": 500.0}),
        Site("Controller.reverse", lambda: w.controller().reverse,
             {"seconds": 0.01, "extra": 1.0}),
        Site("Controller.mask", lambda: w.controller().mask, {"joints": "panda_joint4"}),
        Site("Deadman", lambda: rrc_pin.Deadman, {"timeout": 0.2, "fade": 0.3}),
        Site("Deadman.factor", lambda: rrc_pin.Deadman().factor, {"age": 0.1}),
        Site("DriftCorrection", lambda: rrc_pin.DriftCorrection,
             {"gain": 2.0, "max_linear": 0.01, "max_angular": 0.05}),
        Site("DriftCorrection.twist", lambda: rrc_pin.DriftCorrection().twist,
             {"error": np.full(6, 1e-3)}),
        Site("TrajectoryLog", lambda: rrc_pin.TrajectoryLog,
             {"joint_names": ["a", "b"], "derive": None, "capacity": 10}),
        Site("TrajectoryLog.load", lambda: rrc_pin.TrajectoryLog.load, {"path": w.log_path}),
        Site("TrajectoryLog.save", lambda: w.controller().log.save, {"path": w.tmp / "out.npz"}),
        Site("TrajectoryLog.column", lambda: w.controller().log.column, {"name": "q"}),
        Site("TrajectoryLog.positions", lambda: w.controller().log.positions, {"n": 1}),
        Site("TrajectoryLog.header", lambda: w.controller().log.header, {}),
    ]


def _streaming(ctl: Any) -> Any:
    """``ctl`` with its tool frame streamed."""
    ctl.stream()
    return ctl


def _cells(w: World) -> list[Site]:
    cell = w.cell
    return [
        Site("make_cell", lambda: rrc_pin.make_cell, {
            "arms": {"l": (w.barker, np.eye(4)), "r": (w.barker, w.T)}, "name": "pair",
            "objects": None, "ready": None, "body": None},
            aliases={"body": ("body_velocity",)}),  # a body needs its velocity limits
        Site("Cell.arm", lambda: cell.arm, {"key": "left"}),
        Site("Cell.holder", lambda: cell.holder, {"hand": "left/tool"}),
        Site("Cell.describe", lambda: cell.describe, {}),
        Site("CellController.commandable", lambda: w.cell_controller().commandable, {}),
        Site("CellController.swing", lambda: rrc_pin.CellController(w.tripod).swing,
             {"leg": "leg1"}),
        Site("CellController.land", lambda: _swung(w.tripod).land, {"leg": "leg1"}),
        Site("CellController", lambda: rrc_pin.CellController, {
            "cell": cell, "dt": 0.01, "q0": None, "limits": None, "qp": None, "speed": 1.0,
            "gain": 10.0, "posture_gain": 0.1, "coupled": True, "closure": ClosureBound()}),
        Site("CellController.step", lambda: w.cell_controller().step,
             {"commands": {"object": np.array([0.01, 0, 0, 0, 0, 0])}}),
        Site("CellController.target", lambda: w.cell_controller().target, {"name": "object"}),
        Site("CellController.stream", lambda: w.cell_controller().stream,
             {"name": "object", "options": None}),
        Site("CellController.frame_of", lambda: w.cell_controller().frame_of,
             {"name": "object"}),
        Site("CellController.save", lambda: w.cell_controller().save,
             {"path": w.tmp / "cell.csv"}),
        Site("CellController.reverse", lambda: w.cell_controller(stepped=True).reverse,
             {"seconds": 0.01, "extra": 1.0}),
        Site("CellController.mask", lambda: w.cell_controller().mask,
             {"joints": ["left/joint1", "right/joint7"]}),
        Site("MasterSlave", lambda: rrc_pin.MasterSlave,
             {"scale": 1.0, "rotation": None, "dt": 0.01}),
        Site("MasterSlave.update", lambda: rrc_pin.MasterSlave().update,
             {"master": w.T, "clutch": True}),
    ]


def _swung(tripod: Any) -> Any:
    ctl = rrc_pin.CellController(tripod)
    ctl.swing("leg1")
    return ctl


def _guidance(w: World) -> list[Site]:
    b, q = w.barker, w.qb
    goal = b.fk(q + 0.05)
    P1 = np.array([[0.0, 0, 0], [0, 0, 1], [1, 0, 0]])
    P2 = np.array([[0.1, 0, 0], [0.1, 0, 1], [0.1, 1, 0]])  # a quarter turn about z, moved
    return [
        Site("screw_from_points", lambda: guidance.screw_from_points,
             {"points_1": P1, "points_2": P2}),
        Site("screw_from_poses", lambda: guidance.screw_from_poses, {"T1": np.eye(4), "T2": goal}),
        Site("screw_of_displacement", lambda: guidance.screw_of_displacement,
             {"Q": goal[:3, :3], "q": goal[:3, 3]}, aliases={"Q": ("q",)}),  # q fits Q
        Site("frames_from_points", lambda: guidance.frames_from_points,
             {"points": P1, "name": "points"}),
        Site("joint_rates", lambda: guidance.joint_rates,
             {"increments": np.full(6, 1e-3), "hand_step": 0.01, "hand_speed": 0.1}),
        Site("general", lambda: guidance.general, {
            "arm": b, "q0": q, "goal": goal, "steps": 3, "relocate": True, "solver": "thesis",
            "correction": "none", "frame": None}),
        Site("screw_motion", lambda: guidance.screw_motion, {
            "arm": b, "q0": q, "goal": goal, "steps": 3, "relocate": False, "b_form": "twist",
            "closing": 0}),
        Site("straight_line", lambda: guidance.straight_line,
             {"arm": b, "q0": q, "goal": goal, "steps": 3, "solver": rrc_pin.Resolver(b, 0.1)}),
        Site("operator", lambda: guidance.operator, {
            "arm": b, "q0": q, "commands": [guidance.Command([0.0, 0.0, 1.0], 0.01, 0.0)],
            "steps": 3}),
        Site("ThesisSolver", lambda: guidance.ThesisSolver,
             {"singular_cond": 1e4, "escape": None}),
        Site("general_axes", lambda: guidance.general_axes, {
            "arm": b, "q0": q, "rotation": ([0.0, 0.0, 1.0], 0.1),
            "translation": ([1.0, 0.0, 0.0], 0.01), "steps": 3}),
        Site("straight_line_points", lambda: guidance.straight_line_points, {
            "arm": b, "q0": q, "goal_points": _points(goal), "steps": 2, "spacing": 0.05,
            "substeps": 1, "b_form": "twist", "closing": 0}),
        Site("disp_step", lambda: guidance.disp_step,
             {"screw": guidance.screw_from_points(P1, P2), "k": 3, "b_form": "disp"}),
        Site("displacement", lambda: guidance.displacement,
             {"screw": guidance.screw_from_points(P1, P2)}),
        Site("screw_twist", lambda: guidance.screw_twist,
             {"screw": guidance.screw_from_points(P1, P2)}),
    ]


def _points(T: np.ndarray) -> np.ndarray:
    """Three points of the frame ``T``: its origin, a point on +z, one on +x (Nadkarni)."""
    return np.array([T[:3, 3], T[:3, 3] + 0.1 * T[:3, 2], T[:3, 3] + 0.1 * T[:3, 0]])


def _maps(w: World) -> list[Site]:
    m = w.map
    return [
        Site("capability", lambda: maps.capability, {
            "arm": w.barker, "samples": 64, "voxel": 0.2, "seed": 0, "workers": 1,
            "dexterity": False, "frame": None, "block_size": 64, "blocks_per_task": None},
            {"progress": False}),
        Site("load_map", lambda: maps.load_map, {"path": w.map_path}),
        Site("save_map", lambda: maps.save_map, {"m": m, "path": w.tmp / "again.zarr"}),
        Site("CapabilityMap.at", lambda: m.at, {"points": np.zeros((4, 3))}),
        Site("CapabilityMap.column", lambda: m.column, {"name": "coverage"}),
        Site("CapabilityMap.volume", lambda: m.volume, {"mask": None}),
        Site("CapabilityMap.witnesses", lambda: m.witnesses, {"keys": np.zeros(0, np.int64)}),
        Site("placements_grid", lambda: maps.placements_grid,
             {"x": [0.0, 0.5], "y": [0.0], "yaw": (0.0,), "z": 0.0}),
        Site("audit", lambda: maps.audit, {
            "m": m, "robot": w.barker, "voxels": 2, "seed": 0, "starts": 1, "max_steps": 3}),
        Site("refine", lambda: maps.refine, {
            "m": m, "robot": w.barker, "limit": 2, "seed": 0, "starts": 1, "max_steps": 3}),
    ]


def _strategies(w: World) -> list[Site]:
    return [
        Site("make_strategy", lambda: strategies.make_strategy, {"strategy": "slowdown"}),
        Site("Slowdown", lambda: strategies.Slowdown, {
            "measure": "sigma_min", "start": 0.05, "stop": 0.005, "rate": 4.0, "release": 1.2},
            aliases={"stop": ("start",)}),  # start > stop: the pair named by the later
        Site("Freezing", lambda: strategies.Freezing, {"region": 0.02}),
        Site("WristChoice", lambda: strategies.WristChoice, {"region": 0.05, "margin": 0.0}),
        Site("AuxiliaryHand", lambda: strategies.AuxiliaryHand,
             {"k3": 20.0, "k2": 1.0, "region": 0.05}),
        Site("GeneralizedInverse", lambda: strategies.GeneralizedInverse, {"exact": False}),
        Site("Uncoupled", lambda: strategies.Uncoupled, {}),
        Site("ResolverOnly", lambda: strategies.ResolverOnly, {}),
    ]


def _teleoperation(w: World) -> list[Site]:
    """The teleoperation aids: their tasks and limits, the pose stream, the jerk limiter."""
    tool, z = w.tool, [0.0, 0.0, 1.0]
    return [
        Site("AxisAlignTask", lambda: rrc_pin.AxisAlignTask, {
            "frame": tool, "axis": z, "direction": [0.0, 0.0, -1.0], "gain": 5.0, "weight": 1.0,
            "name": None}),
        Site("AxisAlignTask.set_direction", lambda: rrc_pin.AxisAlignTask(tool).set_direction,
             {"direction": [1.0, 0.0, 0.0]}),
        Site("LookAtTask", lambda: rrc_pin.LookAtTask, {
            "frame": tool, "point": [1.0, 0.0, 0.0], "axis": z, "gain": 5.0, "weight": 1.0,
            "name": None}),
        Site("LookAtTask.set_point", lambda: rrc_pin.LookAtTask(tool, [1.0, 0, 0]).set_point,
             {"point": [0.0, 1.0, 0.0]}),
        Site("ComTask", lambda: rrc_pin.ComTask, {
            "velocity": [0.0, 0.0, 0.01], "axes": "xyz", "gain": 5.0, "weight": 1.0,
            "name": "com"}, aliases={"axes": ("velocity",)}),  # the velocity fits the axes
        Site("ComTask.set_target", lambda: rrc_pin.ComTask().set_target,
             {"target": [0.1, 0.0, 0.5], "velocity": None}),
        Site("ManipulabilityTask", lambda: rrc_pin.ManipulabilityTask,
             {"frame": tool, "gain": 0.05, "rows": "full", "weight": 1.0, "name": None}),
        Site("SingularityLimit", lambda: rrc_pin.SingularityLimit, {
            "frame": tool, "threshold": 0.02, "detection": 0.06, "gain": 0.5, "rows": "full",
            "name": None}, aliases={"threshold": ("detection",)}),  # the later of the pair
        Site("SupportPolygonLimit", lambda: rrc_pin.SupportPolygonLimit,
             {"feet": ["leg1/foot", "leg2/foot", "leg3/foot"], "margin": 0.02, "gain": 0.5,
              "name": "support"}),
        Site("SupportPolygonLimit.set_feet", lambda: rrc_pin.SupportPolygonLimit().set_feet,
             {"feet": ["leg1/foot", "leg2/foot"]}),
        Site("StreamOptions", lambda: rrc_pin.StreamOptions, {
            "gain": 10.0, "linear_speed": 0.5, "angular_speed": 1.5, "jump": 0.05,
            "jump_angle": 0.3, "device_speed": 2.0, "device_rate": 10.0, "timeout": 0.05,
            "decay": 0.05, "settle": 5, "scale": 1.0, "device_axes": None, "lower": None,
            "upper": None}, aliases={"upper": ("lower",)}),  # a lone bound: named by the first
        Site("PoseStream", lambda: rrc_pin.PoseStream, {"hand": w.T, "options": None}),
        Site("PoseStream.push", lambda: rrc_pin.PoseStream(w.T).push, {"t": 0.0, "device": w.T}),
        Site("PoseStream.clutch", lambda: rrc_pin.PoseStream(w.T).clutch,
             {"pressed": True, "t": 0.0}),
        Site("PoseStream.target_for", lambda: rrc_pin.PoseStream(w.T).target_for,
             {"device": w.T}),
        Site("PoseStream.twist", lambda: rrc_pin.PoseStream(w.T).twist, {"t": 0.0, "hand": w.T}),
        Site("PoseStream.reset", lambda: rrc_pin.PoseStream(w.T).reset, {"hand": w.T}),
        Site("JerkLimiter", lambda: rrc_pin.JerkLimiter, {
            "n": 7, "dt": 0.01, "acceleration": 10.0, "jerk": 100.0, "lower": None,
            "upper": None, "margin": 0.0}, aliases={"upper": ("lower",)}),
        Site("JerkLimiter.reset", lambda: rrc_pin.JerkLimiter(7, 0.01, 10.0, 100.0).reset,
             {"rates": np.zeros(7)}),
        Site("JerkLimiter.stop", lambda: rrc_pin.JerkLimiter(7, 0.01, 10.0, 100.0).stop,
             {"stopping": True}),
    ]
