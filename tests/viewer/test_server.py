"""The web server: the page, only the static folder, and websockets that survive bad input."""

from __future__ import annotations

import json

import pytest
from starlette.testclient import TestClient, WebSocketDenialResponse
from starlette.websockets import WebSocketDisconnect

from collidium.presets import preset
from collidium.viewer import protocol
from collidium.viewer.server import MAX_CONNECTIONS, STATIC, create_app, running
from collidium.viewer.session import ViewerSession


@pytest.fixture
def client() -> TestClient:
    app = create_app(lambda: ViewerSession(preset("gas", n=20), preset="gas"))
    return TestClient(app, base_url="http://127.0.0.1:8765")


def test_the_page_and_its_bundle_are_served(client):
    page = client.get("/")
    assert page.status_code == 200 and 'src="static/app.js"' in page.text
    for name in ("app.js", "app.css", "widget.js"):
        response = client.get(f"/static/{name}")
        assert response.status_code == 200
        assert response.content == (STATIC / name).read_bytes()


@pytest.mark.parametrize(
    "path",
    [
        "/static/../server.py",
        "/static/%2e%2e/server.py",
        "/static/..%2fserver.py",
        "/static/%2e%2e/%2e%2e/viewer/session.py",
        "/etc/passwd",
        "/server.py",
    ],
)
def test_nothing_outside_the_static_folder_is_served(client, path):
    response = client.get(path)
    assert response.status_code == 404
    assert b"ViewerSession" not in response.content and b"import" not in response.content


WS = "ws://127.0.0.1:8765/ws"


def receive_json(ws) -> dict:
    while True:
        message = ws.receive()
        if message.get("text") is not None:
            return json.loads(message["text"])


def test_a_websocket_gets_the_handshake_and_frames(client):
    with client.websocket_connect(WS) as ws:
        ws.send_text(json.dumps({"type": "ready"}))
        kinds = [receive_json(ws)["type"] for _ in range(4)]
        assert kinds == ["hello", "scene", "status", "stats"]
        frame = protocol.decode_frame(ws.receive_bytes())
        assert frame["n"] == 20


def test_a_malformed_message_gets_an_error_and_the_server_keeps_going(client):
    with client.websocket_connect(WS) as ws:
        ws.send_text(json.dumps({"type": "ready"}))
        ws.send_text("{this is not json")
        ws.send_bytes(b"\xff\xfe")
        errors, running = [], False
        # The first step's status ("starting" ends, still playing) comes when the server has
        # stepped, which may be after the errors: wait for it, so the next status is the pause's.
        while len(errors) < 2 or not running:
            reply = receive_json(ws)
            if reply["type"] == "error":
                errors.append(reply["field"])
            running = running or (reply["type"] == "status" and reply["phase"] == "running")
        assert errors == ["message", "message"]
        ws.send_text(json.dumps({"type": "pause"}))
        reply = receive_json(ws)
        while reply["type"] != "status":
            reply = receive_json(ws)
        assert reply["playing"] is False


def test_a_page_from_another_site_cannot_connect(client):
    with (
        pytest.raises(WebSocketDisconnect) as closed,
        client.websocket_connect(WS, headers={"origin": "http://evil.example"}) as ws,
    ):
        ws.receive_text()
    assert closed.value.code == 1008


def test_pages_beyond_the_limit_are_refused_with_a_reason(client):
    import contextlib

    with contextlib.ExitStack() as stack:
        for _ in range(MAX_CONNECTIONS):
            ws = stack.enter_context(client.websocket_connect(WS))
            ws.send_text(json.dumps({"type": "ready"}))
            receive_json(ws)
        with client.websocket_connect(WS) as extra:
            reply = json.loads(extra.receive_text())
            assert reply["field"] == "connection" and "close one" in reply["reason"]
            with pytest.raises(WebSocketDisconnect) as closed:
                extra.receive_text()
            assert closed.value.code == 1013


def test_a_site_that_rebinds_its_name_to_this_machine_is_refused(client):
    """DNS rebinding: the attacker's page and name agree with each other, not with us."""
    headers = {"host": "evil.example:8765", "origin": "http://evil.example:8765"}
    assert client.get("/", headers={"host": "evil.example:8765"}).status_code == 400
    with (
        pytest.raises(WebSocketDenialResponse),
        client.websocket_connect("ws://evil.example:8765/ws", headers=headers),
    ):
        pass


def test_a_server_open_to_the_network_accepts_its_own_pages_under_any_name():
    app = create_app(lambda: ViewerSession(preset("gas", n=5)), hosts=("*",))
    client = TestClient(app, base_url="http://192.168.1.20:8765")
    assert client.get("/").status_code == 200
    origin = {"origin": "http://192.168.1.20:8765"}
    with client.websocket_connect("ws://192.168.1.20:8765/ws", headers=origin) as ws:
        ws.send_text(json.dumps({"type": "ready"}))
        assert receive_json(ws)["type"] == "hello"


def test_frames_go_uncompressed_to_a_page_that_offers_compression():
    """Compressing a 1e5-disk frame took longer than drawing it (ARCHITECTURE.md, "The viewer's
    frames")."""
    from websockets.sync.client import connect

    app = create_app(lambda: ViewerSession(preset("gas", n=5)))
    with running(app) as url, connect(url.replace("http", "ws") + "ws") as ws:
        assert "permessage-deflate" in ws.request.headers["Sec-WebSocket-Extensions"]
        assert "Sec-WebSocket-Extensions" not in ws.response.headers
        ws.send(json.dumps({"type": "ready"}))
        assert json.loads(ws.recv(timeout=30))["type"] == "hello"


@pytest.mark.parametrize(
    "path",
    ["/static/../server.py", "/static/%2e%2e/server.py", "/static/..%2f..%2fcli.py",
     "/static//etc/passwd", "/static/%2fetc%2fpasswd"],
)  # fmt: skip
def test_raw_paths_never_leave_the_static_folder(path):
    """Sent byte for byte (http.client does not normalise ``..`` as httpx does)."""
    import http.client
    from urllib.parse import urlsplit

    app = create_app(lambda: ViewerSession(preset("gas", n=5)))
    with running(app) as url:
        address = urlsplit(url)
        connection = http.client.HTTPConnection(address.hostname, address.port, timeout=10)
        connection.request("GET", path)
        response = connection.getresponse()
        body = response.read()
    assert response.status in (400, 404)
    assert b"import" not in body and b"root:" not in body
