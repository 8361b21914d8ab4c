// sculpt page, part paint: the free set: paint or pick control points.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- the free set: paint or pick control points ----------------------------------------------
  // A stroke frees (shift: fixes) the control points whose Greville point (g_u, g_v) lies
  // within the brush radius r of the point under the pointer, distances measured on the
  // parameter domain scaled to [0, 1]² (wrapped across a periodic seam); the control point
  // nearest to it is always included (r = 0 picks one point). With the net shown, a press
  // near a drawn control point centres the brush on that point. Apply re-solves.
  // A body's faces are painted one at a time: the face under the pointer (or of the control
  // point picked), in its own parameters; its points are rows start … start + nu·nv - 1
  // of the net (data.faces[p]: net, greville, domain), sent as faces_free_points.
  const paintBox = document.getElementById("paint"), brushBox = document.getElementById("brush");
  const paintInfo = document.getElementById("paint-info");
  let painting = false;
  // green: free and moving; orange: in the free set but held by an edge preset; grey: fixed;
  // blue: fixed by a pin on this page (a point freed again is no longer a pin)
  const FREE_RGB = [0.1, 0.62, 0.2], HELD_RGB = [0.85, 0.45, 0.1], FIXED_RGB = [0.55, 0.55, 0.58];
  const PINNED_RGB = [0.15, 0.35, 0.95];
  function paintNet() {
    if (!netColors) return;
    const c = netColors.array;
    let count = 0, held = 0;
    const pinnedRows = [];
    for (let k = 0; k < NN; k++) {
      if (freeMask[k]) pinnedMask[k] = 0;
      const edge = freeMask[k] && stillMask[k] && !freeEdited;
      const rgb = !freeMask[k] ? (pinnedMask[k] ? PINNED_RGB : FIXED_RGB) : edge ? HELD_RGB : FREE_RGB;
      count += freeMask[k]; held += edge ? 1 : 0;
      if (pinnedMask[k]) pinnedRows.push(k);
      c[3 * k] = rgb[0]; c[3 * k + 1] = rgb[1]; c[3 * k + 2] = rgb[2];
    }
    // a body's point shared by several faces is one pin: count the points, not the rows
    const pinned = pointClass ? new Set(pinnedRows.map((k) => pointClass[k])).size : pinnedRows.length;
    netColors.needsUpdate = true;
    const perFace = data.body ? faceList.map((face, p) => {
      const start = faceStart(p), size = face.net[0] * face.net[1];
      return "face " + data.body.faces[p] + ": " + freeMask.subarray(start, start + size).reduce((a, b) => a + b, 0);
    }).join(", ") : "";
    paintInfo.textContent = count + " of " + NN + " control points free (green)" +
      (perFace ? " (" + perFace + ")" : "") +
      (held ? ", " + held + " of them held by the edges" + (data.body ? " or a neighbouring face" : "") + " (orange)" : "") +
      (pinned ? ", " + pinned + " pinned (blue)" : "") +
      (freeEdited ? ": not applied yet" : "");
    dirty = true;
  }
  let freeEdited = false;
  // face p's first row in the net; the face of net row k with its (i, j); its Greville
  // abscissae and parameter lengths (one surface: the panel's)
  function faceStart(p) {
    let start = 0;
    for (let m = 0; m < p; m++) start += faceList[m].net[0] * faceList[m].net[1];
    return start;
  }
  function netFace(k) {
    for (let p = 0, start = 0; p < faceList.length; p++) {
      const [nu, nv] = faceList[p].net;
      if (k < start + nu * nv) return { p, i: Math.floor((k - start) / nv), j: (k - start) % nv };
      start += nu * nv;
    }
    return null;
  }
  const faceGreville = (p) => faceList[p].greville || [gU, gV];
  const faceDomain = (p) => faceList[p].domain || data.domain;
  function gap(a, b, length, periodic) {
    const d = Math.abs(a - b) / length;
    return periodic ? Math.min(d % 1, 1 - (d % 1)) : d;
  }
  function nearestNetPoint(cu, cv, p = 0) {
    const [lu, lv] = faceDomain(p), [pu, pv] = faceList[p].periodic, [fu, fv] = faceGreville(p);
    let bi = 0, bj = 0;
    for (let i = 1; i < fu.length; i++) if (gap(fu[i], cu, lu, pu) < gap(fu[bi], cu, lu, pu)) bi = i;
    for (let j = 1; j < fv.length; j++) if (gap(fv[j], cv, lv, pv) < gap(fv[bj], cv, lv, pv)) bj = j;
    return faceStart(p) + bi * fv.length + bj;
  }
  function brush(cu, cv, fix, centre, p = 0) {
    const [lu, lv] = faceDomain(p), [pu, pv] = faceList[p].periodic, r = Number(brushBox.value);
    const [fu, fv] = faceGreville(p), nv = fv.length, start = faceStart(p), want = fix ? 0 : 1;
    let changed = 0;
    const set = (k) => { if (freeMask[k] !== want) { freeMask[k] = want; changed++; } };
    for (let i = 0; i < fu.length; i++) {
      const du = gap(fu[i], cu, lu, pu);
      if (du > r) continue;
      for (let j = 0; j < nv; j++) {
        const dv = gap(fv[j], cv, lv, pv);
        if (du * du + dv * dv <= r * r) set(start + i * nv + j);
      }
    }
    set(centre);
    if (changed) { freeEdited = true; freeSource = "points"; regionOn().checked = false; paintNet(); }
    return changed;
  }
  function netScreen(k) {
    const p = new THREE.Vector3(netRest[3 * k] + netDisp[3 * k], netRest[3 * k + 1] + netDisp[3 * k + 1],
                                netRest[3 * k + 2] + netDisp[3 * k + 2]).project(camera);
    const rect = renderer.domElement.getBoundingClientRect();
    return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height, z: p.z };
  }
  function pickNet(clientX, clientY) {       // the drawn control point within 8 px, or -1
    if (!showNet.checked) return -1;
    camera.updateMatrixWorld();
    let best = -1, bestD = 64;
    for (let k = 0; k < NN; k++) {
      const p = netScreen(k);
      if (p.z > 1) continue;
      const d = (p.x - clientX) ** 2 + (p.y - clientY) ** 2;
      if (d < bestD) { best = k; bestD = d; }
    }
    return best;
  }
  function stroke(event) {                   // true when the pointer is over the net or surface
    const k = pickNet(event.clientX, event.clientY);
    if (k >= 0) {
      const at = netFace(k), [fu, fv] = faceGreville(at.p);
      brush(fu[at.i], fv[at.j], event.shiftKey, k, at.p);
      return true;
    }
    const n = pick(event.clientX, event.clientY);
    if (n < 0) return n === -2;                // outside the trims: refused, no rotation
    const { face: p, u: cu, v: cv } = sampleAt(n);
    brush(cu, cv, event.shiftKey, nearestNetPoint(cu, cv, p), p);
    return true;
  }
  container.addEventListener("pointerdown", (event) => {
    if (event.button !== 0 || !paintBox.checked || !stroke(event)) return;   // else: rotate
    event.stopPropagation();
    painting = true;
    controls.enabled = false;
    container.setPointerCapture && container.setPointerCapture(event.pointerId);
  }, { capture: true });
  container.addEventListener("pointermove", (event) => { if (painting) stroke(event); });
  function endStroke() { if (painting) { painting = false; controls.enabled = true; } }
  container.addEventListener("pointerup", endStroke);
  container.addEventListener("pointercancel", endStroke);
  function setPaint(on) {
    paintBox.checked = on;
    document.getElementById("help").style.display = on ? "none" : "";
    document.getElementById("paint-help").style.display = on ? "block" : "none";
    if (on && !showNet.checked) { showNet.checked = true; showNet.dispatchEvent(new Event("change")); }
  }
  paintBox.addEventListener("change", () => setPaint(paintBox.checked));
  brushBox.addEventListener("input", () => { document.getElementById("brush-out").value = brushBox.value; });
  function fillFree(value) {
    freeMask.fill(value); freeEdited = true; freeSource = "points"; regionOn().checked = false; paintNet();
  }
  document.getElementById("paint-all").addEventListener("click", () => fillFree(1));
  document.getElementById("paint-none").addEventListener("click", () => fillFree(0));
  document.getElementById("apply").addEventListener("click", () => resolve());
  // the box of the panel, shown as a free set (the control points whose Greville point is in it)
  function boxToMask() {
    const box = freeRegion(), nv = gV.length, [lu, lv] = data.domain;
    for (let i = 0; i < gU.length; i++) for (let j = 0; j < nv; j++) {
      const inU = !box || (gU[i] >= box.u[0] - 1e-12 * lu && gU[i] <= box.u[1] + 1e-12 * lu);
      const inV = !box || (gV[j] >= box.v[0] - 1e-12 * lv && gV[j] <= box.v[1] + 1e-12 * lv);
      freeMask[i * nv + j] = inU && inV ? 1 : 0;
    }
    freeEdited = true; freeSource = "box"; paintNet();
  }
  // what a re-solve sends: the box, or the listed points (nothing: the whole net moves);
  // a body's per face whose net is not all free, keyed by the file's face number
  function freeSet() {
    if (freeSource === "box") return { free_region: freeRegion() };
    if (freeMask.every((x) => x === 1)) return {};
    if (data.body) return { faces_free_points: facesFreePoints(freeMask) };
    const nv = gV.length, points = [];
    for (let k = 0; k < NN; k++) if (freeMask[k]) points.push([Math.floor(k / nv), k % nv]);
    return { free_points: points };
  }

  // a body's free set `mask` per face whose net is not all free, keyed by the file's face
  // number: {"3": [[i, j], …]} (a face not listed moves whole)
  function facesFreePoints(mask) {
    const faces = {};
    faceList.forEach((face, p) => {
      const [nu, nv] = face.net, start = faceStart(p), points = [];
      for (let k = 0; k < nu * nv; k++) if (mask[start + k]) points.push([Math.floor(k / nv), k % nv]);
      if (points.length < nu * nv) faces[data.body.faces[p]] = points;
    });
    return faces;
  }
  // the net rows that are the same control point as row k: a body's faces meeting there
  // (pointClass), else k alone
  function samePoint(k) {
    if (!pointClass) return [k];
    const rows = [];
    for (let m = 0; m < NN; m++) if (pointClass[m] === pointClass[k]) rows.push(m);
    return rows;
  }
