"""Control-net files rebuild the surface with other B-spline libraries, from the file alone.

Each test reads the file with ``json`` / ``numpy.load`` only (no splinedeform code) and
follows the file's own ``convention`` text: B-splines of ``degree`` on ``knots``,
coefficients ``control_points[coefficient_index_u][:, coefficient_index_v]``, evaluated
on ``domain``. The reference is :meth:`Surface.evaluate` (our Höllig / Cox–de Boor
evaluator); scipy's ``NdBSpline`` (de Boor), geomdl and splipy are independent
implementations. Tolerance 1e-12 relative to the size of the net: both sides sum at most
``(n+1)² = 16`` products of O(1) values, so round-off is ~1e-15; a misread index or knot
is wrong by 0.1–1.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import NdBSpline

from splinedeform import InputError, shapes
from splinedeform import export

LAYOUTS = {
    "plane, open": lambda: shapes.plane((1.5, 1.0), cells=(5, 4), knots="open"),
    "plane, uniform": lambda: shapes.plane((1.5, 1.0), cells=(5, 4), knots="uniform"),
    "saddle, open x uniform, degree 2": lambda: shapes.saddle(cells=(4, 6), degree=2,
                                                              knots=("open", "uniform")),
    "cylinder, periodic x open": lambda: shapes.cylinder(cells=(9, 4)),
    "torus, periodic x periodic": lambda: shapes.torus(cells=(10, 7)),
    "half sphere, periodic x open": lambda: shapes.half_sphere(cells=(12, 5)),
}


def motion(surface):
    """Two frames: the rest net and a net moved by a smooth, non-symmetric field."""
    P = surface.control_points
    bump = np.sin(np.arange(P.shape[0]))[:, None, None] * np.cos(np.arange(P.shape[1]))[None, :, None]
    return np.array([0.0, 0.5]), np.stack([P, P + 0.3 * bump * np.array([1.0, -0.5, 2.0])])


def read_file(path: Path) -> dict:
    """The file as plain data: {'u': {...}, 'v': {...}, 'control_points': (F, n_u, n_v, 3)}."""
    if path.suffix == ".json":
        doc = json.loads(path.read_text())
        out = {d: doc["basis"][d] for d in "uv"}
        out["control_points"] = np.asarray(doc["control_points"])
        out["convention"] = doc["convention"]
        return out
    with np.load(path, allow_pickle=False) as z:
        out = {d: {key: z[f"{key}_{d}"] for key in ("degree", "knots", "coefficient_index",
                                                     "domain", "periodic")} for d in "uv"}
        out["control_points"] = z["control_points"]
        out["convention"] = str(z["convention"])
        return out


def coefficients(data: dict, frame: int) -> np.ndarray:
    iu = np.asarray(data["u"]["coefficient_index"])
    iv = np.asarray(data["v"]["coefficient_index"])
    return data["control_points"][frame][iu][:, iv]


def sample(data: dict) -> tuple[np.ndarray, np.ndarray]:
    """Parameters covering each domain, ends and knots included, plus random points."""
    rng = np.random.default_rng(3)
    out = []
    for d in "uv":
        a, b = (float(x) for x in data[d]["domain"])
        out.append(np.concatenate([np.linspace(a, b, 23), rng.uniform(a, b, 20)]))
    return out[0], out[1]


def expected(surface, nets, frame, u, v) -> np.ndarray:
    uu, vv = np.meshgrid(u, v, indexing="ij")
    return surface.with_control_points(nets[frame]).evaluate(uu, vv)


def tolerance(nets) -> float:
    return 1e-12 * float(np.abs(nets).max())


@pytest.fixture(params=list(LAYOUTS), scope="module")
def written(request, tmp_path_factory):
    surface = LAYOUTS[request.param]()
    times, nets = motion(surface)
    folder = tmp_path_factory.mktemp("nets")
    export.write_control_nets(folder, "nets", surface, times, nets)
    return surface, nets, folder


@pytest.mark.parametrize("suffix", [".json", ".npz"])
def test_scipy_ndbspline_rebuilds_the_surface_from_the_file_alone(written, suffix):
    surface, nets, folder = written
    data = read_file(folder / f"nets{suffix}")
    u, v = sample(data)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    knots = (np.asarray(data["u"]["knots"], float), np.asarray(data["v"]["knots"], float))
    degrees = (int(data["u"]["degree"]), int(data["v"]["degree"]))
    for frame in (0, 1):
        spline = NdBSpline(knots, coefficients(data, frame), degrees)
        got = spline(np.stack([uu, vv], axis=-1))
        np.testing.assert_allclose(got, expected(surface, nets, frame, u, v),
                                   rtol=0, atol=tolerance(nets))


def test_periodic_directions_are_periodic_by_the_file(written):
    """Across the seam: x(u) = x(u + L) by the file's own knots and indices (and not trivially)."""
    surface, nets, folder = written
    data = read_file(folder / "nets.json")
    for d, axis in (("u", 0), ("v", 1)):
        if not data[d]["periodic"]:
            continue
        a, b = data[d]["domain"]
        t = np.asarray(data[d]["knots"], float)
        n = int(data[d]["degree"])
        assert t[n] == a and t[len(t) - n - 1] == b      # the domain as stated
        s = np.linspace(a, b, 7)
        other = np.full_like(s, 0.37 * float(data["v" if d == "u" else "u"]["domain"][1]))
        spline = NdBSpline((np.asarray(data["u"]["knots"]), np.asarray(data["v"]["knots"])),
                           coefficients(data, 1), (int(data["u"]["degree"]),
                                                    int(data["v"]["degree"])))
        points = np.stack([s, other] if axis == 0 else [other, s], axis=-1)
        x = spline(points)
        np.testing.assert_allclose(x[0], x[-1], rtol=0, atol=tolerance(nets))


