// sculpt page, part grab: grabbing (spring or normal push), and the static correction a saved page computes itself.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- grabbing -------------------------------------------------------------------------------
  function projectSample(n) {
    const p = new THREE.Vector3(rest[3 * n] + disp[3 * n], rest[3 * n + 1] + disp[3 * n + 1],
                                rest[3 * n + 2] + disp[3 * n + 2]).project(camera);
    const rect = renderer.domElement.getBoundingClientRect();
    return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height, z: p.z };
  }
  // the sample under the pointer inside the trims; -1 for none. A trimmed face's grid points
  // outside its trims are not drawn: the pointer over one (and over no drawn sample) is
  // refused with a message, -2 (see splinedeform/sculpt/trimmed.py)
  function pick(clientX, clientY) {
    const n = pickAny(clientX, clientY, true);
    if (n >= 0 || !inside) return n;
    const out = pickAny(clientX, clientY, false);
    if (out < 0) return -1;
    const at = sampleAt(out);
    showMessage("refused: u = " + at.u.toPrecision(4) + ", v = " + at.v.toPrecision(4) +
                (data.body ? " of face " + at.number : "") +
                " lies outside the trims (the cut-away part is not in the model); grab the surface inside its trim loops");
    return -2;
  }
  function pickAny(clientX, clientY, within) {
    camera.updateMatrixWorld();
    const e = camera.matrixWorldInverse.elements, P = camera.projectionMatrix.elements;
    const rect = renderer.domElement.getBoundingClientRect();
    const px = (clientX - rect.left) / rect.width * 2 - 1, py = 1 - (clientY - rect.top) / rect.height * 2;
    const tolX = 14 / rect.width * 2, tolY = 14 / rect.height * 2;
    let best = -1, bestZ = Infinity, bestD = Infinity;
    for (let n = 0; n < N; n++) {
      if (inside && Boolean(inside[n]) !== within) continue;
      const x = rest[3 * n] + disp[3 * n], y = rest[3 * n + 1] + disp[3 * n + 1], z = rest[3 * n + 2] + disp[3 * n + 2];
      const vx = e[0] * x + e[4] * y + e[8] * z + e[12], vy = e[1] * x + e[5] * y + e[9] * z + e[13];
      const vz = e[2] * x + e[6] * y + e[10] * z + e[14];
      if (vz >= 0) continue;
      const cx = P[0] * vx + P[8] * vz, cy = P[5] * vy + P[9] * vz, w = -vz;
      const dx = (cx / w - px) / tolX, dy = (cy / w - py) / tolY, d = dx * dx + dy * dy;
      if (d > 1) continue;
      // nearest to the camera among the samples under the pointer, then nearest to the pointer
      if (w < bestZ - 0.02 * radius || (Math.abs(w - bestZ) <= 0.02 * radius && d < bestD)) {
        best = n; bestZ = Math.min(w, bestZ); bestD = d;
      }
    }
    return best;
  }
  function pointerWorld(clientX, clientY, depth) {
    const rect = renderer.domElement.getBoundingClientRect();
    return new THREE.Vector3((clientX - rect.left) / rect.width * 2 - 1,
                             1 - (clientY - rect.top) / rect.height * 2, depth).unproject(camera);
  }
  function flexibility(index) {       // static deflection of the grabbed point per unit force
    let s = 0;
    const base = index * K;
    for (let i = 0; i < K; i++) s += phi[base + i] * phi[base + i] / lam[i];
    const col = corrections.get(index);
    return s + (col ? col[index] : 0);
  }
  function vertexNormal(n) {
    if (!normals) return new THREE.Vector3(0, 0, 1);
    return new THREE.Vector3(normals[3 * n], normals[3 * n + 1], normals[3 * n + 2]).normalize();
  }
  // -- static correction without the server (a saved page): the envelope Cholesky factor of
  // K_r (reordered by reverse Cuthill-McKee, sent in the page), once, at the first grab;
  // then r_a = G x - Φ_s Λ⁻¹ Φ_s[a]ᵀ with K_r x = G[a]ᵀ, G = E_s T (see correction.py)
  let offlineFactor = null;
  function factorOffline(o) {
    const n = o.n, ip = decode(o.k_indptr, Int32Array), ix = decode(o.k_indices, Int32Array);
    const val = decode(o.k_values, Float64Array), first = new Int32Array(n), start = new Int32Array(n + 1);
    for (let i = 0; i < n; i++) { first[i] = ix[ip[i]]; start[i + 1] = start[i] + (i - first[i] + 1); }
    const L = new Float64Array(start[n]);             // row i: columns first[i] .. i
    for (let i = 0; i < n; i++) for (let p = ip[i]; p < ip[i + 1]; p++) L[start[i] + ix[p] - first[i]] = val[p];
    for (let i = 0; i < n; i++) {
      const fi = first[i], ri = start[i] - fi;
      for (let j = fi; j < i; j++) {
        const fj = first[j], rj = start[j] - fj;
        let s = L[ri + j];
        for (let k = Math.max(fi, fj); k < j; k++) s -= L[ri + k] * L[rj + k];
        L[ri + j] = s / L[rj + j];
      }
      let d = L[ri + i];
      for (let k = fi; k < i; k++) d -= L[ri + k] * L[ri + k];
      if (!(d > 0)) throw new Error("the stiffness is not positive definite");
      L[ri + i] = Math.sqrt(d);
    }
    return { n, first, start, L, gp: decode(o.g_indptr, Int32Array), gi: decode(o.g_indices, Int32Array),
             gv: decode(o.g_values, Float64Array) };
  }
  function offlineColumn(a) {
    if (!offlineFactor) offlineFactor = factorOffline(data.offline);
    const { n, first, start, L, gp, gi, gv } = offlineFactor, x = new Float64Array(n);
    for (let p = gp[a]; p < gp[a + 1]; p++) x[gi[p]] = gv[p];
    for (let i = 0; i < n; i++) {                     // L y = b
      const ri = start[i] - first[i];
      let s = x[i];
      for (let k = first[i]; k < i; k++) s -= L[ri + k] * x[k];
      x[i] = s / L[ri + i];
    }
    for (let i = n - 1; i >= 0; i--) {                // Lᵀ x = y
      const ri = start[i] - first[i];
      x[i] /= L[ri + i];
      const xi = x[i];
      for (let k = first[i]; k < i; k++) x[k] -= L[ri + k] * xi;
    }
    const w = new Float64Array(K), col = new Float32Array(N);
    for (let i = 0; i < K; i++) w[i] = phi[a * K + i] / lam[i];
    for (let m = 0; m < N; m++) {
      let s = 0;
      for (let p = gp[m]; p < gp[m + 1]; p++) s += gv[p] * x[gi[p]];
      for (let i = 0; i < K; i++) s -= phi[m * K + i] * w[i];
      col[m] = s;
    }
    return col;
  }
  function requestCorrection(index) {
    if (data.complete || corrections.has(index)) return;
    if (!online) {
      if (!data.offline) return;
      try { corrections.set(index, offlineColumn(index)); }
      catch (err) { showMessage("static correction: " + err.message); }
      return;
    }
    corrections.set(index, null);
    post("api/correction", { version: data.version, index })
      .then((reply) => { if (reply.version === data.version) corrections.set(index, decode(reply.column, Float32Array)); })
      .catch((err) => { corrections.delete(index); showMessage("static correction: " + err.message); });
  }
  let pendingInput = [];    // event timestamps not yet shown in a frame
  let pointer = null;       // last position of the main pointer while grabbing
  container.addEventListener("pointerdown", (event) => {
    const pinning = event.altKey || grabMode.value === "pin";
    if (event.button !== 0 || paintBox.checked) return;
    if (grab && !pinning && grab.pointerId === event.pointerId) return;
    const index = pick(event.clientX, event.clientY);
    if (index === -2) { event.stopPropagation(); return; }   // outside the trims: refused
    if (index < 0) return;                       // background: OrbitControls rotates
    event.stopPropagation();
    if (pinning) { pin(index); return; }         // pin (a bake: it ends the grabs held), no grab
    controls.enabled = false;
    container.setPointerCapture && container.setPointerCapture(event.pointerId);
    requestCorrection(index);
    const proj = projectSample(index), at = { x: event.clientX, y: event.clientY };
    const g = { index, force: null, push: null, depth: proj.z, normal: vertexNormal(index), pointerId: event.pointerId };
    if (grab) { g.pointer = at; extra.push(g); }  // a second finger: a grab of its own
    else { grab = g; pointer = at; }
    pendingInput.push(event.timeStamp);
    dirty = true;
  }, { capture: true });
  container.addEventListener("pointermove", (event) => {
    const at = { x: event.clientX, y: event.clientY };
    if (grab && grab.pointerId === event.pointerId) pointer = at;
    else {
      const g = extra.find((e) => e.pointer && e.pointerId === event.pointerId);
      if (!g) return;
      g.pointer = at;
    }
    pendingInput.push(event.timeStamp);
    dirty = true;                        // the spring drawn follows the pointer, paused too
  });
  function endPush(g) {                  // a step of no duration (paused) is no push at all
    if (!g.push) return;
    if (g.push.t_on === t) pushes.splice(pushes.indexOf(g.push), 1); else g.push.t_off = t;
    g.push = null;
  }
  // a pointer let go: its grab ends, or, with shift held, stays held by its spring to the
  // place the pointer left (a second grab can then be added)
  function release(event) {
    const id = event && event.pointerId !== undefined ? event.pointerId : null;
    let g = grab && (id === null || grab.pointerId === id) ? grab : null;
    if (!g && id !== null) g = extra.find((e) => e.pointer && e.pointerId === id) || null;
    if (!g) return;
    const keep = Boolean(event && event.shiftKey && g.force);
    const at = g === grab ? pointer : g.pointer;
    if (g === grab) { grab = null; pointer = null; } else extra.splice(extra.indexOf(g), 1);
    if (keep) {
      g.anchor = pointerWorld(at.x, at.y, g.depth);
      g.pointer = null; g.pointerId = null;
      extra.push(g);
    } else endPush(g);
    setForce();
    if (!grab) controls.enabled = true;
    if (event) pendingInput.push(event.timeStamp);
    dirty = true;
  }
  // every grab ends (Esc, a bake, a re-solve, undo)
  function releaseAll() {
    if (!grab && !extra.length) return;
    for (const g of allGrabs()) endPush(g);
    grab = null; pointer = null; extra = [];
    setForce();
    controls.enabled = true;
    dirty = true;
  }
  // a force held at a sample without a spring (for tests and scripts), beside the other
  // grabs, until they are all let go
  function hold(index, force) {
    requestCorrection(index);
    const F = force.slice();
    const g = { index, force: F, push: { index, force: F.slice(), t_on: t, t_off: null }, depth: 0,
                normal: vertexNormal(index), fixed: true };
    extra.push(g);
    pushes.push(g.push);
    setForce();
  }
  container.addEventListener("pointerup", release);
  container.addEventListener("pointercancel", release);
  // The springs (or pushes along the normal) from the grabbed points to their pointers, held
  // constant over one frame: each change is a new step of force at the current time.
  // They are implicit in the frame: the forces F_g held over the coming step τ obey
  // F_g = k_g (x_pointer,g - x_g(t + τ)) with x_g(t + τ) = x⁰_g(t + τ) + Σ_h A_gh(τ) F_h, where
  // x⁰ is the motion with no force from now and A_gh(τ) = Σ_i φ_i(a_g) φ_i(a_h) g_i(τ)
  // (+ r_{a_h}(a_g) (1 - C* - σ* S*), the static correction reached at the pace of its
  // follower mode) the answer at a_g to a unit force at a_h held from now (g_i: the step
  // response). So (A + diag(1/k)) F = x_pointer - x⁰ - A F_fixed, one small symmetric
  // positive definite system (the same for x, y and z); for one grab
  // F = k (x_pointer - x⁰_a(t + τ)) / (1 + k α(τ)), α = A_aa: stable for any spring and frame
  // time (the force computed from the displacement at t alone overshoots by k α each frame
  // and diverges once k α > 1: a stiff small free set at a low frame rate).
  const gz = new Float64Array(3), gzv = new Float64Array(3);
  function springTarget(g) {
    if (g === grab) return pointerWorld(pointer.x, pointer.y, g.depth);
    return g.pointer ? pointerWorld(g.pointer.x, g.pointer.y, g.depth) : g.anchor.clone();
  }
  function updateGrab(interval) {
    const springs = [];
    if (grab && pointer) springs.push(grab);
    for (const g of extra) if (!g.fixed && (g.pointer || g.anchor)) springs.push(g);
    if (!springs.length) return;
    const tau = paused ? 0 : Math.min(interval, 100) / 1000 * speed;
    const fixed = extra.filter((g) => g.fixed && g.force), all = springs.concat(fixed);
    const m = springs.length, n = all.length;
    propagate(q, v, f, t - tEvent, gq, gv);              // the state now
    const free = springs.map(() => [0, 0, 0]);
    lagged.forEach((entry, index) => {                   // the followers' free motion
      const col = corrections.get(index);
      if (!col) return;
      lagAdvance(entry, t - tEvent, gz, gzv);
      followerCS(tau);
      const sigma = damp[K - 1] / 2, c = lagCS[0], sn = lagCS[1];
      springs.forEach((g, r) => {
        const w = col[g.index];
        for (let j = 0; j < 3; j++) free[r][j] += w * (gz[j] * c + (gzv[j] + sigma * gz[j]) * sn);
      });
    });
    followerCS(tau);
    const lagStep = 1 - lagCS[0] - damp[K - 1] / 2 * lagCS[1];
    dampedCS(tau);
    const A = springs.map(() => new Float64Array(n));
    for (let i = 0; i < K; i++) {
      const sigma = damp[i] / 2, c = eC[i], sn = eS[i], step = (1 - c - sigma * sn) / lam[i];
      for (let r = 0; r < m; r++) {
        const p = phi[springs[r].index * K + i];
        for (let j = 0; j < 3; j++) {
          const a = gq[3 * i + j];
          free[r][j] += p * (a * c + (gv[3 * i + j] + sigma * a) * sn);
        }
        for (let h = 0; h < n; h++) A[r][h] += p * phi[all[h].index * K + i] * step;
      }
    }
    if (!data.complete) for (let r = 0; r < m; r++) for (let h = 0; h < n; h++) {
      const col = corrections.get(all[h].index);
      if (col) A[r][h] += col[springs[r].index] * lagStep;
    }
    // (A_ss + diag(1/k)) F = x_pointer - x⁰ - A_sf F_fixed, by Gaussian elimination
    // a point that cannot move (held by an edge: no mode moves it) takes no force
    const still = springs.map((g) => !(flexibility(g.index) > 0));
    const M = springs.map((g, r) => {
      const row = Array.from(A[r].subarray(0, m));
      if (still[r]) return row.map((_, h) => (h === r ? 1 : 0));
      const k = Number(springBox.value) / flexibility(g.index);
      row[r] = Math.max(row[r], 0) + 1 / k;
      return row;
    });
    const b = springs.map((g, r) => {
      if (still[r]) return [0, 0, 0];
      const target = springTarget(g), x = free[r], rhs = [target.x - rest[3 * g.index] - x[0],
        target.y - rest[3 * g.index + 1] - x[1], target.z - rest[3 * g.index + 2] - x[2]];
      for (let h = m; h < n; h++) for (let j = 0; j < 3; j++) rhs[j] -= A[r][h] * all[h].force[j];
      return rhs;
    });
    for (let c = 0; c < m; c++) {
      let piv = c;
      for (let r = c + 1; r < m; r++) if (Math.abs(M[r][c]) > Math.abs(M[piv][c])) piv = r;
      [M[c], M[piv]] = [M[piv], M[c]]; [b[c], b[piv]] = [b[piv], b[c]];
      for (let r = c + 1; r < m; r++) {
        const e = M[r][c] / M[c][c];
        for (let k = c; k < m; k++) M[r][k] -= e * M[c][k];
        for (let j = 0; j < 3; j++) b[r][j] -= e * b[c][j];
      }
    }
    const F = springs.map(() => [0, 0, 0]);
    for (let r = m - 1; r >= 0; r--) for (let j = 0; j < 3; j++) {
      let s = b[r][j];
      for (let k = r + 1; k < m; k++) s -= M[r][k] * F[k][j];
      F[r][j] = s / M[r][r];
    }
    let changed = false;
    springs.forEach((g, r) => {
      let force = F[r];
      if (grabMode.value === "normal") {
        const nn = g.normal, dot = force[0] * nn.x + force[1] * nn.y + force[2] * nn.z;
        force = [dot * nn.x, dot * nn.y, dot * nn.z];
      }
      const old = g.force;
      if (old) {
        const change = Math.hypot(force[0] - old[0], force[1] - old[1], force[2] - old[2]);
        if (change <= 1e-3 * Math.hypot(old[0], old[1], old[2])) return;
      }
      endPush(g);
      g.force = force;
      g.push = { index: g.index, force: force.slice(), t_on: t, t_off: null };
      pushes.push(g.push);
      changed = true;
    });
    if (changed) setForce();
  }
