"""A single CAD face marked reversed in its Brep, run alone, pushes along its outward normal.

A face that its Brep marks reversed (OpenCASCADE's ``TopAbs_REVERSED``, rhino3dm's
``BrepFace.OrientationIsReversed``) has the outward normal ``-(S_u × S_v)``. Read alone
(``face = k``) its surface has :attr:`~splinedeform.Surface.orientation` ``-1``, and every
physics' pressure vector is its surface's own turned over, as on a body's patch
(:attr:`splinedeform.body.Body.orientation`); the parameters stay as they are, and a
uniform force is not turned. Checked independently of the flags: the faces are flat faces
of a box, so the pressure's resultant ``∫ q n dA`` must point away from the box's centre.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import splinedeform as sd

SIZE = (2.0, 3.0, 1.0)
CENTRE = 0.5 * np.asarray(SIZE)
PHYSICS = {"parametric": "w10 = 1.0\nw01 = 1.0\n",
           "intrinsic": 'physics = "intrinsic"\nw10 = 1.0\nw01 = 1.0\n',
           "shell": 'physics = "shell"\nE = 1e4\nnu = 0.3\nthickness = 0.01\n'}
BOUNDARY = '[boundary]\nu0 = "clamped"\n'


def built(folder, source, face: int, physics: str, load: str = "pressure"):
    """``build`` of a static scenario of face ``face`` alone under a unit ``load``."""
    from splinedeform.scenario import build, load_scenario

    force = 'q = 1.0' if load == "pressure" else 'force = [0.0, 0.0, 1.0]'
    path = folder / f"face{face}_{physics}_{load}.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{source}"\nface = {face}\n'
                    'elevate = 1\nrefine = 2\n'      # bilinear faces: room to bend
                    f'[material]\n{PHYSICS[physics]}{BOUNDARY}'
                    f'[[load]]\nkind = "{load}"\n{force}\n[solve]\nkind = "static"\n')
    return build(load_scenario(path))


def plain_vector(result, load):
    """The same model's load vector on the same surface with orientation ``+1``."""
    surface = replace(result.surface, orientation=1)
    model = result.model
    if model.physics == "shell":
        other = sd.ShellModel(surface, model.material, dict(model.edges))
    else:
        other = sd.Model(surface, model.material, {"u0": "clamped"}, physics=model.physics)
    return other.load_vector(load)


def outward_resultant(result) -> float:
    """``Σ_k F_k · n_out`` of the model's full pressure vector: the resultant along the flat
    face's outward normal (the face's axis, pointing away from the box's centre)."""
    surface = result.surface
    points = surface.control_points.reshape(-1, 3)
    axis = int(np.argmin(np.ptp(points, axis=0)))               # the face is flat
    normal = np.zeros(3)
    normal[axis] = np.sign(points[0, axis] - CENTRE[axis])
    F = result.model.reduction.field(sd.Pressure(1.0)).reshape(-1, 3)
    return float(F.sum(axis=0) @ normal), float(np.linalg.norm(F, axis=1).sum())


def check_faces(tmp_path, source, flags):
    turned = [k for k, r in enumerate(flags) if r]
    kept = [k for k, r in enumerate(flags) if not r]
    assert turned and kept                                  # both kinds on the box
    for physics in PHYSICS:
        for face in (turned[0], kept[0]):
            result = built(tmp_path, source, face, physics)
            assert result.surface.orientation == (-1 if face in turned else 1)
            F = result.model.load_vector(sd.Pressure(1.0))
            G = plain_vector(result, sd.Pressure(1.0))
            # the same quadrature on the same surface: equal or opposite to round-off
            sign = -1.0 if face in turned else 1.0
            assert np.abs(F - sign * G).max() <= 1e-12 * np.abs(G).max()
            along, total = outward_resultant(result)
            # the resultant q A n_out: along the outward normal, |Σ F| = Σ |F| on a flat
            # face (every control point's force is along n), to round-off
            assert along >= (1 - 1e-9) * total
    uniform = built(tmp_path, source, turned[0], "parametric", "uniform")
    F = uniform.model.load_vector(uniform.load)
    G = plain_vector(uniform, uniform.load)
    assert np.abs(F - G).max() <= 1e-12 * np.abs(G).max()         # not turned


def test_a_3dm_face_marked_reversed_pushes_outwards_alone(tmp_path):
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    model = r3.File3dm()
    brep = r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, *SIZE)))
    # rhino3dm's box has every S_u × S_v outwards: turn face 2's surface round (its
    # transposed net) and mark the face reversed, so its outward normal is -(S_u × S_v)
    srf = brep.Faces[2].UnderlyingSurface().ToNurbsSurface()
    cu, cv = srf.Points.CountU, srf.Points.CountV
    swapped = r3.NurbsSurface.Create(3, False, srf.OrderV, srf.OrderU, cv, cu)
    for i, k in enumerate(srf.KnotsV):
        swapped.KnotsU[i] = k
    for i, k in enumerate(srf.KnotsU):
        swapped.KnotsV[i] = k
    for i, j in np.ndindex(cu, cv):
        swapped.Points[j, i] = srf.Points[i, j]
    turned = r3.Brep.CreateFromSurface(swapped)
    turned.Faces[0].OrientationIsReversed = True
    flags = [False] * 6
    for k, face in enumerate(brep.Faces):
        if k == 2:
            model.Objects.AddBrep(turned)
            flags[k] = True
        else:
            model.Objects.AddBrep(r3.Brep.CreateFromSurface(
                face.UnderlyingSurface().ToNurbsSurface()))
    path = tmp_path / "box.3dm"
    assert model.Write(str(path), 7)
    from splinedeform.cad import read_cad

    assert [read_cad(path, k).reversed for k in range(6)] == flags
    check_faces(tmp_path, path.name, flags)
    # read as a body, the surfaces carry the same signs, and a body made of them without
    # naming its orientation takes theirs
    from splinedeform.cad_body import read_body

    surfaces, topology, info = read_body(path)
    signs = tuple(-1 if r else 1 for r in info["reversed"])
    assert signs == tuple(-1 if r else 1 for r in flags)
    assert tuple(s.orientation for s in surfaces) == signs
    assert sd.Body(surfaces, topology.interfaces).orientation == signs


def test_an_opencascade_face_marked_reversed_pushes_outwards_alone(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from splinedeform.cad import read_cad
    from splinedeform.cad_faces import read_faces

    shape = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(*SIZE).Shape(), True).Shape()
    path = tmp_path / "box.step"
    writer = STEPControl_Writer()
    assert writer.Transfer(shape, STEPControl_AsIs) == 1
    assert writer.Write(str(path)) == 1
    flags = [f["reversed"] for f in read_faces(path)["faces"]]
    assert len(flags) == 6
    assert [read_cad(path, k).reversed for k in range(6)] == flags
    check_faces(tmp_path, path.name, flags)


@pytest.mark.parametrize("bad", [0, 2, True, "-1"])
def test_an_orientation_is_one_sign(bad):
    plane = sd.shapes.plane(cells=2)
    with pytest.raises(sd.InputError, match="orientation must be"):
        sd.Surface(plane.control_points, plane.basis_u, plane.basis_v, orientation=bad)
