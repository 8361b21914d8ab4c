// sculpt page, part help: tooltips in physical words on every control, the help overlay (?)
// and the keyboard shortcuts. The parts are concatenated in order inside one function scope
// (see sculpt/page.py).
  // what each control means, in the words of the energy
  // E = ½ ∫∫ w10|d_u|² + w01|d_v|² + w20|d_uu|² + 2 w11|d_uv|² + w02|d_vv|² du dv
  // and of μ d_tt + γ d_t + K d = f (modal damping c_i = γ/μ + β λ_i)
  function controlTips() {
    return {
      "material-w10": "w10: tension along u — resistance to stretching in the u direction (|d_u|²); a membrane's stiffness",
      "material-w01": "w01: tension along v — resistance to stretching in the v direction (|d_v|²)",
      "material-w20": "w20: bending stiffness along u — resistance to curving in u (|d_uu|²); a plate's stiffness",
      "material-w11": "w11: twisting stiffness — resistance to twist (|d_uv|²); w20 = w11 = w02 = D is the Kirchhoff plate",
      "material-w02": "w02: bending stiffness along v — resistance to curving in v (|d_vv|²)",
      "material-mass": "mass μ per unit parameter area: heavier rings slower (ω = √λ with λ of K φ = λ M φ)",
      "material-damping": "damping γ (mass-proportional, like air drag): every mode decays as e^{-γt/2μ}",
      "material-rayleigh": "rayleigh β (stiffness-proportional damping, like internal friction): mode i gets c_i = γ/μ + β λ_i, so fast, stiff modes die out first",
      "boundary-u0": data.body ? "every boundary edge of the body (an edge no other face meets): free, pinned (held in place), clamped (held, no slope across it); each edge in the list below can then be set on its own, drawn on the surface green (free), orange (pinned) or black (clamped)" : "edge u = 0: free (moves), pinned (held in place, may turn), clamped (held and no slope across it), pole (collapsed to a point)",
      "boundary-u1": "edge u = 1: free, pinned (held in place), clamped (held, no slope across it), pole (collapsed to a point)",
      "boundary-v0": "edge v = 0: free, pinned (held in place), clamped (held, no slope across it), pole (collapsed to a point)",
      "boundary-v1": "edge v = 1: free, pinned (held in place), clamped (held, no slope across it), pole (collapsed to a point)",
      "region-on": "only the control points whose Greville abscissae lie in the box below move; the others are held at rest",
      "region-u0": "the free box starts at this u", "region-u1": "the free box ends at this u",
      "region-v0": "the free box starts at this v", "region-v1": "the free box ends at this v",
      "resolve": "solve the modes again with the material, edges and free set above; the motion is carried over",
      "pause": "stop or restart time (Space)",
      "reset": "back to rest: pushes forgotten",
      "speed": "how fast time runs: 0.05 … 3 times real time",
      "grab-mode": "what a drag does: a spring from the grabbed point to the pointer, only its push along the surface normal, or pin the nearest control point where it is (also alt-click; on a body, of the face under the pointer, held on every face that shares it)",
      "spring": "spring stiffness as a multiple of the grabbed point's own stiffness (1/flexibility): at 1 the point goes half-way to the pointer when it comes to rest",
      "show-net": "show the control net (its points move with the surface)",
      "colour": "colour the surface by the size of its displacement |d| (plasma), or plain",
      "paint": data.body ? "drag over a face to free its control points under the brush (shift: fix them), one face at a time; Apply re-solves" : "drag over the surface to free the control points under the brush (shift: fix them); Apply re-solves",
      "brush": "brush radius on the parameter domain scaled to [0, 1]²",
      "paint-all": "every control point free", "paint-none": "every control point fixed",
      "apply": "re-solve with the painted free set",
      "bake": "make the current shape the rest shape (B)",
      "undo": "back to the state before the last bake, pin or re-solve (Ctrl-Z)",
      "redo": "forward again (Ctrl-Y or Ctrl-Shift-Z)",
      "save": "write the pushes of this session as a scenario file that splinedeform run replays",
      "save-page": "download this page with the current surface: it opens from a file and runs without the server",
      "export-3dm": "download the shape now as a NURBS surface in a Rhino .3dm file (the model's knots, the current control net)",
      "export-obj": "download the shape now as a triangle mesh (Wavefront OBJ, vertex normals) on the page's sample grid",
      "export-json": "download the current control net as the project's net file (JSON; shape = \"file\" in a scenario reads it)",
      "load": "load a surface from a file: a Rhino .3dm, the project's net file (.json) or a whole scenario (.toml); the modes are solved for it (Undo goes back)",
      "load-file": "a .3dm, .json (net) or .toml (scenario) file",
      "help-button": "keys and what the page computes (?)",
    };
  }
  function applyTips() {
    const tips = controlTips();
    for (const [id, text] of Object.entries(tips)) {
      const node = document.getElementById(id);
      if (!node) continue;
      node.title = text;
      const label = node.closest("label");
      if (label) label.title = text;             // the name beside a slider says it too
    }
  }
  applyTips();
  const helpOverlay = document.getElementById("help-overlay");
  function toggleHelp(show) {
    helpOverlay.style.display = (show === undefined ? helpOverlay.style.display !== "block" : show) ? "block" : "none";
  }
  document.getElementById("help-button").addEventListener("click", () => toggleHelp());
  helpOverlay.addEventListener("click", () => toggleHelp(false));
  // shortcuts; keys typed into a text or number field, or a menu, are theirs
  window.addEventListener("keydown", (event) => {
    const target = event.target, tag = target && target.tagName;
    if (tag === "SELECT" || tag === "TEXTAREA" || (tag === "INPUT" && target.type !== "range" && target.type !== "checkbox")) return;
    const key = event.key, ctrl = event.ctrlKey || event.metaKey;
    let done = true;
    if (ctrl && !event.shiftKey && (key === "z" || key === "Z")) undo();
    else if (ctrl && (key === "y" || key === "Y" || (event.shiftKey && (key === "z" || key === "Z")))) redo();
    else if (ctrl || event.altKey) done = false;
    else if (key === " ") setPaused(!paused);
    else if (key === "Escape") { if (helpOverlay.style.display === "block") toggleHelp(false); else releaseAll(); }
    else if (key === "b" || key === "B") bake();
    else if (key === "?") toggleHelp();
    else done = false;
    if (done) event.preventDefault();
  });
