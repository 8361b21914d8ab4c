// sculpt page, part state: the modal data, the modal state (q, q', f) per mode carried in closed form from event to event, the session (time, pushes, the held grab).
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // Start-up is idempotent: a page saved from the browser ("Webpage, Complete", or the DOM as
  // it is) carries the canvas of its last run, its banners and status lines; they go, and the
  // page is drawn afresh. What is left then is the page as served, kept for "Save offline page".
  document.querySelectorAll("#view > *").forEach((node) => node.remove());
  for (const id of ["message", "hud", "progress", "saved", "paint-info"]) {
    const node = document.getElementById(id);
    if (node) node.textContent = "";
  }
  document.getElementById("message").style.display = "none";
  const pristinePage = document.documentElement.cloneNode(true);
  let data = JSON.parse(document.getElementById("splinedeform-data").textContent);
  const online = location.protocol === "http:" || location.protocol === "https:";
  // the session token of the server that served this page: sent with every API call
  // (the server refuses calls without it; see splinedeform/sculpt/guard.py)
  const tokenTag = document.querySelector('meta[name="splinedeform-token"]');
  const apiHeaders = { "X-Sculpt-Token": tokenTag ? tokenTag.content : "" };
  const messageBox = document.getElementById("message");
  const errors = [];
  let messageTimer = null;
  function showMessage(text, info) {
    messageBox.textContent = text;
    messageBox.className = info ? "info" : "";
    messageBox.style.display = "block";
    if (!info) errors.push(text);
    clearTimeout(messageTimer);
    messageTimer = setTimeout(() => { messageBox.style.display = "none"; }, info ? 4000 : 10000);
  }
  function decode(text, Type) {
    const raw = atob(text), bytes = new Uint8Array(raw.length);
    for (let k = 0; k < raw.length; k++) bytes[k] = raw.charCodeAt(k);
    return new Type(bytes.buffer);
  }

  // -- modal data ------------------------------------------------------------------------
  // K modes, N samples: phi (N x K, float32, sample-major), lam and damping (float64)
  let K, N, ru, rv, lam, damp, phi, rest, phiNet, netRest, NN;
  // the free set (1 = free, row-major over the net, what Apply sends) and where it came from:
  // "box" (the u/v box of the panel), "points" (a list: the scenario's or painted)
  let freeMask, freeSource, gU, gV, stillMask;
  // the rows pinned on this page (alt-click): fixed like painted ones, drawn apart; kept while
  // the net keeps its size, cleared where a point is freed again (paintNet)
  let pinnedMask = null;
  // the faces: a body's samples are face after face, rows p·faceRows … (p+1)·faceRows - 1 of
  // the (ru, rv) grid for face p, and its control points the next nu·nv of the net; a single
  // surface is one face
  let faceList, faceRows;
  // a body's point of each net row (sculpt/body_paint.py point_classes): rows of one class
  // are one control point of the body, shared by the faces that meet there (null: one surface)
  let pointClass = null;
  // trimmed faces (splinedeform/sculpt/trimmed.py): the points where the grid crosses the
  // trim loops follow the grids (samples ru·rv …); trimTriangles are the clipped mesh drawn,
  // inside[n] whether sample n lies in its face's trims (only those are grabbed)
  let trimTriangles = null, inside = null;
  function unpack(d) {
    K = d.modes; [ru, rv] = d.grid;
    N = ru * rv + (d.trim ? d.trim.crossings.u.length : 0);
    trimTriangles = d.trim ? decode(d.trim.triangles, Int32Array) : null;
    inside = d.trim ? decode(d.trim.inside, Uint8Array) : null;
    faceList = d.faces || [{ v: d.v, net: d.net_shape, periodic: d.periodic }];
    faceRows = ru / faceList.length;
    lam = decode(d.lam, Float64Array); damp = decode(d.damping, Float64Array);
    phi = decode(d.phi, Float32Array); rest = decode(d.rest, Float32Array);
    phiNet = decode(d.phi_net, Float32Array); netRest = decode(d.net_rest, Float32Array);
    NN = d.net_shape[0] * d.net_shape[1];
    freeMask = decode(d.free_mask, Uint8Array).slice();
    stillMask = decode(d.still_mask, Uint8Array);   // cannot move in the solved model
    if (!pinnedMask || pinnedMask.length !== NN) pinnedMask = new Uint8Array(NN);
    freeSource = d.free_region ? "box" : "points";
    [gU, gV] = d.greville;
    pointClass = d.body && d.body.classes ? decode(d.body.classes, Int32Array) : null;
  }
  unpack(data);
  // sample n: its face p (the file's face number of a body), and (u, v) on that face
  function sampleAt(n) {
    if (n >= ru * rv) {
      const c = data.trim.crossings, k = n - ru * rv, p = c.face[k];
      return { face: p, number: data.body ? data.body.faces[p] : p, u: c.u[k], v: c.v[k] };
    }
    const p = Math.floor(n / (faceRows * rv));
    return { face: p, number: data.body ? data.body.faces[p] : p, u: data.u[Math.floor(n / rv)], v: faceList[p].v[n % rv] };
  }
  // what fixes the page's geometry: the sample grid and each face's net
  const layoutOf = (d) => JSON.stringify([d.grid, (d.faces || []).map((face) => face.net), d.net_shape, d.periodic,
                                          d.trim ? [d.trim.triangles, d.trim.inside] : null]);

  // -- modal state: (q, q', f) per mode and coordinate at the last event tEvent --------------
  // q(τ) = f/λ + e^{-στ}(a C + (b + σ a) S), q'(τ) = e^{-στ}(b C - (λ a + σ b) S),
  // a = q0 - f/λ, b = q0', σ = c/2, s = σ² - λ, C = Σ (sτ²)^n/(2n)!, S = τ Σ (sτ²)^n/(2n+1)!
  // (cos/sin, 1/τ or cosh/sinh): see splinedeform/sculpt/state.py, its Python twin.
  let q, v, f, qt, eV, eC, eS, gq, gv;
  function allocate() {
    q = new Float64Array(K * 3); v = new Float64Array(K * 3); f = new Float64Array(K * 3);
    qt = new Float64Array(K * 3); eV = new Float64Array(K * 3); eC = new Float64Array(K); eS = new Float64Array(K);
    gq = new Float64Array(K * 3); gv = new Float64Array(K * 3);
    phiPeak = -1;
  }
  function dampedCS(tau) {
    for (let i = 0; i < K; i++) {
      const sigma = damp[i] / 2, s = sigma * sigma - lam[i], x = s * tau * tau;
      const decay = Math.exp(-sigma * tau);
      if (Math.abs(x) < 1e-3) {
        eC[i] = decay * (1 + x * (1 / 2 + x * (1 / 24 + x / 720)));
        eS[i] = decay * tau * (1 + x * (1 / 6 + x * (1 / 120 + x / 5040)));
      } else if (s < 0) {
        const w = Math.sqrt(-s);
        eC[i] = decay * Math.cos(w * tau); eS[i] = decay * Math.sin(w * tau) / w;
      } else {
        const d = Math.sqrt(s), grow = Math.exp((d - sigma) * tau), fall = Math.exp((-d - sigma) * tau);
        eC[i] = (grow + fall) / 2; eS[i] = (grow - fall) / (2 * d);
      }
    }
  }
  // state after tau under the constant modal force f; into (outQ, outV) (outV may be null)
  function propagate(q0, v0, force, tau, outQ, outV) {
    dampedCS(tau);
    for (let i = 0; i < K; i++) {
      const l = lam[i], sigma = damp[i] / 2, c = eC[i], sn = eS[i];
      for (let j = 3 * i; j < 3 * i + 3; j++) {
        const r = force[j] / l, a = q0[j] - r, b = v0[j];
        outQ[j] = r + a * c + (b + sigma * a) * sn;
        if (outV) outV[j] = b * c - (l * a + sigma * b) * sn;
      }
    }
  }

  // -- the static correction follows the dynamics ---------------------------------------------
  // r_a ⊗ z_a, not r_a ⊗ P_a: the omitted modes reach their static part r_a P_a only as fast as
  // their dynamics lets them, so z_a obeys z'' + c* z' + λ* z = λ* P_a(t) (static limit z = P,
  // mode acceleration's exact static answer) with (λ*, c*) = (λ_K, c_K), the highest kept mode:
  // no omitted mode is slower (λ_j ≥ λ_K; over-damped, a step reaches λ_j g_j(τ) ≥ λ_K g_K(τ)),
  // so the correction never adds a static part the dynamics has not reached (damping 1e8: a
  // held push dents the sheet at the pace of the modes, not at once). Kept per grabbed
  // sample as (z, z', force λ* P) at tEvent, like the modes; dropped when the page settles.
  const lagged = new Map();          // sample index -> {z, zv, fz: Float64Array(3)}
  const lagCS = new Float64Array(2); // e^{-στ} C(τ), e^{-στ} S(τ) of the follower mode
  function followerCS(tau) {
    const l = lam[K - 1], sigma = damp[K - 1] / 2, s = sigma * sigma - l, x = s * tau * tau;
    const decay = Math.exp(-sigma * tau);
    if (Math.abs(x) < 1e-3) {
      lagCS[0] = decay * (1 + x * (1 / 2 + x * (1 / 24 + x / 720)));
      lagCS[1] = decay * tau * (1 + x * (1 / 6 + x * (1 / 120 + x / 5040)));
    } else if (s < 0) {
      const w = Math.sqrt(-s);
      lagCS[0] = decay * Math.cos(w * tau); lagCS[1] = decay * Math.sin(w * tau) / w;
    } else {
      const d = Math.sqrt(s), grow = Math.exp((d - sigma) * tau), fall = Math.exp((-d - sigma) * tau);
      lagCS[0] = (grow + fall) / 2; lagCS[1] = (grow - fall) / (2 * d);
    }
  }
  // the follower's state of `entry` after tau (from tEvent) into (outZ, outV)
  function lagAdvance(entry, tau, outZ, outV) {
    followerCS(tau);
    const l = lam[K - 1], sigma = damp[K - 1] / 2, c = lagCS[0], sn = lagCS[1];
    for (let j = 0; j < 3; j++) {
      const r = entry.fz[j] / l, a = entry.z[j] - r, b = entry.zv[j];
      outZ[j] = r + a * c + (b + sigma * a) * sn;
      if (outV) outV[j] = b * c - (l * a + sigma * b) * sn;
    }
  }

  // -- session: time, pushes, the held grab --------------------------------------------------
  let t = 0, tEvent = 0, paused = false, speed = 1;
  let pushes = [];           // {index, force: [3], t_on, t_off|null}: what "Save" sends
  let grab = null;           // the grab of the main pointer: {index, force: [3], push, normal, depth, pointerId}
  // the other grabs held at once: a second finger's ({pointerId, pointer}), a grab released
  // with shift that stays held by its spring to where the pointer was ({anchor}), or a force
  // held without a spring ({fixed}); the forces of all superpose
  let extra = [];
  const corrections = new Map();   // sample index -> Float32Array(N) static correction column
  function allGrabs() { return (grab ? [grab] : []).concat(extra); }
  // a change of the held forces at the current time: carry the state to t, then switch to
  // f = Σ_g φ(a_g) F_g (and the followers of the static correction to λ* Σ F at each point)
  function setForce() {
    propagate(q, v, f, t - tEvent, q, v);
    lagged.forEach((entry) => { lagAdvance(entry, t - tEvent, entry.z, entry.zv); entry.fz.fill(0); });
    tEvent = t;
    dirty = true;                      // redraw even when paused (the static part changes)
    f.fill(0);
    const l = lam[K - 1];
    for (const g of allGrabs()) {
      const force = g.force;
      if (!force) continue;
      if (!data.complete) {
        if (!lagged.has(g.index)) lagged.set(g.index, { z: new Float64Array(3), zv: new Float64Array(3), fz: new Float64Array(3) });
        const fz = lagged.get(g.index).fz;
        fz[0] += l * force[0]; fz[1] += l * force[1]; fz[2] += l * force[2];
      }
      const base = g.index * K;
      for (let i = 0; i < K; i++) {
        const p = phi[base + i];
        f[3 * i] += p * force[0]; f[3 * i + 1] += p * force[1]; f[3 * i + 2] += p * force[2];
      }
    }
  }
  function reset() {
    q.fill(0); v.fill(0); f.fill(0); t = 0; tEvent = 0; pushes = []; grab = null; extra = []; carriedMotion = false;
    lagged.clear();
    controls.enabled = true;
    modalSum();                        // at rest now, not at the next frame (picking reads it)
    dirty = true;
  }

