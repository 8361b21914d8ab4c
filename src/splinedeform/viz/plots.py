"""probes.png (displacement histories) and modes.png (mode shapes along the normal, of a
surface or of every face of a body)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..surface import Surface, grid_faces
from .colour import MODE_COLORMAP
from .figures import CAMERA, _axes3d, _bounds, _box, _collection, _colorbar, _figure, _save_png


def _check_histories(t: NDArray[np.float64], probes: Mapping[str, ArrayLike], what: str
                     ) -> dict[str, NDArray[np.float64]]:
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise InputError(f"{what} must be a finite 1-D array (F,), got shape {t.shape}")
    if not isinstance(probes, Mapping) or not probes:
        raise InputError("probes must be a non-empty mapping of name to (F, 3) displacements")
    histories = {}
    for name, values in probes.items():
        d = np.asarray(values, dtype=float)
        if d.shape != (t.size, 3) or not np.all(np.isfinite(d)):
            raise InputError(f"probe {name!r} must be a finite array of shape ({t.size}, 3), "
                             f"got {d.shape}")
        histories[str(name)] = d
    return histories


def plot_probes(path: str | os.PathLike[str], times: ArrayLike,
                probes: Mapping[str, ArrayLike], dense_times: ArrayLike | None = None,
                dense_probes: Mapping[str, ArrayLike] | None = None) -> Path:
    """Displacement components ``d_x, d_y, d_z`` and ``|d|`` against time, one panel per probe.

    ``probes`` maps a probe name to its displacement history ``(F, 3)`` at the output
    frames ``times (F,)``. When the solution is known at every time (the analytic
    solver), give it sampled densely as ``dense_times (T,)`` and ``dense_probes`` (same
    names, ``(T, 3)``): the curves are drawn from those and the frames marked as dots on
    them; otherwise the curves join the frames. The picture is 800 px wide and 250 px
    high per probe.
    """
    t = np.asarray(times, dtype=float)
    histories = _check_histories(t, probes, "times")
    curves_t, curves = t, histories
    if dense_times is not None or dense_probes is not None:
        curves_t = np.asarray(dense_times, dtype=float)
        curves = _check_histories(curves_t, dense_probes or {}, "dense_times")
        if set(curves) != set(histories):
            raise InputError(f"dense_probes must name the same probes as probes: "
                             f"{sorted(histories)}, got {sorted(curves)}")
    fig = _figure(8.0, 2.5 * len(histories))
    axes = fig.subplots(len(histories), 1, squeeze=False, sharex=True)[:, 0]
    for ax, (name, d) in zip(axes, histories.items()):
        c = curves[name]
        for k, label in enumerate(("$d_x$", "$d_y$", "$d_z$")):
            line, = ax.plot(curves_t, c[:, k], lw=1.2, label=label)
            if curves is not histories:
                ax.plot(t, d[:, k], "o", ms=2.5, color=line.get_color())
        ax.plot(curves_t, np.linalg.norm(c, axis=1), "k--", lw=1.2, label="$|d|$")
        ax.set_title(name, fontsize=10)
        ax.set_ylabel("displacement")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8, ncols=2, framealpha=0.8)
    note = f" (curves: {curves_t.size} samples of the solution; dots: output frames)" \
        if curves is not histories else ""
    axes[-1].set_xlabel("time" + note)
    fig.tight_layout()
    return _save_png(fig, path)


# -- plot_modes ----------------------------------------------------------------------------
def _unit_normals(surface: Surface, u: NDArray[np.float64], v: NDArray[np.float64]
                  ) -> NDArray[np.float64]:
    """``n = x_u × x_v / |x_u × x_v|`` on a grid, never zero.

    Where the surface degenerates (a pole: a parameter line collapses to one point and
    ``x_u = 0``), ``n`` is taken at parameters nudged ``10⁻⁶ L`` into the domain and
    averaged over the grid points that share the degenerate point, so a pole has one
    normal (and a mode drawn along it keeps the pole closed). A point degenerate even
    there takes the mean normal of the grid.
    """
    cross = np.cross(surface.evaluate_grid(u, v, 1, 0), surface.evaluate_grid(u, v, 0, 1))
    length = np.linalg.norm(cross, axis=-1)
    scale = float(length.max()) or 1.0
    bad = length <= 1e-9 * scale
    if np.any(bad):
        i, j = np.nonzero(bad)
        (_, lu), (_, lv) = surface.domain
        uu = np.clip(u[i], 1e-6 * lu, (1 - 1e-6) * lu)
        vv = np.clip(v[j], 1e-6 * lv, (1 - 1e-6) * lv)
        nudged = np.cross(surface.derivative(uu, vv, 1, 0), surface.derivative(uu, vv, 0, 1))
        nudged /= np.maximum(np.linalg.norm(nudged, axis=-1, keepdims=True), 1e-300)
        cross[i, j] = _mean_per_point(surface.evaluate(u[i], v[j]), nudged)
        length = np.linalg.norm(cross, axis=-1)
        bad = length <= 1e-12
    n = cross / np.where(bad, 1.0, length)[..., None]
    if np.any(bad):
        mean = n[~bad].sum(axis=0) if np.any(~bad) else np.zeros(3)
        size = np.linalg.norm(mean)
        n[bad] = mean / size if size > 0 else np.array([0.0, 0.0, 1.0])
    return n


def _mean_per_point(x: NDArray[np.float64], n: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mean of the vectors ``n`` over the points ``x`` that coincide (to 1e-9 of the size)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    size = float(np.ptp(x, axis=0).max()) if len(x) > 1 else 0.0
    pairs = cKDTree(x).query_pairs(1e-9 * max(size, 1.0), output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                       shape=(len(x), len(x)))
    _, label = connected_components(graph, directed=False)
    total = np.zeros((label.max() + 1, 3))
    np.add.at(total, label, n)
    return total[label]


def mode_geometry(surface: Surface, shape: ArrayLike, resolution: int = 40, scale: float = 0.2
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """The surface displaced along its normal by a scalar mode field, for drawing.

    ``φ(u,v) = Σ_kl φ_kl b_k(u) b_l(v)`` and ``y = x + s φ n`` with
    ``s = scale · diameter / max|φ|``. Returns vertices ``(N, 3)``, ``φ`` at the vertices
    ``(N,)`` and faces.
    """
    phi_net = np.asarray(shape, dtype=float)
    u, v = surface.sample_parameters(resolution)
    if surface.trim is not None:
        return _clipped_mode_geometry(surface, phi_net, u, v, scale)
    phi = surface.evaluate_grid(u, v, control_points=phi_net[..., None])[..., 0]
    x = surface.evaluate_grid(u, v)
    _, half = _bounds(x)
    peak = float(np.abs(phi).max())
    s = scale * 2 * half / peak if peak > 0 else 0.0
    y = x + s * phi[..., None] * _unit_normals(surface, u, v)
    return y.reshape(-1, 3), phi.ravel(), grid_faces(u.size, v.size)


def _clipped_mode_geometry(surface: Surface, phi_net: NDArray[np.float64],
                           u: NDArray[np.float64], v: NDArray[np.float64], scale: float
                           ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """:func:`mode_geometry` on the grid clipped to the trim loops
    (:func:`splinedeform.trim.tessellate.surface_grid`)."""
    from ..trim.tessellate import surface_grid

    uv, faces = surface_grid(surface, u, v)
    pu, pv = uv[:, 0], uv[:, 1]
    phi = surface.derivative(pu, pv, control_points=phi_net[..., None])[:, 0]
    x = surface.derivative(pu, pv)
    cross = np.cross(surface.derivative(pu, pv, 1, 0), surface.derivative(pu, pv, 0, 1))
    length = np.linalg.norm(cross, axis=-1, keepdims=True)
    normal = cross / np.where(length > 0, length, 1.0)
    _, half = _bounds(x)
    peak = float(np.abs(phi).max())
    s = scale * 2 * half / peak if peak > 0 else 0.0
    return x + s * phi[:, None] * normal, phi, faces


#: modes.png: each panel is MODE_PANEL_INCHES square, the colour bar's column is
#: MODE_BAR_INCHES wide; white margins are cut down to MARGIN_PIXELS
MODE_PANEL_INCHES = 3.2
MODE_BAR_INCHES = 1.1


def plot_modes(path: str | os.PathLike[str], surface: Surface, omegas: ArrayLike,
               shapes: ArrayLike, resolution: int = 40,
               camera: tuple[float, float] = CAMERA) -> Path:
    """modes.png: mode ``i`` drawn as ``x + s φ_i n`` (see :func:`mode_geometry`).

    Coloured by ``φ_i / max |φ_i|`` on the diverging scale ``[-1, 1]`` shown by the colour
    bar (blue: against the normal, red: along it); the panel title gives ``ω_i``. Up to
    three panels per row, 320 × 320 px each, seen from ``camera = (elevation, azimuth)``;
    the white margins of the figure are trimmed (:func:`~.figures._save_png`).
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
    return _modes_figure(path, w, [mode_geometry(surface, phi, resolution) for phi in phis],
                         camera)


