"""Knot insertion and degree elevation (splinedeform.refine): same geometry, finer bases."""

import numpy as np
import pytest
from scipy import interpolate

import splinedeform as sd
from splinedeform.cad import NurbsPatch, surface_from_patch
from splinedeform.errors import InputError, ScenarioError
from splinedeform.knots import KnotVectorBasis, RationalBasis
from splinedeform.refine import boehm_insert, refine_surface
from splinedeform.scenario import build, load_scenario, parse_scenario, scenario_to_toml

S = np.sqrt(0.5)


def rational_patch() -> NurbsPatch:
    """Quarter of the unit cylinder (weights 1, √½, 1 around) on a non-uniform cubic knot
    vector along, with a double knot (C1) at 0.3 and the domain starting at 2."""
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    along = np.array([0, 0.2, 0.7, 1.1, 1.6, 2.0])
    points = np.stack([ring + [0, 0, z] for z in along], axis=1) + [0, 0.1, 0] * (
        np.arange(6) % 2)[None, :, None]
    knots_v = np.array([2, 2, 2, 2, 2.3, 2.3, 3, 3, 3, 3.0])
    return NurbsPatch((2, 3), np.array([0, 0, 0, 1, 1, 1.0]), knots_v, points,
                      np.outer([1, S, 1], np.ones(6)))


def surfaces():
    return {"open": sd.shapes.saddle(cells=(3, 2), degree=3, knots="open"),
            "uniform": sd.shapes.saddle(cells=(2, 3), degree=2, knots="uniform"),
            "periodic": sd.shapes.cylinder(cells=(5, 2), degree=3),
            "rational": surface_from_patch(rational_patch())}


def _grid_gap(a, b, points=37):
    """Largest distance between two surfaces on one parameter grid, relative to the size."""
    (_, lu), (_, lv) = a.domain
    u, v = np.linspace(0, lu, points), np.linspace(0, lv, points)
    x, y = a.evaluate_grid(u, v), b.evaluate_grid(u, v)
    return np.abs(x - y).max() / np.ptp(x.reshape(-1, 3), axis=0).max()


@pytest.mark.parametrize("name", ["open", "uniform", "periodic", "rational"])
@pytest.mark.parametrize("elevate, insert", [((0, 0), (2, 1)), ((1, 2), (0, 0)),
                                             ((1, 1), (3, 2))])
def test_refinement_leaves_the_geometry_where_it_was(name, elevate, insert):
    surf = surfaces()[name]
    if name == "periodic" and elevate[0]:
        with pytest.raises(InputError, match="periodic layout .direction u."):
            refine_surface(surf, elevate, insert)
        elevate = (0, elevate[1])    # the open direction along the axis still elevates
    fine = refine_surface(surf, elevate, insert)
    for axis, (old, new) in enumerate(((surf.basis_u, fine.basis_u),
                                       (surf.basis_v, fine.basis_v))):
        assert new.degree == old.degree + elevate[axis]
        assert new.cells == old.cells * (insert[axis] + 1)
        assert isinstance(new, RationalBasis) == isinstance(old, RationalBasis)
    # the same surface on two bases: round-off of a few banded solves and products on
    # O(1) numbers, 1e-12 of the surface's size
    assert _grid_gap(surf, fine) <= 1e-12
    if name == "rational":     # the weights stay a product, and stay positive
        assert np.all(fine.weights > 0)


def test_equal_cell_layouts_stay_in_their_layout_under_insertion():
    for name in ("open", "uniform", "periodic"):
        surf = surfaces()[name]
        fine = refine_surface(surf, insert=(1, 2))
        assert fine.basis_u.kind == surf.basis_u.kind and fine.basis_v.kind == surf.basis_v.kind


def test_boehm_step_equals_fitpack_knot_insertion():
    """One inserted knot against FITPACK's ``insert`` (an independent implementation)."""
    t = np.array([0, 0, 0, 0, 0.3, 0.5, 0.5, 1, 1, 1, 1.0])
    c = np.array([0.2, -1.0, 0.7, 2.0, 0.1, -0.4, 1.3])
    for x in (0.1, 0.3, 0.42, 0.5, 0.9):
        knots, new = boehm_insert(t, 3, x, c)
        tck = interpolate.insert(x, (t, np.concatenate([c, np.zeros(4)]), 3))
        assert np.array_equal(knots, tck[0])
        # two evaluations of the same affine combinations: round-off, 1e-14 of |c|
        assert np.abs(new - tck[1][:knots.size - 4]).max() <= 1e-14 * np.abs(c).max()


def test_elevation_keeps_the_continuity_of_every_knot():
    basis = rational_patch()
    surf = surface_from_patch(basis)
    fine = refine_surface(surf, elevate=(0, 2))
    knots = fine.basis_v.knots
    assert fine.basis_v.continuity == surf.basis_v.continuity == 1
    assert np.count_nonzero(np.isclose(knots, 0.3)) == 4     # multiplicity 2 + 2
    assert np.count_nonzero(knots == 0) == 3 + 2 + 1         # clamped at degree 5


