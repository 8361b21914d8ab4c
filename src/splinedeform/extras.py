"""The optional packages of the extras, and which of them are installed (``splinedeform info``)."""

from __future__ import annotations

import importlib
from importlib import metadata

#: optional modules reported by ``splinedeform info``: import name -> (distribution, use)
OPTIONAL = {
    "typer": ("typer", "command line"),
    "rich": ("rich", "progress bars and tables"),
    "meshio": ("meshio", "OBJ / STL / PLY / VTU meshes"),
    "matplotlib": ("matplotlib", "pictures and GIF animation frames"),
    "imageio": ("imageio", "GIF animation"),
    "PIL": ("pillow", "GIF encoding"),
    "imageio_ffmpeg": ("imageio-ffmpeg", "MP4 animation (extra: video)"),
    "pyvista": ("pyvista", "offscreen 3-D rendering (extra: render3d)"),
    "playwright": ("playwright", "viewer test in a headless browser"),
    "starlette": ("starlette", "sculpt server (extra: sculpt)"),
    "uvicorn": ("uvicorn", "sculpt server (extra: sculpt)"),
    "rhino3dm": ("rhino3dm", "openNURBS .3dm files (extra: cad)"),
    "OCP": ("cadquery-ocp-novtk", "STEP and IGES files, OpenCASCADE (extra: cad-step)"),
    "distributed": ("distributed", "splinedeform sweep on Dask (extra: sweep)"),
    "pyarrow": ("pyarrow", "Parquet tables of sweeps (extra: sweep)"),
}


def optional_rows() -> list[tuple[str, str]]:
    """One row per optional package: its version if it imports, else why not."""
    rows = []
    for module, (dist, use) in OPTIONAL.items():
        try:
            importlib.import_module(module)
        except ImportError:
            rows.append((dist, f"not installed  ({use})"))
            continue
        except Exception as exc:  # noqa: BLE001  (installed but broken, e.g. a missing library)
            rows.append((dist, f"installed but fails to import: {type(exc).__name__}: {exc}  "
                               f"({use})"))
            continue
        try:
            version = metadata.version(dist)
        except metadata.PackageNotFoundError:
            version = "?"
        rows.append((dist, f"{version}  ({use})"))
    return rows