def _modes_figure(path: str | os.PathLike[str], w: NDArray[np.float64],
                  panels: Sequence[tuple[NDArray[np.float64], NDArray[np.float64],
                                         NDArray[np.int64]]],
                  camera: tuple[float, float]) -> Path:
    """modes.png of the drawn ``panels`` ``(vertices, φ at the vertices, faces)``, one per
    mode ``ω_i`` (:func:`plot_modes`)."""
    import matplotlib

    cols = min(w.size, 3)
    rows = -(-w.size // cols)
    width, height = MODE_PANEL_INCHES * cols + MODE_BAR_INCHES, MODE_PANEL_INCHES * rows
    fig = _figure(width, height)
    cmap = matplotlib.colormaps[MODE_COLORMAP]
    cell_w, cell_h = MODE_PANEL_INCHES / width, MODE_PANEL_INCHES / height
    for i, (y, phi, faces) in enumerate(panels):
        peak = float(np.abs(phi).max()) or 1.0
        rgba = np.asarray(cmap(0.5 + 0.5 * phi[faces].mean(axis=1) / peak))
        r, c = divmod(i, cols)
        ax = _axes3d(fig, [c * cell_w, 1 - (r + 1) * cell_h, cell_w, 0.9 * cell_h], camera)
        ax.add_collection3d(_collection(y, faces, rgba))
        _box(ax, y, zoom=1.2)
        ax.set_axis_off()
        ax.set_title(f"mode {i + 1}: ω = {w[i]:.5g}", fontsize=11, pad=0)
    bar_h = min(0.7, 2.6 / height)
    _colorbar(fig, [(cols * MODE_PANEL_INCHES + 0.2) / width, 0.5 - bar_h / 2, 0.16 / width,
                    bar_h], 1.0, label="φ / max |φ|  (along the normal)",
              colormap=MODE_COLORMAP, vmin=-1.0)
    return _save_png(fig, path, trim=True)


def plot_body_modes(path: str | os.PathLike[str], patches: Sequence[Surface],
                    omegas: ArrayLike, mode_nets: Sequence[ArrayLike], resolution: int = 24,
                    orientation: Sequence[int] = (), camera: tuple[float, float] = CAMERA
                    ) -> Path:
    """modes.png of a body: every face in every panel, as :func:`plot_modes` draws one.

    ``mode_nets[p]`` ``(K, n_u, n_v, 3)`` are the modes of patch ``p`` as control-net
    displacements ``D_k``. Panel ``k`` is the body's welded mesh
    (:func:`splinedeform.export.body.welded_body_points`, triangles wound along each
    face's ``orientation``) at ``X(P_rest + 2 D_k)``, coloured by the mode's component
    along the outward normal ``φ = (X(P_rest + D_k) − X(P_rest)) · n``, ``n`` the welded
    rest mesh's vertex normals, on the scale ``φ / max |φ|``.
    """
    from ..export.body import welded_body_points
    from ..export.weld import vertex_normals

    w = np.asarray(omegas, dtype=float)
    D = [np.asarray(d, dtype=float) for d in mode_nets]
    if w.ndim != 1 or w.size == 0 or len(D) != len(patches) or \
            any(d.shape != (w.size, *s.shape, 3) for s, d in zip(patches, D)):
        raise InputError(f"omegas must be (k,) and the modes of each of the {len(patches)} "
                         f"patches (k, n_u, n_v, 3); got {w.shape} and "
                         f"{[d.shape for d in D]}")
    if not (np.all(np.isfinite(w)) and all(np.all(np.isfinite(d)) for d in D)):
        raise InputError("omegas and mode shapes must be finite")
    rests = [s.control_points for s in patches]
    X, faces, _, _ = welded_body_points(
        patches, [np.concatenate([r[None], r[None] + d]) for r, d in zip(rests, D)],
        resolution, orientation)
    normal = vertex_normals(X[0], faces)
    panels = [(X[0] + 2.0 * (X[k] - X[0]), np.einsum("ij,ij->i", X[k] - X[0], normal), faces)
              for k in range(1, w.size + 1)]
    return _modes_figure(path, w, panels, camera)
