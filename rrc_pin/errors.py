"""Exceptions of rrc_pin: one root, :class:`RrcPinError`, shared with :mod:`rrc_pin.solvers.errors`.

Bad input raises before any state changes, with a message naming the argument. Numerical
trouble (singularities, infeasible QPs) is never an exception: the resolver falls back and
reports which method answered.
"""

from __future__ import annotations

from rrc_pin.solvers.errors import InvalidInput, RrcPinError, UnknownBackend

__all__ = [
    "CorruptStore",
    "ForeignMap",
    "FrameNotFound",
    "InvalidInput",
    "MissingExtra",
    "RrcPinError",
    "SchedulerUnreachable",
    "ToolFrameRequired",
    "URDFError",
    "UnknownArm",
    "UnknownBackend",
]


class UnknownArm(RrcPinError, ValueError):
    """A name that is neither a catalogue arm, an installed example-robot-data arm, nor a file.

    Attributes:
        name: The requested name.
        available: Every name :func:`rrc_pin.load` accepts.
    """

    def __init__(self, name: str, available: list[str]) -> None:
        self.name = name
        self.available = available
        super().__init__(
            f"name_or_path: unknown arm {name!r} (not a file either); available: "
            + ", ".join(available)
        )


class URDFError(RrcPinError, ValueError):
    """A URDF file is missing, malformed, or describes a model this library refuses.

    Attributes:
        path: The file (or ``"<string>"``).
        reason: The parser's or the library's message.
    """

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"URDF {path}: {reason}")


class FrameNotFound(RrcPinError, ValueError):
    """A frame name that the model does not have.

    Attributes:
        frame: The requested name.
        frames: Names the model has.
        argument: The argument that named it (``tool_frame``, ``frame``...).
    """

    def __init__(self, frame: str, frames: list[str], argument: str = "tool_frame") -> None:
        self.frame = frame
        self.frames = frames
        self.argument = argument
        super().__init__(f"{argument}: no frame {frame!r}; frames: {', '.join(frames)}")


class ToolFrameRequired(InvalidInput):
    """Several frames could be meant and the call named none.

    Raised by :func:`rrc_pin.load` for a URDF whose tree ends in several links (baxter, talos)
    loaded without ``tool_frame``, and by ``Robot.fk`` / ``Robot.jacobian`` without ``frame`` on
    a robot with several tool frames.

    Attributes:
        argument: The argument to pass (``tool_frame`` or ``frame``).
        candidates: The names it may take.
    """

    def __init__(self, argument: str, context: str, candidates: list[str]) -> None:
        self.candidates = candidates
        super().__init__(argument, f"{context}; name one of: {', '.join(candidates)}")


class ForeignMap(InvalidInput):
    """An output folder that holds another map's partial results (refused, never mixed).

    Attributes:
        folder: The folder of partial results.
    """

    def __init__(self, folder: object, reason: str) -> None:
        self.folder = folder
        super().__init__(
            "out", f"{folder} holds {reason}; give another folder or delete this one"
        )


class CorruptStore(RrcPinError, ValueError):
    """Stored results whose files differ from the checksums written with them: never read.

    Attributes:
        path: The store (a folder).
        files: The damaged files, relative to ``path``, and what is wrong with each.
        repair: How to repair it.
    """

    def __init__(self, path: object, files: dict[str, str], repair: str) -> None:
        self.path = path
        self.files = files
        self.repair = repair
        shown = [f"{name} ({why})" for name, why in list(files.items())[:5]]
        more = f" and {len(files) - 5} more files" if len(files) > 5 else ""
        super().__init__(f"{path}: damaged: {', '.join(shown)}{more}. To repair it, {repair}")


class SchedulerUnreachable(InvalidInput):
    """No Dask scheduler answered at the address given (within the connection timeout).

    Attributes:
        address: The address tried.
    """

    def __init__(self, address: str, reason: str) -> None:
        self.address = address
        super().__init__("scheduler", f"no Dask scheduler at {address!r} ({reason})")


class MissingExtra(RrcPinError, ImportError):
    """A feature needs packages of an optional extra that are not installed.

    Attributes:
        extra: The extra to install (``pip install "rrc-pin[<extra>]"``).
        missing: The modules that failed to import.
    """

    def __init__(self, extra: str, missing: list[str]) -> None:
        self.extra = extra
        self.missing = missing
        super().__init__(
            f"{', '.join(missing)} not installed: pip install \"rrc-pin[{extra}]\""
        )
