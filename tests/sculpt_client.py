"""A sculpting session on a small clamped sheet, served to starlette's TestClient as the
page would call it (its own Origin and the session token): shared by the server tests."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

pytest.importorskip("starlette", reason="the sculpt server needs the extra 'sculpt'")
pytest.importorskip("httpx", reason="starlette's TestClient needs httpx")
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    from starlette.testclient import TestClient  # noqa: E402

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt.guard import TOKEN_HEADER, Guard  # noqa: E402
from splinedeform.sculpt.server import create_app  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402

SHEET = """
[surface]
shape = "plane"
cells = 3
[material]
damping = 1.0
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
"""
ORIGIN = "http://127.0.0.1:8765"
TOKEN = "t"


def serve_sheet(folder: Path, text: str = SHEET, resolution: int = 5):
    """``(client, session)``: ``text`` served from ``folder``, saving to ``saved.toml``."""
    session = Session(parse_scenario(text, source="sheet.toml", directory=folder),
                      resolution=resolution, modes=None, save_path=folder / "saved.toml")
    app = create_app(session, Guard.for_address("127.0.0.1", 8765, TOKEN))
    client = TestClient(app, base_url=ORIGIN, raise_server_exceptions=False,
                        headers={"Origin": ORIGIN, TOKEN_HEADER: TOKEN})
    return client, session
