"""The sculpting server answers only its own page: Host, Origin and the session token.

A foreign ``Host`` (DNS rebinding) is refused before any route runs; a ``POST`` from
another origin (a cross-site "simple" request, ``text/plain``) is refused and leaves the
save file untouched; an API call without the token of the served page is refused.
"""

from __future__ import annotations

import json
import warnings

import pytest

pytest.importorskip("starlette", reason="the sculpt server needs the extra 'sculpt'")
pytest.importorskip("httpx", reason="starlette's TestClient needs httpx")
with warnings.catch_warnings():   # starlette >= 1.0 suggests httpx2; httpx still works
    warnings.simplefilter("ignore")
    from starlette.testclient import TestClient  # noqa: E402

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt.guard import TOKEN_HEADER, Guard  # noqa: E402
from splinedeform.sculpt.server import create_app  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")

TINY = """
[surface]
shape = "plane"
cells = 2
[material]
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
"""
PORT = 8765
ORIGIN = f"http://127.0.0.1:{PORT}"
SAVE = {"version": 1, "t_end": 1.0, "pushes": [{"index": 3, "force": [0, 0, -1], "t_on": 0}]}


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    folder = tmp_path_factory.mktemp("guard")
    scenario = parse_scenario(TINY, source="tiny.toml", directory=folder)
    session = Session(scenario, resolution=3, modes=None, save_path=folder / "saved.toml")
    guard = Guard.for_address("127.0.0.1", PORT)
    client = TestClient(create_app(session, guard), base_url=ORIGIN,
                        raise_server_exceptions=False)
    return client, guard, session


def _token_of(page: str) -> str:
    return page.split('name="splinedeform-token" content="', 1)[1].split('"', 1)[0]


def test_the_served_page_carries_the_token_and_its_calls_pass(served):
    client, guard, session = served
    page = client.get("/")
    assert page.status_code == 200 and _token_of(page.text) == guard.token
    assert len(guard.token) >= 40                          # 32 random bytes
    assert guard.token not in json.dumps(client.get(
        "/api/basis", headers={TOKEN_HEADER: guard.token}).json())   # not in the API answers
    headers = {TOKEN_HEADER: guard.token, "Origin": ORIGIN}
    reply = client.post("/api/save", json=SAVE, headers=headers)
    assert reply.status_code == 200, reply.text
    session.save_path.unlink()
    # localhost names the same loopback server
    reply = client.get(f"http://localhost:{PORT}/api/status",
                       headers={TOKEN_HEADER: guard.token, "Origin": f"http://localhost:{PORT}"})
    assert reply.status_code == 200


@pytest.mark.parametrize("host", ["attacker.example", f"attacker.example:{PORT}",
                                  "127.0.0.1:9999", f"127.0.0.2:{PORT}", f"localhost.evil:{PORT}",
                                  "", f"[::1]:{PORT}x"])
def test_a_foreign_host_is_refused(served, host):
    """DNS rebinding: the attacker's name arrives in Host; refused on every route, even
    with the right token (the page itself would hand the token out)."""
    client, guard, _ = served
    for path in ("/", "/api/basis", "/api/status"):
        reply = client.get(path, headers={"Host": host, TOKEN_HEADER: guard.token})
        assert reply.status_code == 400, (host, path, reply.status_code)
        assert "Host" in reply.json()["error"] and guard.token not in reply.text


@pytest.mark.parametrize("origin", ["http://attacker.example", f"http://127.0.0.1:{PORT + 1}",
                                    "null", f"https://127.0.0.1:{PORT}", "file://"])
def test_a_foreign_origin_post_is_refused_and_the_save_file_untouched(served, origin):
    client, guard, session = served
    session.save_path.write_text("# the user's file\n")
    for headers in ({"Origin": origin, "Content-Type": "text/plain"},
                    {"Origin": origin, "Content-Type": "text/plain", TOKEN_HEADER: guard.token}):
        reply = client.post("/api/save", content=json.dumps(SAVE), headers=headers)
        assert reply.status_code == 403, reply.text
        assert "Origin" in reply.json()["error"]
    assert session.save_path.read_text() == "# the user's file\n"
    reply = client.get("/api/basis", headers={"Origin": origin, TOKEN_HEADER: guard.token})
    assert reply.status_code == 403
    session.save_path.unlink()


@pytest.mark.parametrize("token", [None, "", "wrong", "x" * 43])
def test_a_missing_or_wrong_token_is_refused(served, token):
    client, guard, session = served
    headers = {"Origin": ORIGIN} if token is None else {"Origin": ORIGIN, TOKEN_HEADER: token}
    for method, path in (("GET", "/api/basis"), ("GET", "/api/status"), ("GET", "/api/page"),
                         ("POST", "/api/save"), ("POST", "/api/resolve"),
                         ("POST", "/api/correction")):
        reply = client.request(method, path, headers=headers,
                               content=json.dumps(SAVE) if method == "POST" else None)
        assert reply.status_code == 403, (path, reply.status_code)
        assert TOKEN_HEADER in reply.json()["error"]
    assert not session.save_path.exists()


def test_a_post_without_origin_is_refused(served):
    """Every browser sends Origin on a POST; a request without it is no page's."""
    client, guard, session = served
    reply = client.post("/api/save", json=SAVE, headers={TOKEN_HEADER: guard.token})
    assert reply.status_code == 403 and "Origin" in reply.json()["error"]
    assert not session.save_path.exists()


def test_a_wildcard_bind_takes_ip_literals_but_no_domain_name():
    guard = Guard.for_address("0.0.0.0", 80, "t")
    assert guard.host_ok("192.168.1.7") and guard.host_ok("192.168.1.7:80")
    assert guard.host_ok("[fe80::1]") and guard.host_ok("localhost")
    assert not guard.host_ok("attacker.example") and not guard.host_ok("10.0.0.1:81")
    v6 = Guard.for_address("::1", 5000, "t")
    assert v6.host_ok("[::1]:5000") and v6.host_ok("localhost:5000")
    assert not v6.host_ok("::1:5000") and not v6.host_ok("[::2]:5000")
    assert v6.origin_ok("http://[::1]:5000", "[::1]:5000")
    assert not v6.origin_ok("http://[::1]:5001", "[::1]:5000")


def test_a_dropped_upload_is_logged_as_a_disconnect(served, capsys):
    """The page goes away mid-upload: the server says so, and it is no internal error."""
    import asyncio

    client, guard, session = served
    sent = []

    async def receive():
        return {"type": "http.disconnect"}

    async def send(message):
        sent.append(message)

    scope = {"type": "http", "method": "POST", "path": "/api/save", "raw_path": b"/api/save",
             "query_string": b"", "scheme": "http", "http_version": "1.1",
             "server": ("127.0.0.1", PORT), "client": ("127.0.0.1", 50000), "root_path": "",
             "headers": [(b"host", f"127.0.0.1:{PORT}".encode()), (b"origin", ORIGIN.encode()),
                         (TOKEN_HEADER.lower().encode(), guard.token.encode()),
                         (b"content-type", b"application/json")]}
    asyncio.run(client.app(scope, receive, send))
    err = capsys.readouterr().err
    assert "disconnected" in err and "internal error" not in err
    assert not session.save_path.exists()
