"""A serial arm backed by Pinocchio: forward kinematics and Jacobians in three frames.

One ``pinocchio.Data`` per Robot, reused by every call (no allocation of Data per call).
Joints are one coordinate each at this API: revolute, prismatic, and continuous (unbounded)
revolute joints, which Pinocchio stores as (cos, sin) with nq = 2, nv = 1; the Robot maps
one angle per joint to Pinocchio's configuration vector. Any other joint (free-flyer,
spherical, planar) is refused with a message saying why.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import FrameNotFound, InvalidInput, URDFError
from rrc_pin.models.arm_spec import ArmSpec
from solvers.spatial import Reference, check_reference
from solvers.validation import as_vector

PIN_REFERENCE = {
    "world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
    "local": pin.ReferenceFrame.LOCAL,
    "world": pin.ReferenceFrame.WORLD,
}


class Robot:
    """A Pinocchio model with a tool frame, joint limits and SI units at every method.

    Attributes:
        name: Arm name (catalogue name, example-robot-data name or URDF stem).
        model: The ``pinocchio.Model``.
        data: Its one ``pinocchio.Data``, reused by every call.
        tool_frame: Name of the frame whose pose and velocity the methods return.
        nq: Number of joints (one coordinate each at this API).
        joint_names: Joint names, in the order of q.
        lower: Joint lower limits (nq,) [rad or m]; -inf for continuous joints.
        upper: Joint upper limits (nq,) [rad or m]; +inf for continuous joints.
        velocity_limit: Joint speed limits (nq,) [rad/s or m/s]; +inf where the URDF gives none.
        spec: The catalogue :class:`ArmSpec` the robot was built from, or None.
        source: Where the model came from (a path, or ``catalogue``).
    """

    def __init__(
        self,
        model: pin.Model,
        tool_frame: str,
        *,
        name: str,
        source: str,
        spec: ArmSpec | None = None,
    ) -> None:
        """Wrap ``model``; ``tool_frame`` must name one of its frames.

        Raises:
            URDFError: The model has a joint that is not one coordinate (free-flyer, spherical...).
            FrameNotFound: ``tool_frame`` is not a frame of the model.
        """
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
        self.name = name
        self.source = source
        self.spec = spec
        self.model = model
        self.data = model.createData()
        self.tool_frame = tool_frame
        self._frame_id = frame_id(model, tool_frame)
        self.nq = model.nv
        self.joint_names = [model.names[j] for j in range(1, model.njoints)]
        self._scalar = (np.array(scalar_api, dtype=int), np.array(scalar_pin, dtype=int))
        self._angle = (np.array(angle_api, dtype=int), np.array(angle_pin, dtype=int))
        self._identity_map = not angle_api and model.nq == model.nv
        self._q_pin = pin.neutral(model)

        self.lower = np.full(self.nq, -np.inf)
        self.upper = np.full(self.nq, np.inf)
        self.lower[self._scalar[0]] = model.lowerPositionLimit[self._scalar[1]]
        self.upper[self._scalar[0]] = model.upperPositionLimit[self._scalar[1]]
        velocity = np.array(model.velocityLimit, dtype=float)
        self.velocity_limit = np.where(velocity > 0.0, velocity, np.inf)
        self._closed_form: Any = None

    def __repr__(self) -> str:
        return f"Robot({self.name!r}, nq={self.nq}, tool_frame={self.tool_frame!r})"

    @property
    def closed_form(self) -> Any:
        """The paper's closed-form fast path (a ``solvers.closed_form`` object), or None.

        Built from this arm's actual parameters (a variant gets a matching closed form).
        """
        if self._closed_form is None and self.spec is not None and self.spec.closed_form:
            self._closed_form = self.spec.closed_form()
        return self._closed_form

    def check_q(self, q: npt.ArrayLike, name: str = "q") -> npt.NDArray[np.float64]:
        """Return ``q`` as a finite (nq,) float array.

        Raises:
            InvalidInput: Wrong length, non-numeric, NaN or inf, naming ``name``.
        """
        return as_vector(q, name, self.nq, InvalidInput)

    def to_pinocchio(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Pinocchio configuration vector (model.nq,) of joint positions ``q`` (nq,).

        Continuous joints become (cos, sin). The returned array is an internal buffer: copy it
        to keep it.
        """
        q = self.check_q(q)
        if self._identity_map:
            return q
        api, pin_idx = self._scalar
        self._q_pin[pin_idx] = q[api]
        api, pin_idx = self._angle
        self._q_pin[pin_idx] = np.cos(q[api])
        self._q_pin[pin_idx + 1] = np.sin(q[api])
        return self._q_pin

    def neutral(self) -> npt.NDArray[np.float64]:
        """The zero configuration clipped into the joint limits, (nq,)."""
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    def random_q(self, rng: np.random.Generator) -> npt.NDArray[np.float64]:
        """A configuration drawn uniformly within the limits ([-pi, pi] for continuous joints)."""
        lo = np.where(np.isfinite(self.lower), self.lower, -np.pi)
        hi = np.where(np.isfinite(self.upper), self.upper, np.pi)
        return rng.uniform(lo, hi)

    def fk(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Pose of the tool frame in the base frame, (4, 4), [m].

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """
        pin.forwardKinematics(self.model, self.data, self.to_pinocchio(q))
        return pin.updateFramePlacement(self.model, self.data, self._frame_id).homogeneous

    def frame_pose(self, q: npt.ArrayLike, frame: str) -> npt.NDArray[np.float64]:
        """Pose (4, 4) of any named frame of the model in the base frame.

        Raises:
            FrameNotFound: No such frame.
        """
        fid = frame_id(self.model, frame)
        pin.forwardKinematics(self.model, self.data, self.to_pinocchio(q))
        return pin.updateFramePlacement(self.model, self.data, fid).homogeneous

    def jacobian(
        self, q: npt.ArrayLike, ref: Reference = "world_aligned"
    ) -> npt.NDArray[np.float64]:
        """Geometric Jacobian of the tool frame, (6, nq), rows [v; w].

        Args:
            q: Joint positions (nq,).
            ref: ``world_aligned`` (tool-origin velocity, base axes), ``local`` (tool axes) or
                ``world`` (spatial velocity at the base origin).

        Raises:
            InvalidInput: Bad ``q`` or ``ref``.
        """
        ref = check_reference(ref, InvalidInput)
        q_pin = self.to_pinocchio(q)
        return pin.computeFrameJacobian(
            self.model, self.data, q_pin, self._frame_id, PIN_REFERENCE[ref]
        )


def frame_id(model: pin.Model, name: str) -> int:
    """Index of the frame ``name``, preferring the body frame where a joint shares the name.

    Raises:
        FrameNotFound: No frame has that name.
    """
    matches = [i for i, f in enumerate(model.frames) if f.name == name]
    if not matches:
        raise FrameNotFound(name, sorted({f.name for f in model.frames}))
    bodies = [i for i in matches if model.frames[i].type == pin.FrameType.BODY]
    return (bodies or matches)[0]
