"""viewer.html: one offline page (inlined three.js) to orbit, zoom and play the motion."""

from __future__ import annotations

import base64
import hashlib
import html
import json
import os
import re
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..export import check_frames, check_net, tessellate_frames, write_text
from ..surface import Surface
from .colour import COLORMAP, colormap_table


def _b64(array: ArrayLike, dtype: str) -> str:
    """Little-endian bytes of ``array`` as base64 text."""
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def vertex_checksum(vertices: ArrayLike) -> float:
    """The viewer's checksum of a vertex array: ``Σ_k (1 + k mod 7) x_k`` over float32 values.

    ``x_k`` runs over the flattened ``(N, 3)`` positions after rounding to float32, as the
    browser draws them; the weights make it sensitive to reordering.
    """
    x = np.asarray(vertices, dtype=np.float32).ravel().astype(np.float64)
    return float(np.sum((1 + np.arange(x.size) % 7) * x))


def viewer_data(surface: Surface, rest_net: ArrayLike, times: ArrayLike, nets: ArrayLike,
                resolution: int = 32, title: str | None = None,
                modes: tuple[ArrayLike, ArrayLike] | None = None) -> dict[str, Any]:
    """The JSON document the viewer reads: meshes of every frame, control nets, colours.

    ``frames`` holds float32 vertex positions ``(F, N, 3)`` and ``nets`` the control
    nets ``(F, n_u, n_v, 3)`` as base64; ``rest`` the rest mesh for ``|d|``; ``title``
    (default: the surface's name) heads the page. The page opens at ``startFrame``, the
    frame of largest displacement ``argmax_f max |x_f - x_rest|`` over the tessellation
    (the first such), as ``surfaces.png`` shows it. ``modes = (ω, D)`` (a modes solve:
    ``D (K, n_u, n_v, 3)`` the modes as net displacements) adds the menu of every mode
    (:func:`mode_menu`).
    """
    t, P = check_frames(surface, times, nets)
    rest = check_net(surface, rest_net, "rest net")
    X, faces = tessellate_frames(surface, P, resolution)
    X0, _ = tessellate_frames(surface, rest, resolution)
    largest = np.linalg.norm(X - X0, axis=-1).max(axis=-1)
    vmax = float(largest.max())
    menu = {} if modes is None else {"modes": mode_menu(
        modes[0], t, tessellate_frames(surface, _mode_nets(surface, modes[1]), resolution)[0],
        np.asarray(modes[1], dtype=float).reshape(len(modes[1]), -1, 3), rest.reshape(-1, 3),
        X0)}
    return {**menu, "name": surface.name, "title": surface.name if title is None else str(title),
            "times": t.tolist(), "startFrame": int(np.argmax(largest)),
            "vertexCount": int(X.shape[1]),
            "frames": _b64(X, "<f4"), "rest": _b64(X0, "<f4"), "faces": _b64(faces, "<u4"),
            "faceCount": int(faces.shape[0]), "netShape": list(surface.shape),
            "periodic": [surface.basis_u.periodic, surface.basis_v.periodic],
            "nets": _b64(P, "<f4"), "vmax": vmax, "colormap": colormap_table(),
            "colormapName": COLORMAP}


def _mode_nets(surface: Surface, mode_nets: ArrayLike) -> NDArray[np.float64]:
    D = np.asarray(mode_nets, dtype=float)
    if D.ndim != 4 or D.shape[0] == 0 or D.shape[1:] != (*surface.shape, 3):
        raise InputError(f"mode nets must be an array (K, {surface.shape[0]}, "
                         f"{surface.shape[1]}, 3) with K >= 1, got shape {D.shape}")
    return D


def mode_menu(omegas: ArrayLike, phases: ArrayLike, fields: ArrayLike, net_fields: ArrayLike,
              net_rest: ArrayLike, rest: ArrayLike) -> dict[str, Any]:
    """The viewer's menu of the modes of a modes solve.

    Mode ``k`` is drawn at frame ``f`` as ``x_rest + sin(2π φ_f) d_k`` (the drawn points)
    and ``P_rest + sin(2π φ_f) D_k`` (the control net), as the run's frames draw mode 1:
    ``fields (K, N, 3)`` holds ``d_k`` at the mesh's points, ``net_fields (K, NN, 3)``
    ``D_k`` at the net's points, ``net_rest (NN, 3)`` and ``rest (N, 3)`` the rest
    positions, ``phases`` the frames' ``φ_f``. The page computes each mode's frames when
    it is chosen (``setMode(k)``), so the file holds ``K`` fields instead of ``K F``
    frames.
    """
    w = np.asarray(omegas, dtype=float)
    d, D = np.asarray(fields, dtype=float), np.asarray(net_fields, dtype=float)
    X0, P0 = np.asarray(rest, dtype=float), np.asarray(net_rest, dtype=float)
    if w.ndim != 1 or d.shape != (w.size, *X0.shape) or D.shape != (w.size, *P0.shape) \
            or not all(np.all(np.isfinite(a)) for a in (w, d, D)):
        raise InputError(f"the viewer's modes need finite ω (K,) and fields (K, {len(X0)}, 3) "
                         f"and (K, {len(P0)}, 3); got {w.shape}, {d.shape} and {D.shape}")
    return {"omegas": w.tolist(),
            "amplitude": np.sin(2.0 * np.pi * np.asarray(phases, dtype=float)).tolist(),
            "fields": _b64(d, "<f4"), "netFields": _b64(D, "<f4"), "netRest": _b64(P0, "<f4")}


