"""``splinedeform sculpt [SCENARIO.toml]``: solve the modes, serve the page, stop on Ctrl-C."""

from __future__ import annotations

import sys
import webbrowser
from pathlib import Path
from typing import Any, Optional

import typer

from ..errors import InputError

DEFAULT_MODES = 200
DEFAULT_RESOLUTION = 64


def sculpt_scenario(path: Path | None, allow_outside_paths: bool = False) -> Any:
    """The scenario to sculpt: a file, or the built-in sheet (``data/sculpt_demo.toml``)."""
    from importlib import resources

    from ..scenario import load_scenario, parse_scenario

    if path is not None:
        return load_scenario(path, allow_outside_paths=allow_outside_paths)
    text = resources.files("splinedeform").joinpath("data/sculpt_demo.toml").read_text("utf-8")
    return parse_scenario(text, source="sculpt_demo.toml")


def start(scenario: Any, host: str, port: int, browser: bool, resolution: int,
          modes: int | None, save: Path | None, quiet: bool) -> None:
    """Solve, bind, print the address (stdout), open the browser, serve until Ctrl-C."""
    try:
        from .server import bind, serve, url_of
    except ImportError as exc:
        raise InputError(f"sculpt needs the extra 'sculpt' (starlette, uvicorn): pip install "
                         f"'splinedeform[sculpt]' ({exc})") from None
    from .session import Session

    if resolution < 2 or resolution > 400:
        raise InputError(f"--resolution must be between 2 and 400, got {resolution}")
    if modes is not None and modes < 1:
        raise InputError(f"--modes must be >= 1, got {modes}")
    if not (0 <= port <= 65535):
        raise InputError(f"--port must be between 0 and 65535, got {port}")
    say = (lambda text: None) if quiet else (lambda text: print(text, file=sys.stderr, flush=True))
    say(f"sculpt: solving the modes of {scenario.title or scenario.name} ...")
    session = Session(scenario, resolution=resolution, modes=modes, save_path=save)
    basis = session.basis
    grid = f"{resolution}x{resolution}"
    faces = f"{len(basis.samples)} faces of {grid}" if basis.is_body else grid
    say(f"sculpt: {basis.lam.size} of {basis.model.n_free} modes on {faces} "
        f"samples in {session.timing:.2f} s; Save writes {session.save_path.resolve()}")
    sock = bind(host, port)
    url = url_of(sock)
    if host not in ("127.0.0.1", "localhost", "::1"):
        say(f"sculpt: warning: listening on {host}: other machines can reach this page")
    print(f"sculpt: serving {url}  (Ctrl-C stops)", flush=True)
    if browser:
        webbrowser.open(url)
    try:
        serve(session, sock, quiet, names=(host,))
    except KeyboardInterrupt:
        pass
    finally:
        sock.close()
    say("sculpt: stopped")


def register(app: typer.Typer) -> None:
    """Add the ``sculpt`` command to the command line ``app``."""
    from ..cli import DEBUG_OPT, OUTSIDE_OPT, QUIET_OPT, _reported_errors

    @app.command("sculpt")
    def sculpt_command(
            scenario: Optional[Path] = typer.Argument(
                None, help="Scenario file (TOML) giving surface, material and boundary; "
                           "its loads are not used. [default: a built-in square sheet]",
                show_default=False),
            host: str = typer.Option("127.0.0.1", "--host", help="Address to listen on."),
            port: int = typer.Option(0, "--port", help="Port (0: a free one)."),
            no_browser: bool = typer.Option(False, "--no-browser",
                                            help="Do not open the page in a browser."),
            resolution: int = typer.Option(DEFAULT_RESOLUTION, "--resolution",
                                           help="Surface samples per direction."),
            modes: int = typer.Option(DEFAULT_MODES, "--modes",
                                      help="Modes kept (the others enter statically)."),
            save: Optional[Path] = typer.Option(
                None, "--save", help="File that 'Save' writes. [default: "
                                     "<scenario name>-sculpt.toml]"),
            allow_outside_paths: bool = OUTSIDE_OPT,
            quiet: bool = QUIET_OPT, debug: bool = DEBUG_OPT) -> None:
        """Sculpt a surface in the browser: grab, pull, release and watch it ring down."""
        with _reported_errors(debug):
            start(sculpt_scenario(scenario, allow_outside_paths), host, port, not no_browser,
                  resolution, modes, save, quiet)
