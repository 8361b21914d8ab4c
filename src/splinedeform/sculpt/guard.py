"""Who may talk to the sculpting server: its own page, on its own address, and no one else.

The server listens on the loopback address by default, but a page of any web site open in
the same browser can still send it requests: a cross-site ``POST`` (a "simple" request,
``text/plain``, sent without asking) would overwrite the save file, and a name of the
attacker's domain rebound to 127.0.0.1 (DNS rebinding) would let that site read the
answers. Three checks, on every request, refuse both:

- ``Host`` must name the address the server is bound to (with its port): a rebound
  domain name arrives with the attacker's name in ``Host``;
- ``Origin``, when present, must be the server's own origin, and a ``POST`` must carry it
  (every browser sends ``Origin`` on a ``POST``, also a same-origin one);
- every ``/api/`` request must carry :data:`TOKEN_HEADER` with the session's random token,
  which only the served page knows (it is written into the page; another origin can
  neither read the page nor send a custom header without a CORS preflight, which the
  server never grants).

Refusals are answered ``{"error": ...}``: 400 for a foreign ``Host``, 403 otherwise.
"""

from __future__ import annotations

import hmac
import ipaddress
import json
import secrets
import socket
from collections.abc import Awaitable, Callable, Iterable, MutableMapping
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import urlsplit

TOKEN_HEADER = "X-Sculpt-Token"
"""The request header that carries the session token."""

Scope = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[MutableMapping[str, Any]]]
Send = Callable[[MutableMapping[str, Any]], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]


def new_token() -> str:
    """A fresh session token: 32 random bytes, URL-safe base64 (43 characters)."""
    return secrets.token_urlsafe(32)


def _split_host(value: str) -> tuple[str, int | None] | None:
    """``(name, port)`` of a ``Host`` header (``name``, ``name:port``, ``[v6]:port``),
    the name lower-cased; None when it is not of that form."""
    value = value.strip().lower()
    if value.startswith("["):
        name, sep, rest = value[1:].partition("]")
        if not sep or (rest and not rest.startswith(":")):
            return None
        port_text = rest[1:] if rest else None
    else:
        name, sep, port_text = value.rpartition(":") if ":" in value else (value, "", None)
        if sep and ":" in name:
            return None          # a bare IPv6 address without brackets
    if not name:
        return None
    if port_text is None:
        return name, None
    if not port_text.isdigit() or len(port_text) > 5:
        return None
    return name, int(port_text)


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class Guard:
    """The accepted ``Host`` names and port, and the session token.

    Parameters
    ----------
    names : frozenset of str
        Host names (lower case; IPv6 without brackets) a request may address.
    port : int
        The port the server listens on (a ``Host`` without a port means 80).
    token : str
        The session token every ``/api/`` request must carry.
    any_address : bool
        Bound to every interface (``0.0.0.0``/``::``): any IP literal is a valid name too
        (a DNS rebinding needs a domain name, never an address).
    """

    names: frozenset[str]
    port: int
    token: str = field(repr=False)
    any_address: bool = False

    @classmethod
    def for_address(cls, host: str, port: int, token: str | None = None,
                    also: Iterable[str] = ()) -> "Guard":
        """The guard of a server bound to ``host:port`` (``also``: other names the user gave).

        A loopback address also answers to ``localhost``; a wildcard address to this
        machine's name and any IP literal.
        """
        host = host.strip("[]").lower()
        names = {host, *(n.strip("[]").lower() for n in also)}
        wildcard = host in ("0.0.0.0", "::", "")
        try:
            loopback = ipaddress.ip_address(host).is_loopback
        except ValueError:
            loopback = host == "localhost"
        if loopback or wildcard:
            names.add("localhost")
        if wildcard:
            names |= {socket.gethostname().lower(), socket.getfqdn().lower()}
        names.discard("")
        return cls(frozenset(names), int(port), token or new_token(), wildcard)

    def host_ok(self, value: str | None) -> bool:
        """Whether a ``Host`` header names this server."""
        parts = None if value is None else _split_host(value)
        if parts is None:
            return False
        name, port = parts
        if (port if port is not None else 80) != self.port:
            return False
        return name in self.names or (self.any_address and _is_ip(name))

    def origin_ok(self, origin: str, host: str) -> bool:
        """Whether ``Origin`` is the server's own origin, ``http://`` + the (valid) ``Host``."""
        try:
            parts = urlsplit(origin.strip())
            port = parts.port
        except ValueError:
            return False
        if parts.scheme != "http" or parts.path or parts.query or parts.username:
            return False
        mine = _split_host(host)
        name = (parts.hostname or "").lower()
        return mine is not None and name == mine[0] and (port or 80) == (mine[1] or 80)

    def token_ok(self, value: str | None) -> bool:
        """Whether a request's token is the session's (compared in constant time)."""
        return value is not None and hmac.compare_digest(value.encode(), self.token.encode())

    def refusal(self, method: str, path: str, headers: dict[str, str]) -> tuple[int, str] | None:
        """``(status, message)`` for a request to refuse, None for one to serve."""
        host = headers.get("host")
        if not self.host_ok(host):
            return 400, ("this server answers only requests addressed to it by the address it "
                         "listens on (the Host header names another site)")
        origin = headers.get("origin")
        if origin is not None and not self.origin_ok(origin, host or ""):
            return 403, "requests from other web sites are refused (foreign Origin)"
        if method not in ("GET", "HEAD") and origin is None:
            return 403, "a request that changes the session must come from the sculpting page " \
                        "(no Origin header)"
        if path.startswith("/api/") and not self.token_ok(headers.get(TOKEN_HEADER.lower())):
            return 403, (f"missing or wrong {TOKEN_HEADER}: only the page served by this "
                         "session may use its API (reload the page)")
        return None


def guarded(app: ASGIApp, guard: Guard) -> ASGIApp:
    """``app`` behind ``guard``: every HTTP request is checked before ``app`` sees it."""

    async def checked(scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await app(scope, receive, send)
            return
        headers: dict[str, str] = {}
        for key, value in scope.get("headers", []):
            name = key.decode("latin-1").lower()
            if name in headers:          # a repeated Host, Origin or token is never accepted
                headers[name] = "\x00"
            else:
                headers[name] = value.decode("latin-1")
        refused = guard.refusal(scope.get("method", "GET"), scope.get("path", ""), headers)
        if refused is None:
            await app(scope, receive, send)
            return
        status, message = refused
        body = json.dumps({"error": message}).encode()
        await send({"type": "http.response.start", "status": status,
                    "headers": [(b"content-type", b"application/json"),
                                (b"content-length", str(len(body)).encode()),
                                (b"cache-control", b"no-store")]})
        await send({"type": "http.response.body", "body": body})

    return checked
