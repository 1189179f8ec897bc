"""The intake's limits: message shapes read before decoding, and the per-connection budget."""

from __future__ import annotations

import secrets

import msgspec
import numpy as np
import pytest

from rrc_pin.console.intake import Intake, TokenBucket, shape_refusal
from rrc_pin.errors import InvalidInput

FRESH = secrets.randbits(32)


def reference_shape(value: object) -> tuple[int, int]:
    """(depth of non-empty lists and maps, values in all), by recursion on the decoded value."""
    if isinstance(value, (list, tuple)):
        shapes = [reference_shape(v) for v in value]
    elif isinstance(value, dict):
        shapes = [reference_shape(v) for kv in value.items() for v in kv]
    else:
        return 0, 1
    depth = 1 + max(d for d, _ in shapes) if shapes else 0
    return depth, 1 + sum(n for _, n in shapes)


def random_value(rng: np.random.Generator, depth: int) -> object:
    kind = rng.integers(0, 12 if depth > 0 else 9)
    if kind == 0:
        return None
    if kind == 1:
        return bool(rng.integers(0, 2))
    if kind == 2:  # every integer width, both signs
        return int(rng.integers(-(2**63), 2**63 - 1)) >> int(rng.integers(0, 64))
    if kind == 3:
        return int(rng.integers(0, 2**63 - 1)) * 2 + int(rng.integers(0, 2))  # up to 2^64 - 1
    if kind == 4:
        return float(rng.normal() * 10.0 ** rng.integers(-30, 30))
    if kind == 5:  # fixstr, str8, str16
        return "x" * int(rng.choice([0, 5, 31, 32, 200, 300, 70_000]))
    if kind == 6:  # bin8, bin16, bin32
        return bytes(int(rng.choice([0, 1, 255, 256, 70_000])))
    if kind in (7, 8):  # fixext 1 to 16, ext8, ext16
        size = int(rng.choice([1, 2, 4, 8, 16, 3, 300, 70_000]))
        return msgspec.msgpack.Ext(int(rng.integers(0, 127)), bytes(size))
    n = int(rng.choice([0, 1, 3, 15, 16, 40]))
    if kind in (9, 10):
        return [random_value(rng, depth - 1) for _ in range(n)]
    return {f"k{i}": random_value(rng, depth - 1) for i in range(n)}


@pytest.mark.parametrize("seed", [0, 1, 2, FRESH])
def test_shapes_read_without_decoding_match_the_decoded_values(seed):
    rng = np.random.default_rng(seed)
    for _ in range(150):
        value = random_value(rng, int(rng.integers(0, 6)))
        data = msgspec.msgpack.encode(value)
        depth, items = reference_shape(value)
        assert shape_refusal(data, depth, items) is None, seed
        if depth > 0:
            assert "nested more than" in shape_refusal(data, depth - 1, items), seed
        assert shape_refusal(data, depth, items - 1) is not None, seed
        for cut in {1, len(data) // 2, len(data) - 1} - {0, len(data)}:
            assert shape_refusal(data[:cut], 64, 10**9) is not None, (seed, cut)  # prefix-free
        assert shape_refusal(data + b"\x00", 64, 10**9) is not None, seed


def test_a_deep_message_is_refused_at_its_limit_without_recursion():
    deep = b"\x91" * 200_000 + b"\x00"
    assert shape_refusal(deep, 16, 2000) == "nested more than 16 deep"
    assert shape_refusal(b"\x91" * 16 + b"\x00", 16, 2000) is None
    assert shape_refusal(b"\xdd\xff\xff\xff\xff", 16, 2000) == "not msgpack (truncated)"
    assert shape_refusal(b"\xc1", 16, 2000) == "not msgpack"
    assert shape_refusal(b"", 16, 2000) == "not msgpack (truncated)"
    assert shape_refusal(b"\xca\x00\x00\x80\x3f", 16, 2000) is None  # a float32
    assert shape_refusal(msgspec.msgpack.encode(list(range(3000))), 16, 2000) == (
        "more than 2000 values"
    )


def test_the_budget_lets_a_burst_through_then_its_rate():
    bucket = TokenBucket(rate=100.0, burst=10, now=0.0)
    assert [bucket.wait(0.0) for _ in range(10)] == [0.0] * 10
    waits = [bucket.wait(0.0) for _ in range(3)]
    np.testing.assert_allclose(waits, [0.01, 0.02, 0.03], rtol=1e-12)
    assert bucket.level == pytest.approx(-3.0, abs=1e-12)
    assert bucket.wait(1.0) == 0.0 and bucket.level == pytest.approx(9.0, abs=1e-12)  # capped
    quick = TokenBucket(rate=20.0, burst=2, now=0.0)
    assert quick.take(0.0) and quick.take(0.0) and not quick.take(0.0)
    assert quick.level == pytest.approx(0.0, abs=1e-12)  # a refusal takes nothing
    assert not quick.take(0.04) and quick.take(0.05)


@pytest.mark.parametrize(
    ("field", "value"),
    [("rate", 0.0), ("rate", float("nan")), ("burst", 0), ("burst", 1.5), ("patience", -1.0),
     ("max_bytes", 100), ("max_depth", True), ("max_items", 0), ("max_pages", 0)],
)  # fmt: skip
def test_intake_limits_are_checked(field, value):
    with pytest.raises(InvalidInput, match=field):
        Intake(**{field: value})
