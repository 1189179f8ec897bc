"""Mailbox: the one door from the page's threads into the control loop."""

from __future__ import annotations

import threading
from collections import deque

from rrc_pin.console.commands import Command
from rrc_pin.errors import InvalidInput


class Mailbox:
    """A bounded, thread-safe queue of commands: many posters, one reader (the loop).

    The page's callbacks run in viser's threads and only :meth:`post`; the loop
    :meth:`drain` s it once per tick and applies the commands in order. When more than
    ``capacity`` commands wait (a page flooding the server), the oldest are dropped and
    counted: the loop's memory and its time per tick stay bounded whatever the page sends.

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
        """Queue ``command`` (any thread); the oldest waiting one is dropped when full."""
        with self._lock:
            if len(self._queue) >= self.capacity:
                self._queue.popleft()
                self._dropped += 1
            self._queue.append(command)
            self._posted += 1

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
