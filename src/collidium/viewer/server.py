"""The viewer's web server: the page, its static files, and one websocket per open page.

`create_app` builds the starlette application; `serve` runs it with uvicorn for
``collidium view``; `running` runs it on a background thread (tests, benchmarks). Each websocket
gets its own `ViewerSession`; a `Connection` decides what it is sent.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import json
import socket
import threading
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

import anyio.to_thread
from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.requests import Request
from starlette.responses import FileResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from collidium.errors import InputError
from collidium.viewer import protocol
from collidium.viewer.connection import Connection, Outgoing
from collidium.viewer.session import ViewerSession

if TYPE_CHECKING:
    import uvicorn

#: The page and the bundled front end (built from frontend/ when the package is built).
STATIC = Path(__file__).parent / "static"
#: Wall-clock seconds between ticks of a connection (at most 60 frames per second).
TICK = 1 / 60
#: Pages open at once; a further one is refused (each runs its own simulation).
MAX_CONNECTIONS = 4
#: Addresses that reach this machine only.
LOOPBACK = ("127.0.0.1", "localhost", "::1")
#: Host names a page may use to reach a server listening on this machine only (checked on every
#: request: a site that rebinds its own name to 127.0.0.1 is refused).
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "::1", "[::1]")


def check_built(static: Path = STATIC) -> None:
    """Refuse to start without the bundled front end.

    Raises
    ------
    InputError
        If the bundle is missing (a source tree in which ``npm run build`` has not run).
    """
    for name in ("index.html", "app.js", "widget.js"):
        if not (static / name).is_file():
            raise InputError(
                "viewer",
                f"the front end is not built ({name} missing); reinstall with "
                "`pip install .` from a clone, which needs Node.js and npm",
            )


def create_app(
    make_session: Callable[[], ViewerSession],
    static: Path = STATIC,
    hosts: Sequence[str] = LOOPBACK_HOSTS,
) -> Starlette:
    """The viewer's application.

    Parameters
    ----------
    make_session : callable
        Builds the session of a newly opened page.
    static : Path
        Folder of ``index.html`` and the bundle; nothing outside it is served.
    hosts : sequence of str
        Host names requests may be addressed to (``"*"``: any, for a server open to a network).
    """
    open_pages = 0

    async def index(request: Request) -> Response:
        return FileResponse(static / "index.html")

    async def websocket(ws: WebSocket) -> None:
        nonlocal open_pages
        if not _same_origin(ws):
            await ws.close(code=1008)
            return
        await ws.accept()
        if open_pages >= MAX_CONNECTIONS:
            reason = f"{MAX_CONNECTIONS} pages are open already; close one"
            await ws.send_text(json.dumps({"type": "error", "field": "connection",
                                           "reason": reason}))  # fmt: skip
            await ws.close(code=1013)
            return
        open_pages += 1
        try:
            session = await anyio.to_thread.run_sync(make_session)
            await _converse(ws, Connection(session))
        finally:
            open_pages -= 1

    return Starlette(
        routes=[
            Route("/", index),
            WebSocketRoute("/ws", websocket),
            Mount("/static", StaticFiles(directory=static)),
        ],
        middleware=[Middleware(TrustedHostMiddleware, allowed_hosts=list(hosts))],
    )


def _same_origin(ws: WebSocket) -> bool:
    """Whether the page that opened the socket came from this server (a page from another site
    open in the same browser must not drive the simulation)."""
    origin = ws.headers.get("origin")
    if origin is None:  # not a browser: a script on this machine
        return True
    return urlsplit(origin).netloc == ws.headers.get("host")


async def _converse(ws: WebSocket, connection: Connection) -> None:
    """Receive messages and tick the connection until the page closes."""
    lock = asyncio.Lock()  # one of receive/tick at a time, and their sends in order

    async def run(work: Callable[[], list[Outgoing]]) -> None:
        async with lock:
            for item in await anyio.to_thread.run_sync(work):
                if isinstance(item, bytes):
                    await ws.send_bytes(item)
                else:
                    await ws.send_text(json.dumps(item, allow_nan=False))

    async def pump() -> None:
        loop = asyncio.get_running_loop()
        while True:
            started = loop.time()
            await run(connection.tick)
            await asyncio.sleep(max(0.0, TICK - (loop.time() - started)))

    ticking = asyncio.create_task(pump())
    try:
        while not ticking.done():
            message = await ws.receive()
            if message["type"] == "websocket.disconnect":
                break
            data = message.get("text")
            data = message.get("bytes", b"") if data is None else data
            await run(functools.partial(connection.receive, data))
    except WebSocketDisconnect:
        pass
    finally:
        ticking.cancel()
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await ticking  # a send to a page that has gone ends it too


def bind(host: str, port: int) -> socket.socket:
    """A listening socket, or one clear error (address in use, unknown host).

    Raises
    ------
    InputError
        Naming ``--port`` or ``--host``.
    """
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as exc:
        raise InputError("--host", f"cannot resolve {host!r}: {exc.strerror}") from None
    family, kind, _, _, address = infos[0]
    sock = socket.socket(family, kind)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(address)
    except OSError as exc:
        sock.close()
        raise InputError("--port", f"cannot listen on {host}:{port}: {exc.strerror}") from None
    sock.listen(16)
    return sock


def url_of(sock: socket.socket, host: str) -> str:
    """The page's address for a bound socket (this machine's, when it listens on all)."""
    port = sock.getsockname()[1]
    shown = {"0.0.0.0": "127.0.0.1", "::": "::1", "": "127.0.0.1"}.get(host, host)
    shown = f"[{shown}]" if ":" in shown else shown
    return f"http://{shown}:{port}/"


def _server(app: Starlette) -> uvicorn.Server:
    import uvicorn

    # uvicorn refuses larger websocket messages before they are read. Frames go uncompressed:
    # permessage-deflate took 84 ms a 1e5-disk frame (1.6 MB of floats, made 5% smaller), which
    # held the frame rate under 10 a second.
    limit = protocol.MAX_MESSAGE_BYTES + 1024
    config = uvicorn.Config(app, log_level="warning", ws_max_size=limit, lifespan="off",
                            ws_per_message_deflate=False)  # fmt: skip
    return uvicorn.Server(config)


def serve(app: Starlette, sock: socket.socket) -> None:
    """Run the application on ``sock`` until Ctrl+C (a clean stop, exit status 0)."""
    with contextlib.suppress(KeyboardInterrupt):  # uvicorn raises the signal again once stopped
        _server(app).run(sockets=[sock])


@contextlib.contextmanager
def running(app: Starlette, host: str = "127.0.0.1") -> Iterator[str]:
    """Serve ``app`` on a free port on a background thread; yields the page's address."""
    sock = bind(host, 0)
    server = _server(app)
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    try:
        while not server.started:
            if not thread.is_alive():
                raise RuntimeError("the viewer's server failed to start")
            threading.Event().wait(0.01)
        yield url_of(sock, host)
    finally:
        server.should_exit = True
        thread.join(timeout=10)
        sock.close()
