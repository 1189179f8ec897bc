"""Mailbox: the one door from the page's threads into the control loop."""

from __future__ import annotations

import threading
from collections import deque

from rrc_pin.console.commands import Command, Latch, Released, Stop
from rrc_pin.errors import InvalidInput


def urgent(command: Command) -> bool:
    """Whether ``command`` stops or releases the arm: STOP, the latch let go, no page left."""
    return isinstance(command, (Stop, Released)) or (isinstance(command, Latch) and not command.on)


class Mailbox:
    """A bounded, thread-safe queue of commands: many posters, one reader (the loop).

    The page's callbacks :meth:`post`; the loop :meth:`drain` s it once per tick and applies
    the commands in order, all before it steps: a STOP takes effect at the next tick whatever
    came before it. When more than ``capacity`` commands wait (a loop stalled, a program
    posting faster than the loop ticks), the oldest are dropped and counted, but never one
    that stops or releases the arm (:func:`urgent`) while another can go: the loop's memory
    and its time per tick stay bounded whatever is posted.

    Args:
        capacity: Most commands kept waiting, >= 1.

    Raises:
        InvalidInput: ``capacity`` is not an int >= 1.
    """

    def __init__(self, capacity: int = 256) -> None:
        if isinstance(capacity, bool) or not isinstance(capacity, int) or capacity < 1:
            raise InvalidInput("capacity", f"expected an int >= 1, got {capacity!r}")
        self.capacity = capacity
        self._queue: deque[Command] = deque()
        self._lock = threading.Lock()
        self._dropped = 0
        self._posted = 0

    def post(self, command: Command) -> None:
        """Queue ``command`` (any thread); when full, the oldest that is not urgent is dropped."""
        with self._lock:
            self._posted += 1
            if len(self._queue) >= self.capacity and not self._dropped_one(urgent(command)):
                self._dropped += 1  # full of urgent ones, and this one is not
                return
            self._queue.append(command)

    def _dropped_one(self, for_urgent: bool) -> bool:
        """Drop the oldest command that is not urgent (or, for an urgent one, the oldest)."""
        for i, waiting in enumerate(self._queue):
            if not urgent(waiting):
                del self._queue[i]
                break
        else:
            if not for_urgent:
                return False
            self._queue.popleft()  # a later urgent command stops or releases the arm as well
        self._dropped += 1
        return True

    def drain(self) -> list[Command]:
        """Every waiting command, oldest first, removed from the queue (the loop's call)."""
        with self._lock:
            if not self._queue:
                return []
            out = list(self._queue)
            self._queue.clear()
        return out

    @property
    def dropped(self) -> int:
        """Commands dropped because the mailbox was full, since it was made."""
        return self._dropped

    @property
    def posted(self) -> int:
        """Commands posted since the mailbox was made."""
        return self._posted

    def __len__(self) -> int:
        return len(self._queue)
