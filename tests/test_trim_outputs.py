"""Trimmed surfaces: the clipped output mesh, the model's refusals, loads on the region."""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.errors import InputError
from splinedeform.export import tessellate_frames
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain
from splinedeform.trim.tessellate import clipped_grid

R = 0.37
DISC = TrimDomain(CircleLoop((0.5, 0.5), R))


def _boundary_edges(faces):
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    keys, counts = np.unique(edges, axis=0, return_counts=True)
    return keys[counts == 1]


@pytest.mark.parametrize("resolution", [20, 40, 80])
def test_clipped_mesh_area_is_the_disc_less_its_chords(resolution):
    u = np.linspace(0.0, 1.0, resolution)
    uv, faces = clipped_grid(DISC, u, u)
    P = uv[faces]
    e1, e2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert np.all(area > 0)                       # orientation of the grid kept
    edges = _boundary_edges(faces)
    # the boundary vertices lie on the circle to round-off (bisection to 2⁻⁶⁰ of an edge)
    radius = np.hypot(*(uv[edges.ravel()] - 0.5).T)
    assert np.max(np.abs(radius - R)) < 1e-14
    # welded: each boundary vertex closes the loop, in exactly two boundary edges
    assert np.all(np.bincount(edges.ravel())[np.unique(edges)] == 2)
    # a chord of length s cuts off s³/(12 R) + O(s⁵/R³) of the disc: with that added the
    # area is πR² to the next term, below 3e-6 relative at 20 points (s ≈ 0.05)
    chords = np.linalg.norm(uv[edges[:, 0]] - uv[edges[:, 1]], axis=1)
    assert area.sum() < np.pi * R * R
    assert abs((area.sum() + np.sum(chords ** 3) / (12 * R)) / (np.pi * R * R) - 1) < 3e-6


def test_tessellated_frames_of_a_trimmed_surface_lie_on_the_surface():
    # the clipped vertices are surface points: a plane's x, y are its parameters, within
    # 1e-14 (the evaluation's round-off)
    surface = sd.shapes.plane(cells=(6, 6), knots="uniform").with_trim(DISC)
    X, faces = tessellate_frames(surface, surface.control_points, 24)
    inside = np.hypot(X[:, 0] - 0.5, X[:, 1] - 0.5)
    assert inside.max() < R + 1e-14 and faces.max() == len(X) - 1


def _plate(domain=DISC, **kwargs):
    surface = sd.shapes.plane(cells=(8, 8), knots="uniform", **kwargs)
    return surface.with_trim(domain)


def test_uniform_load_integrates_over_the_trimmed_region():
    # Σ_k F_k = ∫_Ω f Σ_k b_k = f |Ω| (partition of unity), 1e-12 of the area: the
    # cut-cell rule is exact to round-off on a circle (docs/trim.md)
    F = sd.Uniform([0.0, 0.0, 2.0]).field_vector(_plate())
    assert abs(F[:, 2].sum() / (2 * np.pi * R * R) - 1) < 1e-12


def test_refusals_name_the_problem():
    surface = _plate()
    membrane = sd.Material(w10=1.0, w01=1.0)
    with pytest.raises(InputError, match="rectangle's edges"):
        sd.Model(surface, membrane, boundary={"u0": "clamped"})
    with pytest.raises(InputError, match="hole7"):
        sd.Model(surface, membrane, boundary={"hole7": "clamped"})
    with pytest.raises(InputError, match="every control point is fixed"):
        sd.Model(surface, membrane, boundary="pinned", fixed=np.ones(surface.shape, bool))
    with pytest.raises(InputError, match="ShellModel"):
        sd.Model(surface, membrane, boundary="pinned", physics="shell")
    with pytest.raises(InputError, match="rest = 'none'"):
        sd.Model(surface, membrane, boundary="pinned", rest="none")
    with pytest.raises(InputError, match="every control point is fixed"):
        sd.ShellModel(surface, sd.ShellMaterial(1.0, 0.3, 0.01, 1.0),
                      fixed=np.ones(surface.shape, bool))
    with pytest.raises(InputError, match="outside the trimmed region"):
        sd.Model(surface, membrane, boundary="pinned").static(
            sd.Point(0.05, 0.05, [0.0, 0.0, 1.0]))
    with pytest.raises(InputError, match="reaches outside the parameter domain"):
        surface.with_trim(TrimDomain(CircleLoop((0.5, 0.5), 0.6)))
    with pytest.raises(InputError, match="uniform or open knots.*closed .periodic. "
                       "direction.*knots='open'"):
        sd.shapes.cylinder(cells=(8, 4)).with_trim(
            TrimDomain(PolygonLoop([[1, 0.5], [3, 0.5], [3, 1.5], [1, 1.5]])))
    from splinedeform.knots import KnotVectorBasis

    kinked = KnotVectorBasis(3, [0, 0, 0, 0, 0.5, 0.5, 1, 1, 1, 1])
    bv = sd.shapes.plane(cells=(4, 4)).basis_v
    net = np.zeros((kinked.size, bv.size, 3))
    with pytest.raises(InputError, match=r"'kinked'.*in u .*interior knot\(s\) \[0.5\].*"
                       "split the surface"):
        sd.Surface(net, kinked, bv, name="kinked").with_trim(TrimDomain(CircleLoop(
            (0.5, 0.5), 0.3)))


def test_a_holed_rectangle_keeps_its_edges_in_the_mesh():
    # the rectangle as outer loop: the grid's boundary vertices count as inside (the
    # polygon's even–odd test alone is ambiguous there); area 1 − πr² less the hole's
    # chords, s³/(12 r) each, to 3e-6 relative as for the disc
    from splinedeform.trim.tessellate import surface_grid

    rectangle = PolygonLoop([[0, 0], [1, 0], [1, 1], [0, 1]])
    surface = sd.shapes.plane(cells=(6, 6)).with_trim(
        TrimDomain(rectangle, (CircleLoop((0.5, 0.5), R),)))
    u = np.linspace(0.0, 1.0, 21)
    uv, faces = surface_grid(surface, u, u)
    P = uv[faces]
    e1, e2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    edges = _boundary_edges(faces)
    on_hole = np.abs(np.hypot(*(uv[edges] - 0.5).transpose(2, 0, 1)) - R).max(axis=1) < 1e-14
    chords = np.linalg.norm(uv[edges[on_hole, 0]] - uv[edges[on_hole, 1]], axis=1)
    exact = 1 - np.pi * R * R
    assert abs((area.sum() - np.sum(chords ** 3) / (12 * R)) / exact - 1) < 3e-6
