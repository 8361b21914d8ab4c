// sculpt page, part history: "bake" (the current shape becomes the rest shape) and undo/redo of every change of basis.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // Each re-solve or bake keeps the page's whole state before it (the modal data, (q, q', f),
  // the clock, the pushes, the free set); undo puts it back exactly after the server has
  // switched back to that basis (splinedeform/sculpt/history.py), redo likewise.
  const MAX_UNDO = 20;                 // as the server keeps
  let undoStack = [], redoStack = [];
  const undoButton = document.getElementById("undo"), redoButton = document.getElementById("redo");
  function pageState() {
    return { data, q: Float64Array.from(q), v: Float64Array.from(v), f: Float64Array.from(f),
             t, tEvent, pushes: pushes.map((p) => Object.assign({}, p, { force: p.force.slice() })),
             freeMask: freeMask.slice(), pinnedMask: pinnedMask.slice(), freeSource, freeEdited, carriedMotion,
             corrections: new Map(corrections), lagged: copyLagged(lagged) };
  }
  function copyLagged(from) {
    const out = new Map();
    from.forEach((e, k) => out.set(k, { z: Float64Array.from(e.z), zv: Float64Array.from(e.zv), fz: Float64Array.from(e.fz) }));
    return out;
  }
  function showHistory() {
    undoButton.disabled = !online || undoStack.length === 0;
    redoButton.disabled = !online || redoStack.length === 0;
  }
  function remember(state) {            // a new basis replaced the one of `state`
    undoStack.push(state);
    if (undoStack.length > MAX_UNDO) undoStack.shift();
    redoStack = [];
    showHistory();
  }
  function restore(state) {
    releaseAll();
    const sameGrid = layoutOf(state.data) === layoutOf(data);
    data = state.data;
    unpack(data);
    allocate();
    q.set(state.q); v.set(state.v); f.set(state.f);
    t = state.t; tEvent = state.tEvent;
    pushes = state.pushes.map((p) => Object.assign({}, p, { force: p.force.slice() }));
    freeMask = state.freeMask.slice(); freeSource = state.freeSource; freeEdited = state.freeEdited;
    pinnedMask = state.pinnedMask.slice();
    carriedMotion = state.carriedMotion;
    corrections.clear();
    state.corrections.forEach((c, k) => { if (c) corrections.set(k, c); });
    lagged.clear();
    copyLagged(state.lagged).forEach((e, k) => lagged.set(k, e));
    offlineFactor = null; grab = null; extra = []; controls.enabled = true; lastSwitch = null;
    if (!sameGrid || !geometry) buildGeometry();
    buildForms();
    paintNet();
    modalSum();
    dirty = true;
  }
  async function switchBasis(path, from, to) {
    if (solving || from.length === 0) return;
    solving = true;
    try {
      const target = from[from.length - 1];
      const reply = await post(path, { version: data.version });
      if (reply.version !== target.data.version) {
        throw new Error("the server's history differs from the page's (basis " + reply.version +
                        " instead of " + target.data.version + "); reload the page");
      }
      from.pop();
      to.push(pageState());
      restore(target);
      progressBox.textContent = (path === "api/undo" ? "undone" : "redone") + ": basis " + data.version;
    } catch (err) {
      showMessage((path === "api/undo" ? "undo" : "redo") + " refused: " + err.message);
    } finally {
      solving = false;
      showHistory();
    }
  }
  function undo() { return switchBasis("api/undo", undoStack, redoStack); }
  function redo() { return switchBasis("api/redo", redoStack, undoStack); }
  // bake; with `pinned` (a control point, row-major) also a pin: the free set less that
  // point, which then stays where the bake put it (its displaced place) whatever is pulled.
  // On a body the point is taken out of every face that has it (a merged interface's
  // point is one point of the body) and the faces' sets are sent as faces_free_points.
  async function bake(pinned) {
    if (solving) return;
    const pinning = pinned !== undefined && pinned !== null;
    let extra = {}, rows = [];
    if (pinning && data.body) {
      extra = bodyPin(pinned);
      if (!extra) return;
      rows = samePoint(pinned);
    } else if (pinning) {
      if (!freeMask[pinned] || stillMask[pinned]) {
        showMessage("control point " + netName(pinned) + " is held already", true);
        return;
      }
      const mask = freeMask.slice(), nv = gV.length, points = [];
      mask[pinned] = 0;
      rows = [pinned];
      for (let k = 0; k < NN; k++) if (mask[k]) points.push([Math.floor(k / nv), k % nv]);
      extra = { free_points: points };
    }
    solving = true;
    progressBox.textContent = pinning ? "pinning…" : "baking…";
    const wasPaused = paused;
    setPaused(true);                  // the shape sent is the shape when the new modes arrive
    try {
      releaseAll();
      const earlier = pageState();
      const now = new Float64Array(K * 3);
      propagate(q, v, f, t - tEvent, now, null);   // the shape now: x = x0 + Φ q(t)
      const reply = await post("api/bake", Object.assign({ version: data.version, q: Array.from(now) }, extra));
      remember(earlier);
      load(reply);
      if (pinning) {                  // drawn blue from now on (paintNet)
        rows.forEach((m) => { if (!freeMask[m]) pinnedMask[m] = 1; });
        paintNet();
      }
      const also = rows.length > 1 ? " (held on every face that has it: " + rows.map(netName).join(", ") + ")" : "";
      progressBox.textContent = pinning
        ? "pinned control point " + netName(pinned) + " where it is" + also + " (shape baked in " + reply.solve_seconds + " s, " + K + " modes)"
        : "baked in " + reply.solve_seconds + " s: this shape is the rest shape (" + K + " modes)";
    } catch (err) {
      progressBox.textContent = "";
      showMessage((pinning ? "pin" : "bake") + " refused: " + err.message);
    } finally {
      setPaused(wasPaused);
      solving = false;
      showHistory();
    }
  }
  // the message of a body's pin of net row k: every face's free set less that point (on
  // each face that has it), or null with the refusal shown
  function bodyPin(k) {
    const rows = samePoint(k), name = netName(k);
    if (!freeMask[k]) { showMessage("control point " + name + " is fixed already (not in the free set)", true); return null; }
    if (stillMask[k]) {
      const edge = rows.length > 1 ? "an edge preset or a neighbouring face" : "an edge preset";
      showMessage("control point " + name + " is held already by " + edge + ": nothing to pin", true);
      return null;
    }
    const mask = freeMask.slice();
    rows.forEach((m) => { mask[m] = 0; });
    const faces = facesFreePoints(mask), empty = Object.keys(faces).filter((face) => faces[face].length === 0);
    if (empty.length) {
      showMessage("pinning " + name + " would leave face " + empty.join(", face ") + " no free control point; " +
                  "free more of its points first (a face's free set is never empty)", true);
      return null;
    }
    return { faces_free_points: faces };
  }
  function netName(k) {
    if (data.body) {
      const at = netFace(k), [fu, fv] = faceGreville(at.p);
      return "[" + at.i + ", " + at.j + "] of face " + data.body.faces[at.p] +
             " (u = " + fu[at.i].toPrecision(3) + ", v = " + fv[at.j].toPrecision(3) + ")";
    }
    const nv = gV.length, i = Math.floor(k / nv), j = k % nv;
    return "[" + i + ", " + j + "] (u = " + gU[i].toPrecision(3) + ", v = " + gV[j].toPrecision(3) + ")";
  }
  // pin the control point nearest (Greville points, parameter domain) to sample n
  // (a body's: the nearest of the face under the pointer, in that face's parameters)
  function pin(n) {
    const { face: p, u: cu, v: cv } = sampleAt(n);
    return bake(data.body ? nearestNetPoint(cu, cv, p) : nearestNetPoint(cu, cv));
  }
  document.getElementById("bake").addEventListener("click", () => { bake(); });
  undoButton.addEventListener("click", () => { undo(); });
  redoButton.addEventListener("click", () => { redo(); });
  showHistory();
