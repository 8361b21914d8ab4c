// sculpt page, part edges: a body's boundary edges, each with its own preset, listed in the
// boundary panel and drawn on the surface in the colour of their preset.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  // -- a body's boundary edges ------------------------------------------------------------------
  // data.body.edges lists every boundary edge (an edge no other face meets) as
  // {face, patch, edge, preset} (splinedeform/sculpt/body_edges.py). The "edges" preset sets
  // them all; each can then be set on its own. A re-solve sends as boundary.faces only the
  // edges whose preset differs from the one for all.
  // free green, pinned orange (the paint tool's free and held), clamped near black
  const EDGE_RGB = { free: [0.1, 0.62, 0.2], pinned: [0.93, 0.55, 0.1], clamped: [0.08, 0.08, 0.1] };
  let edgeLines = null, edgeSamples = [];
  const edgeSelect = (e) => document.getElementById("edge-" + e.face + "-" + e.edge);
  function bodyEdgeForms(box) {
    const edges = (data.body && data.body.edges) || [];
    if (!edges.length) return;
    const all = document.getElementById("boundary-u0");
    const list = document.createElement("div");
    list.id = "body-edges";
    list.style.cssText = "max-height: 150px; overflow-y: auto; margin: 2px 0 4px 0;";
    for (const e of edges) {
      const label = document.createElement("label");
      label.innerHTML = '<span class="name"></span><select></select>';
      label.querySelector(".name").textContent = "face " + e.face + " " + e.edge;
      const select = label.querySelector("select");
      select.id = "edge-" + e.face + "-" + e.edge;
      select.title = "edge " + e.edge + " of face " + e.face + " (drawn in the colour of its preset)";
      for (const preset of ["free", "pinned", "clamped"]) {
        const option = document.createElement("option");
        option.value = option.textContent = preset;
        select.appendChild(option);
      }
      select.value = e.preset;
      select.addEventListener("change", colourEdges);
      list.appendChild(label);
    }
    box.appendChild(list);
    all.addEventListener("change", () => {
      for (const e of edges) edgeSelect(e).value = all.value;
      colourEdges();
    });
    buildEdgeLines(edges);
  }
  // boundary.faces of a re-solve: {face: {edge: preset}} where an edge differs from "edges"
  function bodyEdgeFaces() {
    const all = document.getElementById("boundary-u0").value, faces = {};
    for (const e of (data.body && data.body.edges) || []) {
      const value = edgeSelect(e).value;
      if (value !== all) (faces[e.face] = faces[e.face] || {})[e.edge] = value;
    }
    return Object.keys(faces).length ? faces : null;
  }
  // the samples along each boundary edge of face p: rows p·faceRows … of the (ru, rv) grid
  function edgeRow(e) {
    const lo = e.patch * faceRows, hi = lo + faceRows - 1, out = [];
    if (e.edge === "u0" || e.edge === "u1") for (let j = 0; j < rv; j++) out.push((e.edge === "u0" ? lo : hi) * rv + j);
    else for (let i = lo; i <= hi; i++) out.push(i * rv + (e.edge === "v0" ? 0 : rv - 1));
    return out;
  }
  function buildEdgeLines(edges) {
    if (edgeLines) { scene.remove(edgeLines); edgeLines.geometry.dispose(); }
    edgeSamples = edges.map(edgeRow);
    const count = edgeSamples.reduce((s, row) => s + 2 * (row.length - 1), 0);
    const geometryE = new THREE.BufferGeometry();
    geometryE.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * count), 3));
    geometryE.setAttribute("color", new THREE.BufferAttribute(new Float32Array(3 * count), 3));
    edgeLines = new THREE.LineSegments(geometryE, new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false }));
    edgeLines.frustumCulled = false; edgeLines.renderOrder = 5;
    scene.add(edgeLines);
    colourEdges();
  }
  function colourEdges() {
    if (!edgeLines) return;
    const col = edgeLines.geometry.attributes.color.array, edges = data.body.edges;
    let m = 0;
    edgeSamples.forEach((row, k) => {
      const select = edgeSelect(edges[k]), rgb = EDGE_RGB[select ? select.value : edges[k].preset];
      for (let s = 0; s < 2 * (row.length - 1); s++, m += 3) col.set(rgb, m);
    });
    edgeLines.geometry.attributes.color.needsUpdate = true;
    dirty = true;
  }
  // each frame: the edges follow the surface (pos: the drawn sample positions)
  function drawEdges(pos) {
    if (!edgeLines) return;
    const out = edgeLines.geometry.attributes.position.array;
    let m = 0;
    for (const row of edgeSamples) for (let s = 0; s + 1 < row.length; s++) {
      const a = 3 * row[s], b = 3 * row[s + 1];
      out[m++] = pos[a]; out[m++] = pos[a + 1]; out[m++] = pos[a + 2];
      out[m++] = pos[b]; out[m++] = pos[b + 1]; out[m++] = pos[b + 2];
    }
    edgeLines.geometry.attributes.position.needsUpdate = true;
  }
  // a basis of one surface (or of a body without boundary edges) draws no edge lines
  function dropEdgeLines() {
    if (edgeLines) { scene.remove(edgeLines); edgeLines.geometry.dispose(); edgeLines = null; }
  }