def test_geomdl_rebuilds_the_surface_from_the_file_alone(written):
    BSpline = pytest.importorskip("geomdl.BSpline", reason="geomdl is not installed")
    surface, nets, folder = written
    data = read_file(folder / "nets.json")
    # geomdl evaluates on [0, 1]: normalise the knots and map the parameters the same way
    knots, lo, width = {}, {}, {}
    for d in "uv":
        t = np.asarray(data[d]["knots"], float)
        lo[d], width[d] = t[0], t[-1] - t[0]
        knots[d] = ((t - lo[d]) / width[d]).tolist()
    u, v = sample(data)
    u, v = u[::3], v[::3]                  # geomdl evaluates point by point in Python
    frame = 1
    C = coefficients(data, frame)
    patch = BSpline.Surface(normalize_kv=False)
    patch.degree_u, patch.degree_v = int(data["u"]["degree"]), int(data["v"]["degree"])
    patch.ctrlpts_size_u, patch.ctrlpts_size_v = C.shape[0], C.shape[1]
    patch.ctrlpts = C.reshape(-1, 3).tolist()          # v varies fastest, as geomdl expects
    patch.knotvector_u, patch.knotvector_v = knots["u"], knots["v"]
    params = [((a - lo["u"]) / width["u"], (b - lo["v"]) / width["v"]) for a in u for b in v]
    got = np.asarray(patch.evaluate_list(params)).reshape(u.size, v.size, 3)
    # parameters pass through (x - t0) / (t_end - t0) and back: a few ulps of L more
    np.testing.assert_allclose(got, expected(surface, nets, frame, u, v),
                               rtol=0, atol=tolerance(nets))


def test_splipy_rebuilds_the_surface_from_the_file_alone(written):
    splipy = pytest.importorskip("splipy", reason="splipy is not installed")
    surface, nets, folder = written
    data = read_file(folder / "nets.npz")
    bases = [splipy.BSplineBasis(int(data[d]["degree"]) + 1, np.asarray(data[d]["knots"]))
             for d in "uv"]
    frame = 1
    C = coefficients(data, frame)
    # a flat list would have the first parameter varying fastest; raw takes (n_u, n_v, 3)
    patch = splipy.Surface(*bases, C, raw=True)
    u, v = sample(data)
    got = patch(u, v)
    np.testing.assert_allclose(got, expected(surface, nets, frame, u, v),
                               rtol=0, atol=tolerance(nets))


