"""The sculpting server: starlette routes over a :class:`~.session.Session`, run by uvicorn.

Routes (JSON in and out; every error is ``{"error": message}`` with a 4xx status, and the
page shows it):

- ``GET /``: the page, with the current modal basis inside (it keeps working offline);
- ``GET /api/basis``: the current modal data (after a re-solve);
- ``GET /api/page``: the page for the current basis without the session token, to be kept
  as a file ("Save offline page");
- ``GET /api/status``: progress of a re-solve ``{busy, stage, elapsed, error, version}``;
- ``POST /api/resolve``: ``{material, boundary, free_region | free_points |
  faces_free_points}`` → new modes,
  answered with the new data and ``carry``, the map of the old modal state onto the new
  modes (:mod:`.carry`);
- ``POST /api/correction``: ``{version, index}`` → the static correction column of a sample;
- ``POST /api/save``: ``{version, t_end, pushes}`` → the scenario written to the save path;
- ``POST /api/export``: ``{version, q, format}`` → the shape of modal state ``q`` as a
  ``.3dm``, OBJ or net JSON file (:mod:`.shape_files`);
- ``POST /api/load``: the bytes of a ``.3dm``, net or scenario file (its name in the
  header ``X-Sculpt-File-Name``, at most 16 MiB) → a new surface, answered like a
  re-solve without ``carry`` (:mod:`.upload`);
- ``POST /api/bake``: ``{version, q}`` → the shape of modal state ``q`` becomes the rest
  shape, modes solved again (answered like a re-solve, with ``baked: true``); a pin adds
  the new free set, ``free_points`` (one surface) or ``faces_free_points`` (a body);
- ``POST /api/undo``, ``POST /api/redo``: ``{version}`` → back to the basis before, or
  forward again (:mod:`.history`), answered ``{version}``.

The server binds to 127.0.0.1 unless told otherwise; it never reads or writes a file named
by a message (the save path is fixed when it starts). Every request passes the
:class:`~.guard.Guard` first: addressed to the bound address (``Host``), from the server's
own origin (``Origin``), and, for ``/api/``, with the session token the served page carries.
"""

from __future__ import annotations

import json
import socket
import sys
from collections.abc import Awaitable, Callable
from pydantic import BaseModel, ValidationError
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import ClientDisconnect, Request
from starlette.responses import HTMLResponse, JSONResponse, Response
from starlette.routing import Route

from ..errors import InputError
from .export import _b64
from .guard import ASGIApp, Guard, guarded
from .messages import (MAX_BODY, BakeMessage, CorrectionMessage, ExportMessage,
                       HistoryMessage, ResolveMessage, SaveMessage, describe_error)
from .page import sculpt_page
from .session import Busy, Session


def _error(message: str, status: int = 400) -> JSONResponse:
    return JSONResponse({"error": message}, status_code=status)


async def _message(request: Request, model: type[BaseModel]) -> BaseModel | JSONResponse:
    """The body validated as ``model``, or the error response saying what is wrong."""
    declared = request.headers.get("content-length")
    if declared is not None and (not declared.isdigit() or int(declared) > MAX_BODY):
        return _error(f"message too large (at most {MAX_BODY} bytes)", 413)
    body = b""
    async for chunk in request.stream():
        body += chunk
        if len(body) > MAX_BODY:
            return _error(f"message too large (at most {MAX_BODY} bytes)", 413)
    try:
        data = json.loads(body)
    except (ValueError, RecursionError):
        return _error("the message is not JSON")
    if not isinstance(data, dict):
        return _error("the message must be a JSON object")
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        return _error(f"invalid message: {describe_error(exc)}", 422)


Handler = Callable[[Request], Awaitable[Response]]


