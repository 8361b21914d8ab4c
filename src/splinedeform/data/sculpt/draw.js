// sculpt page, part draw: the scene, and per frame x = x0 + Φ_s q(t) (+ r_a ⊗ P held) summed over the samples and drawn.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- scene -------------------------------------------------------------------------------
  const container = document.getElementById("view");
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: false, powerPreference: "high-performance" });
  } catch (err) {
    showMessage("This browser cannot draw WebGL: " + err.message);
    throw err;
  }
  renderer.setPixelRatio(1);        // software WebGL pays per pixel: no 2x or 3x canvas on dense screens
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f5f7);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
  camera.up.set(0, 0, 1);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.enableDamping = false;
  let radius = 1;
  function frameCamera() {
    const box = new THREE.Box3(), p = new THREE.Vector3();
    for (let k = 0; k < rest.length; k += 3) if (!inside || inside[k / 3]) box.expandByPoint(p.set(rest[k], rest[k + 1], rest[k + 2]));
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    radius = sphere.radius > 0 ? sphere.radius : 1;
    camera.near = radius / 100; camera.far = radius * 100;
    camera.position.copy(sphere.center).add(new THREE.Vector3(1.5, -2.6, 0.95).multiplyScalar(radius * 0.95));
    controls.target.copy(sphere.center);
    controls.update();
  }

  // The surface is lit per vertex on the CPU (below, in draw) and drawn with a shader that
  // only passes the vertex colour on: software WebGL (SwiftShader) runs every shader on
  // the CPU, and Phong lighting per pixel (or even per vertex in the shader) cost it more
  // per frame than the modal sum costs the page.
  const surfaceMaterial = new THREE.ShaderMaterial({
    side: THREE.DoubleSide, vertexColors: true,
    vertexShader: `
      varying vec3 shade;
      void main() { shade = color; gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`,
    fragmentShader: `
      varying vec3 shade;
      void main() { gl_FragColor = vec4(shade, 1.0); }`,
  });
  const lightDir = new THREE.Vector3(0, 0, 1);     // towards the directional light (the camera)
  // linear -> sRGB 8 bit, by table: 4096 steps of the linear value
  const SRGB = new Uint8Array(4097);
  for (let k = 0; k <= 4096; k++) {
    const c = k / 4096;
    SRGB[k] = Math.round(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1 / 2.4) - 0.055));
  }
  const toLinear = (c) => { c /= 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); };
  const cmap = Float32Array.from(data.colormap.flatMap((rgb) => rgb.map(toLinear)));
  const PLAIN = [0.55, 0.68, 0.85];                 // linear colour when not coloured
  let geometry, positions, colors, normals, magnitude, surfaceMesh, netGeometry, netPositions, netColors, netGroup = [];
  let disp, netDisp;
  function buildGeometry() {
    if (surfaceMesh) { scene.remove(surfaceMesh); geometry.dispose(); }
    netGroup.forEach((o) => scene.remove(o));
    geometry = new THREE.BufferGeometry();
    positions = new THREE.BufferAttribute(new Float32Array(N * 3), 3);
    colors = new THREE.BufferAttribute(new Uint8Array(N * 3), 3, true);   // lit, sRGB
    positions.setUsage(35048); colors.setUsage(35048);   // gl.DYNAMIC_DRAW: rewritten each frame
    geometry.setAttribute("position", positions);
    geometry.setAttribute("color", colors);
    normals = new Float32Array(N * 3);               // for the lighting, on the CPU only
    magnitude = new Float32Array(N);
    // two triangles per grid cell, in bands of 8 cells across: a triangle's vertices were
    // mostly used by the triangles just before it, which the vertex cache of a software
    // renderer keeps; 16-bit indices when they suffice
    // (face by face: no triangle joins two faces of a body)
    // (a trimmed face: the clipped mesh the server sends, welded along the trim loops)
    const faces = new (N <= 65536 ? Uint16Array : Uint32Array)(trimTriangles ? trimTriangles.length : faceList.length * (faceRows - 1) * (rv - 1) * 6);
    let m = 0;
    if (trimTriangles) faces.set(trimTriangles);
    else for (let lo = 0; lo < ru; lo += faceRows) {
      for (let j0 = 0; j0 + 1 < rv; j0 += 8) for (let i = lo; i + 1 < lo + faceRows; i++) {
        for (let j = j0; j < Math.min(j0 + 8, rv - 1); j++) {
          const a = i * rv + j, b = (i + 1) * rv + j;
          faces[m++] = a; faces[m++] = b; faces[m++] = b + 1;
          faces[m++] = a; faces[m++] = b + 1; faces[m++] = a + 1;
        }
      }
    }
    geometry.setIndex(new THREE.BufferAttribute(faces, 1));
    surfaceMesh = new THREE.Mesh(geometry, surfaceMaterial);
    surfaceMesh.frustumCulled = false;     // the surface stays in view: no bounding sphere per frame
    scene.add(surfaceMesh);
    const segments = [];
    let start = 0;                   // each face's net: its own lines, none between faces
    for (const face of faceList) {
      const [nu, nv] = face.net, [wrapU, wrapV] = face.periodic;
      for (let k = 0; k < nu; k++) for (let l = 0; l < nv; l++) {
        if (k + 1 < nu || wrapU) segments.push(start + k * nv + l, start + ((k + 1) % nu) * nv + l);
        if (l + 1 < nv || wrapV) segments.push(start + k * nv + l, start + k * nv + (l + 1) % nv);
      }
      start += nu * nv;
    }
    netGeometry = new THREE.BufferGeometry();
    netPositions = new THREE.BufferAttribute(new Float32Array(NN * 3), 3);
    netGeometry.setAttribute("position", netPositions);
    netColors = new THREE.BufferAttribute(new Float32Array(NN * 3), 3);
    netGeometry.setAttribute("color", netColors);
    netGeometry.setIndex(segments);
    netGroup = [
      new THREE.LineSegments(netGeometry, new THREE.LineBasicMaterial({ color: 0x333333 })),
      new THREE.Points(netGeometry, new THREE.PointsMaterial({ vertexColors: true, size: 6, sizeAttenuation: false })),
    ];
    netGroup.forEach((o) => { o.frustumCulled = false; o.visible = showNet.checked; scene.add(o); });
    disp = new Float64Array(N * 3); netDisp = new Float64Array(NN * 3);
    paintNet();
  }

  // -- the grab, seen: a marker at the grabbed point and the spring drawn to the pointer -----
  const GRAB_COLOUR = 0xd0302a, MAX_SHOWN = 16;
  const markerPositions = new THREE.BufferAttribute(new Float32Array(3 * MAX_SHOWN), 3);
  const springPositions = new THREE.BufferAttribute(new Float32Array(6 * MAX_SHOWN), 3);
  const markerGeometry = new THREE.BufferGeometry(), springGeometry = new THREE.BufferGeometry();
  markerGeometry.setAttribute("position", markerPositions);
  springGeometry.setAttribute("position", springPositions);
  const grabMarker = new THREE.Points(markerGeometry, new THREE.PointsMaterial(
    { color: GRAB_COLOUR, size: 11, sizeAttenuation: false, depthTest: false }));
  const springLine = new THREE.LineSegments(springGeometry, new THREE.LineBasicMaterial(
    { color: GRAB_COLOUR, depthTest: false }));
  for (const o of [grabMarker, springLine]) { o.frustumCulled = false; o.visible = false; o.renderOrder = 10; scene.add(o); }
  // where the main grab's point is drawn and where its spring ends (null: no spring, e.g. a
  // held force); every grab held gets its marker and its spring (to its pointer or anchor)
  let grabEnds = null;
  function showGrab() {
    grabEnds = null;
    const shown = allGrabs().slice(0, MAX_SHOWN);
    let points = 0, lines = 0;
    for (const g of shown) {
      const n = g.index, at = [rest[3 * n] + disp[3 * n], rest[3 * n + 1] + disp[3 * n + 1], rest[3 * n + 2] + disp[3 * n + 2]];
      markerPositions.array.set(at, 3 * points++);
      let end = null;
      if (g === grab ? pointer : (g.pointer || g.anchor)) {
        const p = springTarget(g);
        end = [p.x, p.y, p.z];
        springPositions.array.set(at, 6 * lines); springPositions.array.set(end, 6 * lines + 3);
        lines++;
      }
      if (g === grab) grabEnds = { point: at, pointer: end };
    }
    markerGeometry.setDrawRange(0, points); springGeometry.setDrawRange(0, 2 * lines);
    markerPositions.needsUpdate = springPositions.needsUpdate = true;
    grabMarker.visible = points > 0; springLine.visible = lines > 0;
  }

  // -- per frame: x = x0 + Φ_s q(t) (+ r_a ⊗ P held) ---------------------------------------------
  let vmax = 0, dmax = 0, dirty = true;   // colour scale (never 0), largest |d| drawn
  // out[3n + c] = Σ_i A[n K + i] q_c,i for the rows n of a (rows × K) float32 matrix A
  // (Φ_s or the net's), float64 sums in the order i = 0 … K-1; two rows at a time, so that
  // each modal coordinate is loaded once for both (the loop is bound by its loads)
  let qx = null, qy = null, qz = null;
  const lagZ = new Float64Array(3), lagV = new Float64Array(3);
  function superpose(A, rows, out) {
    let n = 0;
    for (; n + 1 < rows; n += 2) {
      let ax = 0, ay = 0, az = 0, bx = 0, by = 0, bz = 0;
      const r0 = n * K, r1 = r0 + K;
      for (let i = 0; i < K; i++) {
        const x = qx[i], y = qy[i], z = qz[i], p = A[r0 + i], r = A[r1 + i];
        ax += p * x; ay += p * y; az += p * z; bx += r * x; by += r * y; bz += r * z;
      }
      const k = 3 * n;
      out[k] = ax; out[k + 1] = ay; out[k + 2] = az; out[k + 3] = bx; out[k + 4] = by; out[k + 5] = bz;
    }
    for (; n < rows; n++) {
      let sx = 0, sy = 0, sz = 0;
      const r0 = n * K;
      for (let i = 0; i < K; i++) { const p = A[r0 + i]; sx += p * qx[i]; sy += p * qy[i]; sz += p * qz[i]; }
      out[3 * n] = sx; out[3 * n + 1] = sy; out[3 * n + 2] = sz;
    }
  }
  function modalSum() {
    propagate(q, v, f, t - tEvent, qt, null);
    if (!qx || qx.length !== K) { qx = new Float64Array(K); qy = new Float64Array(K); qz = new Float64Array(K); }
    for (let i = 0; i < K; i++) { qx[i] = qt[3 * i]; qy[i] = qt[3 * i + 1]; qz[i] = qt[3 * i + 2]; }
    superpose(phi, N, disp);
    lagged.forEach((entry, index) => {           // r_a ⊗ z_a(t), the correction reached so far
      const col = corrections.get(index);
      if (!col) return;
      lagAdvance(entry, t - tEvent, lagZ, null);
      const zx = lagZ[0], zy = lagZ[1], zz = lagZ[2];
      for (let n = 0; n < N; n++) {
        const r = col[n];
        disp[3 * n] += r * zx; disp[3 * n + 1] += r * zy; disp[3 * n + 2] += r * zz;
      }
    });
    if (showNet.checked) superpose(phiNet, NN, netDisp);
  }
  // Released and rung down: once no mode can move any sample by more than 1e-6 of the
  // surface's size (far below a pixel), the state is set to rest and nothing more is
  // computed or drawn until the next push. With
  // mass-normalised modes the energy E = Σ (q'² + λ q²) / 2 bounds each amplitude by
  // √(2E/λ_min), hence |d| ≤ √(2E/λ_min) Σ_i max_n |Φ_s[n, i]|.
  let phiPeak = -1;
  function settle() {
    const lagging = lagged.size > 0;
    if (grab || extra.length || paused || f.some((x) => x !== 0) || !(lagging || q.some((x) => x !== 0) || v.some((x) => x !== 0))) return;
    if (phiPeak < 0) {
      phiPeak = 0;
      const top = new Float64Array(K);
      for (let k = 0; k < N * K; k++) { const a = Math.abs(phi[k]), i = k % K; if (a > top[i]) top[i] = a; }
      for (let i = 0; i < K; i++) phiPeak += top[i];
    }
    propagate(q, v, f, t - tEvent, qt, eV);
    let energy = 0, lmin = Infinity;
    for (let i = 0; i < K; i++) {
      lmin = Math.min(lmin, lam[i]);
      for (let j = 3 * i; j < 3 * i + 3; j++) energy += (eV[j] * eV[j] + lam[i] * qt[j] * qt[j]) / 2;
    }
    // the correction's follower: |r_a z_a| ≤ max |r_a| √(2 E_z / λ*), E_z = (z'² + λ* z²) / 2
    let lagBound = 0;
    lagged.forEach((entry, index) => {
      const col = corrections.get(index);
      lagAdvance(entry, t - tEvent, lagZ, lagV);
      let e = 0, top = 0;
      for (let j = 0; j < 3; j++) e += (lagV[j] * lagV[j] + lam[K - 1] * lagZ[j] * lagZ[j]) / 2;
      if (col) for (let n = 0; n < N; n++) top = Math.max(top, Math.abs(col[n]));
      lagBound += top * Math.sqrt(2 * e / lam[K - 1]);
    });
    if (Math.sqrt(2 * energy / lmin) * phiPeak + lagBound < 1e-6 * radius) {
      q.fill(0); v.fill(0); lagged.clear(); tEvent = t; dirty = true;
    }
  }
  // normals of the sample grid: x_u × x_v by differences along the grid (one-sided at the
  // edges of each face), the same orientation as the faces; cheaper than three.js' per-face
  // accumulation
  function gridNormals(pos, out) {
    for (let i = 0; i < ru; i++) {
      const lo = i - (i % faceRows), hi = lo + faceRows - 1;
      const i0 = i > lo ? i - 1 : i, i1 = i < hi ? i + 1 : i;
      for (let j = 0; j < rv; j++) {
        const j0 = j > 0 ? j - 1 : j, j1 = j + 1 < rv ? j + 1 : j;
        const a = 3 * (i1 * rv + j), b = 3 * (i0 * rv + j), c = 3 * (i * rv + j1), d = 3 * (i * rv + j0);
        const ux = pos[a] - pos[b], uy = pos[a + 1] - pos[b + 1], uz = pos[a + 2] - pos[b + 2];
        const vx = pos[c] - pos[d], vy = pos[c + 1] - pos[d + 1], vz = pos[c + 2] - pos[d + 2];
        let nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
        const len = Math.hypot(nx, ny, nz) || 1, k = 3 * (i * rv + j);
        out[k] = nx / len; out[k + 1] = ny / len; out[k + 2] = nz / len;
      }
    }
  }
  // A pole (an edge row of samples collapsed to one point, e.g. the top of a half sphere)
  // has x_v = 0 (or x_u = 0) there, so x_u × x_v = 0: use the limit normal instead, the sum
  // Σ_j t_j × t_{j+1} of the cross products of consecutive tangents t_j = x_u(i, v_j) leaving
  // the pole (they span the tangent plane there), oriented like the normals of the next row.
  function poleNormals(pos, out) {
    const tol = 1e-6 * radius;
    const at = (i, j) => 3 * (i * rv + j);
    const collapsed = (count, index) => {
      const a = index(0);
      for (let m = 1; m < count; m++) {
        const b = index(m);
        if (Math.abs(pos[a] - pos[b]) + Math.abs(pos[a + 1] - pos[b + 1]) + Math.abs(pos[a + 2] - pos[b + 2]) > tol) return false;
      }
      return true;
    };
    // edge = [count along it, sample index (m) on the edge, on the next row inwards], for
    // each face (rows lo … hi)
    const edges = [];
    for (let lo = 0; lo < ru; lo += faceRows) {
      const hi = lo + faceRows - 1;
      edges.push([rv, (m) => at(lo, m), (m) => at(lo + 1, m)], [rv, (m) => at(hi, m), (m) => at(hi - 1, m)],
                 [faceRows, (m) => at(lo + m, 0), (m) => at(lo + m, 1)], [faceRows, (m) => at(lo + m, rv - 1), (m) => at(lo + m, rv - 2)]);
    }
    for (const [count, edge, inner] of edges) {
      if (faceRows < 2 || rv < 2 || !collapsed(count, edge)) continue;
      let nx = 0, ny = 0, nz = 0, ox = 0, oy = 0, oz = 0;
      for (let m = 0; m + 1 < count; m++) {
        const a = edge(m), b = inner(m), c = edge(m + 1), d = inner(m + 1);
        const tx = pos[b] - pos[a], ty = pos[b + 1] - pos[a + 1], tz = pos[b + 2] - pos[a + 2];
        const sx = pos[d] - pos[c], sy = pos[d + 1] - pos[c + 1], sz = pos[d + 2] - pos[c + 2];
        nx += ty * sz - tz * sy; ny += tz * sx - tx * sz; nz += tx * sy - ty * sx;
        ox += out[b]; oy += out[b + 1]; oz += out[b + 2];
      }
      const sign = nx * ox + ny * oy + nz * oz < 0 ? -1 : 1, len = Math.hypot(nx, ny, nz);
      if (!(len > 0)) continue;
      for (let m = 0; m < count; m++) {
        const k = edge(m);
        out[k] = sign * nx / len; out[k + 1] = sign * ny / len; out[k + 2] = sign * nz / len;
      }
    }
  }
  // normals of the clipped mesh of trimmed faces: the sum of the (area-weighted) normals
  // of the triangles at each vertex, oriented like the triangles (x_u × x_v)
  function meshNormals(pos, out) {
    out.fill(0);
    const tri = trimTriangles;
    for (let m = 0; m < tri.length; m += 3) {
      const a = 3 * tri[m], b = 3 * tri[m + 1], c = 3 * tri[m + 2];
      const ux = pos[b] - pos[a], uy = pos[b + 1] - pos[a + 1], uz = pos[b + 2] - pos[a + 2];
      const vx = pos[c] - pos[a], vy = pos[c + 1] - pos[a + 1], vz = pos[c + 2] - pos[a + 2];
      const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      for (const k of [a, b, c]) { out[k] += nx; out[k + 1] += ny; out[k + 2] += nz; }
    }
    for (let k = 0; k < out.length; k += 3) {
      const len = Math.hypot(out[k], out[k + 1], out[k + 2]) || 1;
      out[k] /= len; out[k + 1] /= len; out[k + 2] /= len;
    }
  }
  // x = x0 + d, |d|, grid normals, and the colour of each vertex lit on the CPU: the
  // colour c (plasma of |d| / max |d|, or plain) times the irradiance / π of a hemisphere
  // light (white sky +z, grey ground, 1.6) and a directional light from the camera (1.4),
  // Lambert, on the side of the surface in view; to sRGB by table
  function draw() {
    const pos = positions.array, col = colors.array, coloured = colourBox.checked;
    let top = 0;
    for (let n = 0, k = 0; n < N; n++, k += 3) {
      const dx = disp[k], dy = disp[k + 1], dz = disp[k + 2];
      pos[k] = rest[k] + dx; pos[k + 1] = rest[k + 1] + dy; pos[k + 2] = rest[k + 2] + dz;
      const m = Math.sqrt(dx * dx + dy * dy + dz * dz);
      magnitude[n] = m;
      if (m > top && (!inside || inside[n])) top = m;     // what is drawn: inside the trims
    }
    vmax = Math.max(top, vmax * 0.995, 1e-6 * radius);
    dmax = top;
    if (trimTriangles) meshNormals(pos, normals); else { gridNormals(pos, normals); poleNormals(pos, normals); }
    const cam = camera.position, lx = lightDir.x, ly = lightDir.y, lz = lightDir.z;
    const steps = cmap.length / 3 - 1, toIndex = steps / vmax, ground = 0.2462;
    let r = PLAIN[0], g = PLAIN[1], b = PLAIN[2];
    for (let n = 0, k = 0; n < N; n++, k += 3) {
      let nx = normals[k], ny = normals[k + 1], nz = normals[k + 2];
      if (nx * (cam.x - pos[k]) + ny * (cam.y - pos[k + 1]) + nz * (cam.z - pos[k + 2]) < 0) {
        nx = -nx; ny = -ny; nz = -nz;
      }
      const direct = Math.max(nx * lx + ny * ly + nz * lz, 0);
      const light = 4096 * (1.6 * (ground + (1 - ground) * (0.5 * nz + 0.5)) + 1.4 * direct) / Math.PI;
      if (coloured) {
        const c = 3 * Math.min(steps, Math.round(magnitude[n] * toIndex));
        r = cmap[c]; g = cmap[c + 1]; b = cmap[c + 2];
      }
      col[k] = SRGB[Math.min(4096, (r * light) | 0)];
      col[k + 1] = SRGB[Math.min(4096, (g * light) | 0)];
      col[k + 2] = SRGB[Math.min(4096, (b * light) | 0)];
    }
    positions.needsUpdate = true; colors.needsUpdate = true;
    if (showNet.checked) {
      const np = netPositions.array;
      for (let k = 0; k < NN * 3; k++) np[k] = netRest[k] + netDisp[k];
      netPositions.needsUpdate = true;
    }
    drawEdges(pos);
    showGrab();
    renderer.render(scene, camera);
  }

