"""A body's ``.3dm`` as one openNURBS Brep (cad_on_archive.py, cad_brep_3dm.py,
cad_brep_trims.py), read back by rhino3dm (not by the package's reader): valid, with the
topology's counts, its edges joined, its nets and its trim loops."""

import base64

import numpy as np
import pytest

import splinedeform as sd

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

from body_patches import rhino3dm_box  # noqa: E402
from splinedeform.body import Interface  # noqa: E402
from splinedeform.cad import FACE_NAME, NurbsPatch, patch_from_surface, write_3dm  # noqa: E402
from splinedeform.cad_body import read_body  # noqa: E402
from splinedeform.cad_brep_3dm import BrepTopology, body_brep  # noqa: E402
from splinedeform.cad_on_archive import BrepRecord, Nurbs, brep_bytes  # noqa: E402
from splinedeform.errors import InputWarning  # noqa: E402
from splinedeform.export.body import write_body_3dm  # noqa: E402
from splinedeform.trim.loops import CircleLoop, PolygonLoop, TrimDomain  # noqa: E402


def only_brep(path):
    """The one object of a .3dm file, a Brep, with its attributes."""
    model = r3.File3dm.Read(str(path))
    (obj,) = list(model.Objects)
    assert isinstance(obj.Geometry, r3.Brep)
    return obj.Geometry, obj.Attributes, model


def trims_per_edge(brep) -> list[int]:
    """How many trims use each edge (over every face's loops)."""
    count = [0] * len(brep.Edges)
    for face in brep.Faces:
        for loop in face.Loops:
            for trim in loop.Trims:
                if trim.EdgeIndex >= 0:
                    count[trim.EdgeIndex] += 1
    return count


def net_of(face) -> np.ndarray:
    """A face's control points (rhino3dm gives them homogeneous, (w x, w y, w z, w))."""
    srf = face.UnderlyingSurface().ToNurbsSurface()
    H = np.array([[[srf.Points[i, j].X, srf.Points[i, j].Y, srf.Points[i, j].Z,
                    srf.Points[i, j].W] for j in range(srf.Points.CountV)]
                  for i in range(srf.Points.CountU)])
    return H[..., :3] / H[..., 3:]


def assert_clean(brep):
    valid, log = brep.IsValidWithLog
    assert valid and not str(log).strip(), log


def test_a_brep_rhino3dm_made_is_written_back_byte_for_byte():
    """The writer reproduces rhino3dm's own archive of a one-face Brep, read field by
    field from rhino3dm's API (bytes compared: the same record, not two computations)."""
    srf = r3.NurbsSurface.Create(3, False, 3, 3, 4, 3)
    for i, j in np.ndindex(4, 3):
        srf.Points[i, j] = r3.Point4d(i, j, 0.1 * i * j, 1)
    for i, k in enumerate([0, 0, 1, 2, 2]):
        srf.KnotsU[i] = k
    for i, k in enumerate([0, 0, 1, 1]):
        srf.KnotsV[i] = k
    brep = r3.Brep.CreateFromSurface(srf)
    source = base64.b64decode(brep.Encode()["data"])
    full = lambda t: np.r_[t[0], t, t[-1]]  # noqa: E731
    net = np.array([[[i, j, 0.1 * i * j] for j in range(3)] for i in range(4)], float)
    record = BrepRecord(surfaces=[Nurbs((2, 2), (full([0, 0, 1, 2, 2.]), full([0, 0, 1, 1.])),
                                        net)])
    corners = [(0, 0), (2, 0), (2, 1), (0, 1)]
    iso = [4, 5, 6, 3]
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        length = 2.0 if k % 2 == 0 else 1.0
        record.curves_2d.append(Nurbs((1,), (np.array([0, 0, length, length]),),
                                      np.array([a, b], float)))
        record.trims.append({"c2i": k, "domain": (0.0, length), "ei": k,
                             "vi": (k, (k + 1) % 4), "rev3d": False, "type": 1,
                             "iso": iso[k], "li": 0})
    for k, edge in enumerate(brep.Edges):      # rhino3dm's own edge curves and vertices
        c = edge.ToNurbsCurve()
        knots = [c.Knots[i] for i in range(len(c.Knots))]
        record.curves_3d.append(Nurbs((c.Degree,), (full(knots),), np.array(
            [[c.Points[i].X, c.Points[i].Y, c.Points[i].Z] for i in range(len(c.Points))])))
        record.edges.append({"c3i": k, "vi": (k, (k + 1) % 4), "ti": [k],
                             "domain": (edge.Domain.T0, edge.Domain.T1)})
    for v in brep.Vertices:
        p = v.Location
        record.vertices.append({"point": (p.X, p.Y, p.Z), "ei": list(v.EdgeIndices())})
    record.loops.append({"ti": [0, 1, 2, 3], "type": 1, "fi": 0})
    record.faces.append({"li": [0], "si": 0, "rev": False})
    assert brep_bytes(record) == source