def _vendor_text(name: str) -> str:
    try:
        return resources.files("splinedeform").joinpath("data", "vendor", name).read_text(
            encoding="utf-8")
    except (FileNotFoundError, OSError) as exc:   # a broken installation, not user input
        raise RuntimeError(f"splinedeform's packaged viewer file {name} is missing: {exc}") \
            from exc


def viewer_html(data: Mapping[str, Any]) -> str:
    """The self-contained page: template + inlined three.js + the JSON data."""
    template = resources.files("splinedeform").joinpath("data", "viewer_template.html") \
        .read_text(encoding="utf-8")
    three = _vendor_text("three-orbit.min.js")
    if "</script" in three.lower():
        raise RuntimeError("the vendored three.js contains '</script' and cannot be inlined")
    fills = {"__SPLINEDEFORM_TITLE__": html.escape(str(data.get("title", data["name"]))),
             "/*__SPLINEDEFORM_THREE__*/": three,
             "__SPLINEDEFORM_DATA__": script_json(data),
             "__SPLINEDEFORM_CSP__": content_security_policy(template, three)}
    # One pass: text put in by one placeholder is never searched for another.
    pattern = re.compile("|".join(re.escape(key) for key in fills))
    return pattern.sub(lambda match: fills[match.group(0)], template)


def content_security_policy(template: str, three: str) -> str:
    """The page's Content-Security-Policy: nothing but its own inline scripts and style.

    ``default-src 'none'`` forbids every fetch (no network, no images but ``data:``, no
    frames, no plugins); scripts and the style sheet run only when their text hashes to a
    listed SHA-256 (three.js and the viewer's own script, as inlined; the JSON data block is
    not a script). A script smuggled into the page by a name or title would not run.
    """
    scripts = [three] + [body for attrs, body in
                         re.findall(r"<script([^>]*)>(.*?)</script>", template, re.S)
                         if not attrs.strip() and "__SPLINEDEFORM_" not in body]
    styles = re.findall(r"<style>(.*?)</style>", template, re.S)

    def hashes(blocks: list[str]) -> str:
        return " ".join("'sha256-" + base64.b64encode(hashlib.sha256(b.encode("utf-8"))
                                                      .digest()).decode("ascii") + "'"
                        for b in blocks)
    return (f"default-src 'none'; script-src {hashes(scripts)}; style-src {hashes(styles)}; "
            "img-src data:; base-uri 'none'; form-action 'none'")


def script_json(data: Any) -> str:
    """JSON safe inside ``<script>``: ``<``, ``>``, ``&``, U+2028 and U+2029 as ``\\uXXXX``."""
    text = json.dumps(data, separators=(",", ":"))
    for char in ("<", ">", "&", "\u2028", "\u2029"):
        text = text.replace(char, f"\\u{ord(char):04x}")
    return text


def write_viewer(path: str | os.PathLike[str], surface: Surface, rest_net: ArrayLike,
                 times: ArrayLike, nets: ArrayLike, resolution: int = 32,
                 title: str | None = None,
                 modes: tuple[ArrayLike, ArrayLike] | None = None) -> Path:
    """Write ``viewer.html``: one offline page to orbit, zoom and play the motion.

    three.js (r187, MIT, vendored) is inlined; frames are float32 base64. The page
    exposes ``window.splinedeformViewer`` with ``setFrame(i)``, ``frameCount``,
    ``currentFrame``, ``play()``, ``pause()`` and ``vertexChecksum()`` (see
    :func:`vertex_checksum`), and for ``modes`` (:func:`viewer_data`) ``modeCount``,
    ``currentMode``, ``setMode(k)`` and ``faceMotion()`` (the largest drawn ``|x - x_rest|``
    on each face). ``title`` (e.g. the scenario's title) heads the page.
    """
    target = Path(path)
    if target.suffix.lower() not in (".html", ".htm"):
        raise InputError(f"the viewer is an .html file, got {target.name!r}")
    return write_text(target, viewer_html(viewer_data(surface, rest_net, times, nets,
                                                      resolution, title, modes)))
