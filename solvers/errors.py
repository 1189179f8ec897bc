"""Exceptions of rrc-pin: one root, :class:`RrcPinError`, for both of its packages.

The numerical layer (:mod:`solvers`) raises the classes defined here; :mod:`rrc_pin.errors`
adds the framework's own (unknown arm, URDF, frames) as subclasses of the same root, so that
``except rrc_pin.RrcPinError`` catches everything either package raises for bad input.
Numerical trouble is never an exception at the public calls: :class:`NumericalFailure` and
:class:`ProblemError` stay inside the pipeline, which falls back and reports.
"""

from __future__ import annotations


class RrcPinError(Exception):
    """Root of every exception raised by :mod:`rrc_pin` and :mod:`solvers`."""


class InvalidInput(RrcPinError, ValueError):
    """An argument has the wrong shape, a non-finite entry or an invalid value.

    Attributes:
        argument: Name of the offending argument, as the caller spelled it.
        reason: What was expected and what came.
    """

    def __init__(self, argument: str, message: str) -> None:
        self.argument = argument
        self.reason = message
        super().__init__(f"{argument}: {message}")


class UnknownBackend(InvalidInput):
    """An unknown or uninstalled QP backend was requested.

    Attributes:
        backend: The requested name.
        available: Names of the installed backends.
    """

    def __init__(self, backend: str, available: list[str], argument: str = "backend") -> None:
        self.backend = backend
        self.available = available
        super().__init__(
            argument, f"unknown or not installed {backend!r}; installed: {', '.join(available)} "
            "(install more with `pip install rrc-pin[bench]`)",
        )  # fmt: skip


class ProblemError(RrcPinError):
    """A QP backend failed in a way that is not a numerical answer (bad setup, crash).

    Internal: the pipeline treats it as a :class:`NumericalFailure`.
    """


class NumericalFailure(RrcPinError):
    """A method of the numerics found no usable answer.

    No solution, an answer outside the constraints, a backend's fault or time-out.

    Internal: the pipeline records it in the resolution's ``attempts`` and goes on to the
    next method; it never reaches a caller of the resolver.
    """
