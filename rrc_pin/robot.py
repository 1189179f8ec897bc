"""A Pinocchio model with named tool frames: forward kinematics and Jacobians in three frames.

Joints are one coordinate each at this API: revolute, prismatic, and continuous (unbounded)
revolute joints, which Pinocchio stores as (cos, sin) with nq = 2, nv = 1; the Robot maps
one angle per joint to Pinocchio's configuration vector. Any other joint (free-flyer,
spherical, planar) is refused with a message saying why.

Threads: a Robot may be shared between threads. Its methods never write shared state: each
thread computes in its own ``pinocchio.Data`` (a ``threading.local``, created on the thread's
first call), and :meth:`Robot.to_pinocchio` returns a new array. Chosen over one Data behind
a ``threading.Lock`` by measurement (panda, 2-core AMD EPYC, Pinocchio 4.1, six interleaved
runs of 20,000 calls): one thread, ``fk`` 4.7-7.0 us per call either way and ``jacobian``
4.4-6.7 us (the two within run-to-run noise); two threads calling at once, 4.5-7.4 us per
call with a Data per thread and 5.2-11.9 us with the lock, whose callers wait for each other.
The cost of a Data per thread is its memory: about 0.2 MB for panda, 0.8 MB for baxter.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import FrameNotFound, InvalidInput, ToolFrameRequired, URDFError
from rrc_pin.models.arm_spec import ArmSpec
from solvers.closed_form.base import ClosedForm
from solvers.errors import InputError
from solvers.spatial import Reference, check_reference
from solvers.validation import as_vector

PIN_REFERENCE = {
    "world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
    "local": pin.ReferenceFrame.LOCAL,
    "world": pin.ReferenceFrame.WORLD,
}


Seed = np.random.Generator | int | None
"""What :meth:`Robot.random_q` takes: a numpy Generator, an int seed (>= 0) or None."""


class Robot:
    """A Pinocchio model with its tool frames, joint limits and SI units at every method.

    Attributes:
        name: Robot name (catalogue name, example-robot-data name or URDF stem).
        model: The ``pinocchio.Model`` (read only: shared by every thread).
        tool_frames: Names of the end-effector frames, one for an arm, several for a robot
            with several arms (baxter, pr2, a :func:`rrc_pin.combine` cell).
        tool_frame: The tool frame of an arm, or None when there are several.
        nq: Number of joints (one coordinate each at this API).
        joint_names: Joint names, in the order of q.
        lower: Joint lower limits (nq,) [rad or m]; -inf for continuous joints.
        upper: Joint upper limits (nq,) [rad or m]; +inf for continuous joints.
        velocity_limit: Joint speed limits (nq,) [rad/s or m/s]; +inf where the URDF gives none.
        spec: The catalogue :class:`ArmSpec` the robot was built from, or None.
        source: Where the model came from (a path, ``catalogue``, a combination).
    """

    def __init__(
        self,
        model: pin.Model,
        tool_frames: str | Sequence[str] | None,
        *,
        name: str,
        source: str,
        spec: ArmSpec | None = None,
    ) -> None:
        """Wrap ``model``; every entry of ``tool_frames`` must name one of its frames.

        Args:
            model: The kinematic model (1-DOF joints only).
            tool_frames: One frame name, several, or None: the model's one end link (the
                unique leaf of its tree that a joint moves, see :func:`end_links`).
            name: Robot name.
            source: Where the model came from, for messages.
            spec: The catalogue arm it was built from, if any.

        Raises:
            URDFError: The model has no moving joint, or a joint that is not one coordinate
                (free-flyer, spherical...).
            ToolFrameRequired: ``tool_frames`` is None and the tree has several end links
                (lists them).
            InvalidInput: ``tool_frames`` is empty or names a frame twice.
            FrameNotFound: A tool frame is not a frame of the model.
        """
        if model.nv == 0:
            raise URDFError(source, "no moving joint: there is nothing to control")
        scalar_api, scalar_pin, angle_api, angle_pin = [], [], [], []
        for j in range(1, model.njoints):
            joint = model.joints[j]
            if joint.nv != 1 or joint.nq not in (1, 2):
                raise URDFError(
                    source,
                    f"joint {model.names[j]!r} is a {joint.shortname()} (nq={joint.nq}, "
                    f"nv={joint.nv}); rrc-pin handles serial arms of 1-DOF joints only "
                    "(lock or remove it, e.g. with pinocchio.buildReducedModel)",
                )
            if joint.nq == 1:
                scalar_api.append(joint.idx_v)
                scalar_pin.append(joint.idx_q)
            else:
                angle_api.append(joint.idx_v)
                angle_pin.append(joint.idx_q)
        self._frame_ids = frame_index(model)
        if tool_frames is None:
            ends = end_links(model)
            if len(ends) != 1:
                raise ToolFrameRequired(
                    "tool_frame", f"{source} is a tree with {len(ends)} end links", ends
                )
            tool_frames = ends
        tools = (tool_frames,) if isinstance(tool_frames, str) else tool_frames
        if (
            not isinstance(tools, Sequence)
            or not tools
            or not all(isinstance(t, str) for t in tools)
            or len(set(tools)) != len(tools)
        ):
            raise InvalidInput("tool_frame", f"expected distinct frame names, got {tools!r}")
        tools = tuple(tools)
        for tool in tools:
            self._frame(tool, "tool_frame")
        self.name = name
        self.source = source
        self.spec = spec
        self.model = model
        self.tool_frames: tuple[str, ...] = tools
        self.tool_frame: str | None = tools[0] if len(tools) == 1 else None
        self.nq: int = model.nv
        self.joint_names = [str(model.names[j]) for j in range(1, model.njoints)]
        self._scalar = (np.array(scalar_api, dtype=int), np.array(scalar_pin, dtype=int))
        self._angle = (np.array(angle_api, dtype=int), np.array(angle_pin, dtype=int))
        self._identity_map = not angle_api and model.nq == model.nv

        self.lower = np.full(self.nq, -np.inf)
        self.upper = np.full(self.nq, np.inf)
        self.lower[self._scalar[0]] = model.lowerPositionLimit[self._scalar[1]]
        self.upper[self._scalar[0]] = model.upperPositionLimit[self._scalar[1]]
        velocity = np.array(model.velocityLimit, dtype=float)
        self.velocity_limit = np.where(velocity > 0.0, velocity, np.inf)

        self._local = threading.local()  # this thread's pinocchio.Data, see _scratch
        self._lock = threading.Lock()  # guards the one-time build of the closed form
        self._closed_form: ClosedForm | None = None

    def __repr__(self) -> str:
        tools = self.tool_frame if self.tool_frame is not None else self.tool_frames
        return f"Robot({self.name!r}, nq={self.nq}, tool_frame={tools!r})"

    @property
    def closed_form(self) -> ClosedForm | None:
        """The paper's closed-form fast path (a ``solvers.closed_form`` object), or None.

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
                except InputError as exc:  # e.g. kr5_3r with a2 = 0: no closed form exists
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
        return as_vector(q, name, self.nq, InvalidInput)

    def to_pinocchio(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Pinocchio configuration vector (model.nq,) of joint positions ``q`` (nq,).

        Continuous joints become (cos, sin). Returns the checked ``q`` itself when the map is
        the identity (no continuous joint), else a new array: never a buffer shared between
        calls.

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        return self.configuration(q)[1]

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
        out = np.empty(self.model.nq)
        api, pin_idx = self._scalar
        out[pin_idx] = q[api]
        api, pin_idx = self._angle
        out[pin_idx] = np.cos(q[api])
        out[pin_idx + 1] = np.sin(q[api])
        return q, out

    def neutral(self) -> npt.NDArray[np.float64]:
        """The zero configuration clipped into the joint limits, (nq,) [rad or m]."""
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    def random_q(self, rng: Seed = None) -> npt.NDArray[np.float64]:
        """A configuration (nq,) drawn uniformly within the limits ([-pi, pi] if continuous).

        Args:
            rng: A ``numpy.random.Generator`` (advanced by the draw), an int seed >= 0 (the
                same seed gives the same q), or None (fresh entropy).

        Raises:
            InvalidInput: ``rng`` is none of these.
        """
        generator = _generator(rng)
        lo = np.where(np.isfinite(self.lower), self.lower, -np.pi)
        hi = np.where(np.isfinite(self.upper), self.upper, np.pi)
        return generator.uniform(lo, hi)

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
        """Geometric Jacobian of a frame, (6, nq), rows [v; w] ([m/s], [rad/s] per unit rate).

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
        ref = check_reference(ref, InvalidInput)
        fid = self._frame(frame)
        q_pin = self.to_pinocchio(q)
        data = self._scratch()
        J: npt.NDArray[np.float64] = pin.computeFrameJacobian(
            self.model, data, q_pin, fid, PIN_REFERENCE[ref]
        )
        return J

    def _frame(self, frame: str | None, argument: str = "frame") -> int:
        """Index of ``frame`` (None: the tool frame), raising the errors of :meth:`fk`."""
        if frame is None:
            if self.tool_frame is None:
                raise ToolFrameRequired(
                    argument, f"{self.name} has several tool frames", list(self.tool_frames)
                )
            frame = self.tool_frame
        fid = self._frame_ids.get(frame) if isinstance(frame, str) else None
        if fid is None:
            raise FrameNotFound(str(frame), sorted(self._frame_ids), argument)
        return fid

    def _scratch(self) -> pin.Data:
        """The calling thread's ``pinocchio.Data``, created on the thread's first call."""
        try:
            return self._local.data
        except AttributeError:
            self._local.data = data = self.model.createData()
            return data


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
    grippers, fingertips, cameras and sensor links.
    """
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]
    parents = set()
    for i in bodies:
        parent = model.frames[i].parentFrame
        while parent and model.frames[parent].type != pin.FrameType.BODY:
            parent = model.frames[parent].parentFrame
        parents.add(parent)
    return [
        str(model.frames[i].name)
        for i in bodies
        if i not in parents and model.frames[i].parentJoint != 0
    ]


def frame_id(model: pin.Model, name: str) -> int:
    """Index of the frame ``name``, preferring the body frame where a joint shares the name.

    Raises:
        FrameNotFound: No frame has that name.
    """
    index = frame_index(model)
    if name not in index:
        raise FrameNotFound(name, sorted(index))
    return index[name]


def _generator(rng: Seed) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or (
        isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0
    ):
        return np.random.default_rng(rng)
    raise InvalidInput("rng", f"expected a numpy Generator, an int seed >= 0 or None, got {rng!r}")