@pytest.fixture(scope="module")
def box(tmp_path_factory):
    """The 1 × 2 × 3 box of docs/cad.md (rhino3dm, metres) and a deformed net per face
    (a smooth field applied to every control point, so shared edges move alike)."""
    surfaces, topology, info = read_body(rhino3dm_box(tmp_path_factory.mktemp("brep"), "Meters"))
    body = sd.Body(surfaces, topology.interfaces,
                   orientation=[-1 if r else 1 for r in info["reversed"]])
    nets = [P + 0.01 * np.stack([np.sin(P[..., 1]), np.cos(P[..., 2]), P[..., 0] * P[..., 1]],
                                axis=-1) for P in (s.control_points for s in surfaces)]
    return body, nets, info["units"]


def test_the_box_is_one_valid_closed_brep_with_its_nets(box, tmp_path):
    body, nets, units = box
    path = write_body_3dm(tmp_path / "box.3dm", list(body), nets, units=units, body=body,
                          name="box")
    brep, attributes, model = only_brep(path)
    assert str(model.Settings.ModelUnitSystem).endswith("Meters")
    assert attributes.Name == "box"
    assert [attributes.GetUserString(f"{FACE_NAME}{k}") for k in range(6)] == \
        [s.name for s in body]
    assert_clean(brep)
    assert (len(brep.Faces), len(brep.Edges), len(brep.Vertices)) == (6, 12, 8)
    assert [len(list(f.Loops)) for f in brep.Faces] == [1] * 6
    assert trims_per_edge(brep) == [2] * 12             # every edge joins two faces
    assert brep.IsSolid
    for face, P in zip(brep.Faces, nets):
        # the numbers written read back as doubles (weights 1): 1e-12 of the size
        np.testing.assert_allclose(net_of(face), P, rtol=0, atol=1e-12 * 3)


def test_a_sphere_from_opencascade_is_solid_with_its_seam_and_poles(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    source = tmp_path / "sphere.step"
    writer = STEPControl_Writer()
    shape = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeSphere(1.5).Shape(), True).Shape()
    assert writer.Transfer(shape, STEPControl_AsIs) == 1 and writer.Write(str(source)) == 1
    surfaces, topology, info = read_body(source)
    body = sd.Body(surfaces, topology.interfaces,
                   orientation=[-1 if r else 1 for r in info["reversed"]])
    assert body.summary()["seam"] == 1 and body.summary()["poles"] == 2
    nets = [s.control_points * 1.1 for s in surfaces]     # inflated by 10 %
    brep, _, _ = only_brep(write_body_3dm(tmp_path / "sphere.3dm", list(body), nets,
                                          units=info["units"], body=body))
    assert_clean(brep)
    # one face, one seam edge used twice by its loop, two singular trims at the poles
    assert (len(brep.Faces), len(brep.Edges), len(brep.Vertices)) == (1, 1, 2)
    trims = list(brep.Faces[0].OuterLoop.Trims)
    assert sorted(t.EdgeIndex for t in trims) == [-1, -1, 0, 0]
    assert brep.IsSolid
    P = nets[0]
    scale = np.abs(P).max()
    # weights are not 1 here: x = (w x)/w read back, a few roundings of the size
    np.testing.assert_allclose(net_of(brep.Faces[0]), P, rtol=0, atol=1e-12 * scale)


