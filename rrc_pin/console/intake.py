"""What the console takes from a page: messages of bounded size and shape, at a bounded rate.

Each message's size and shape are checked before it is decoded, and each connection has a rate.

A page's messages are msgpack. Decoding one builds Python objects as deep and as many as the
bytes say (a message nested 200,000 deep made the decoder raise ``RecursionError``), so the
bytes are read first, without decoding them, by :func:`shape_refusal`: at most
:attr:`Intake.max_depth` containers deep and :attr:`Intake.max_items` values in all (its cost
is bounded by the latter). Each connection then spends from its own :class:`TokenBucket`:
a message beyond the budget waits, and the connection reads nothing meanwhile, so a page that
floods the console fills its own socket and waits; one that keeps its budget spent for
:attr:`Intake.patience` is closed. The flood costs its sender: the server handles at most
``rate`` messages a second from a connection however fast it sends, and for a few seconds.
"""

from __future__ import annotations

from dataclasses import dataclass

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_number


@dataclass(frozen=True)
class Intake:
    """The limits on what one connection may send.

    Attributes:
        rate: Messages a second a connection may send on average, > 0 (a page sends up to
            about 40: the hold button's heartbeats, a dragged slider, the camera, keys; a
            device streaming its poses 90 to 120 more).
        burst: Messages it may send at once beyond the rate, >= 1.
        patience: How long [s] a connection may keep its budget spent (every message waiting
            for its token) before it is closed, > 0.
        max_bytes: Largest message [bytes], >= 1024 (a file upload comes in parts of 512 kiB).
        max_depth: Deepest nesting of lists and maps, >= 1.
        max_items: Most values in a message (every list, map, key and scalar), >= 1.
        max_pages: Most connections open at once, >= 1 (more are refused, HTTP 503); twice
            as many may open in a row, then one a second (each costs the server the scene).

    Raises:
        InvalidInput: A limit out of its range, named.
    """

    rate: float = 200.0
    burst: int = 10
    patience: float = 2.0
    max_bytes: int = 2**20 + 2**16
    max_depth: int = 16
    max_items: int = 2000
    max_pages: int = 8

    def __post_init__(self) -> None:
        finite_number(self.rate, "rate", 0.0, inclusive=False)
        finite_number(self.patience, "patience", 0.0, inclusive=False)
        for name, least in (("burst", 1), ("max_bytes", 1024), ("max_depth", 1),
                            ("max_items", 1), ("max_pages", 1)):  # fmt: skip
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < least:
                raise InvalidInput(name, f"expected an int >= {least}, got {value!r}")


class TokenBucket:
    """A rate limit: ``burst`` tokens, refilled at ``rate`` a second; each message takes one.

    Args:
        rate: Tokens a second, > 0.
        burst: Most tokens held, >= 1 (full at the start).
        now: The clock's time at the start [s].
    """

    def __init__(self, rate: float, burst: int, now: float) -> None:
        self.rate = finite_number(rate, "rate", 0.0, inclusive=False)
        self.burst = float(burst)
        self._tokens = self.burst
        self._at = now

    def wait(self, now: float) -> float:
        """Take a token at ``now`` [s]; how long [s] to wait before the message may pass.

        A message that must wait has its token spent in advance: the next one waits one more
        period after it.
        """
        self._refill(now)
        self._tokens -= 1.0
        return 0.0 if self._tokens >= 0.0 else -self._tokens / self.rate

    @property
    def level(self) -> float:
        """Tokens held after the last take (negative: owed by messages that waited)."""
        return self._tokens

    def take(self, now: float) -> bool:
        """Take a token at ``now`` [s] if there is one; whether there was."""
        self._refill(now)
        if self._tokens < 1.0:
            return False
        self._tokens -= 1.0
        return True

    def _refill(self, now: float) -> None:
        self._tokens = min(self.burst, self._tokens + (now - self._at) * self.rate)
        self._at = now


def shape_refusal(data: bytes, max_depth: int, max_items: int) -> str | None:
    """Why the msgpack message ``data`` is refused before decoding, or None.

    Reads the type bytes of every value (the payloads of strings, binaries and extensions are
    skipped by their lengths) with an explicit stack, never recursion.

    Args:
        data: One message as it arrived.
        max_depth: Deepest nesting of arrays and maps allowed.
        max_items: Most values allowed (containers, keys and scalars alike).

    Returns:
        None for one whole msgpack value within the limits, else a short reason.
    """
    pos, items, end = 0, 0, len(data)
    pending = [1]  # values still to read at each open level (the message is one value)
    while pending:
        if pending[-1] == 0:
            pending.pop()
            continue
        pending[-1] -= 1
        items += 1
        if items > max_items:
            return f"more than {max_items} values"
        if pos >= end:
            return "not msgpack (truncated)"
        head = _header(data, pos)
        if head is None:
            return "not msgpack"
        pos, children, skip = head
        pos += skip
        if pos > end:
            return "not msgpack (truncated)"
        if children:
            if len(pending) > max_depth:
                return f"nested more than {max_depth} deep"
            pending.append(children)
    return None if pos == end else "not msgpack (bytes after the message)"


def _header(data: bytes, pos: int) -> tuple[int, int, int] | None:
    """The value at ``pos``: (position after its header, its children, payload bytes to skip).

    None for a reserved byte or a header cut short. A map of n pairs has 2 n children.
    """
    b = data[pos]
    pos += 1
    if b <= 0x7F or b >= 0xE0 or b in (0xC0, 0xC2, 0xC3):  # fixints, nil, false, true
        return pos, 0, 0
    if b <= 0x8F:
        return pos, 2 * (b & 0x0F), 0
    if b <= 0x9F:
        return pos, b & 0x0F, 0
    if b <= 0xBF:
        return pos, 0, b & 0x1F
    if b in _FIXED:
        return pos, 0, _FIXED[b]
    kind = _SIZED.get(b)
    if kind is None:  # 0xC1, never used
        return None
    width, what = kind
    if pos + width > len(data):
        return None
    n = int.from_bytes(data[pos : pos + width], "big")
    pos += width
    if what == "bytes":
        return pos, 0, n
    if what == "ext":
        return pos, 0, n + 1
    return pos, (2 * n if what == "map" else n), 0


_FIXED = {
    0xCA: 4, 0xCB: 8, 0xCC: 1, 0xCD: 2, 0xCE: 4, 0xCF: 8, 0xD0: 1, 0xD1: 2, 0xD2: 4, 0xD3: 8,
    0xD4: 2, 0xD5: 3, 0xD6: 5, 0xD7: 9, 0xD8: 17,
}  # fmt: skip
"""Headers of fixed size: floats, ints and fixext (type byte and data) -> payload bytes."""
_SIZED = {
    0xC4: (1, "bytes"), 0xC5: (2, "bytes"), 0xC6: (4, "bytes"),
    0xC7: (1, "ext"), 0xC8: (2, "ext"), 0xC9: (4, "ext"),
    0xD9: (1, "bytes"), 0xDA: (2, "bytes"), 0xDB: (4, "bytes"),
    0xDC: (2, "array"), 0xDD: (4, "array"), 0xDE: (2, "map"), 0xDF: (4, "map"),
}  # fmt: skip
"""Headers followed by a length of ``width`` bytes -> (width, what the length counts)."""

