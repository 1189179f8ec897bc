"""Exceptions of the numerical kernels: one root, :class:`SolverError`."""

from __future__ import annotations


class SolverError(Exception):
    """Root of every exception raised by :mod:`solvers`."""


class InputError(SolverError, ValueError):
    """An argument has the wrong shape, a non-finite entry or an invalid value.

    Attributes:
        argument: Name of the offending argument, as the caller spelled it.
        reason: What was expected and what came.
    """

    def __init__(self, argument: str, message: str) -> None:
        self.argument = argument
        self.reason = message
        super().__init__(f"{argument}: {message}")


class ProblemError(SolverError):
    """A QP backend failed in a way that is not a numerical answer (bad setup, crash)."""


class NumericalFailure(SolverError):
    """A method of the numerics found no usable answer.

    No solution, an answer outside the constraints, a backend's fault or time-out.

    Internal: the pipeline records it in the resolution's ``attempts`` and goes on to the
    next method; it never reaches a caller of the resolver.
    """


class BackendNotFound(SolverError, ValueError):
    """An unknown or uninstalled QP backend was requested.

    Attributes:
        backend: The requested name.
        available: Names of the installed backends.
    """

    def __init__(self, backend: str, available: list[str]) -> None:
        self.backend = backend
        self.available = available
        super().__init__(
            f"backend: unknown or not installed {backend!r}; installed: {', '.join(available)} "
            "(install more with `pip install rrc-pin[bench]`)"
        )
