"""A Pinocchio model with named tool frames: forward kinematics and Jacobians in three frames.

Joints are one coordinate each at this API: revolute, prismatic, and continuous (unbounded)
revolute joints, which Pinocchio stores as (cos, sin) with nq = 2, nv = 1; the Robot maps
one angle per joint to Pinocchio's configuration vector. Mimic joints (Pinocchio's
``JointModelMimic``, nq = nv = 0) follow their primary joint and take no coordinate.

A floating base is a free-flyer root joint (Pinocchio's ``JointModelFreeFlyer`` as the first
joint, hanging from the universe: a legged cell's body). Its coordinates are Pinocchio's own,
``[x, y, z, qx, qy, qz, qw]`` (position [m], unit quaternion), at the start of q; its six
rates ``[v; w]`` (in the body's axes, Pinocchio's convention) start qdot. Then
``nq = nv + 1``: configurations are moved by :meth:`Robot.integrate` (``pinocchio.integrate``),
never by ``q + qdot dt``, and the arrays indexed by joint rate (``velocity_limit``,
``dof_lower``, ``dof_upper``) have ``nv`` entries, those indexed by coordinate (``lower``,
``upper``) ``nq``. The base is not actuated: it has no position limits, and its rates move
only as far as the rows (contacts) and its velocity limits (set in the model) allow. Any
other joint (a free-flyer below the root, spherical, planar) is refused with a message
saying why.

Threads: a Robot may be shared between threads. Its methods never write shared state: each
thread computes in its own ``pinocchio.Data`` (a ``threading.local``, created on the thread's
first call), and :meth:`Robot.to_pinocchio` returns a new array. Chosen over one Data behind
a ``threading.Lock`` by measurement (docs/api.md, "Threads"): as fast on one thread, and two
threads do not wait for each other; the cost is a Data's memory per thread.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import FrameNotFound, InvalidInput, ToolFrameRequired, URDFError
from rrc_pin.mimic import Mimic, MimicLimits, mimics_of, tightened, velocity_caps
from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.solvers.checks import as_vector, finite_number
from rrc_pin.solvers.closed_form.base import ClosedForm
from rrc_pin.solvers.spatial import Reference, check_reference

PIN_REFERENCE = {
    "world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
    "local": pin.ReferenceFrame.LOCAL,
    "world": pin.ReferenceFrame.WORLD,
}


Seed = np.random.Generator | int | None
"""What :meth:`Robot.random_q` takes: a numpy Generator, an int seed (>= 0) or None."""

BASE_AXES = ("vx", "vy", "vz", "wx", "wy", "wz")
"""Names of a floating base's six rates (body axes), in :attr:`Robot.dof_names`."""

UNBOUNDED = 1e6
"""A joint limit beyond +-this [rad or m] counts as none (URDFs write 1e16 or 1e308 for none):
:meth:`Robot.random_q` draws such a joint over a finite window, see there."""
QUATERNION_TOL = 1e-6
"""A base quaternion shorter than this is refused (it has no direction); any longer one is
normalised."""
READY_INSET = 0.1
"""Fraction of a joint's range that :meth:`Robot.ready` keeps from each limit when the robot
has no named ready configuration."""


