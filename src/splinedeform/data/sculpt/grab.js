// sculpt page, part grab: grabbing (spring or normal push), and the static correction a saved page computes itself.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- grabbing -------------------------------------------------------------------------------
  function projectSample(n) {
    const p = new THREE.Vector3(rest[3 * n] + disp[3 * n], rest[3 * n + 1] + disp[3 * n + 1],
                                rest[3 * n + 2] + disp[3 * n + 2]).project(camera);
    const rect = renderer.domElement.getBoundingClientRect();
    return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height, z: p.z };
  }
  function pick(clientX, clientY) {
    camera.updateMatrixWorld();
    const e = camera.matrixWorldInverse.elements, P = camera.projectionMatrix.elements;
    const rect = renderer.domElement.getBoundingClientRect();
    const px = (clientX - rect.left) / rect.width * 2 - 1, py = 1 - (clientY - rect.top) / rect.height * 2;
    const tolX = 14 / rect.width * 2, tolY = 14 / rect.height * 2;
    let best = -1, bestZ = Infinity, bestD = Infinity;
    for (let n = 0; n < N; n++) {
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
  let pointer = null;       // last pointer position while grabbing
  container.addEventListener("pointerdown", (event) => {
    const pinning = event.altKey || grabMode.value === "pin";
    if (event.button !== 0 || (grab && !pinning) || paintBox.checked) return;
    const index = pick(event.clientX, event.clientY);
    if (index < 0) return;                       // background: OrbitControls rotates
    event.stopPropagation();
    if (pinning) { pin(index); return; }         // pin (a bake: it ends a held grab), no grab
    controls.enabled = false;
    container.setPointerCapture && container.setPointerCapture(event.pointerId);
    requestCorrection(index);
    const proj = projectSample(index);
    grab = { index, force: null, push: null, depth: proj.z, normal: vertexNormal(index) };
    pointer = { x: event.clientX, y: event.clientY };
    pendingInput.push(event.timeStamp);
    dirty = true;
  }, { capture: true });
  container.addEventListener("pointermove", (event) => {
    if (!grab) return;
    pointer = { x: event.clientX, y: event.clientY };
    pendingInput.push(event.timeStamp);
    dirty = true;                        // the spring drawn follows the pointer, paused too
  });
  function release(event) {
    if (!grab) return;
    if (grab.push) {                     // a step of no duration (paused) is no push at all
      if (grab.push.t_on === t) pushes.splice(pushes.indexOf(grab.push), 1); else grab.push.t_off = t;
    }
    setForce(0, null);
    grab = null; pointer = null;
    controls.enabled = true;
    if (event) pendingInput.push(event.timeStamp);
    dirty = true;
  }
  // a force held at a sample without a spring (for tests and scripts): a grab whose force
  // stays what it is given until release
  function hold(index, force) {
    if (grab) release(null);
    requestCorrection(index);
    const F = force.slice();
    grab = { index, force: F, push: { index, force: F.slice(), t_on: t, t_off: null }, depth: 0,
             normal: vertexNormal(index) };
    pushes.push(grab.push);
    setForce(index, F);
  }
  container.addEventListener("pointerup", release);
  container.addEventListener("pointercancel", release);
  // the spring (or the push along the normal) from the grabbed point to the pointer, held
  // constant over one frame: each change is a new step of force at the current time.
  // The spring is implicit in the frame: the force F held over the coming step τ obeys
  // F = k (x_pointer - x_a(t + τ)) with x_a(t + τ) = x⁰_a(t + τ) + α(τ) F, where x⁰ is the
  // motion with no force from now and α(τ) = Σ_i φ_i(a)² g_i(τ) (+ r_a(a), the static
  // correction, reached at the pace of its follower mode) the point's answer to a unit force
  // held from now (g_i: the step response).
  // So F = k (x_pointer - x⁰_a(t + τ)) / (1 + k α(τ)): stable for any spring and frame
  // time (the force computed from the displacement at t alone overshoots by k α each frame
  // and diverges once k α > 1: a stiff small free set at a low frame rate).
  const gz = new Float64Array(3), gzv = new Float64Array(3);
  function grabPrediction(n, tau) {
    propagate(q, v, f, t - tEvent, gq, gv);              // the state now
    dampedCS(tau);
    const base = n * K, x = [0, 0, 0];
    let alpha = 0;
    for (let i = 0; i < K; i++) {
      const p = phi[base + i], sigma = damp[i] / 2, c = eC[i], sn = eS[i];
      for (let j = 0; j < 3; j++) {
        const a = gq[3 * i + j];
        x[j] += p * (a * c + (gv[3 * i + j] + sigma * a) * sn);
      }
      alpha += p * p * (1 - c - sigma * sn) / lam[i];
    }
    // the correction's followers: free motion from now, and the grabbed point's own step
    // response r_a(a) (1 - C* - σ* S*) (see the follower in the state part)
    lagged.forEach((entry, index) => {
      const col = corrections.get(index);
      if (!col) return;
      lagAdvance(entry, t - tEvent, gz, gzv);
      followerCS(tau);
      const sigma = damp[K - 1] / 2, c = lagCS[0], sn = lagCS[1], r = col[n];
      for (let j = 0; j < 3; j++) x[j] += r * (gz[j] * c + (gzv[j] + sigma * gz[j]) * sn);
    });
    const col = corrections.get(n);
    if (col && !data.complete) {
      followerCS(tau);
      alpha += col[n] * (1 - lagCS[0] - damp[K - 1] / 2 * lagCS[1]);
    }
    return { x, alpha };
  }
  function updateGrab(interval) {
    if (!grab || !pointer) return;
    const n = grab.index, tau = paused ? 0 : Math.min(interval, 100) / 1000 * speed;
    const target = pointerWorld(pointer.x, pointer.y, grab.depth);
    const { x, alpha } = grabPrediction(n, tau);
    const next = new THREE.Vector3(rest[3 * n] + x[0], rest[3 * n + 1] + x[1], rest[3 * n + 2] + x[2]);
    let pull = target.sub(next);
    if (grabMode.value === "normal") pull = grab.normal.clone().multiplyScalar(pull.dot(grab.normal));
    const spring = Number(springBox.value) / Math.max(flexibility(n), 1e-300);
    const k = spring / (1 + spring * Math.max(alpha, 0));
    const F = [k * pull.x, k * pull.y, k * pull.z];
    const old = grab.force;
    if (old) {
      const change = Math.hypot(F[0] - old[0], F[1] - old[1], F[2] - old[2]);
      if (change <= 1e-3 * Math.hypot(old[0], old[1], old[2])) return;
    }
    if (grab.push) {
      if (grab.push.t_on === t) pushes.pop(); else grab.push.t_off = t;
    }
    grab.force = F;
    grab.push = { index: n, force: F.slice(), t_on: t, t_off: null };
    pushes.push(grab.push);
    setForce(n, F);
  }