def test_the_file_states_its_convention_and_domain(written):
    surface, nets, folder = written
    for suffix in (".json", ".npz"):
        data = read_file(folder / f"nets{suffix}")
        assert "coefficient_index" in data["convention"] and "periodic" in data["convention"]
        for d, basis in (("u", surface.basis_u), ("v", surface.basis_v)):
            assert [float(x) for x in data[d]["domain"]] == [0.0, basis.length]
            index = np.asarray(data[d]["coefficient_index"])
            assert len(data[d]["knots"]) == index.size + int(data[d]["degree"]) + 1
            assert sorted(set(index.tolist())) == list(range(basis.size))


@pytest.mark.parametrize("suffix", [".json", ".npz"])
def test_read_control_net_round_trips_every_layout(written, suffix):
    surface, nets, folder = written
    back = export.read_control_net(folder / f"nets{suffix}", 1)
    assert back.basis_u == surface.basis_u and back.basis_v == surface.basis_v
    # no arithmetic between writing and reading: NPZ stores the doubles and JSON writes
    # their shortest round-tripping repr; 1e-15 relative allows no more than the last bit
    np.testing.assert_allclose(back.control_points, nets[1], rtol=1e-15, atol=0)


def test_knots_that_contradict_the_layout_are_refused(tmp_path):
    surface = shapes.cylinder(cells=(9, 4))
    times, nets = motion(surface)
    (path,) = export.write_control_nets(tmp_path, "nets", surface, times, nets, formats=["json"])
    doc = json.loads(path.read_text())
    doc["basis"]["u"]["knots"][5] += 0.1
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"basis\.u\.knots are not the periodic knots"):
        export.read_control_net(path)


def test_a_huge_cell_count_is_refused_before_anything_is_built(tmp_path):
    surface = shapes.plane(cells=(3, 3))
    times, nets = motion(surface)
    (path,) = export.write_control_nets(tmp_path, "nets", surface, times, nets, formats=["json"])
    doc = json.loads(path.read_text())
    doc["basis"]["u"]["cells"] = 2_000_000_000
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"basis\.u: .* 2000000003 functions"):
        export.read_control_net(path)


def test_only_the_requested_formats_are_written(tmp_path):
    surface = shapes.plane(cells=(3, 3))
    times, nets = motion(surface)
    (tmp_path / "nets.npz").write_bytes(b"a file of the user's")
    paths = export.write_control_nets(tmp_path, "nets", surface, times, nets, formats=["json"])
    assert [p.name for p in paths] == ["nets.json"]
    assert (tmp_path / "nets.npz").read_bytes() == b"a file of the user's"
    with pytest.raises(InputError, match="json"):
        export.write_control_nets(tmp_path, "nets", surface, times, nets, formats=["csv"])


def test_files_of_version_1_without_knots_are_still_read(tmp_path):
    surface = shapes.plane(cells=(3, 3))
    doc = {"format": "splinedeform-control-nets", "version": 1,
           "basis": {d: {"degree": 3, "cells": 3, "length": 1.0, "kind": "open"} for d in "uv"},
           "times": [0.0], "control_points": [surface.control_points.tolist()]}
    (tmp_path / "old.json").write_text(json.dumps(doc))
    back = export.read_control_net(tmp_path / "old.json")
    # JSON floats written by repr read back as the same doubles (no arithmetic in between);
    # 1e-15 relative allows no more than the last bit
    np.testing.assert_allclose(back.control_points, surface.control_points, rtol=1e-15, atol=0)
    doc["version"] = 99
    (tmp_path / "new.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match="version 99 is newer"):
        export.read_control_net(tmp_path / "new.json")
