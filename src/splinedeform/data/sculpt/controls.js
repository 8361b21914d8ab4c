// sculpt page, part controls: the frame loop, the controls, and the state read by tests and benchmarks.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- the frame loop ------------------------------------------------------------------------
  const frameLog = [];      // {at, interval, compute, latency} of the last frames
  const latencies = [];     // input event -> end of the first frame drawn after it (ms)
  let last = null;
  function frame(now) {
    const start = performance.now();
    const interval = last === null ? 0 : now - last;
    last = now;
    updateGrab(interval);                           // force switched at the old t
    settle();                                       // rung down: rest, nothing more to draw
    const moving = !paused && (grab || extra.length || q.some((x) => x !== 0) || v.some((x) => x !== 0));
    if (!paused) t += Math.min(interval, 100) / 1000 * speed;
    let sum = 0;
    if (moving || dirty) {
      modalSum();
      sum = performance.now() - start;
      draw();
      dirty = false;
    }
    const end = performance.now();
    let latency = null;
    if (pendingInput.length) {
      latency = end - pendingInput[0];
      for (const ts of pendingInput) latencies.push(end - ts);
      if (latencies.length > 2000) latencies.splice(0, latencies.length - 2000);
      pendingInput = [];
    }
    frameLog.push({ at: end, interval, compute: end - start, sum, latency });
    if (frameLog.length > 1200) frameLog.shift();
    hud();
    requestAnimationFrame(frame);
  }
  const hudBox = document.getElementById("hud");
  let hudAt = 0;
  function hud() {
    const now = performance.now();
    if (now - hudAt < 250) return;
    hudAt = now;
    const recent = frameLog.slice(-60).filter((r) => r.interval > 0);
    const mean = recent.reduce((s, r) => s + r.interval, 0) / Math.max(recent.length, 1);
    const work = recent.reduce((s, r) => s + r.compute, 0) / Math.max(recent.length, 1);
    hudBox.textContent = "t = " + t.toFixed(2) + (paused ? " (paused)" : "") +
      "   " + (mean > 0 ? (1000 / mean).toFixed(0) : "-") + " fps, " + work.toFixed(1) + " ms per frame" +
      "\n" + K + (data.complete ? " modes (all)" : " of " + data.n_free + " modes" +
      (online || data.offline ? " + static correction" : "")) + ", " + (data.body ? faceList.length + " faces of " + faceRows : ru) + "×" + rv + " samples" + (trimTriangles ? " clipped to the trims" : "") + ", max |d| = " + (dmax > 0 ? dmax.toPrecision(3) : "0") +
      (grab || extra.length ? "\n" + grabWords() : "");
  }

  // the grab in words: where on the surface (its parameters) and the force held there
  function grabWords() {
    const g = grab || extra[extra.length - 1], at = sampleAt(g.index), F = g.force;
    const how = g !== grab || !pointer ? "holding" : grabMode.value === "normal" ? "pushing" : "pulling";
    const others = grab ? extra.length : extra.length - 1;
    return how + " the point at u = " + at.u.toPrecision(3) + ", v = " + at.v.toPrecision(3) +
      (data.body ? " of face " + at.number : "") +
      (F ? " with |F| = " + Math.hypot(F[0], F[1], F[2]).toPrecision(3) : "") +
      (others > 0 ? " (+ " + others + " more held; Esc lets go of all)" : "");
  }
  // -- controls ---------------------------------------------------------------------------------
  const pauseButton = document.getElementById("pause");
  const speedBox = document.getElementById("speed"), springBox = document.getElementById("spring");
  const grabMode = document.getElementById("grab-mode");
  const showNet = document.getElementById("show-net"), colourBox = document.getElementById("colour");
  function setPaused(p) { paused = p; pauseButton.textContent = p ? "Play" : "Pause"; }
  pauseButton.addEventListener("click", () => setPaused(!paused));
  document.getElementById("reset").addEventListener("click", () => reset());
  speedBox.addEventListener("input", () => { speed = Number(speedBox.value); document.getElementById("speed-out").value = speedBox.value; });
  springBox.addEventListener("input", () => { document.getElementById("spring-out").value = springBox.value; });
  showNet.addEventListener("change", () => {
    netGroup.forEach((o) => { o.visible = showNet.checked; });
    if (showNet.checked) modalSum();     // the hidden net's displacement is not kept up: now, not next frame
    dirty = true;
  });
  colourBox.addEventListener("change", () => { dirty = true; });

  const WEIGHTS = ["damping", "rayleigh", "mass", "w10", "w01", "w20", "w11", "w02"];
  const EDGES = ["u0", "u1", "v0", "v1"];
  const materialBox = document.getElementById("material"), boundaryBox = document.getElementById("boundary");
  function buildForms() {
    materialBox.textContent = ""; boundaryBox.textContent = "";
    for (const key of WEIGHTS) {
      const value = Number(data.material[key]), top = Math.max(value * 4, key === "mass" ? 4 : 1);
      const label = document.createElement("label");
      label.innerHTML = '<span class="name"></span><input type="range"><output></output>';
      label.querySelector(".name").textContent = key;
      const input = label.querySelector("input"), out = label.querySelector("output");
      input.id = "material-" + key; input.min = key === "mass" ? String(top / 200) : "0";
      input.max = String(top); input.step = String(top / 200); input.value = String(value);
      out.value = String(Number(value.toPrecision(3)));
      input.addEventListener("input", () => { out.value = String(Number(Number(input.value).toPrecision(3))); });
      materialBox.appendChild(label);
    }
    // a body: one preset for every boundary edge (an edge no other face meets), then each
    // edge on its own (edges.js); its free set is painted face by face (paint.js), with no
    // free region (a box of one face's parameters); a pin holds a point of the face under
    // the pointer (history.js)
    for (const edge of data.body ? ["u0"] : EDGES) {
      const label = document.createElement("label");
      label.innerHTML = '<span class="name"></span><select></select>';
      label.querySelector(".name").textContent = data.body ? "edges" : edge;
      const select = label.querySelector("select");
      select.id = "boundary-" + edge;
      if (data.body) select.title = "every edge of the body that no other face meets";
      // a periodic direction has no edges: nothing to choose there
      const periodic = data.periodic && data.periodic[edge[0] === "u" ? 0 : 1];
      if (periodic) { select.disabled = true; select.title = "periodic in " + edge[0] + ": no edge"; }
      for (const preset of periodic ? ["free"] : data.body ? ["free", "pinned", "clamped"] : ["free", "pinned", "clamped", "pole"]) {
        const option = document.createElement("option");
        option.value = option.textContent = preset;
        select.appendChild(option);
      }
      select.value = data.boundary[edge];
      boundaryBox.appendChild(label);
    }
    dropEdgeLines();
    if (data.body) bodyEdgeForms(boundaryBox);     // each boundary edge on its own (edges.js)
    // free region: only control points whose Greville abscissae lie in the box move
    const region = data.free_region || {}, [lu, lv] = data.domain;
    const box = document.createElement("div");
    box.innerHTML = '<label><input id="region-on" type="checkbox"> only a free region moves</label>' +
      '<label><span class="name">u from</span><input id="region-u0" type="number" step="any"> to <input id="region-u1" type="number" step="any"></label>' +
      '<label><span class="name">v from</span><input id="region-v0" type="number" step="any"> to <input id="region-v1" type="number" step="any"></label>';
    boundaryBox.appendChild(box);
    box.style.display = data.body ? "none" : "";
    box.querySelectorAll("input[type=number]").forEach((input) => { input.style.width = "60px"; });
    document.getElementById("region-on").checked = Boolean(data.free_region);
    box.addEventListener("input", boxToMask);
    box.addEventListener("change", boxToMask);
    const range = (key, length) => region[key] || [0.25 * length, 0.75 * length];
    [["u", lu], ["v", lv]].forEach(([key, length]) => {
      const [a, b] = range(key, length);
      document.getElementById("region-" + key + "0").value = String(Number(a.toPrecision(6)));
      document.getElementById("region-" + key + "1").value = String(Number(b.toPrecision(6)));
    });
    applyTips();                          // the help part's tooltips on the new fields
  }
  const regionOn = () => document.getElementById("region-on");
  function freeRegion() {
    if (!document.getElementById("region-on").checked) return null;
    const pair = (key) => [Number(document.getElementById("region-" + key + "0").value),
                           Number(document.getElementById("region-" + key + "1").value)];
    return { u: pair("u"), v: pair("v") };
  }

  async function post(path, body) {
    if (!online) throw new Error("this page is not served by splinedeform sculpt (offline copy)");
    const response = await fetch(path, { method: "POST", headers: Object.assign({ "Content-Type": "application/json" }, apiHeaders),
                                         body: JSON.stringify(body) });
    let reply;
    try { reply = await response.json(); } catch (err) { reply = { error: "no JSON answer (" + response.status + ")" }; }
    if (!response.ok) throw new Error(reply.error || ("HTTP " + response.status));
    return reply;
  }
  const progressBox = document.getElementById("progress");
  let solving = false;
  async function resolve() {
    if (solving) return;
    solving = true;
    releaseAll();                     // the held pushes end now (as when the new modes arrive)
    const material = {}, boundary = {};
    for (const key of WEIGHTS) material[key] = Number(document.getElementById("material-" + key).value);
    for (const edge of EDGES) boundary[edge] = document.getElementById("boundary-" + (data.body ? "u0" : edge)).value;
    const faces = data.body ? bodyEdgeFaces() : null;
    if (faces) boundary.faces = faces;
    const started = performance.now();
    const poll = setInterval(async () => {
      try {
        const s = await (await fetch("api/status", { headers: apiHeaders })).json();
        if (!solving) return;              // answered after the re-solve: its result stays
        progressBox.textContent = "re-solving: " + s.stage + " (" + ((performance.now() - started) / 1000).toFixed(1) + " s)";
      } catch (err) { /* the answer of the re-solve reports errors */ }
    }, 150);
    progressBox.textContent = "re-solving…";
    try {
      const earlier = pageState();
      const reply = await post("api/resolve", Object.assign({ material, boundary }, freeSet()));
      remember(earlier);
      load(reply);
      const s = lastSwitch;
      progressBox.textContent = "re-solved in " + reply.solve_seconds + " s (" + K + " modes); " +
        (!s.carried ? "motion reset" : s.scale === 0 ? "at rest" :
         "motion carried over (largest jump " + (100 * s.jump / s.scale).toPrecision(2) + " % of |d|)");
    } catch (err) {
      progressBox.textContent = "";
      restoreAccepted();
      showMessage("re-solve refused: " + err.message);
    } finally {
      clearInterval(poll);
      solving = false;
      showHistory();
    }
  }
  document.getElementById("resolve").addEventListener("click", resolve);
  // a refused re-solve changes nothing: the forms and the free set show the basis in use again
  function restoreAccepted() {
    freeMask = decode(data.free_mask, Uint8Array).slice();
    freeSource = data.free_region ? "box" : "points";
    freeEdited = false;
    buildForms();
    paintNet();
  }

  async function save() {
    const list = pushes.map((p) => ({ index: p.index, force: p.force, t_on: p.t_on, t_off: p.t_off }));
    const note = carriedMotion ? " (from the last re-solve on; the motion carried over it is not in the file: a scenario starts at rest)" : "";
    try {
      const reply = await post("api/save", { version: data.version, t_end: Math.max(t, 1e-3), pushes: list });
      document.getElementById("saved").textContent = "saved " + reply.steps + " force steps as " + reply.loads + " loads (one per grab and direction) to " + reply.path + note;
      showMessage("saved " + reply.path, true);
      return reply;
    } catch (err) {
      showMessage("save refused: " + err.message);
      throw err;
    }
  }
  document.getElementById("save").addEventListener("click", () => { save().catch(() => {}); });

  // A new basis: the motion is carried over (see splinedeform/sculpt/carry.py): a held push
  // ends now, the state (q, q') of the old modes at the current time is mapped by
  // P = Φ_newᵀ T_newᵀ M T_old Φ_old (sent with the answer), the clock restarts at 0 and the
  // push list with it (Save records the pushes since the last re-solve).
  let lastSwitch = null, carriedMotion = false;
  function load(d) {
    const sameGrid = layoutOf(d) === layoutOf(data);
    releaseAll();
    propagate(q, v, f, t - tEvent, q, v);
    tEvent = t;
    modalSum();
    const before = Float64Array.from(disp), oldK = K, oldQ = q, oldV = v, oldVersion = data.version;
    const oldRest = rest;             // a bake moves the rest shape: jumps are of x = x0 + d
    data = Object.assign({}, d, { colormap: data.colormap });
    unpack(data);
    allocate();
    const carry = d.carry;
    const carried = Boolean(sameGrid && carry && carry.from_version === oldVersion &&
                            carry.shape[0] === K && carry.shape[1] === oldK);
    if (carried) {
      const P = decode(carry.transfer, Float64Array);
      for (let i = 0; i < K; i++) for (let c = 0; c < 3; c++) {
        let sq = 0, sv = 0;
        for (let j = 0; j < oldK; j++) { const p = P[i * oldK + j]; sq += p * oldQ[3 * j + c]; sv += p * oldV[3 * j + c]; }
        q[3 * i + c] = sq; v[3 * i + c] = sv;
      }
      if (d.baked) q.fill(0);          // the shape now is the rest shape: only the velocity goes on
    }
    corrections.clear();
    lagged.clear();
    offlineFactor = null;
    t = 0; tEvent = 0; pushes = []; grab = null; extra = []; controls.enabled = true; dirty = true;
    freeEdited = false;
    if (!sameGrid || !geometry) buildGeometry();
    buildForms();
    paintNet();
    modalSum();
    let jump = 0, scale = 0;
    if (sameGrid) for (let k = 0; k < N * 3; k++) {
      jump = Math.max(jump, Math.abs(rest[k] + disp[k] - oldRest[k] - before[k]));
      scale = Math.max(scale, Math.abs(before[k]));
    }
    if (carried && scale > 0) carriedMotion = true;
    lastSwitch = { carried, jump, scale, before: Array.from(before), after: Array.from(disp) };
  }

  function resize() {
    const w = container.clientWidth || 1, h = container.clientHeight || 1;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    dirty = true;
  }
  controls.addEventListener("change", () => { lightDir.copy(camera.position).normalize(); dirty = true; });
  window.addEventListener("resize", resize);

  allocate();
  buildGeometry();
  buildForms();
  frameCamera();
  lightDir.copy(camera.position).normalize();
  resize();
  modalSum();
  draw();
  requestAnimationFrame(frame);

  // -- state for tests and benchmarks ------------------------------------------------------------
  window.sculptState = {
    get time() { return t; },
    get paused() { return paused; },
    get modes() { return K; },
    get grid() { return [ru, rv]; },
    get version() { return data.version; },
    get grabbed() { return grab ? { index: grab.index, force: grab.force && grab.force.slice() } : null; },
    get pushes() { return pushes.map((p) => Object.assign({}, p)); },
    get errors() { return errors.slice(); },
    get resting() { return !grab && !extra.length && lagged.size === 0 && !q.some((x) => x !== 0) && !v.some((x) => x !== 0); },
    get corrections() { return Array.from(corrections.keys()).filter((k) => corrections.get(k)); },
    get freeMask() { return Array.from(freeMask); },
    correction(n) { requestCorrection(n); const c = corrections.get(n); return c ? Array.from(c) : null; },
    get lastSwitch() { return lastSwitch; },
    netDisplacement() { return Array.from(netDisp); },
    netScreen(k) { camera.updateMatrixWorld(); return netScreen(k); },
    setPaint, freeSet,
    online,
    displacement(n) { return [disp[3 * n], disp[3 * n + 1], disp[3 * n + 2]]; },
    // one consistent snapshot between frames: time, pushes, every sample's displacement
    snapshot() { return { time: t, pushes: pushes.map((p) => Object.assign({}, p)), displacement: Array.from(disp) }; },
    rest(n) { return [rest[3 * n], rest[3 * n + 1], rest[3 * n + 2]]; },
    normal(n) { return [normals[3 * n], normals[3 * n + 1], normals[3 * n + 2]]; },
    screen(n) { camera.updateMatrixWorld(); return projectSample(n); },
    pick(x, y) { return pick(x, y); },
    frames() { return frameLog.slice(); },
    latencies() { return latencies.slice(); },
    setPaused, reset, save, resolve, bake() { return bake(); }, pin, undo, redo, hold, release: releaseAll,
    get grabs() { return allGrabs().map((g) => ({ index: g.index, force: g.force && g.force.slice(), held: Boolean(g.anchor || g.fixed) })); },
    netPosition(k) { return [netRest[3 * k] + netDisp[3 * k], netRest[3 * k + 1] + netDisp[3 * k + 1], netRest[3 * k + 2] + netDisp[3 * k + 2]]; },
    uv(n) { const at = sampleAt(n); return [at.u, at.v]; },
    face(n) { return sampleAt(n).number; },
    get faceCount() { return faceList.length; },
    triangleCount() { return geometry.index.count / 3; },
    get sampleCount() { return N; },
    get bodyEdges() { return data.body ? data.body.edges.map((e) => Object.assign({}, e)) : null; },
    get edgeSegments() { return edgeLines ? edgeLines.geometry.attributes.position.count / 2 : 0; },
    inside(n) { return !inside || Boolean(inside[n]); },
    nearestNet(n) { const at = sampleAt(n); return nearestNetPoint(at.u, at.v, at.face); },
    netFace(k) { const at = netFace(k); return at && { face: data.body ? data.body.faces[at.p] : at.p, i: at.i, j: at.j }; },
    samePoint(k) { return samePoint(k); },
    get stillMask() { return Array.from(stillMask); },
    get pinnedMask() { return Array.from(pinnedMask); },
    netColor(k) { return netColors ? Array.from(netColors.array.slice(3 * k, 3 * k + 3)) : null; },
    get grabView() { return grabEnds && { point: grabEnds.point.slice(), pointer: grabEnds.pointer && grabEnds.pointer.slice(),
                                          marker: grabMarker.visible, spring: springLine.visible }; },
    get hud() { return hudBox.textContent; },
    pointerWorld(x, y) { const p = pointerWorld(x, y, grab ? grab.depth : 0.5); return [p.x, p.y, p.z]; },
    get progress() { return document.getElementById("progress").textContent; },
    modalState() { return { q: Array.from(q), v: Array.from(v), f: Array.from(f), t, tEvent }; },
    get history() { return [undoStack.length, redoStack.length]; },
    setSpeed(s) { speed = s; speedBox.value = String(s); },
    // the page's own closed form from rest for given pushes, at ascending times (no drawing):
    // [{index, force, t_on, t_off}], [t...] -> per time the displacement of every sample
    simulate(list, times) {
      const sq = new Float64Array(K * 3), sv = new Float64Array(K * 3), sf = new Float64Array(K * 3);
      const out = new Float64Array(K * 3);
      const events = Array.from(new Set(list.flatMap((p) => (p.t_off === null ? [p.t_on] : [p.t_on, p.t_off])))).sort((a, b) => a - b);
      const forceAt = (time) => {
        sf.fill(0);
        for (const p of list) if (p.t_on <= time && (p.t_off === null || time < p.t_off)) {
          for (let i = 0; i < K; i++) for (let c = 0; c < 3; c++) sf[3 * i + c] += phi[p.index * K + i] * p.force[c];
        }
      };
      let t0 = 0;
      forceAt(0);
      const result = [];
      for (const time of times) {
        while (events.length && events[0] <= time) {
          const te = events.shift();
          if (te > t0) { propagate(sq, sv, sf, te - t0, sq, sv); t0 = te; }
          forceAt(te);
        }
        propagate(sq, sv, sf, time - t0, out, null);
        const d = new Array(N * 3);
        for (let n = 0; n < N; n++) for (let c = 0; c < 3; c++) {
          let s = 0;
          for (let i = 0; i < K; i++) s += phi[n * K + i] * out[3 * i + c];
          d[3 * n + c] = s;
        }
        result.push(d);
      }
      return result;
    },
  };
