"""ResolverOnly: no strategy of its own; the resolver's damping and limits answer."""

from __future__ import annotations

from rrc_pin.control.strategies.base import KEEP, Decision, Situation, Strategy


class ResolverOnly(Strategy):
    """The command as given, resolved by the QP resolver (the controller's default).

    Near a singularity the resolver damps only where the exact rates would exceed the joint
    limits, and keeps the command's direction while slowing down (``Resolver``).
    """

    name = "resolver"
    passive = True

    def decide(self, situation: Situation) -> Decision:
        """The command unchanged."""
        return KEEP
