"""The sculpting page: one HTML file with the vendored three.js and the modal data inlined.

The page does the per-frame work itself (``data/sculpt_template.html`` and the parts of its
script in ``data/sculpt/``, concatenated in :data:`PARTS` order into one function scope): it
carries the modal state ``(q, q', f)`` of every mode from event to event in closed form
(:mod:`.state` is its Python twin) and sums ``x = x0 + Φ_s q(t)`` (plus the static
correction of held pushes) over the sample grid in typed arrays. Saved from the browser it
keeps working offline; only a re-solve, the static correction and "Save" need the server.
"""

from __future__ import annotations

import html
import re
from importlib import resources
from typing import Any, Mapping

from ..viz import colormap_table, script_json
from ..viz.viewer import _vendor_text


#: the parts of the page's script, in the order they are put together
PARTS = ("state", "draw", "grab", "paint", "edges", "controls", "history", "files", "help")


def sculpt_page(data: Mapping[str, Any], token: str = "") -> str:
    """The self-contained page for the modal data ``data`` (see :meth:`.session.Session.payload`).

    ``token`` is the session token the page's script sends with every API call
    (:mod:`.guard`); a page written for offline use needs none.
    """
    folder = resources.files("splinedeform").joinpath("data")
    template = folder.joinpath("sculpt_template.html").read_text(encoding="utf-8")
    app = "".join(folder.joinpath("sculpt", f"{part}.js").read_text(encoding="utf-8")
                  for part in PARTS)
    if "</script" in app.lower():
        raise RuntimeError("the sculpt page's script contains '</script' and cannot be inlined")
    three = _vendor_text("three-orbit.min.js")
    if "</script" in three.lower():
        raise RuntimeError("the vendored three.js contains '</script' and cannot be inlined")
    fills = {"__SPLINEDEFORM_TITLE__": html.escape(str(data.get("title", "sculpt"))),
             "__SPLINEDEFORM_TOKEN__": html.escape(token, quote=True),
             "/*__SPLINEDEFORM_THREE__*/": three,
             "/*__SPLINEDEFORM_APP__*/": app,
             "__SPLINEDEFORM_DATA__": script_json({**data, "colormap": colormap_table(64)})}
    # one pass: text put in by one placeholder is never searched for another
    pattern = re.compile("|".join(re.escape(key) for key in fills))
    return pattern.sub(lambda match: fills[match.group(0)], template)
