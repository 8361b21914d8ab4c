"""Files for other programs: meshes, ParaView time series, control nets and reports.

Every file is written atomically (:mod:`.atomic`): the content goes to a temporary file
in the target folder, which then replaces the target with :func:`os.replace`.

* :mod:`.frames` — validation of frames, ``X = B_u P B_vᵀ`` for many nets at once;
* :mod:`.mesh` — triangle meshes (.obj with normals, .stl, .ply, .vtu, .vtk);
* :mod:`.weld` — welded meshes of closed and degenerate surfaces, vertex normals;
* :mod:`.series` — ParaView ``.pvd`` + ``.vtu`` time series;
* :mod:`.body` — a body's patches in one .3dm / STEP file, one welded mesh or series;
* :mod:`.modes` — vibration modes as displacement fields of one ``.vtu`` (a surface's or
  a body's, welded);
* :mod:`.nets` — control nets as JSON / NPZ with their full knot vectors;
* :mod:`.report` — ``report.json`` and ``report.md``;
* :mod:`.run_folder` — a run's manifest, stale files of earlier runs, the folder lock.
"""

from .atomic import atomic_path, write_text, write_with
from .frames import check_frames, check_net, tessellate_frames
from .mesh import MESH_FORMATS, write_mesh, write_obj
from .nets import (CONTROL_NET_FORMAT, CONTROL_NET_FORMATS, CONTROL_NET_VERSION, CONVENTION,
                   control_net_document, coefficient_index, read_control_net,
                   write_control_nets)
from .run_folder import (MANIFEST_FORMAT, FolderClaim, claim_folder, file_digest,
                         manifest_name, read_manifest)
from .report import (REPORT_TABLE_ROWS, format_value, plain, report_markdown, section_markdown,
                     write_report)
from .weld import WELD_TOLERANCE, vertex_normals, weld
from .series import frame_file_names, pvd_text, write_time_series
from .modes import mode_field_names, write_body_mode_fields, write_mode_fields

__all__ = ["FolderClaim", "MANIFEST_FORMAT", "claim_folder", "file_digest", "manifest_name",
           "read_manifest", "CONTROL_NET_FORMAT", "CONTROL_NET_FORMATS", "CONTROL_NET_VERSION", "CONVENTION",
           "coefficient_index", "control_net_document", "MESH_FORMATS", "REPORT_TABLE_ROWS",
           "atomic_path", "check_frames", "check_net", "format_value", "frame_file_names", "plain", "pvd_text",
           "read_control_net", "report_markdown", "section_markdown", "tessellate_frames",
           "write_control_nets", "write_mesh", "write_report", "write_text", "write_time_series",
           "write_with", "write_obj", "weld", "vertex_normals", "WELD_TOLERANCE",
           "mode_field_names", "write_body_mode_fields", "write_mode_fields"]