def _guarded(handler: Handler) -> Handler:
    """Input errors become 400 answers, anything else a 500 answer; the server keeps running."""
    async def guarded(request: Request) -> Response:
        try:
            return await handler(request)
        except Busy as exc:
            return _error(str(exc), 409)
        except InputError as exc:
            return _error(str(exc))
        except ClientDisconnect:      # the page went away mid-upload: no error of ours
            print(f"sculpt: {request.url.path}: the page disconnected before its message "
                  "arrived; nothing done", file=sys.stderr)
            return _error("disconnected before the message arrived", 400)
        except Exception as exc:  # noqa: BLE001  (never let one message stop the server)
            print(f"sculpt: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
            return _error(f"internal error: {type(exc).__name__}: {exc}", 500)
    return guarded


def create_app(session: Session, guard: Guard) -> ASGIApp:
    """The starlette application serving ``session``, behind ``guard``."""

    async def page(request: Request) -> Response:
        # the page as served keeps working when saved: it carries what the static
        # correction needs (the API answers do not: a page online asks the server)
        data = await run_in_threadpool(session.page_payload)
        html = await run_in_threadpool(sculpt_page, data, guard.token)
        return HTMLResponse(html, headers={"Cache-Control": "no-store"})

    async def offline_page(request: Request) -> Response:
        # "Save offline page": the page for the current basis, carrying what a page on its
        # own needs, without the session token
        data = await run_in_threadpool(session.page_payload)
        html = await run_in_threadpool(sculpt_page, data, "")
        return HTMLResponse(html, headers={"Cache-Control": "no-store"})

    async def basis(request: Request) -> Response:
        return JSONResponse(await run_in_threadpool(session.payload))

    async def status(request: Request) -> Response:
        return JSONResponse({**session.progress, "version": session.version})

    async def resolve(request: Request) -> Response:
        message = await _message(request, ResolveMessage)
        if isinstance(message, JSONResponse):
            return message
        await run_in_threadpool(session.resolve, message)
        data = await run_in_threadpool(session.payload)
        return JSONResponse({**data, "carry": session.transfer_payload()})

    async def bake(request: Request) -> Response:
        message = await _message(request, BakeMessage)
        if isinstance(message, JSONResponse):
            return message
        await run_in_threadpool(session.bake, message)
        data = await run_in_threadpool(session.payload)
        return JSONResponse({**data, "carry": session.transfer_payload(), "baked": True})

    def history(step: str) -> Handler:
        async def switch(request: Request) -> Response:
            message = await _message(request, HistoryMessage)
            if isinstance(message, JSONResponse):
                return message
            assert isinstance(message, HistoryMessage)
            await run_in_threadpool(getattr(session, step), message.version)
            return JSONResponse({"version": session.version})
        return switch

    async def correction(request: Request) -> Response:
        message = await _message(request, CorrectionMessage)
        if isinstance(message, JSONResponse):
            return message
        assert isinstance(message, CorrectionMessage)
        column = await run_in_threadpool(session.correction_column, message.version,
                                         message.index)
        return JSONResponse({"version": message.version, "index": message.index,
                             "column": _b64(column)})

    async def save(request: Request) -> Response:
        message = await _message(request, SaveMessage)
        if isinstance(message, JSONResponse):
            return message
        assert isinstance(message, SaveMessage)
        if not message.pushes:
            raise InputError("nothing to save yet: push the surface first")
        path, text = await run_in_threadpool(session.save, message)
        loads = text.splitlines().count("[[load]]")       # table headers: lines of their own
        print(f"sculpt: saved {len(message.pushes)} force steps as {loads} loads to {path}",
              file=sys.stderr)
        return JSONResponse({"path": str(path), "loads": loads, "steps": len(message.pushes)})

    async def export(request: Request) -> Response:
        message = await _message(request, ExportMessage)
        if isinstance(message, JSONResponse):
            return message
        assert isinstance(message, ExportMessage)
        content, name, media = await run_in_threadpool(session.export, message)
        return Response(content, media_type=media,
                        headers={"Content-Disposition": f'attachment; filename="{name}"',
                                 "Cache-Control": "no-store"})

    async def load(request: Request) -> Response:
        from urllib.parse import unquote

        from .upload import MAX_UPLOAD, loadable

        name = unquote(request.headers.get("x-sculpt-file-name", ""))
        if not name or "/" in name or "\\" in name or len(name) > 255:
            return _error("a loaded file needs its name (header X-Sculpt-File-Name, no folders)")
        loadable(name)
        declared = request.headers.get("content-length")
        if declared is not None and (not declared.isdigit() or int(declared) > MAX_UPLOAD):
            return _error(f"{name}: too large (at most {MAX_UPLOAD} bytes)", 413)
        body = b""
        async for chunk in request.stream():
            body += chunk
            if len(body) > MAX_UPLOAD:
                return _error(f"{name}: too large (at most {MAX_UPLOAD} bytes)", 413)
        await run_in_threadpool(session.load, name, body)
        data = await run_in_threadpool(session.page_payload)
        data.pop("offline", None)
        return JSONResponse({**data, "loaded": name})

    async def no_icon(request: Request) -> Response:
        return Response(status_code=204)

    routes = [Route("/", _guarded(page)), Route("/favicon.ico", no_icon), Route("/api/basis", _guarded(basis)),
              Route("/api/page", _guarded(offline_page)),
              Route("/api/status", _guarded(status)),
              Route("/api/resolve", _guarded(resolve), methods=["POST"]),
              Route("/api/correction", _guarded(correction), methods=["POST"]),
              Route("/api/save", _guarded(save), methods=["POST"]),
              Route("/api/export", _guarded(export), methods=["POST"]),
              Route("/api/load", _guarded(load), methods=["POST"]),
              Route("/api/bake", _guarded(bake), methods=["POST"]),
              Route("/api/undo", _guarded(history("undo")), methods=["POST"]),
              Route("/api/redo", _guarded(history("redo")), methods=["POST"])]
    return guarded(Starlette(routes=routes), guard)


def bind(host: str, port: int) -> socket.socket:
    """A listening socket on ``host:port`` (port 0: a free port chosen by the system)."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as exc:
        raise InputError(f"--host {host!r} is not an address of this machine ({exc})") from None
    family, _, _, _, address = infos[0]
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(address)
    except OSError as exc:
        sock.close()
        raise InputError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    sock.listen(64)
    return sock


def serve(session: Session, sock: socket.socket, quiet: bool = False,
          names: tuple[str, ...] = ()) -> None:
    """Serve until Ctrl-C (uvicorn handles SIGINT/SIGTERM and shuts down cleanly).

    Requests must address the socket's address and port (or ``names``, e.g. the
    ``--host`` name it was bound by) and carry the token of the page served.
    """
    import uvicorn

    host, port = sock.getsockname()[:2]
    guard = Guard.for_address(host, port, also=names)
    config = uvicorn.Config(create_app(session, guard), log_level="warning" if not quiet else "error",
                            access_log=False, lifespan="off")
    uvicorn.Server(config).run(sockets=[sock])


def url_of(sock: socket.socket) -> str:
    host, port = sock.getsockname()[:2]
    shown = f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}/"

