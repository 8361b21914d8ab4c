// sculpt page, part files: what the page writes as files (the offline page).
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
