"""Control-net files of rational (NURBS) and general-knot surfaces: read back by us, and
rebuilt from the file alone by other libraries in homogeneous coordinates.

The surface is the exact quarter of the unit cylinder on non-uniform knots (knot insertion
at 0.3 and 0.7 in u, at 0.5 in v), deformed by a smooth non-symmetric field. Tolerance
1e-12 of the net's size: every evaluator sums at most 9 products of O(1) numbers and
divides once, round-off ~1e-15; a dropped weight is wrong by ~0.1 (the radius error of a
polynomial quarter circle through the same control points).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.interpolate import NdBSpline

import splinedeform as sd
from splinedeform.cad import NurbsPatch, surface_from_patch
from splinedeform.export import read_control_net, write_control_nets
from splinedeform.errors import InputError

S = np.sqrt(0.5)


def cylinder_on_odd_knots() -> sd.Surface:
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 1.0], ring + [0, 0, 2.0]], axis=1)
    knots = np.array([0, 0, 0, 1, 1, 1.0])
    patch = NurbsPatch((2, 2), knots, 2 * knots, points, np.outer([1, S, 1], [1, 1, 1]))
    # insert knots by the library's refinement at non-uniform places: solve for the new net
    from splinedeform.knots import KnotVectorBasis

    def insert(n, t, new):
        coarse, fine = KnotVectorBasis(n, t), KnotVectorBasis(n, np.sort(np.r_[t, new]))
        g = fine.greville()
        return fine.knots, np.linalg.solve(fine(g), coarse(g))

    ku, Su = insert(2, patch.knots_u, [0.3, 0.7])
    kv, Sv = insert(2, patch.knots_v, [1.0])
    w = patch.weights
    hom = np.concatenate([patch.points * w[..., None], w[..., None]], axis=-1)
    hom = np.einsum("ai,ijc,bj->abc", Su, hom, Sv)
    return surface_from_patch(NurbsPatch((2, 2), ku, kv, hom[..., :3] / hom[..., 3:],
                                         hom[..., 3]))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    surface = cylinder_on_odd_knots()
    assert isinstance(surface.basis_u, sd.RationalBasis)
    P = surface.control_points
    bump = np.sin(np.arange(P.shape[0]))[:, None, None] * np.cos(np.arange(P.shape[1]))[None, :, None]
    nets = np.stack([P, P + 0.2 * bump * np.array([1.0, -0.5, 2.0])])
    folder = tmp_path_factory.mktemp("rational")
    write_control_nets(folder, "nets", surface, [0.0, 1.0], nets)
    return surface, nets, folder


def grid(surface):
    return (np.linspace(0, surface.basis_u.length, 50), np.linspace(0, surface.basis_v.length, 50))


def expected(surface, nets, frame):
    return surface.evaluate_grid(*grid(surface), control_points=nets[frame])


def test_read_back_keeps_knots_and_weights(written):
    surface, nets, folder = written
    for suffix in (".json", ".npz"):
        back = read_control_net(folder / f"nets{suffix}", frame=1)
        assert isinstance(back.basis_u, sd.RationalBasis)
        assert isinstance(back.basis_v, sd.KnotVectorBasis)
        # knots and weights stored by repr / float64: the same numbers, compared to 1e-15
        assert np.abs(back.basis_u.knots - surface.basis_u.knots).max() <= 1e-15
        assert np.abs(back.weights - surface.weights).max() <= 1e-15
        got = back.evaluate_grid(*grid(surface))
        assert np.abs(got - expected(surface, nets, 1)).max() <= 1e-12


def test_scipy_rebuilds_the_nurbs_from_the_file_alone(written):
    surface, nets, folder = written
    doc = json.loads((folder / "nets.json").read_text())
    u, v = doc["basis"]["u"], doc["basis"]["v"]
    assert (u["kind"], v["kind"]) == ("rational", "general")
    c = np.asarray(doc["control_points"][1])[u["coefficient_index"]][:, v["coefficient_index"]]
    w = np.asarray(doc["weights"])[u["coefficient_index"]][:, v["coefficient_index"]]
    hom = np.concatenate([c * w[..., None], w[..., None]], axis=-1)
    spline = NdBSpline((np.array(u["knots"]), np.array(v["knots"])), hom,
                       (u["degree"], v["degree"]))
    a, b = grid(surface)
    uu, vv = np.meshgrid(a, b, indexing="ij")
    h = spline(np.stack([uu, vv], axis=-1))
    assert np.abs(h[..., :3] / h[..., 3:] - expected(surface, nets, 1)).max() <= 1e-12
    # the rest frame is the exact cylinder: radius 1 to round-off
    rest = NdBSpline(spline.t, np.concatenate(
        [np.asarray(doc["control_points"][0]) * w[..., None], w[..., None]], axis=-1), spline.k)
    r = rest(np.stack([uu, vv], axis=-1))
    assert np.abs(np.hypot(*(r[..., :2] / r[..., 3:]).transpose(2, 0, 1)) - 1).max() <= 1e-12


def test_geomdl_rebuilds_the_nurbs_from_the_file_alone(written):
    NURBS = pytest.importorskip("geomdl.NURBS", reason="geomdl is not installed")
    surface, nets, folder = written
    with np.load(folder / "nets.npz", allow_pickle=False) as z:
        c = z["control_points"][1][z["coefficient_index_u"]][:, z["coefficient_index_v"]]
        w = z["weights"][z["coefficient_index_u"]][:, z["coefficient_index_v"]]
        ku, kv = z["knots_u"], z["knots_v"]
        pu, pv = int(z["degree_u"]), int(z["degree_v"])
    patch = NURBS.Surface(normalize_kv=False)
    patch.degree_u, patch.degree_v = pu, pv
    patch.ctrlpts_size_u, patch.ctrlpts_size_v = c.shape[0], c.shape[1]
    patch.ctrlpts = c.reshape(-1, 3).tolist()          # v fastest, as geomdl expects
    patch.weights = w.ravel().tolist()
    patch.knotvector_u, patch.knotvector_v = ku.tolist(), kv.tolist()
    a, b = (x[::5] for x in grid(surface))              # geomdl evaluates point by point
    got = np.asarray(patch.evaluate_list([(p, q) for p in a for q in b])).reshape(a.size, b.size, 3)
    want = surface.evaluate_grid(a, b, control_points=nets[1])
    assert np.abs(got - want).max() <= 1e-12


def test_splipy_rebuilds_the_nurbs_from_the_file_alone(written):
    splipy = pytest.importorskip("splipy", reason="splipy is not installed")
    surface, nets, folder = written
    doc = json.loads((folder / "nets.json").read_text())
    u, v = doc["basis"]["u"], doc["basis"]["v"]
    bases = [splipy.BSplineBasis(d["degree"] + 1, np.asarray(d["knots"])) for d in (u, v)]
    c = np.asarray(doc["control_points"][1])[u["coefficient_index"]][:, v["coefficient_index"]]
    w = np.asarray(doc["weights"])[u["coefficient_index"]][:, v["coefficient_index"]]
    # splipy's rational controlpoints are homogeneous (w x, w y, w z, w)
    patch = splipy.Surface(*bases, np.concatenate([c * w[..., None], w[..., None]], axis=-1),
                           rational=True, raw=True)
    got = patch(*grid(surface))
    assert np.abs(got - expected(surface, nets, 1)).max() <= 1e-12


def test_bad_weights_are_refused(written, tmp_path):
    surface, nets, folder = written
    doc = json.loads((folder / "nets.json").read_text())
    doc["weights"] = doc["weights"][:-1]
    (tmp_path / "short.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match="short.json: NURBS weights must be > 0 of shape"):
        read_control_net(tmp_path / "short.json")


def test_weights_on_polynomial_directions_are_general_weights(written, tmp_path):
    """Differing weights on directions not marked rational are read per control point:
    the same surface (the product weights given as general ones)."""
    surface, nets, folder = written
    doc = json.loads((folder / "nets.json").read_text())
    doc["basis"]["u"]["kind"] = "general"
    doc["basis"]["v"]["kind"] = "general"
    (tmp_path / "general.json").write_text(json.dumps(doc))
    back = read_control_net(tmp_path / "general.json")
    assert back.net_weights is not None
    u, v = np.linspace(0, surface.domain[0][1], 7), np.linspace(0, surface.domain[1][1], 5)
    # the same rational function by two evaluations (per direction, homogeneous): to 1e-13
    # of the net's size (a few roundings of a degree-3 quotient)
    size = np.abs(nets[-1]).max()
    assert np.abs(back.evaluate_grid(u, v) - surface.evaluate_grid(
        u, v, control_points=nets[-1])).max() <= 1e-13 * size


def test_polynomial_nets_state_unit_weights(tmp_path):
    plane = sd.shapes.plane(cells=(3, 2))
    write_control_nets(tmp_path, "plane", plane, [0.0], plane.control_points[None])
    doc = json.loads((tmp_path / "plane.json").read_text())
    # unit weights are written as 1.0 and read back by JSON; one rounding (2⁻⁵³) at most
    np.testing.assert_allclose(np.asarray(doc["weights"]), np.ones(plane.shape), rtol=1e-15,
                               atol=0)