def test_plate_frequency_converges_at_order_four_under_k_refinement():
    """One quadratic cell elevated to cubic and refined by knot insertion to 4, 8, 16 cells:
    simply supported Kirchhoff plate, ω₁₁ a² √(μ/D) = 2π² (Leissa, NASA SP-160, 1969). A
    cubic Ritz eigenvalue converges as h^{2(p-1)} = h⁴ (measured 1.5e-4, 8.6e-6, 5.2e-7)."""
    a, D, mu = 1.5, 0.8, 2.0
    base = sd.shapes.plane(size=(a, a), cells=(1, 1), degree=2, knots="open")
    errors = []
    for k in (3, 7, 15):
        surf = refine_surface(base, (1, 1), (k, k))
        model = sd.Model(surf, sd.Material(mass=mu, w20=D, w11=D, w02=D), boundary="pinned")
        omega = model.frequencies(1)[0] * a**2 * np.sqrt(mu / D)
        errors.append(omega / (2 * np.pi**2) - 1)
    assert min(errors) > 0     # Rayleigh–Ritz with the consistent mass: an upper bound
    order = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(order > 3.5) and errors[-1] < 1e-6


def test_refusals_name_the_problem():
    surf = surfaces()["open"]
    with pytest.raises(InputError, match="refine in v must be an integer >= 0"):
        refine_surface(surf, insert=(1, -1))
    with pytest.raises(InputError, match="elevate in u is 9; at most 6"):
        refine_surface(surf, elevate=(9, 0))
    big = sd.shapes.plane(cells=(40, 2), degree=2)
    with pytest.raises(InputError, match="refining direction u .* gives about 2602 functions "
                                         "from 42; at most 1024"):
        refine_surface(big, insert=(64, 0))


CASE = ('[material]\nw10 = 1.0\nw01 = 1.0\n[boundary]\nu0 = "pinned"\nu1 = "pinned"\n'
        '[[load]]\nkind = "pressure"\nq = -1.0\n[solve]\nkind = "static"\n')


def test_scenario_refines_a_cad_surface(tmp_path):
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    assert r3
    from splinedeform.cad import write_3dm

    write_3dm(tmp_path / "roof.3dm", [rational_patch()])
    path = tmp_path / "case.toml"
    path.write_text('[surface]\nshape = "cad"\npath = "roof.3dm"\nrefine = {u = 3, v = 1}\n'
                    'elevate = {v = 1}\n' + CASE)
    scenario = load_scenario(path)
    assert scenario.surface.refine == (3, 1) and scenario.surface.elevate == (0, 1)
    surf = build(scenario).surface
    coarse = surface_from_patch(rational_patch())
    # u: 3 points + 3 inserted; v: 6 points, elevation adds one per span and end (8), + 2
    assert surf.shape == (3 + 3, 8 + 2)
    # written to .3dm and read back (full doubles), then refined: round-off
    assert _grid_gap(coarse, surf) <= 1e-12
    again = parse_scenario(scenario_to_toml(scenario), directory=tmp_path)
    assert again.surface.refine == (3, 1) and again.surface.elevate == (0, 1)


def test_scenario_refusals_are_located(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text('[surface]\nshape = "cylinder"\nelevate = 1\n' + CASE)
    with pytest.raises(ScenarioError, match=r"surface\.elevate.*periodic layout"):
        build(load_scenario(path))
    path.write_text('[surface]\nshape = "plane"\nrefine = {w = 1}\n' + CASE)
    with pytest.raises(ScenarioError, match=r"surface\.refine.*inline table \{u = …, v = …\}"):
        load_scenario(path)


def test_c0_lines_with_bending_are_coupled_not_refused():
    b = KnotVectorBasis(3, [0, 0, 0, 0, 0.25, 0.25, 0.25, 1, 1, 1, 1])
    c = KnotVectorBasis(2, [0, 0, 0, 1, 1, 1])
    u, v = np.meshgrid(b.greville(), c.greville(), indexing="ij")
    surf = sd.Surface(np.stack([u, v, 0 * u], -1), b, c)
    model = sd.Model(surf, sd.Material(w10=1, w20=1))
    # the rotation penalty across u = 0.25 is no Kronecker product of the Gram factors
    assert sd.spectrum.kronecker_reason(model) == sd.spectrum.NO_FACTORS
    sd.ShellModel(surf, sd.ShellMaterial(E=1.0, nu=0.3, thickness=0.01, density=1.0))


def test_a_c0_cad_face_with_bending_builds_in_a_scenario(tmp_path):
    pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    from splinedeform.cad import write_3dm

    knots_u = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1.0])
    knots_v = np.array([0, 0, 0, 1, 1, 1.0])
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 3), indexing="ij")
    write_3dm(tmp_path / "kinked.3dm", [NurbsPatch((2, 2), knots_u, knots_v,
                                                   np.stack([x, y, x * y], -1), np.ones((5, 3)))])
    path = tmp_path / "case.toml"
    path.write_text('[surface]\nshape = "cad"\npath = "kinked.3dm"\n'
                    + CASE.replace("w01 = 1.0\n", "w01 = 1.0\nw20 = 0.1\n"))
    build(load_scenario(path))          # the C0 line u = 0.5 is coupled by its penalty
