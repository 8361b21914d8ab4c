// sculpt page, part paint: the free set: paint or pick control points.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- the free set: paint or pick control points ----------------------------------------------
  // A stroke frees (shift: fixes) the control points whose Greville point (g_u, g_v) lies
  // within the brush radius r of the point under the pointer, distances measured on the
  // parameter domain scaled to [0, 1]² (wrapped across a periodic seam); the control point
  // nearest to it is always included (r = 0 picks one point). With the net shown, a press
  // near a drawn control point centres the brush on that point. Apply re-solves.
  const paintBox = document.getElementById("paint"), brushBox = document.getElementById("brush");
  const paintInfo = document.getElementById("paint-info");
  let painting = false;
  // green: free and moving; orange: in the free set but held by an edge preset; grey: fixed
  const FREE_RGB = [0.1, 0.62, 0.2], HELD_RGB = [0.85, 0.45, 0.1], FIXED_RGB = [0.55, 0.55, 0.58];
  function paintNet() {
    if (!netColors) return;
    const c = netColors.array;
    let count = 0, held = 0;
    for (let k = 0; k < NN; k++) {
      const edge = freeMask[k] && stillMask[k] && !freeEdited;
      const rgb = !freeMask[k] ? FIXED_RGB : edge ? HELD_RGB : FREE_RGB;
      count += freeMask[k]; held += edge ? 1 : 0;
      c[3 * k] = rgb[0]; c[3 * k + 1] = rgb[1]; c[3 * k + 2] = rgb[2];
    }
    netColors.needsUpdate = true;
    paintInfo.textContent = count + " of " + NN + " control points free (green)" +
      (held ? ", " + held + " of them held by the edges (orange)" : "") +
      (freeEdited ? ": not applied yet" : "");
    dirty = true;
  }
  let freeEdited = false;
  function gap(a, b, length, periodic) {
    const d = Math.abs(a - b) / length;
    return periodic ? Math.min(d % 1, 1 - (d % 1)) : d;
  }
  function nearestNetPoint(cu, cv) {
    const [lu, lv] = data.domain, [pu, pv] = data.periodic;
    let bi = 0, bj = 0;
    for (let i = 1; i < gU.length; i++) if (gap(gU[i], cu, lu, pu) < gap(gU[bi], cu, lu, pu)) bi = i;
    for (let j = 1; j < gV.length; j++) if (gap(gV[j], cv, lv, pv) < gap(gV[bj], cv, lv, pv)) bj = j;
    return bi * gV.length + bj;
  }
  function brush(cu, cv, fix, centre) {
    const [lu, lv] = data.domain, [pu, pv] = data.periodic, r = Number(brushBox.value);
    const nv = gV.length, want = fix ? 0 : 1;
    let changed = 0;
    const set = (k) => { if (freeMask[k] !== want) { freeMask[k] = want; changed++; } };
    for (let i = 0; i < gU.length; i++) {
      const du = gap(gU[i], cu, lu, pu);
      if (du > r) continue;
      for (let j = 0; j < nv; j++) {
        const dv = gap(gV[j], cv, lv, pv);
        if (du * du + dv * dv <= r * r) set(i * nv + j);
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
    const k = pickNet(event.clientX, event.clientY), nv = gV.length;
    if (k >= 0) { brush(gU[Math.floor(k / nv)], gV[k % nv], event.shiftKey, k); return true; }
    const n = pick(event.clientX, event.clientY);
    if (n < 0) return n === -2;                // outside the trims: refused, no rotation
    const { u: cu, v: cv } = sampleAt(n);
    brush(cu, cv, event.shiftKey, nearestNetPoint(cu, cv));
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
  // what a re-solve sends: the box, or the listed points (nothing: the whole net moves)
  function freeSet() {
    if (freeSource === "box") return { free_region: freeRegion() };
    if (freeMask.every((x) => x === 1)) return {};
    const nv = gV.length, points = [];
    for (let k = 0; k < NN; k++) if (freeMask[k]) points.push([Math.floor(k / nv), k % nv]);
    return { free_points: points };
  }

