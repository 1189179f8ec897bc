"""The mailbox: many posting threads, one reader, bounded."""

from __future__ import annotations

import threading

import pytest

from rrc_pin.console import commands as cmd
from rrc_pin.console.mailbox import Mailbox, urgent
from rrc_pin.errors import InvalidInput


def test_drain_returns_commands_in_order_and_empties():
    box = Mailbox()
    box.post(cmd.Latch(True))
    box.post(cmd.Speed(0.5))
    assert box.drain() == [cmd.Latch(True), cmd.Speed(0.5)]
    assert box.drain() == []
    assert len(box) == 0


def test_a_full_mailbox_drops_the_oldest_and_counts():
    box = Mailbox(capacity=3)
    for k in range(5):
        box.post(cmd.Speed(k / 10))
    assert [c.value for c in box.drain()] == [0.2, 0.3, 0.4]
    assert box.dropped == 2
    assert box.posted == 5


def test_a_full_mailbox_never_drops_a_stop_or_a_release_for_another_command():
    box = Mailbox(capacity=3)
    box.post(cmd.Stop())
    for k in range(5):
        box.post(cmd.Speed(k / 10))
    box.post(cmd.Latch(False))
    assert box.drain() == [cmd.Stop(), cmd.Speed(0.4), cmd.Latch(False)]
    assert box.dropped == 4
    full = Mailbox(capacity=2)
    full.post(cmd.Released())
    full.post(cmd.Stop())
    full.post(cmd.Latch(True))  # not urgent, and no room: this one goes
    full.post(cmd.Latch(False))  # urgent: the oldest urgent one goes
    assert full.drain() == [cmd.Stop(), cmd.Latch(False)]
    assert (full.dropped, full.posted) == (2, 4)
    kinds = (cmd.Stop(), cmd.Released(), cmd.Latch(False), cmd.Latch(True), cmd.Hold())
    assert [urgent(c) for c in kinds] == [True, True, True, False, False]


def test_posting_threads_and_a_draining_reader_lose_nothing_but_the_dropped():
    box = Mailbox(capacity=100)
    got: list[cmd.Command] = []
    done = threading.Event()

    def reader():
        while not done.is_set():
            got.extend(box.drain())
        got.extend(box.drain())

    def poster():
        for _ in range(2000):
            box.post(cmd.Hold())

    read = threading.Thread(target=reader)
    read.start()
    posters = [threading.Thread(target=poster) for _ in range(4)]
    for t in posters:
        t.start()
    for t in posters:
        t.join()
    done.set()
    read.join()
    assert len(got) + box.dropped == 8000 == box.posted


@pytest.mark.parametrize("capacity", [0, -1, 1.5, True])
def test_capacity_is_checked(capacity):
    with pytest.raises(InvalidInput, match="capacity"):
        Mailbox(capacity)
