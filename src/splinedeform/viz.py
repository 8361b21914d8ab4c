"""Pictures, animations and the interactive HTML viewer of a deforming surface.

Colour encodes the displacement magnitude ``|d| = |x - x_rest|`` sampled on the
tessellation grid, mapped linearly to the perceptually uniform ``plasma`` colormap
(dark blue at ``|d| = 0``, bright yellow at the largest displacement shown), the same in
the PNGs, the animation and the viewer's legend.

matplotlib (Agg canvas, no pyplot state) draws everywhere. If PyVista is importable and
can render off screen, :func:`render_surfaces` uses it; otherwise, or if it fails for
any reason, matplotlib draws the same picture without a message.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import os
import re
from collections.abc import Callable, Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import InputError
from .export import check_frames, check_net, tessellate_frames, write_text, write_with
from .surface import Surface, grid_faces

COLORMAP = "plasma"
MODE_COLORMAP = "coolwarm"
DPI = 100
PANEL_INCHES = 4.0          # each surface panel is 400 × 400 px
COLORBAR_INCHES = 1.2
ANIMATION_PIXELS = (640, 480)  # divisible by 16 for video encoders
LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])

Progress = Callable[[int, int], object] | None


# -- colour -------------------------------------------------------------------------
def displacement_colors(magnitude: ArrayLike, vmax: float | None = None) -> NDArray[np.float64]:
    """RGBA colours of displacement magnitudes: ``plasma(clip(|d| / vmax, 0, 1))``.

    ``vmax`` defaults to ``max |d|``; when it is 0 every value gets the low end.
    Returns an array of shape ``magnitude.shape + (4,)``.
    """
    import matplotlib

    m = np.asarray(magnitude, dtype=float)
    if not np.all(np.isfinite(m)) or np.any(m < 0):
        raise InputError("displacement magnitudes must be finite and >= 0")
    top = float(m.max()) if vmax is None and m.size else float(vmax or 0.0)
    if not np.isfinite(top) or top < 0:
        raise InputError(f"vmax must be finite and >= 0, got {vmax!r}")
    scaled = m / top if top > 0 else np.zeros_like(m)
    return np.asarray(matplotlib.colormaps[COLORMAP](np.clip(scaled, 0.0, 1.0)))


def colormap_table(n: int = 256) -> list[list[int]]:
    """The colormap as ``n`` RGB byte triples (for the viewer's shader and legend)."""
    rgba = displacement_colors(np.linspace(0.0, 1.0, n), 1.0)
    return (rgba[:, :3] * 255).round().astype(int).tolist()


def shade(rgba: NDArray[np.float64], normals: NDArray[np.float64]) -> NDArray[np.float64]:
    """Two-sided Lambert shading ``rgb · (0.55 + 0.45 |n · l|)`` with a fixed light ``l``."""
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    n = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    factor = 0.55 + 0.45 * np.abs(n @ LIGHT)
    out = rgba.copy()
    out[..., :3] *= factor[..., None]
    return out


# -- matplotlib helpers -----------------------------------------------------------------
def _figure(width: float, height: float) -> Any:
    """A matplotlib Figure on an Agg canvas (no global pyplot state, no display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _save_png(fig: Any, path: str | os.PathLike[str]) -> Path:
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"pictures are written as PNG; the file name must end in .png, "
                         f"got {target.name!r}")
    return write_with(target, lambda tmp: fig.savefig(tmp, format="png", dpi=DPI))


def _bounds(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """Centre and half-width of the cube that holds ``points (..., 3)``."""
    flat = points.reshape(-1, 3)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    half = 0.5 * float(np.max(hi - lo))
    return 0.5 * (lo + hi), half if half > 0 else 1.0


def _box(ax: Any, points: NDArray[np.float64], zoom: float = 1.0) -> None:
    """Equal aspect: the tight box around ``points``, padded where it is flat."""
    flat = points.reshape(-1, 3)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    pad = np.maximum(hi - lo, 0.05 * max(float(np.max(hi - lo)), 1e-12)) / 2
    centre = 0.5 * (lo + hi)
    ax.set_xlim(centre[0] - pad[0], centre[0] + pad[0])
    ax.set_ylim(centre[1] - pad[1], centre[1] + pad[1])
    ax.set_zlim(centre[2] - pad[2], centre[2] + pad[2])
    ax.set_box_aspect(tuple(2 * pad), zoom=zoom)
    from matplotlib.ticker import MaxNLocator

    for axis, extent in zip((ax.xaxis, ax.yaxis, ax.zaxis), pad / pad.max()):
        if extent < 0.15:            # a thin side of the box has no room for tick labels
            axis.set_ticks([])
        elif extent < 0.4:
            axis.set_major_locator(MaxNLocator(3))


def _collection(vertices: NDArray[np.float64], faces: NDArray[np.int64],
                face_rgba: NDArray[np.float64]) -> Any:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    triangles = vertices[faces]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    rgba = shade(face_rgba, normals)
    # edges in the face colour close the hairline gaps between antialiased triangles
    return Poly3DCollection(triangles, facecolors=rgba, edgecolors=rgba, linewidths=0.3)


def _face_colors(magnitude: NDArray[np.float64], faces: NDArray[np.int64], vmax: float
                 ) -> NDArray[np.float64]:
    return displacement_colors(magnitude[faces].mean(axis=1), vmax)


def _axes3d(fig: Any, rect: Sequence[float] | tuple[int, int, int]) -> Any:
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3-D projection)

    ax = fig.add_axes(rect, projection="3d") if len(rect) == 4 else \
        fig.add_subplot(*rect, projection="3d")
    ax.view_init(elev=28, azim=-60)
    ax.tick_params(labelsize=7)
    return ax


def _colorbar(fig: Any, rect: Sequence[float], vmax: float, label: str = "|displacement|"
              ) -> None:
    import matplotlib
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    mappable = ScalarMappable(Normalize(0.0, vmax if vmax > 0 else 1.0),
                              matplotlib.colormaps[COLORMAP])
    bar = fig.colorbar(mappable, cax=fig.add_axes(rect))
    bar.set_label(label)


# -- render_surfaces ------------------------------------------------------------------------
def _displaced_meshes(surface: Surface, rest_net: ArrayLike, nets: Sequence[ArrayLike],
                      resolution: int) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                NDArray[np.int64]]:
    """Vertices ``(F, N, 3)``, displacement magnitudes ``(F, N)`` and faces."""
    P = np.stack([check_net(surface, net, f"nets[{i}]") for i, net in enumerate(nets)])
    rest = check_net(surface, rest_net, "rest net")
    X, faces = tessellate_frames(surface, P, resolution)
    X0, _ = tessellate_frames(surface, rest, resolution)
    return X, np.linalg.norm(X - X0, axis=-1), faces


def _pyvista() -> Any:
    """The pyvista module if it is installed, else None."""
    try:
        import pyvista
    except Exception:   # noqa: BLE001  (any import failure means: not available)
        return None
    return pyvista


def _render_pyvista(path: Path, X: NDArray[np.float64], mag: NDArray[np.float64],
                    faces: NDArray[np.int64], titles: Sequence[str], vmax: float) -> Path:
    pv = _pyvista()
    if pv is None:
        raise RuntimeError("pyvista is not installed")
    n = X.shape[0]
    size = (int(PANEL_INCHES * DPI) * n + int(COLORBAR_INCHES * DPI), int(PANEL_INCHES * DPI))
    plotter = pv.Plotter(off_screen=True, shape=(1, n), window_size=size, border=False)
    try:
        cells = np.hstack([np.full((faces.shape[0], 1), 3), faces]).ravel()
        for i in range(n):
            plotter.subplot(0, i)
            mesh = pv.PolyData(X[i], cells)
            mesh.point_data["|displacement|"] = mag[i]
            plotter.add_mesh(mesh, scalars="|displacement|", cmap=COLORMAP,
                             clim=(0.0, vmax if vmax > 0 else 1.0), show_scalar_bar=i == n - 1)
            plotter.add_text(titles[i], font_size=10)
            plotter.view_isometric()
        plotter.link_views()
        return write_with(path, lambda tmp: plotter.screenshot(str(tmp)))
    finally:
        plotter.close()


def _render_matplotlib(path: Path, X: NDArray[np.float64], mag: NDArray[np.float64],
                       faces: NDArray[np.int64], titles: Sequence[str], vmax: float) -> Path:
    n = X.shape[0]
    width = PANEL_INCHES * n + COLORBAR_INCHES
    fig = _figure(width, PANEL_INCHES)
    for i in range(n):
        ax = _axes3d(fig, [i * PANEL_INCHES / width, 0.02, PANEL_INCHES / width, 0.9])
        ax.add_collection3d(_collection(X[i], faces, _face_colors(mag[i], faces, vmax)))
        _box(ax, X)
        ax.set_title(titles[i], fontsize=10)
    _colorbar(fig, [(n * PANEL_INCHES + 0.1) / width, 0.12, 0.18 / width, 0.72], vmax)
    return _save_png(fig, path)


def render_surfaces(path: str | os.PathLike[str], surface: Surface, rest_net: ArrayLike,
                    nets: Sequence[ArrayLike], titles: Sequence[str], resolution: int = 48
                    ) -> Path:
    """PNG with one panel per control net, coloured by ``|x - x_rest|`` on a shared scale.

    All panels share the colour scale ``[0, max |d|]`` and the same equal-aspect box, so
    sizes and colours compare across panels. With matplotlib the picture is
    ``(400 n + 120) × 400`` pixels for ``n`` panels.
    """
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"render_surfaces writes PNG; got {target.name!r}")
    if isinstance(nets, np.ndarray) and nets.ndim == 3:
        nets = [nets]
    if len(nets) == 0 or len(nets) != len(titles):
        raise InputError(f"give one title per net and at least one net; got {len(nets)} net(s) "
                         f"and {len(titles)} title(s)")
    X, mag, faces = _displaced_meshes(surface, rest_net, nets, resolution)
    vmax = float(mag.max())
    titles = [str(t) for t in titles]
    if _pyvista() is not None:
        try:
            return _render_pyvista(target, X, mag, faces, titles, vmax)
        except Exception:   # noqa: BLE001  (no off-screen context: draw with matplotlib)
            pass
    return _render_matplotlib(target, X, mag, faces, titles, vmax)


# -- plot_probes ---------------------------------------------------------------------------
def plot_probes(path: str | os.PathLike[str], times: ArrayLike,
                probes: Mapping[str, ArrayLike]) -> Path:
    """Displacement components ``d_x, d_y, d_z`` and ``|d|`` against time, one panel per probe.

    ``probes`` maps a probe name to its displacement history ``(F, 3)`` at ``times (F,)``.
    The picture is 800 px wide and 250 px high per probe.
    """
    t = np.asarray(times, dtype=float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise InputError(f"times must be a finite 1-D array (F,), got shape {t.shape}")
    if not isinstance(probes, Mapping) or not probes:
        raise InputError("probes must be a non-empty mapping of name to (F, 3) displacements")
    histories = {}
    for name, values in probes.items():
        d = np.asarray(values, dtype=float)
        if d.shape != (t.size, 3) or not np.all(np.isfinite(d)):
            raise InputError(f"probe {name!r} must be a finite array of shape ({t.size}, 3), "
                             f"got {d.shape}")
        histories[str(name)] = d
    fig = _figure(8.0, 2.5 * len(histories))
    axes = fig.subplots(len(histories), 1, squeeze=False, sharex=True)[:, 0]
    for ax, (name, d) in zip(axes, histories.items()):
        for c, label in enumerate(("$d_x$", "$d_y$", "$d_z$")):
            ax.plot(t, d[:, c], lw=1.2, label=label)
        ax.plot(t, np.linalg.norm(d, axis=1), "k--", lw=1.2, label="$|d|$")
        ax.set_title(name, fontsize=10)
        ax.set_ylabel("displacement")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8, ncols=2, framealpha=0.8)
    axes[-1].set_xlabel("time")
    fig.tight_layout()
    return _save_png(fig, path)


# -- plot_modes ----------------------------------------------------------------------------
def _unit_normals(surface: Surface, u: NDArray[np.float64], v: NDArray[np.float64]
                  ) -> NDArray[np.float64]:
    """``x_u × x_v / |x_u × x_v|`` on a grid, 0 where the surface is degenerate (poles)."""
    cross = np.cross(surface.evaluate_grid(u, v, 1, 0), surface.evaluate_grid(u, v, 0, 1))
    length = np.linalg.norm(cross, axis=-1, keepdims=True)
    return np.divide(cross, length, out=np.zeros_like(cross), where=length > 1e-12 * length.max())


def mode_geometry(surface: Surface, shape: ArrayLike, resolution: int = 40, scale: float = 0.2
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """The surface displaced along its normal by a scalar mode field, for drawing.

    ``φ(u,v) = Σ_kl φ_kl b_k(u) b_l(v)`` and ``y = x + s φ n`` with
    ``s = scale · diameter / max|φ|``. Returns vertices ``(N, 3)``, ``φ`` at the vertices
    ``(N,)`` and faces.
    """
    phi_net = np.asarray(shape, dtype=float)
    u, v = surface.sample_parameters(resolution)
    phi = surface.evaluate_grid(u, v, control_points=phi_net[..., None])[..., 0]
    x = surface.evaluate_grid(u, v)
    _, half = _bounds(x)
    peak = float(np.abs(phi).max())
    s = scale * 2 * half / peak if peak > 0 else 0.0
    y = x + s * phi[..., None] * _unit_normals(surface, u, v)
    return y.reshape(-1, 3), phi.ravel(), grid_faces(u.size, v.size)


def plot_modes(path: str | os.PathLike[str], surface: Surface, omegas: ArrayLike,
               shapes: ArrayLike, resolution: int = 40) -> Path:
    """modes.png: mode ``i`` drawn as ``x + s φ_i n`` (see :func:`mode_geometry`).

    Coloured by ``φ_i`` on a symmetric diverging scale; the panel title gives ``ω_i``.
    Up to three panels per row, 400 × 400 px each.
    """
    w = np.asarray(omegas, dtype=float)
    phis = np.asarray(shapes, dtype=float)
    if not isinstance(surface, Surface):
        raise InputError(f"surface must be a splinedeform.Surface, got {type(surface).__name__}")
    if w.ndim != 1 or w.size == 0 or phis.shape != (w.size, *surface.shape):
        raise InputError(f"omegas must be (k,) and shapes (k, n_u, n_v) = "
                         f"(k, {surface.shape[0]}, {surface.shape[1]}); got {w.shape} and "
                         f"{phis.shape}")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(phis))):
        raise InputError("omegas and mode shapes must be finite")
    import matplotlib

    cols = min(w.size, 3)
    rows = -(-w.size // cols)
    fig = _figure(PANEL_INCHES * cols, PANEL_INCHES * rows)
    cmap = matplotlib.colormaps[MODE_COLORMAP]
    for i in range(w.size):
        y, phi, faces = mode_geometry(surface, phis[i], resolution)
        peak = float(np.abs(phi).max()) or 1.0
        rgba = np.asarray(cmap(0.5 + 0.5 * phi[faces].mean(axis=1) / peak))
        ax = _axes3d(fig, (rows, cols, i + 1))
        ax.add_collection3d(_collection(y, faces, rgba))
        _box(ax, y, zoom=1.3)
        ax.set_axis_off()
        ax.set_title(f"mode {i + 1}: ω = {w[i]:.5g}", fontsize=11)
    return _save_png(fig, path)


# -- animation -------------------------------------------------------------------------------
def mp4_available() -> bool:
    """Whether an MP4 encoder (imageio-ffmpeg, the ``video`` extra) can be used."""
    try:
        import imageio_ffmpeg

        return bool(imageio_ffmpeg.get_ffmpeg_exe())
    except Exception:   # noqa: BLE001  (missing package or missing binary)
        return False


def animation_frames(surface: Surface, rest_net: ArrayLike, times: ArrayLike, nets: ArrayLike,
                     resolution: int = 32, progress: Progress = None
                     ) -> list[NDArray[np.uint8]]:
    """RGB images ``(480, 640, 3)`` of every frame, with fixed axes and colour scale."""
    t, P = check_frames(surface, times, nets)
    X, mag, faces = _displaced_meshes(surface, rest_net, list(P), resolution)
    vmax = float(mag.max())
    width, height = ANIMATION_PIXELS
    fig = _figure(width / DPI, height / DPI)
    ax = _axes3d(fig, [0.0, 0.02, 0.84, 0.9])
    _box(ax, X)
    _colorbar(fig, [0.86, 0.15, 0.025, 0.7], vmax)
    images = []
    collection = None
    for f in range(t.size):
        if collection is not None:
            collection.remove()
        collection = _collection(X[f], faces, _face_colors(mag[f], faces, vmax))
        ax.add_collection3d(collection)
        ax.set_title(f"t = {t[f]:.4g}", fontsize=11)
        fig.canvas.draw()
        images.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
        if progress is not None:
            progress(f + 1, t.size)
    return images


def write_animation(path: str | os.PathLike[str], surface: Surface, rest_net: ArrayLike,
                    times: ArrayLike, nets: ArrayLike, resolution: int = 32,
                    progress: Progress = None, fps: float = 15.0) -> Path:
    """Animate the motion as a looping GIF (imageio + pillow) or an MP4 (imageio-ffmpeg).

    One 640 × 480 image per frame (see :func:`animation_frames`), ``fps`` frames per
    second. ``progress(done, total)`` is called after each rendered frame.
    """
    import imageio.v3 as iio

    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise InputError(f"animations are written as .gif or .mp4, got {target.name!r}")
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be finite and > 0, got {fps!r}")
    if suffix == ".mp4" and not mp4_available():
        raise InputError("MP4 needs an ffmpeg encoder: install the extra `video` "
                         "(pip install 'splinedeform[video]') or write a .gif")
    check_frames(surface, times, nets)
    images = np.stack(animation_frames(surface, rest_net, times, nets, resolution, progress))
    if suffix == ".gif":
        return write_with(target, lambda tmp: iio.imwrite(
            tmp, images, extension=".gif", duration=1000.0 / fps, loop=0))
    return write_with(target, lambda tmp: _write_mp4(tmp, images, fps))


def _write_mp4(path: Path, images: NDArray[np.uint8], fps: float) -> None:
    import imageio.v2 as iio2

    writer = iio2.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                             quality=7, macro_block_size=16, ffmpeg_log_level="error")
    try:
        for image in images:
            writer.append_data(image)
    finally:
        writer.close()


# -- interactive viewer ---------------------------------------------------------------------------
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
                resolution: int = 32) -> dict[str, Any]:
    """The JSON document the viewer reads: meshes of every frame, control nets, colours.

    ``frames`` holds float32 vertex positions ``(F, N, 3)`` and ``nets`` the control
    nets ``(F, n_u, n_v, 3)`` as base64; ``rest`` the rest mesh for ``|d|``.
    """
    t, P = check_frames(surface, times, nets)
    rest = check_net(surface, rest_net, "rest net")
    X, faces = tessellate_frames(surface, P, resolution)
    X0, _ = tessellate_frames(surface, rest, resolution)
    vmax = float(np.linalg.norm(X - X0, axis=-1).max())
    return {"name": surface.name, "times": t.tolist(), "vertexCount": int(X.shape[1]),
            "frames": _b64(X, "<f4"), "rest": _b64(X0, "<f4"), "faces": _b64(faces, "<u4"),
            "faceCount": int(faces.shape[0]), "netShape": list(surface.shape),
            "periodic": [surface.basis_u.periodic, surface.basis_v.periodic],
            "nets": _b64(P, "<f4"), "vmax": vmax, "colormap": colormap_table(),
            "colormapName": COLORMAP}


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
    fills = {"__SPLINEDEFORM_TITLE__": html.escape(str(data["name"])),
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
                 times: ArrayLike, nets: ArrayLike, resolution: int = 32) -> Path:
    """Write ``viewer.html``: one offline page to orbit, zoom and play the motion.

    three.js (r187, MIT, vendored) is inlined; frames are float32 base64. The page
    exposes ``window.splinedeformViewer`` with ``setFrame(i)``, ``frameCount``,
    ``currentFrame``, ``play()``, ``pause()`` and ``vertexChecksum()`` (see
    :func:`vertex_checksum`).
    """
    target = Path(path)
    if target.suffix.lower() not in (".html", ".htm"):
        raise InputError(f"the viewer is an .html file, got {target.name!r}")
    return write_text(target, viewer_html(viewer_data(surface, rest_net, times, nets,
                                                      resolution)))
