"""The .pvd/.vtu series read by ParaView's own reader: Warp By Vector gives the deformed shape.

Runs Debian's ``pvpython`` (package ``paraview``) in a subprocess; skipped when absent.
ParaView's points are matched to the rest grid by nearest neighbour (the mesh may be
welded, so point order is not assumed), and the warped points are compared with the
deformed surface evaluated point by point by :meth:`Surface.evaluate`. Tolerance 1e-12
of the size: the file stores float64, ParaView adds rest + displacement once (one
rounding); a displacement applied twice or not at all is off by the displacement itself,
here 0.2–0.6.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import textwrap

import numpy as np
import pytest
from scipy.spatial import cKDTree

from splinedeform import shapes
from splinedeform import export

PVPYTHON = shutil.which("pvpython")
pytestmark = pytest.mark.skipif(PVPYTHON is None, reason="ParaView's pvpython is not installed "
                                                        "(Debian package 'paraview')")

WARP = textwrap.dedent("""
    import json, sys
    from paraview import servermanager
    from paraview.simple import PVDReader, WarpByVector
    from vtk.util.numpy_support import vtk_to_numpy

    reader = PVDReader(FileName=sys.argv[1])
    warp = WarpByVector(Input=reader)
    warp.Vectors = ["POINTS", "displacement"]
    warp.ScaleFactor = 1.0
    frames = []
    for t in reader.TimestepValues:
        warp.UpdatePipeline(t)
        rest, moved = servermanager.Fetch(reader), servermanager.Fetch(warp)
        data = rest.GetPointData()
        frames.append({"time": t,
                       "rest": vtk_to_numpy(rest.GetPoints().GetData()).tolist(),
                       "warped": vtk_to_numpy(moved.GetPoints().GetData()).tolist(),
                       "arrays": [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]})
    with open(sys.argv[2], "w") as fh:
        json.dump(frames, fh)
""")


def test_paraview_warp_by_vector_gives_the_deformed_surface(tmp_path):
    surface = shapes.half_sphere(cells=(8, 4))
    P = surface.control_points
    times = np.array([0.0, 0.25, 1.0])
    # varies around the axis but not at the pole row, so the pole stays one point
    k = np.arange(P.shape[0])[:, None, None]
    fade = 1.0 - np.arange(P.shape[1])[None, :, None] / (P.shape[1] - 1)
    field = np.concatenate([0.2 * np.cos(k) * fade * np.ones_like(P[..., :2]),
                            0.6 * np.ones_like(P[..., :1])], axis=-1)
    nets = P[None] + times[:, None, None, None] * field[None]
    r = 9
    pvd = export.write_time_series(tmp_path, "motion", surface, P, times, nets, resolution=r)
    (tmp_path / "warp.py").write_text(WARP)
    subprocess.run([PVPYTHON, str(tmp_path / "warp.py"), str(pvd), str(tmp_path / "out.json")],
                   check=True, capture_output=True, timeout=300)
    frames = json.loads((tmp_path / "out.json").read_text())
    assert [f["time"] for f in frames] == times.tolist()

    u, v = surface.sample_parameters(r)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    rest_grid = surface.evaluate(uu, vv).reshape(-1, 3)
    for f, frame in enumerate(frames):
        assert {"displacement", "displacement_magnitude"} <= set(frame["arrays"])
        seen = np.asarray(frame["rest"])
        distance, index = cKDTree(rest_grid).query(seen)
        assert distance.max() < 1e-12                     # the points are the rest geometry
        moved = surface.with_control_points(nets[f]).evaluate(uu, vv).reshape(-1, 3)[index]
        np.testing.assert_allclose(np.asarray(frame["warped"]), moved, rtol=0, atol=1e-12)