class Robot:
    """A Pinocchio model with its tool frames, joint limits and SI units at every method.

    Attributes:
        name: Robot name (catalogue name, example-robot-data name or URDF stem).
        model: The ``pinocchio.Model`` (read only: shared by every thread).
        tool_frames: Names of the end-effector frames, one for an arm, several for a robot
            with several arms (baxter, pr2, a :func:`rrc_pin.combine` cell).
        tool_frame: The tool frame of an arm, or None when there are several.
        nq: Number of coordinates of q: one per joint, plus 7 for a floating base.
        nv: Number of joint rates (qdot): one per joint, plus 6 for a floating base; nq
            without one.
        floating: Whether the root joint is a free-flyer (module docstring).
        base_joint: The free-flyer's name, or None.
        joint_names: Names of the actuated joints, in the order of q (after the base's 7).
        dof_names: Names of the nv rates: ``base:vx`` ... ``base:wz``, then the joints.
        actuated: Mask (nv,) of the rates a joint drives (False for the base's six).
        lower: Lower limits (nq,) of q's coordinates [rad or m]; -inf for continuous joints
            and the base.
        upper: Upper limits (nq,) [rad or m]; +inf for continuous joints and the base.
        velocity_limit: Speed limits (nv,) [rad/s or m/s]; +inf where the model gives none.
        spec: The catalogue :class:`ArmSpec` the robot was built from, or None.
        source: Where the model came from (a path, ``catalogue``, a combination).
        poses: Named configurations (nq,) [rad or m] (read-only arrays); ``"ready"``, where
            present, is :meth:`ready`'s.
        mimic_joints: Joints that follow another (URDF ``<mimic>``): in the model, not in q.
        mimics: Each mimic joint: its primary, multiplier, offset and own limits
            (:class:`rrc_pin.mimic.Mimic`), which tighten the primary's ``lower``, ``upper``
            and ``velocity_limit``.
        mimic_velocity: Speed limits (nv,) the mimic joints put on their primaries [rad/s or
            m/s] (inf where none): within ``velocity_limit``, and kept by
            :class:`~rrc_pin.limits.JointLimits` where its ``velocity`` replaces the robot's.
        continuous: Mask (nq,) of the continuous (unbounded revolute) joints.
    """

    def __init__(
        self,
        model: pin.Model,
        tool_frames: str | Sequence[str] | None,
        *,
        name: str,
        source: str,
        spec: ArmSpec | None = None,
        poses: Mapping[str, npt.ArrayLike] | None = None,
        mimic_limits: MimicLimits | None = None,
    ) -> None:
        """Wrap ``model``; every entry of ``tool_frames`` must name one of its frames.

        Args:
            model: The kinematic model, a ``pinocchio.Model`` (1-DOF joints, and mimic joints
                that follow one of them).
            tool_frames: One frame name, several, or None: the model's one end link (the
                unique leaf of its tree that a joint moves, see :func:`end_links`).
            name: Robot name.
            source: Where the model came from, for messages.
            spec: The catalogue arm it was built from, if any.
            poses: Named configurations (nq,) [rad or m], each within the joint limits;
                ``"ready"`` is the one :meth:`ready` returns. Default: the ``spec``'s named
                poses, else none.
            mimic_limits: The mimic joints' own limits by name, ``(lower, upper, velocity)``
                [rad or m, rad/s or m/s] (a URDF's ``<limit>``, which Pinocchio's model does
                not keep): each tightens its primary's limits through the multiplier and
                offset (:mod:`rrc_pin.mimic`); default none.

        Raises:
            InvalidInput: ``model`` is not a ``pinocchio.Model``, ``name`` or ``source`` not a
                string, ``spec`` not an ArmSpec, ``tool_frames`` empty, not names or naming a
                frame twice, a pose not a finite (nq,) vector within the limits, or
                ``mimic_limits`` not limits of the model's mimic joints (named).
            URDFError: The model has no moving joint, a joint that is not one coordinate
                (free-flyer, spherical...), or a mimic joint's limits that no position of its
                primary keeps.
            ToolFrameRequired: ``tool_frames`` is None and the tree has several end links
                (lists them).
            FrameNotFound: A tool frame is not a frame of the model.
        """
        _check_arguments(model, name, source, spec)
        mimics = mimics_of(model, mimic_limits)
        model = tightened(model, mimics, source, UNBOUNDED)
        joints = _Joints.of(model, source)
        floating, offset = joints.floating, joints.offset
        scalar_api, scalar_pin, angle_api, angle_pin = joints.coordinates
        self._frame_ids = frame_index(model)
        tools = _tool_names(model, tool_frames, source)
        for tool in tools:
            self._frame(tool, "tool_frame")
        self.name = name
        self.source = source
        self.spec = spec
        self.model = model
        self.tool_frames: tuple[str, ...] = tools
        self.tool_frame: str | None = tools[0] if len(tools) == 1 else None
        self.floating: bool = floating
        self.nv: int = model.nv
        self.nq: int = model.nv + offset
        self.base_joint: str | None = str(model.names[1]) if floating else None
        self.joint_names = [joint for _, joint in sorted(joints.moving)]  # = moving_joints(model)
        base_dofs = [f"{self.base_joint}:{axis}" for axis in BASE_AXES] if floating else []
        self.dof_names: tuple[str, ...] = (*base_dofs, *self.joint_names)
        self.mimic_joints: tuple[str, ...] = tuple(joints.mimic)
        self.mimics: tuple[Mimic, ...] = mimics
        self.mimic_velocity = velocity_caps(model, mimics)
        self.mimic_velocity.flags.writeable = False
        self._scalar = (np.array(scalar_api, dtype=int), np.array(scalar_pin, dtype=int))
        self._angle = (np.array(angle_api, dtype=int), np.array(angle_pin, dtype=int))
        self._offset = offset
        self.continuous = np.zeros(self.nq, dtype=bool)
        self.continuous[self._angle[0]] = True
        self.continuous.flags.writeable = False
        self._identity_map = not angle_api and model.nq == model.nv
        # a floating base and one coordinate per joint, in Pinocchio's order: Pinocchio's vector
        # is q with its quaternion normalised
        self._same_order = (floating and not angle_api and model.nq == self.nq
                            and scalar_api == scalar_pin)  # fmt: skip

        self.lower = np.full(self.nq, -np.inf)
        self.upper = np.full(self.nq, np.inf)
        self.lower[self._scalar[0]] = model.lowerPositionLimit[self._scalar[1]]
        self.upper[self._scalar[0]] = model.upperPositionLimit[self._scalar[1]]
        velocity = np.array(model.velocityLimit, dtype=float)
        self.velocity_limit = np.where((velocity > 0.0) & (velocity < UNBOUNDED), velocity, np.inf)
        self.actuated = np.ones(self.nv, dtype=bool)
        self.actuated[: 6 * offset] = False
        self.actuated.flags.writeable = False
        named = (spec.named_poses if spec is not None else {}) if poses is None else poses
        self.poses: dict[str, npt.NDArray[np.float64]] = self._checked_poses(named)

        self._local = threading.local()  # this thread's pinocchio.Data, see _scratch
        self._lock = threading.Lock()  # guards the one-time build of the closed form
        self._closed_form: ClosedForm | None = None

    def __repr__(self) -> str:
        tools = self.tool_frame if self.tool_frame is not None else self.tool_frames
        return f"Robot({self.name!r}, nq={self.nq}, tool_frame={tools!r})"

    @property
    def closed_form(self) -> ClosedForm | None:
        """The paper's closed-form fast path (a ``rrc_pin.solvers.closed_form`` object), or None.

        Built once from this arm's actual parameters (a variant gets a matching closed form).
        None for arms the papers do not cover, and whenever the tool frame is not the frame
        the closed form answers for (its ``frame`` attribute: ``"tool"``, e.g. Barker's wrist
        centre), so that ``load("barker6", tool_frame="flange").closed_form`` is None rather
        than the wrist-centre rates under the flange's name.

        Raises:
            InvalidInput: The geometry has no closed form (e.g. ``kr5_3r`` with ``a2=0``),
                naming the parameter.
        """
        factory = self.spec.closed_form if self.spec is not None else None
        if factory is None or self.tool_frame != ClosedForm.frame:
            return None
        with self._lock:
            if self._closed_form is None:
                try:
                    self._closed_form = factory()
                except InvalidInput as exc:  # e.g. kr5_3r with a2 = 0: no closed form exists
                    raise InvalidInput(
                        exc.argument, f"{self.name} has no closed form for this geometry ({exc})"
                    ) from exc
            return self._closed_form

    @property
    def data(self) -> pin.Data:
        """The calling thread's ``pinocchio.Data`` (each thread has its own; never shared).

        For code that calls Pinocchio on :attr:`model` itself, in the calling thread only. An
        object that keeps a Data across calls (a resolver, a controller) creates its own with
        ``robot.model.createData()`` instead.
        """
        return self._scratch()

    def check_q(self, q: npt.ArrayLike, name: str = "q") -> npt.NDArray[np.float64]:
        """Return ``q`` as a finite (nq,) float array (``q`` itself when it already is one).

        Raises:
            InvalidInput: Wrong length, non-numeric, NaN or inf, naming ``name``.
        """
        return as_vector(q, name, self.nq)

    def to_pinocchio(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Pinocchio configuration vector (model.nq,) of joint positions ``q`` (nq,).

        Continuous joints become (cos, sin). Returns the checked ``q`` itself when the map is
        the identity (no continuous joint), else a new array: never a buffer shared between
        calls.

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        return self.configuration(q)[1]

    def dof_positions(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Each rate's position (nv,) [rad or m]: the joints' coordinates, 0 for the base's six.

        What position limits and posture tasks compare with, indexed like qdot; ``q``
        itself (checked) without a floating base.

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        q = self.check_q(q)
        return self._dof(q)

    def positions(
        self, q: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``q`` checked once, each rate's position and Pinocchio's configuration vector.

        What one tick's kinematics reads: :meth:`dof_positions` and :meth:`configuration`
        with one check.

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        if self._identity_map:  # q is each rate's position and Pinocchio's vector
            q = self.check_q(q)
            return q, q, q
        q, q_pin = self.configuration(q)
        return q, self._dof(q), q_pin

    def _dof(self, q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        if not self.floating:
            return q
        out = np.zeros(self.nv)
        out[6:] = q[7:]
        return out

    @property
    def dof_lower(self) -> npt.NDArray[np.float64]:
        """Lower position limits (nv,) per rate [rad or m]; -inf for the base's six."""
        return self._dof_limits(self.lower, -np.inf)

    @property
    def dof_upper(self) -> npt.NDArray[np.float64]:
        """Upper position limits (nv,) per rate [rad or m]; +inf for the base's six."""
        return self._dof_limits(self.upper, np.inf)

    def _dof_limits(
        self, limits: npt.NDArray[np.float64], base: float
    ) -> npt.NDArray[np.float64]:
        if not self.floating:
            return limits
        out: npt.NDArray[np.float64] = np.concatenate([np.full(6, base), limits[7:]])
        return out

    def integrate(
        self, q: npt.ArrayLike, qdot: npt.ArrayLike, dt: float
    ) -> npt.NDArray[np.float64]:
        r"""The configuration (nq,) reached from ``q`` at rates ``qdot`` (nv,) after ``dt`` [s].

        .. math:: q_{k+1} = q_k \oplus \dot q\, \Delta t \quad (\texttt{pinocchio.integrate})

        ``q + qdot dt`` exactly (the same floats) without a floating base or a continuous
        joint; a floating base moves on SE(3) (its twist in body axes), its quaternion
        normalised; a continuous joint's angle advances by ``qdot dt``.

        Raises:
            InvalidInput: Bad ``q``, ``qdot`` (not finite (nv,)) or ``dt``.
        """
        q, q_pin = self.configuration(q)
        v = as_vector(qdot, "qdot", self.nv)
        step = finite_number(dt, "dt")
        if self._identity_map:
            out: npt.NDArray[np.float64] = q + v * step
            return out
        moved = pin.integrate(self.model, q_pin, v * step)
        if not self.floating:  # continuous joints: back to angles by the difference
            angles: npt.NDArray[np.float64] = q + pin.difference(self.model, q_pin, moved)
            return angles
        out = q.copy()
        out[:7] = moved[:7]
        delta = pin.difference(self.model, q_pin, moved)
        out[7:] = q[7:] + delta[6:]
        return out

    def configuration(
        self, q: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``q`` checked (nq,) and as Pinocchio's configuration vector (model.nq,).

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        q = self.check_q(q)
        if self._identity_map:
            return q, q
        if self._same_order:
            out = q.copy()
        else:
            out = np.empty(self.model.nq)
            if self.floating:
                out[:7] = q[:7]
            api, pin_idx = self._scalar
            out[pin_idx] = q[api]
            api, pin_idx = self._angle
            if api.size:  # continuous joints: (cos, sin)
                out[pin_idx] = np.cos(q[api])
                out[pin_idx + 1] = np.sin(q[api])
        if self.floating:
            norm = math.hypot(*q[3:7].tolist())
            if not norm > QUATERNION_TOL:
                raise InvalidInput("q", f"the base quaternion q[3:7] = {q[3:7]} has no direction")
            out[3:7] /= norm
        return q, out

    def neutral(self) -> npt.NDArray[np.float64]:
        """The zero configuration clipped into the joint limits, (nq,) [rad or m].

        It may sit on a limit (panda's joint 4) or at a singularity (an arm stretched out):
        start a session from :meth:`ready` instead.
        """
        return self._identity_base(np.clip(np.zeros(self.nq), self.lower, self.upper))

    def _identity_base(self, q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """``q`` with a floating base at the origin, unrotated (in place; ``q`` returned)."""
        if self.floating:
            q[:7] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        return q

    def ready(self) -> npt.NDArray[np.float64]:
        """A configuration (nq,) [rad or m] to start from, away from limits and singularities.

        The robot's named ``"ready"`` pose (:attr:`poses`): every catalogue arm and every
        robot :func:`rrc_pin.load` knows by name has one (from example-robot-data's SRDF
        where it gives one, else chosen and stated with the arm's data; ``rrc-pin arms``
        says which), and a :func:`rrc_pin.combine` cell has its arms'. Any other model: the
        zero configuration moved at least :data:`READY_INSET` of each joint's range inside
        its limits (of the window :meth:`random_q` draws from, for unbounded joints), with
        no promise about singularities (pass ``poses={"ready": q}`` to :class:`Robot` to
        name one). A new array at every call.
        """
        pose = self.poses.get("ready")
        if pose is not None:
            named: npt.NDArray[np.float64] = np.array(pose)
            return named
        lo, hi = _finite_window(self.lower, self.upper)
        inset = READY_INSET * (hi - lo)
        inside: npt.NDArray[np.float64] = np.clip(np.zeros(self.nq), lo + inset, hi - inset)
        return self._identity_base(inside)

    def random_q(self, rng: Seed = None) -> npt.NDArray[np.float64]:
        """A configuration (nq,) drawn uniformly within the limits.

        A floating base is left where :meth:`ready` puts it (its pose is not a joint's: a
        cell's ready pose stands the body on its feet). Unbounded joints (continuous, or
        limits beyond +-:data:`UNBOUNDED`) are drawn in
        [-pi, pi]; a joint bounded on one side only, over 2 pi [rad or m] from that limit.

        Args:
            rng: A ``numpy.random.Generator`` (advanced by the draw), an int seed >= 0 (the
                same seed gives the same q), or None (fresh entropy).

        Raises:
            InvalidInput: ``rng`` is none of these.
        """
        generator = _generator(rng)
        lo, hi = _finite_window(self.lower, self.upper)
        q: npt.NDArray[np.float64] = generator.uniform(lo, hi)
        if self.floating:
            q[:7] = self.ready()[:7]
        return q

    def fk(self, q: npt.ArrayLike, frame: str | None = None) -> npt.NDArray[np.float64]:
        """Pose (4, 4) of a frame in the base frame, translation in [m].

        Args:
            q: Joint positions (nq,) [rad or m].
            frame: Any frame of the model; default: the tool frame.

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
            ToolFrameRequired: No ``frame`` on a robot with several tool frames (lists them).
            FrameNotFound: ``frame`` is not a frame of the model (lists them).
        """
        fid = self._frame(frame)
        q_pin = self.to_pinocchio(q)
        data = self._scratch()
        pin.forwardKinematics(self.model, data, q_pin)
        pose: npt.NDArray[np.float64] = pin.updateFramePlacement(self.model, data, fid).homogeneous
        return pose

    def frame_pose(self, q: npt.ArrayLike, frame: str) -> npt.NDArray[np.float64]:
        """Pose (4, 4) of the named ``frame`` in the base frame: ``fk(q, frame)``.

        Raises:
            InvalidInput: Bad ``q``.
            FrameNotFound: No such frame.
        """
        return self.fk(q, frame)

    def jacobian(
        self, q: npt.ArrayLike, ref: Reference = "world_aligned", frame: str | None = None
    ) -> npt.NDArray[np.float64]:
        """Geometric Jacobian of a frame, (6, nv), rows [v; w] ([m/s], [rad/s] per unit rate).

        Args:
            q: Joint positions (nq,).
            ref: ``world_aligned`` (frame-origin velocity, base axes), ``local`` (frame axes)
                or ``world`` (spatial velocity at the base origin).
            frame: Any frame of the model; default: the tool frame.

        Raises:
            InvalidInput: Bad ``q`` or ``ref``.
            ToolFrameRequired: No ``frame`` on a robot with several tool frames (lists them).
            FrameNotFound: ``frame`` is not a frame of the model (lists them).
        """
        ref = check_reference(ref)
        fid = self._frame(frame)
        q_pin = self.to_pinocchio(q)
        data = self._scratch()
        J: npt.NDArray[np.float64] = pin.computeFrameJacobian(
            self.model, data, q_pin, fid, PIN_REFERENCE[ref]
        )
        if J.ndim == 1:  # Pinocchio's binding returns a (6, 1) matrix as a (6,) array
            J = J.reshape(6, 1)
        return J

    def _frame(self, frame: str | None, argument: str = "frame") -> int:
        """Index of ``frame`` (None: the tool frame), raising the errors of :meth:`fk`."""
        if frame is None:
            if self.tool_frame is None:
                raise ToolFrameRequired(
                    argument, f"{self.name} has several tool frames", list(self.tool_frames)
                )
            frame = self.tool_frame
        if not isinstance(frame, str):
            raise InvalidInput(argument, f"expected a frame name (str), got {_brief(frame)}")
        fid = self._frame_ids.get(frame)
        if fid is None:
            raise FrameNotFound(frame, sorted(self._frame_ids), argument)
        return fid

    def _checked_poses(
        self, poses: Mapping[str, npt.ArrayLike]
    ) -> dict[str, npt.NDArray[np.float64]]:
        """``poses`` as read-only (nq,) arrays, each within the limits.

        Raises:
            InvalidInput: Not a mapping of names to finite (nq,) vectors within the limits.
        """
        if not isinstance(poses, Mapping):
            raise InvalidInput("poses", f"expected a mapping name -> q, got {_brief(poses)}")
        out: dict[str, npt.NDArray[np.float64]] = {}
        for key, value in poses.items():
            if not isinstance(key, str) or not key:
                raise InvalidInput("poses", f"expected names (str) as keys, got {_brief(key)}")
            q = as_vector(value, f"poses[{key!r}]", self.nq).copy()
            outside = (q < self.lower) | (q > self.upper)
            if outside.any():
                j = int(np.argmax(outside))
                raise InvalidInput(
                    f"poses[{key!r}]",
                    f"joint {self.joint_names[j]!r} at {q[j]:.6g} is outside its limits "
                    f"[{self.lower[j]:.6g}, {self.upper[j]:.6g}]",
                )
            q.flags.writeable = False
            out[key] = q
        return out

    def _scratch(self) -> pin.Data:
        """The calling thread's ``pinocchio.Data``, created on the thread's first call."""
        try:
            return self._local.data
        except AttributeError:
            self._local.data = data = self.model.createData()
            return data


def moving_joints(model: pin.Model) -> list[str]:
    """Names of the joints that take a coordinate of q (one rate each), in q's order.

    Mimic joints, which follow their primary joint, are left out.
    """
    joints = [
        (model.joints[j].idx_v, str(model.names[j]))
        for j in range(1, model.njoints)
        if model.joints[j].nv > 0 and model.joints[j].shortname() != "JointModelMimic"
    ]
    return [name for _, name in sorted(joints)]


def frame_index(model: pin.Model) -> dict[str, int]:
    """Frame name -> index, preferring the body frame where a joint shares the name."""
    index: dict[str, int] = {}
    for i, f in enumerate(model.frames):
        known = index.get(f.name)
        if known is None or (
            model.frames[known].type != pin.FrameType.BODY and f.type == pin.FrameType.BODY
        ):
            index[f.name] = i
    return index


def end_links(model: pin.Model) -> list[str]:
    """Links at the ends of the kinematic tree that a joint moves: the candidate tool frames.

    A link (body frame) is an end link when no other link hangs from it and it is not fixed
    to the base: a serial arm has one (a chain URDF's last link), baxter's tree has its
    grippers, fingertips, cameras and sensor links. A model whose frames name no link as
    another's parent (built in code, as ``pinocchio.buildSampleModelManipulator()``) has its
    tree in its joints: its end links are the links of the joints no joint hangs from.
    """
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]
    moved = [i for i in bodies if model.frames[i].parentJoint != 0]
    parents = {parent_link(model, i) for i in bodies}
    if moved and parents <= {0}:
        leaves = set(range(1, model.njoints)) - set(model.parents[1:])
        return [str(model.frames[i].name) for i in moved if model.frames[i].parentJoint in leaves]
    return [str(model.frames[i].name) for i in moved if i not in parents]


def is_chain(model: pin.Model) -> bool:
    """Whether the model's joints make one serial chain (no joint carries two)."""
    children = list(model.parents[1:])
    return all(children.count(j) <= 1 for j in set(children))


def parent_link(model: pin.Model, frame: int) -> int:
    """Index of the body frame (link) that frame ``frame`` hangs from; 0 for the universe.

    Walks up ``parentFrame`` to the first body frame, on any frame graph: where the walk comes
    back to a frame it has seen (``pinocchio.buildReducedModel`` in Pinocchio 4.1 makes the
    frame of a locked joint its own parent), it takes instead the last body frame before
    ``frame`` moved by the same joint (``parentJoint``), else 0.
    """
    frames = model.frames
    seen = {frame}
    parent = frames[frame].parentFrame
    while parent and frames[parent].type != pin.FrameType.BODY:
        if parent in seen:  # a cycle: the frame graph is broken here
            joint = frames[frame].parentJoint
            same = [i for i in range(frame) if frames[i].type == pin.FrameType.BODY
                    and frames[i].parentJoint == joint]  # fmt: skip
            return same[-1] if same else 0
        seen.add(parent)
        parent = frames[parent].parentFrame
    return int(parent)


def frame_id(model: pin.Model, name: str) -> int:
    """Index of the frame ``name``, preferring the body frame where a joint shares the name.

    Raises:
        FrameNotFound: No frame has that name.
    """
    index = frame_index(model)
    if name not in index:
        raise FrameNotFound(name, sorted(index))
    return index[name]


class _Joints(NamedTuple):
    """A model's joints as a :class:`Robot` reads them.

    Attributes:
        floating: The first joint is a free-flyer (the floating base).
        offset: API coordinates before a joint's: ``idx_v + offset`` (1 with a floating
            base, whose position is 7 coordinates and its rates 6).
        coordinates: The 1-DOF joints' API and Pinocchio indices: scalar ones (api, pin),
            then continuous ones (cos, sin in Pinocchio: api, pin).
        moving: (index in qdot, name) of each 1-DOF joint.
        mimic: The mimic joints' names (they follow a primary: no coordinate).
    """

    floating: bool
    offset: int
    coordinates: tuple[list[int], list[int], list[int], list[int]]
    moving: list[tuple[int, str]]
    mimic: list[str]

    @classmethod
    def of(cls, model: pin.Model, source: str) -> _Joints:
        """``model``'s joints.

        Raises:
            URDFError: A joint that is not one coordinate, a floating base aside (named).
        """
        scalar_api: list[int] = []
        scalar_pin: list[int] = []
        angle_api: list[int] = []
        angle_pin: list[int] = []
        moving: list[tuple[int, str]] = []
        mimic: list[str] = []
        floating = model.njoints > 1 and model.joints[1].shortname() == "JointModelFreeFlyer"
        offset = 1 if floating else 0
        for j in range(2 if floating else 1, model.njoints):
            joint = model.joints[j]
            if joint.shortname() == "JointModelMimic":
                mimic.append(str(model.names[j]))
                continue
            if joint.nv != 1 or joint.nq not in (1, 2):
                raise URDFError(
                    source,
                    f"joint {model.names[j]!r} is a {joint.shortname()} (nq={joint.nq}, "
                    f"nv={joint.nv}); rrc-pin handles serial arms of 1-DOF joints only "
                    "(lock or remove it, e.g. with pinocchio.buildReducedModel); a floating "
                    "base is a free-flyer as the first joint, from the universe",
                )
            moving.append((joint.idx_v, str(model.names[j])))
            if joint.nq == 1:
                scalar_api.append(joint.idx_v + offset)
                scalar_pin.append(joint.idx_q)
            else:
                angle_api.append(joint.idx_v + offset)
                angle_pin.append(joint.idx_q)
        return cls(floating, offset, (scalar_api, scalar_pin, angle_api, angle_pin), moving, mimic)


def _tool_names(model: pin.Model, tool_frames: str | Sequence[str] | None,
                source: str) -> tuple[str, ...]:  # fmt: skip
    """The tool frames' names: ``tool_frames``, or the model's one end link where None.

    Raises:
        ToolFrameRequired: None given and the tree has several end links (listed).
        InvalidInput: Not distinct frame names.
    """
    if tool_frames is None:
        ends = end_links(model)
        if len(ends) != 1:
            shape = "a serial chain ending in" if is_chain(model) else "a tree with"
            raise ToolFrameRequired("tool_frame", f"{source} is {shape} {len(ends)} end links",
                                    ends)  # fmt: skip
        tool_frames = ends
    tools = (tool_frames,) if isinstance(tool_frames, str) else tool_frames
    if (
        not isinstance(tools, Sequence)
        or not tools
        or not all(isinstance(t, str) for t in tools)
        or len(set(tools)) != len(tools)
    ):
        raise InvalidInput("tool_frame", f"expected distinct frame names, got {tools!r}")
    return tuple(tools)


def _finite_window(
    lower: npt.NDArray[np.float64], upper: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Finite bounds (nq,) to draw from, (lo, hi).

    The limits where they are within +-:data:`UNBOUNDED`; [-pi, pi] where neither is; 2 pi
    [rad or m] from the one that is, where only one is.
    """
    lo_ok, hi_ok = np.abs(lower) <= UNBOUNDED, np.abs(upper) <= UNBOUNDED
    lo = np.where(lo_ok, lower, np.where(hi_ok, upper - 2.0 * np.pi, -np.pi))
    hi = np.where(hi_ok, upper, np.where(lo_ok, lower + 2.0 * np.pi, np.pi))
    return lo, hi


def _check_arguments(model: object, name: object, source: object, spec: object) -> None:
    """:class:`Robot`'s ``model``, ``name``, ``source`` and ``spec`` refused where they are not
    a pinocchio.Model that moves, non-empty strings and an ArmSpec or None (named).
    """  # noqa: D205
    if not isinstance(model, pin.Model):
        raise InvalidInput("model", f"expected a pinocchio.Model, got {_brief(model)}")
    for label, value in (("name", name), ("source", source)):
        if not isinstance(value, str) or not value:
            raise InvalidInput(label, f"expected a non-empty string, got {_brief(value)}")
    if spec is not None and not isinstance(spec, ArmSpec):
        raise InvalidInput("spec", f"expected an ArmSpec or None, got {_brief(spec)}")
    if model.nv == 0:
        raise URDFError(str(source), "no moving joint: there is nothing to control")


def _brief(value: object, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters, with its type (for error messages)."""
    text = repr(value)
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    return f"{text} ({type(value).__name__})"


def _generator(rng: Seed) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or (
        isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0
    ):
        return np.random.default_rng(rng)
    raise InvalidInput("rng", f"expected a numpy Generator, an int seed >= 0 or None, got {rng!r}")
