// sculpt page, part files: what the page writes as files (the offline page, the shape) and
// the surface it loads from one.
// The parts are concatenated in order inside one function scope (see sculpt/page.py).
  function download(name, content, type) {
    const url = URL.createObjectURL(new Blob([content], { type }));
    const link = document.createElement("a");
    link.href = url; link.download = name; link.style.display = "none";
    document.body.appendChild(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(url), 10000);
  }
  function fileStem() {
    return String(data.title || "sculpt").replace(/[^A-Za-z0-9._-]+/g, "_").replace(/^[._]+/, "") || "sculpt";
  }
  // "Save offline page": a page known to work from file:// — served, the server writes it
  // afresh for the current basis, with what the static correction needs (GET api/page);
  // offline, the page as it was parsed (kept by the state part before anything was drawn),
  // without the session token
  async function saveOfflinePage() {
    let text;
    try {
      if (online) {
        const response = await fetch("api/page", { headers: apiHeaders });
        if (!response.ok) {
          let reply;
          try { reply = await response.json(); } catch (err) { reply = {}; }
          throw new Error(reply.error || ("HTTP " + response.status));
        }
        text = await response.text();
      } else {
        const copy = pristinePage.cloneNode(true), token = copy.querySelector('meta[name="splinedeform-token"]');
        if (token) token.setAttribute("content", "");
        text = "<!DOCTYPE html>\n" + copy.outerHTML;
      }
    } catch (err) {
      showMessage("Save offline page: " + err.message);
      return null;
    }
    const name = fileStem() + "-offline.html";
    download(name, text, "text/html");
    showMessage("wrote " + name + " (opens from a file, no server needed)", true);
    return name;
  }
  document.getElementById("save-page").addEventListener("click", () => saveOfflinePage());
  window.sculptState.saveOfflinePage = saveOfflinePage;

  // the modal state now (what a bake or an export sends): q(t) of every mode, mode-major
  function currentQ() {
    const now = new Float64Array(K * 3);
    propagate(q, v, f, t - tEvent, now, null);
    return now;
  }
  // "Export": the shape now, x = P + T Φ_net q(t), as .3dm, OBJ or the net file, written by
  // the server's writers (POST api/export: splinedeform/sculpt/shape_files.py)
  async function exportShape(format) {
    if (!online) { showMessage("export needs the server (this is an offline copy): run splinedeform sculpt"); return null; }
    try {
      const response = await fetch("api/export", { method: "POST",
        headers: Object.assign({ "Content-Type": "application/json" }, apiHeaders),
        body: JSON.stringify({ version: data.version, q: Array.from(currentQ()), format }) });
      if (!response.ok) {
        let reply;
        try { reply = await response.json(); } catch (err) { reply = {}; }
        throw new Error(reply.error || ("HTTP " + response.status));
      }
      const named = /filename="([^"]+)"/.exec(response.headers.get("Content-Disposition") || "");
      const name = named ? named[1] : fileStem() + "-shape." + format;
      download(name, await response.blob(), response.headers.get("Content-Type") || "application/octet-stream");
      showMessage("wrote " + name + ((grab || extra.length) && !data.complete ? " (the modes' shape: the static correction of the held grab is not in it)" : ""), true);
      return name;
    } catch (err) {
      showMessage("export refused: " + err.message);
      return null;
    }
  }
  for (const format of ["3dm", "obj", "json"]) {
    document.getElementById("export-" + format).addEventListener("click", () => exportShape(format));
  }
  window.sculptState.currentQ = () => Array.from(currentQ());

  // "Load surface": a .3dm, a net file (.json) or a scenario (.toml) sent to the server
  // (POST api/load, at most 16 MiB: splinedeform/sculpt/upload.py); the new surface's modes
  // replace the page's (undo goes back), nothing carried over
  const MAX_UPLOAD = 16 * 2 ** 20;
  async function loadFile(file) {
    if (!online) { showMessage("loading a surface needs the server (this is an offline copy)"); return false; }
    if (!/\.(3dm|stp|step|igs|iges|json|toml)$/i.test(file.name)) { showMessage(file.name + ": the page loads .3dm (or STEP, IGES), .json (a net file) or .toml (a scenario)"); return false; }
    if (file.size > MAX_UPLOAD) { showMessage(file.name + ": " + file.size + " bytes, more than the " + MAX_UPLOAD + " the page may load"); return false; }
    if (solving) return false;
    solving = true;
    progressBox.textContent = "loading " + file.name + "…";
    try {
      releaseAll();
      const earlier = pageState();
      const response = await fetch("api/load", { method: "POST", body: await file.arrayBuffer(),
        headers: Object.assign({ "Content-Type": "application/octet-stream", "X-Sculpt-File-Name": encodeURIComponent(file.name) }, apiHeaders) });
      let reply;
      try { reply = await response.json(); } catch (err) { reply = { error: "no JSON answer (" + response.status + ")" }; }
      if (!response.ok) throw new Error(reply.error || ("HTTP " + response.status));
      remember(earlier);
      load(reply);
      frameCamera();
      progressBox.textContent = "loaded " + reply.loaded + ": " + K + " modes in " + reply.solve_seconds + " s";
      return true;
    } catch (err) {
      progressBox.textContent = "";
      showMessage("load refused: " + err.message);
      return false;
    } finally {
      solving = false;
      showHistory();
    }
  }
  const loadInput = document.getElementById("load-file");
  loadInput.addEventListener("change", () => { if (loadInput.files.length) loadFile(loadInput.files[0]).then(() => { loadInput.value = ""; }); });
  document.getElementById("load").addEventListener("click", () => loadInput.click());
