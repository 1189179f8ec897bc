"""Who may open the console: the token, the Host and the Origin of each request (no server)."""

from __future__ import annotations

import pytest

from rrc_pin.console import Console
from rrc_pin.console.access import MIN_TOKEN, TOKEN_CHARACTERS, Access, check_token, is_loopback
from rrc_pin.console.app import exposed
from rrc_pin.errors import InvalidInput

TOKEN = "a-token-of-ours-0123456789"


def request(access: Access, path: str = "/", websocket: bool = False, host="127.0.0.1:8080",
            **headers: str | list[str]):  # fmt: skip
    """The verdict on a request to ``path`` with these headers (a list: a repeated header)."""
    sent = {"Host": host, **headers}
    as_lists = {k: v if isinstance(v, list) else [v] for k, v in sent.items() if v is not None}
    return access.verdict(path, as_lists, websocket)


@pytest.fixture
def access() -> Access:
    a = Access("127.0.0.1", TOKEN)
    a.name_cookie(8080)
    return a


def test_a_token_is_made_at_each_start_and_a_users_is_checked():
    made = {Access("127.0.0.1").token for _ in range(5)}
    assert len(made) == 5 and all(len(t) == 43 and set(t) <= TOKEN_CHARACTERS for t in made)
    assert Access("127.0.0.1").chosen is False and Access("::1", TOKEN).chosen is True
    for bad in ("x" * (MIN_TOKEN - 1), "a token with spaces!", 12345678901234567890, b"x" * 20):
        with pytest.raises(InvalidInput, match="token"):
            check_token(bad)
    assert check_token("A-b_c.d~" * 2) == "A-b_c.d~" * 2


@pytest.mark.parametrize(
    ("host", "loopback"),
    [("127.0.0.1", True), ("127.3.2.1", True), ("::1", True), ("[::1]", True),
     ("localhost", True), ("0.0.0.0", False), ("::", False), ("192.168.1.20", False),
     ("robot-lab.example", False), ("", False)],
)  # fmt: skip
def test_only_this_machines_own_addresses_are_loopback(host, loopback):
    assert is_loopback(host) is loopback


def test_serving_beyond_this_machine_needs_a_token_of_ones_own():
    for host in ("0.0.0.0", "::", "192.168.1.20", "robot-lab.example"):
        with pytest.raises(InvalidInput, match="token") as refused:
            Console("barker6", host=host)
        assert "RRC_PIN_CONSOLE_TOKEN" in str(refused.value)
        exposed_access = Access(host, TOKEN)
        assert not exposed_access.loopback and exposed_access.token == TOKEN
    warning = exposed("0.0.0.0", 8080)
    assert "0.0.0.0" in warning and "plain HTTP" in warning and "SSH tunnel" in warning


def test_the_page_with_its_token_sets_the_cookie_and_leaves_the_address(access):
    verdict = request(access, f"/?token={TOKEN}&dark=1")
    assert verdict.refused is None and verdict.set_cookie and verdict.location == "/?dark=1"
    assert request(access, f"/?token={TOKEN}").location == "/"
    assert access.cookie_header() == (
        f"rrc-pin-console-8080={TOKEN}; Path=/; HttpOnly; SameSite=Lax"
    )
    with_cookie = request(access, Cookie=f"theme=dark; rrc-pin-console-8080={TOKEN}")
    assert with_cookie == (None, False, None)
    websocket = request(access, f"/?token={TOKEN}", websocket=True)
    assert websocket == (None, False, None)  # a program's websocket: no cookie, no redirect


@pytest.mark.parametrize(
    ("path", "headers"),
    [
        ("/", {}),
        ("/?token=not-it-but-long-enough", {}),
        ("/", {"Cookie": "rrc-pin-console-8080=not-it-but-long-enough"}),
        ("/", {"Cookie": f"rrc-pin-console-9090={TOKEN}"}),  # another console's cookie
        (f"/?token={TOKEN[:-1]}", {}),
    ],
)
def test_no_token_or_another_is_refused(access, path, headers):
    for websocket in (False, True):
        assert "needs its token" in request(access, path, websocket, **headers).refused


@pytest.mark.parametrize(
    ("host", "origin", "why"),
    [
        ("127.0.0.1:8080", "http://evil.example", "a page of 'http://evil.example'"),
        ("127.0.0.1:8080", "http://127.0.0.1:9999", "a page of 'http://127.0.0.1:9999'"),
        ("127.0.0.1:8080", "null", "a page of 'null'"),
        ("evil.example:8080", "http://evil.example:8080", "this machine's own names"),  # rebinding
        ("", None, "this machine's own names"),
        ("[", None, "this machine's own names"),
        (["127.0.0.1:8080", "127.0.0.1:8080"], None, "one Host header"),
        ("127.0.0.1:8080", ["http://127.0.0.1:8080"] * 2, "at most one Origin"),
    ],
)
def test_a_request_of_another_origin_or_host_is_refused_token_or_not(access, host, origin, why):
    for path in ("/", f"/?token={TOKEN}"):
        verdict = request(access, path, True, host=host, Origin=origin,
                          Cookie=f"rrc-pin-console-8080={TOKEN}")  # fmt: skip
        assert why in verdict.refused


def test_the_pages_own_origin_passes_through_any_of_this_machines_names(access):
    for host in ("127.0.0.1:8080", "localhost:8080", "[::1]:8080", "localhost:9000"):  # a tunnel
        for scheme in ("http", "https"):
            verdict = request(access, "/", True, host=host, Origin=f"{scheme}://{host.upper()}",
                              Cookie=f"rrc-pin-console-8080={TOKEN}")  # fmt: skip
            assert verdict.refused is None, (host, scheme)
    exposed_access = Access("0.0.0.0", TOKEN)
    exposed_access.name_cookie(8080)
    lab = request(exposed_access, f"/?token={TOKEN}", True, host="robot-lab.example:8080",
                  Origin="http://robot-lab.example:8080")  # fmt: skip
    assert lab.refused is None  # beyond this machine: any name the network gives it
