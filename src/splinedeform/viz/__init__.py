"""Pictures, animations and the interactive HTML viewer of a deforming surface.

* :mod:`.colour` — displacement colours (``plasma``) and Lambert shading;
* :mod:`.figures` — matplotlib helpers (Agg canvas, no pyplot state);
* :mod:`.surfaces` — ``surfaces.png`` (PyVista if it can render off screen, else matplotlib);
* :mod:`.plots` — ``probes.png`` and ``modes.png``;
* :mod:`.animation` — GIF / MP4, drawn and encoded frame by frame;
* :mod:`.gif` — the GIF's one palette (the colour bar's ramp held exactly) and its writer;
* :mod:`.warp` — the warp factor of the pictures (``output.warp``);
* :mod:`.viewer` — ``viewer.html``; :mod:`.viewer_body` — the one of a body.
"""

from .animation import (ANIMATION_PIXELS, animation_frames, mp4_available, write_animation,
                        write_body_animation)
from .colour import COLORMAP, LIGHT, MODE_COLORMAP, colormap_table, displacement_colors, shade
from .figures import COLORBAR_INCHES, DPI, PANEL_INCHES, RENDERER_VERSION
from .plots import mode_geometry, plot_body_modes, plot_modes, plot_probes
from .surfaces import render_body_surfaces, render_surfaces
from .viewer import content_security_policy, script_json, vertex_checksum, viewer_data, viewer_html, write_viewer

__all__ = ["ANIMATION_PIXELS", "COLORBAR_INCHES", "COLORMAP", "DPI", "LIGHT", "MODE_COLORMAP",
           "PANEL_INCHES", "RENDERER_VERSION", "animation_frames", "colormap_table",
           "content_security_policy", "displacement_colors",
           "mode_geometry", "mp4_available", "plot_body_modes", "plot_modes", "plot_probes",
           "render_body_surfaces", "render_surfaces",
           "script_json", "shade", "vertex_checksum", "viewer_data", "viewer_html",
           "write_animation", "write_body_animation", "write_viewer"]