def test_an_open_body_has_as_many_naked_edges_as_its_boundary(tmp_path):
    """Two plates side by side with different cells (a non-conforming interface) and a
    third on top of the first: 3 faces, 2 shared edges, 8 boundary edges."""
    left = sd.shapes.plane(size=(0.5, 1.0), cells=(2, 2))
    right = sd.shapes.plane(size=(0.5, 1.0), cells=(3, 2))
    right = right.with_control_points(right.control_points + [0.5, 0, 0])
    top = left.with_control_points(left.control_points + [0, 1.0, 0])
    body = sd.Body([left, right, top])
    assert body.summary()["shared"] == 2 and body.summary()["boundary"] == 8
    nets = [s.control_points for s in body]
    brep, _, _ = only_brep(write_body_3dm(tmp_path / "open.3dm", list(body), nets,
                                          body=body))
    assert_clean(brep)
    counts = trims_per_edge(brep)
    assert len(brep.Faces) == 3 and len(counts) == 10
    assert counts.count(1) == body.summary()["boundary"] and counts.count(2) == 2
    assert not brep.IsSolid


def loop_points(pieces: np.ndarray, count: int = 9) -> np.ndarray:
    """Points of Bézier pieces ``(K, n + 1, 2)`` at ``count`` parameters each."""
    from splinedeform.trim.bezier import evaluate

    return evaluate(pieces, np.linspace(0.0, 1.0, count)).reshape(-1, 2)


def test_a_trimmed_face_keeps_its_loops(tmp_path):
    """A cubic patch z = 0.3 x y² trimmed by a quadrilateral with a circular hole: the
    trims read back from the Brep's edges (as the package reads any .3dm Brep face,
    cad_trims_3dm.brep_face_trims) lie on the model's loops."""
    from splinedeform.cad_trims_3dm import brep_face_trims

    plane = sd.shapes.plane(size=(1.0, 1.0), cells=(4, 4), degree=3, knots="open")
    P = plane.control_points.copy()
    P[..., 2] = 0.3 * P[..., 0] * P[..., 1] ** 2
    domain = TrimDomain(PolygonLoop([[0.1, 0.1], [0.9, 0.15], [0.8, 0.9], [0.2, 0.8]]),
                        holes=(CircleLoop((0.5, 0.45), 0.2),))
    path = write_3dm(tmp_path / "trimmed.3dm", [patch_from_surface(plane, P)],
                     names=["sheet"], trims=[domain], body=BrepTopology((), name="sheet"))
    brep, attributes, _ = only_brep(path)
    assert_clean(brep)
    face = brep.Faces[0]
    assert [str(lp.LoopType).split(".")[-1] for lp in face.Loops] == ["Outer", "Inner"]
    assert trims_per_edge(brep) == [1, 1]
    got = brep_face_trims(brep, face, "trimmed face")
    assert len(got["loops"]) == 2
    for loop, pieces in zip(domain.loops, got["loops"]):
        x = loop_points(pieces)
        # on the loop: the edge is S(c(t)) to round-off, its points projected back onto
        # the surface by Gauss-Newton (converged to ~1e-15) and fitted by the reader to
        # 1e-10 of the domain: 1e-9
        assert np.abs(loop.distance(x)).max() <= 1e-9
        # and all of it: the read-back loop reaches every point of the model's loop
        ends = pieces[:, [0, -1]].reshape(-1, 2)
        assert np.ptp(ends, axis=0).min() > 0.3
    # the outer loop's area (shoelace of dense points: polygon edges exact) is kept
    outer = loop_points(got["loops"][0], 65)
    area = 0.5 * np.sum(outer[:, 0] * np.roll(outer[:, 1], -1)
                        - np.roll(outer[:, 0], -1) * outer[:, 1])
    # a polygon read back as straight pieces: its shoelace area exact to round-off 1e-12
    assert abs(area - domain.outer.signed_area) <= 1e-9


