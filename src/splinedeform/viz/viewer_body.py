"""viewer.html of a body: every face in one page, welded across the shared edges.

The page is the one of a single surface (:func:`.viewer.viewer_html`, the same template and
inlined three.js); its mesh is the body's welded mesh (:func:`splinedeform.export.body.
welded_body`: each face sampled on its ``r × r`` grid, ``X_k = B_u P_k B_vᵀ``, the points
of a shared edge or a seam merged), so the faces are drawn as one connected surface, and
its control net is every face's net drawn face by face (``netFaces``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError
from ..export import write_text
from ..export.body import welded_motion
from ..surface import Surface
from .colour import COLORMAP, colormap_table
from .viewer import _b64, mode_menu, viewer_html


def body_viewer_data(surfaces: Sequence[Surface], rest_nets: Sequence[ArrayLike],
                     times: ArrayLike, nets: Sequence[ArrayLike], resolution: int = 32,
                     title: str = "body",
                     modes: tuple[ArrayLike, Sequence[ArrayLike]] | None = None
                     ) -> dict[str, Any]:
    """The viewer's JSON document (:func:`.viewer.viewer_data`) of a body.

    ``nets[k]`` holds the frames ``(F, n_u, n_v, 3)`` of face ``k`` at ``times``. The
    frames are the welded mesh's points (float32 ``(F, N, 3)``), ``faceOf`` the face each
    point was first sampled on, ``nets`` every face's net after the other per frame
    (``(F, Σ n_u n_v, 3)``) and ``netFaces`` the shape of each; the page opens at the frame
    of largest displacement ``argmax_f max |x_f - x_rest|`` over the welded points.
    ``modes = (ω, D)``, ``D[p] (K, n_u, n_v, 3)`` the modes of patch ``p`` as net
    displacements, adds the menu of every mode over every face (:func:`.viewer.mode_menu`;
    the points are welded where they coincide at rest, in every frame and in every mode).
    """
    K = 0 if modes is None else len(modes[0])
    D = [] if modes is None else [np.asarray(d, dtype=float) for d in modes[1]]
    if modes is not None and (len(D) != len(surfaces) or any(
            d.shape != (K, *s.shape, 3) for s, d in zip(surfaces, D))):
        raise InputError(f"the modes of a body of {len(surfaces)} patch(es) need one array "
                         f"(K, n_u, n_v, 3) per patch with K = {K}, got "
                         f"{[d.shape for d in D]}")
    extra = [np.asarray(r, dtype=float)[None] + d for r, d in zip(rest_nets, D)]
    t, X, faces, owner, _ = welded_motion(surfaces, rest_nets, times, nets, resolution,
                                          extra=extra)
    X0, X, fields = X[0], X[1:X.shape[0] - K], X[X.shape[0] - K:] - X[0]
    largest = np.linalg.norm(X - X0, axis=-1).max(axis=-1)
    frames = np.concatenate([np.reshape(P, (t.size, -1, 3)) for P in nets], axis=1)
    menu = {} if modes is None else {"modes": mode_menu(
        modes[0], t, fields,
        np.concatenate([d.reshape(K, -1, 3) for d in D], axis=1),
        np.concatenate([np.reshape(r, (-1, 3)) for r in rest_nets]), X0)}
    return {**menu, "name": title, "title": title, "times": t.tolist(),
            "startFrame": int(np.argmax(largest)), "vertexCount": int(X.shape[1]),
            "frames": _b64(X, "<f4"), "rest": _b64(X0, "<f4"), "faces": _b64(faces, "<u4"),
            "faceCount": int(faces.shape[0]), "faceOf": _b64(owner, "<u4"),
            "patchCount": len(surfaces), "netShape": [int(frames.shape[1]), 1],
            "periodic": [False, False],
            "netFaces": [{"net": list(s.shape), "periodic": [bool(s.basis_u.periodic),
                                                             bool(s.basis_v.periodic)]}
                         for s in surfaces],
            "nets": _b64(frames, "<f4"), "vmax": float(largest.max()),
            "colormap": colormap_table(), "colormapName": COLORMAP}


def write_body_viewer(path: str | os.PathLike[str], surfaces: Sequence[Surface],
                      rest_nets: Sequence[ArrayLike], times: ArrayLike,
                      nets: Sequence[ArrayLike], resolution: int = 32,
                      title: str = "body",
                      modes: tuple[ArrayLike, Sequence[ArrayLike]] | None = None) -> Path:
    """Write the ``viewer.html`` of a body (:func:`body_viewer_data`); the page's API is
    the single surface's (:func:`.viewer.write_viewer`)."""
    target = Path(path)
    if target.suffix.lower() not in (".html", ".htm"):
        raise InputError(f"the viewer is an .html file, got {target.name!r}")
    return write_text(target, viewer_html(body_viewer_data(surfaces, rest_nets, times, nets,
                                                           resolution, title, modes)))