def test_iso_trims_carry_the_flags_openNURBS_computes(tmp_path):
    """openNURBS' validity check recomputes every trim's iso flag from its 2-D curve
    (``ON_Surface::IsIsoparametric``): a polygon loop with sides on the domain's edges
    (S, E), inside it (x, y) and slanted (none), each of its sides one trim, is valid."""
    plane = sd.shapes.plane(size=(1.0, 1.0), cells=(3, 3), degree=2, knots="open")
    polygon = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [1.0, 0.6], [0.5, 0.6], [0.5, 0.9],
                           [0.1, 0.8]])
    domain = TrimDomain(polygon, edges=((0, 1, 2, 3, 4, 5),))
    brep = body_brep([patch_from_surface(plane)], BrepTopology(()), r3, [domain])
    assert_clean(brep)
    assert len(list(brep.Faces[0].OuterLoop.Trims)) == 6 and len(brep.Vertices) == 6


def test_two_trimmed_faces_meeting_along_a_circle_share_one_edge(tmp_path):
    """The unit square as a disc face and a face of the square less the disc (two
    trimmed patches of different cells): the disc's loop and the ring's hole are one
    closed edge, run opposite ways (both faces keep their normals), and only the square's
    four sides are naked, as the body's boundary says."""
    circle = CircleLoop((0.5, 0.5), 0.3)
    square = PolygonLoop([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    disc = sd.shapes.plane(cells=(3, 3), degree=3, knots="open")
    ring = sd.shapes.plane(cells=(4, 4), degree=3, knots="open")
    body = sd.Body([disc.with_trim(TrimDomain(circle)),
                    ring.with_trim(TrimDomain(square, (circle,)))])
    assert len(body.trim_interfaces) == 1 and body.summary()["boundary"] == 4
    brep, _, _ = only_brep(write_body_3dm(tmp_path / "split.3dm", list(body),
                                          [s.control_points for s in body], body=body))
    assert_clean(brep)
    counts = trims_per_edge(brep)
    assert len(brep.Faces) == 2 and counts.count(1) == 4 and counts.count(2) == 1
    (disc_trim,) = list(brep.Faces[0].OuterLoop.Trims)
    (hole,) = [lp for lp in brep.Faces[1].Loops if str(lp.LoopType).endswith("Inner")]
    (hole_trim,) = list(hole.Trims)
    assert disc_trim.EdgeIndex == hole_trim.EdgeIndex
    assert disc_trim.IsReversed != hole_trim.IsReversed


def test_a_brep_that_cannot_be_formed_falls_back_to_one_surface_per_face(tmp_path):
    """An interface that joins a plate's side u0 to its own side v0 makes the corner
    (0, 0) both ends of one open edge: openNURBS refuses it, and the file holds the
    surface, with one warning line saying why."""
    plate = sd.shapes.plane(size=(1.0, 1.0), cells=(2, 2))
    topology = BrepTopology((Interface(0, "u0", 0, "v0", False, False),))
    with pytest.warns(InputWarning, match="separate surfaces, not one Brep: .*not valid"):
        path = write_3dm(tmp_path / "odd.3dm", [patch_from_surface(plate)], names=["plate"],
                         body=topology)
    (obj,) = list(r3.File3dm.Read(str(path)).Objects)
    assert obj.Attributes.Name == "plate" and not isinstance(obj.Geometry, r3.Brep)


def test_brep_faces_keep_a_reversed_orientation(tmp_path):
    plate = sd.shapes.plane(size=(1.0, 1.0), cells=(2, 2))
    brep = body_brep([patch_from_surface(plate)], BrepTopology((), (), (-1,)), r3)
    assert brep.Faces[0].OrientationIsReversed
    assert not body_brep([patch_from_surface(plate)], BrepTopology(()), r3
                         ).Faces[0].OrientationIsReversed


@pytest.mark.parametrize("shape, edges, vertices, naked, solid", [
    ("cylinder", 3, 2, 2, False),      # the seam, two circles (naked)
    ("torus", 2, 1, 0, True),          # two seams meeting at one vertex, closed
    ("half_sphere", 2, 2, 1, False),   # the seam, the rim (naked); a pole, no edge
])
def test_periodic_built_in_shapes_are_joined_along_their_seams(shape, edges, vertices, naked,
                                                               solid):
    """A periodic direction (its net unwrapped in the .3dm) is a seam of its face: one
    edge used twice by the face's loop."""
    surface = getattr(sd.shapes, shape)()
    body = sd.Body([surface])
    brep = body_brep([patch_from_surface(surface)], BrepTopology.of(body), r3)
    assert_clean(brep)
    counts = trims_per_edge(brep)
    assert (len(brep.Edges), len(brep.Vertices)) == (edges, vertices)
    assert counts.count(1) == naked == body.summary()["boundary"]
    assert brep.IsSolid == solid


def test_a_topology_of_other_faces_is_refused_with_a_warning(tmp_path):
    plate = sd.shapes.plane(size=(1.0, 1.0), cells=(2, 2))
    topology = BrepTopology((Interface(0, "u1", 3, "u0"),))
    with pytest.warns(InputWarning, match="names a face outside the 1 written"):
        write_3dm(tmp_path / "other.3dm", [patch_from_surface(plate)], body=topology)


def test_a_drilled_box_is_a_closed_brep_its_wall_sewn_to_the_holes(tmp_path_factory,
                                                                   tmp_path):
    """OpenCASCADE's box less a cylinder (tests/test_cad_step_trims.py): four planes, top
    and bottom holed (rectangles less a circle), the hole's wall a closed face. The body
    joins the planes along 12 edges and the wall along its seam; each hole's loop lies on
    a circle of the wall (a trim edge the body shares with it) and is sewn to it, as OpenCASCADE's
    file has it: no naked edge, a solid."""
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from occt_shapes import free_edges, read_shape
    from test_cad_step_trims import _box_body, drilled_box

    source = drilled_box.__wrapped__(tmp_path_factory)
    patches, signs, units = _box_body(source)
    body = sd.Body(patches, orientation=signs)
    # the wall's circles are the holes' trim edges, shared (coupled), not boundary edges
    assert body.summary()["boundary"] == 0
    assert body.trim_summary()["shared"] == 2
    brep, _, _ = only_brep(write_body_3dm(tmp_path / "drilled.3dm", patches,
                                          [s.control_points for s in patches], units=units,
                                          body=body))
    assert_clean(brep)
    counts = trims_per_edge(brep)
    assert (len(brep.Faces), len(brep.Edges)) == (7, 15)
    assert counts.count(1) == free_edges(read_shape(source)) == 0
    assert brep.IsSolid


def test_a_trim_edge_is_the_trim_curve_on_the_surface_to_round_off():
    """The 3-D edge of a loop on a rational, non-uniform surface is S(c(t)): exact between
    the knot lines it crosses, a rational polynomial of degree m (p + q) (a circle, m = 2,
    on degree (2, 2): 8), off S(c(t)) between its interpolation points by round-off."""
    from splinedeform.cad_brep_trims import loop_pieces, trim_edge

    knots = np.array([0, 0, 0, 0.3, 0.7, 1, 1, 1.0])
    x = np.linspace(0.0, 1.0, 5)
    P = np.stack([*np.meshgrid(x, x, indexing="ij"), np.zeros((5, 5))], axis=-1)
    P[..., 2] = 0.2 * np.sin(3 * P[..., 0]) * P[..., 1]
    w = 1.0 + 0.3 * np.outer(np.sin(np.arange(5.0)) ** 2, np.cos(np.arange(5.0)) ** 2)
    patch = NurbsPatch((2, 2), knots, knots, P, w)
    (pieces, weights), = loop_pieces(TrimDomain(CircleLoop((0.5, 0.45), 0.3)))
    edge, gap = trim_edge(pieces, weights, patch, 0.0)
    assert edge.degrees == (8,)
    assert gap <= 1e-13                        # round-off of the surface's size (1)
