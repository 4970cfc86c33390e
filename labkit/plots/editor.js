// The browser side of labkit.plots.patch_editor (an anywidget module; scene.js comes before this file).
// The kernel sends a background picture and the mesh as a scene (both at the page's devicePixelRatio,
// which this module reports in `pixel_ratio`), the handles in data coordinates and where the axes lie in
// the picture (CSS pixels); this module paints the scene on a canvas over the background (in
// requestAnimationFrame, the newest scene only; each paint raises data-labkit-shown once its frame is
// rendered), draws the handles over it, moves them under the mouse at once, and sends the dragged
// handle's position to the kernel, one request at a time (the newest wins). A move of the mesh-size or twist
// slider to the values of a picture the kernel sent ahead (scene.js's sceneAhead) shows it, its readout and
// status at once; pictures drawn ahead are keyed by the last drag drawn (`ack`) too, and none is shown mid-drag.
// A handle's move is drawn here at once (mesh.js, from the kernel's `sketch`: the mesh, its colours and title as the
// kernel draws them); the kernel's picture of that move, when it comes, is drawn over it without counting as a
// new picture, and an answer older than the page is not drawn at all.
// Keyboard: Tab enters and leaves the editor like any control (never trapped, WCAG 2.1.2); n / p select
// the next / previous handle; the arrow keys move it (Shift: 5 times further). The picture and handles
// form an ARIA "application" named by the model's label; a polite live region speaks the model's status
// (the selected handle and the worst quality, both from the kernel) after every change.
const SVG = "http://www.w3.org/2000/svg";
const COLORS = ["#111", "#d62728", "#6a3d9a"]; // corner, d/ds tip, d/dt tip
const NAMES = "ABCD";
const CYCLE = { n: 1, p: 11 }; // next and previous handle, of 12
const STYLE = `.labkit-editor:focus { outline: none; }
.labkit-editor:focus-visible { outline: 3px solid #1a73e8; outline-offset: 2px; }`;

function make(tag, attrs, parent) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, value);
  if (parent) parent.appendChild(node);
  return node;
}

function render({ model, el }) {
  const root = document.createElement("div");
  root.className = "labkit-editor-box";
  root.style.cssText = "display:flex; gap:12px; align-items:flex-start";
  const style = document.createElement("style");
  style.textContent = STYLE;
  // the picture and its handles take the keyboard: an application, so a screen reader passes the keys on
  const stage = document.createElement("div");
  stage.className = "labkit-editor";
  stage.tabIndex = 0;
  stage.setAttribute("role", "application");
  stage.setAttribute("aria-label", model.get("label"));
  stage.dataset.lmSuppressShortcuts = "true"; // keys here are the editor's, not JupyterLab's commands
  stage.style.cssText = "position:relative; line-height:0";
  const img = document.createElement("img");
  img.className = "labkit-editor-image";
  img.draggable = false;
  img.style.cssText = "display:block";
  const canvas = document.createElement("canvas");
  canvas.className = "labkit-editor-canvas";
  canvas.setAttribute("aria-hidden", "true");
  canvas.style.cssText = "position:absolute; left:0; top:0; pointer-events:none";
  stage.dataset.labkitShown = "0";
  const svg = make("svg", { class: "labkit-editor-handles", "aria-hidden": "true", focusable: "false" });
  svg.style.cssText = "position:absolute; left:0; top:0; touch-action:none; cursor:default";
  const side = document.createElement("div");
  side.style.cssText = "display:flex; flex-direction:column; gap:6px; max-width:36em";
  const readout = document.createElement("pre");
  readout.className = "labkit-editor-readout";
  readout.style.cssText =
    "font-size:12px; margin:0; padding:6px; border:1px solid #767676; user-select:text; white-space:pre-wrap";
  const live = document.createElement("div");
  live.className = "labkit-editor-status";
  live.setAttribute("role", "status");
  live.setAttribute("aria-live", "polite");
  live.setAttribute("aria-atomic", "true");
  live.style.cssText = "font-size:12px";
  const keys = document.createElement("div");
  keys.className = "labkit-editor-keys";
  keys.style.cssText = "font-size:12px";
  keys.textContent = "Keys: " + model.get("key_help");
  stage.append(img, canvas, svg);
  side.append(readout, live, keys);
  root.append(style, stage, side);
  el.appendChild(root);

  let positions = model.get("handles").map((p) => p.slice());
  let dragging = null, selected = model.get("selected"), waiting = false, queued = [], seq = 0, url = null, timer = null;
  let ready = Promise.resolve(), painting = false, alive = true, media = null, next = null;
  // the corner data the handles stand for (the kernel's, then moved here) and the twist they were taken at; the
  // handles' moves made; the move whose mesh was sketched here and waits for the kernel's picture (0: none); and,
  // for each drag sent, the moves its answer shows (-1: not all, another handle's newest place is still to go)
  let corners = null, cornersTwist = null, moved = 0, sketched = 0;
  const sentMoved = new Map();
  const settled = () => dragging === null && !waiting && queued.length === 0; // nothing on its way to the kernel

  const frame = () => model.get("frame");
  function toPixels([x, y]) {
    const f = frame();
    return [f.left + ((x - f.x0) / (f.x1 - f.x0)) * (f.right - f.left),
            f.bottom - ((y - f.y0) / (f.y1 - f.y0)) * (f.bottom - f.top)];
  }
  function toData(px, py) {
    const f = frame();
    return [f.x0 + ((px - f.left) / (f.right - f.left)) * (f.x1 - f.x0),
            f.y0 + ((f.bottom - py) / (f.bottom - f.top)) * (f.y1 - f.y0)];
  }

  function draw() {
    const f = frame();
    svg.setAttribute("width", f.width);
    svg.setAttribute("height", f.height);
    img.style.width = f.width + "px";
    img.style.height = f.height + "px";
    canvas.style.width = f.width + "px";
    canvas.style.height = f.height + "px";
    svg.replaceChildren();
    for (let c = 0; c < 4; c++) {
      const [cx, cy] = toPixels(positions[c]);
      for (const tip of [c + 4, c + 8]) {
        const [tx, ty] = toPixels(positions[tip]);
        make("line", { x1: cx, y1: cy, x2: tx, y2: ty, stroke: COLORS[Math.floor(tip / 4)], "stroke-width": 2 }, svg);
      }
      make("text", { x: cx + 8, y: cy - 8, "font-size": 13, "font-weight": "bold" }, svg).textContent = NAMES[c];
    }
    positions.forEach((p, index) => {
      const [x, y] = toPixels(p);
      make("circle", {
        cx: x, cy: y, r: index < 4 ? 7 : 5, fill: COLORS[Math.floor(index / 4)], "data-handle": index,
        stroke: index === selected ? "#ffbf00" : "white", "stroke-width": index === selected ? 3 : 1.5,
        class: "labkit-handle", style: "cursor:grab",
      }, svg);
    });
  }

  // one drag message on its way at a time; meanwhile each moved handle waits in `queued`, sent in turn at its
  // newest place, so no handle's last move is lost
  function send(index) {
    if (waiting) { if (!queued.includes(index)) queued.push(index); return; }
    waiting = true;
    const [x, y] = positions[index];
    model.set("drag", { index, x, y, seq: ++seq });
    model.save_changes();
    sentMoved.set(seq, queued.length ? -1 : moved);
    clearTimeout(timer);
    timer = setTimeout(lost, 2000); // never stall if an answer is lost
  }

  // the kernel acknowledges every position it has drawn (even one that leaves the picture unchanged)
  function answered() {
    clearTimeout(timer);
    waiting = false;
    if (queued.length) send(queued.shift());
  }
  // no answer for 2 s: go on, and draw whatever the kernel sends next
  function lost() {
    sketched = 0;
    sentMoved.clear();
    answered();
  }
  function takeCorners(scene) {
    if (!scene || !scene.corners || !scene.values) return;
    corners = scene.corners.map((c) => c.slice());
    cornersTwist = scene.values.twist;
  }

  function place(index, point) {
    if (index < 4) { // a corner carries its two arrows along
      const dx = point[0] - positions[index][0], dy = point[1] - positions[index][1];
      for (const tip of [index + 4, index + 8]) positions[tip] = [positions[tip][0] + dx, positions[tip][1] + dy];
    }
    positions[index] = point;
    const arrow = (model.get("sketch") || {}).arrow;
    corners = corners && arrow ? meshMove(corners, index, point, arrow) : null;
    moved += 1;
    draw();
    send(index);
    sketch();
  }

  // the mesh of the handles' new place, drawn here, when the kernel's sketch is of the sliders' values and the
  // background shown
  function sketch() {
    const plan = model.get("sketch") || {};
    const now = ahead.controlsNow();
    if (!corners || !plan.in_s || !now || !sameValues(plan.values, now)) return;
    if (!sameValues({ twist: cornersTwist }, { twist: plan.values.twist })) return; // corners of another twist
    if (plan.background !== (model.get("scene") || {}).background) return;
    sketched = moved;
    show({ scene: { size: plan.size, items: meshItems(plan, corners).items }, sketched: true });
  }

  function mouse(event) {
    const box = svg.getBoundingClientRect();
    return toData(event.clientX - box.left, event.clientY - box.top);
  }

  svg.addEventListener("pointerdown", (event) => {
    const index = event.target.getAttribute && event.target.getAttribute("data-handle");
    if (index === null || index === undefined) return;
    dragging = Number(index);
    select(dragging);
    svg.setPointerCapture(event.pointerId);
    stage.focus();
    event.preventDefault();
  });
  svg.addEventListener("pointermove", (event) => {
    if (dragging !== null) place(dragging, mouse(event));
  });
  const release = (event) => {
    if (dragging === null) return;
    place(dragging, mouse(event));
    dragging = null;
    announce();
  };
  svg.addEventListener("pointerup", release);
  // a click on the picture gives it the keyboard (after JupyterLab has focused the cell)
  stage.addEventListener("pointerup", () => setTimeout(() => stage.focus(), 0));
  svg.addEventListener("pointercancel", release);

  // the kernel answers a new selection with the status sentence the live region speaks
  function select(index) {
    selected = index;
    draw();
    model.set("selected", index);
    model.save_changes();
  }

  stage.addEventListener("keydown", (event) => {
    if (event.altKey || event.ctrlKey || event.metaKey) return; // Tab and the browser's keys are not ours
    const f = frame();
    const step = (event.shiftKey ? 0.05 : 0.01) * (f.x1 - f.x0);
    const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, step], ArrowDown: [0, -step] };
    const key = event.key.length === 1 ? event.key.toLowerCase() : event.key;
    if (CYCLE[key]) {
      select((selected + CYCLE[key]) % 12);
    } else if (moves[event.key]) {
      const [dx, dy] = moves[event.key];
      place(selected, [positions[selected][0] + dx, positions[selected][1] + dy]);
    } else {
      return;
    }
    event.preventDefault();
    event.stopPropagation();
  });

  function showBackground() {
    const bytes = sceneBytes(model.get("background"));
    if (!bytes.length) return;
    const old = url;
    url = URL.createObjectURL(new Blob([bytes], { type: "image/png" }));
    img.src = url;
    ready = img.decode().catch(() => {}); // the scene waits for its background: both show in one frame
    if (old) ready.then(() => URL.revokeObjectURL(old));
  }
  function paint() {
    painting = false;
    if (!alive || !next) return;
    const picture = next;
    next = null;
    const scene = picture.scene;
    const [width, height] = scene.size || [0, 0];
    if (canvas.width !== width) canvas.width = width;
    if (canvas.height !== height) canvas.height = height;
    drawScene(canvas, scene.items || [], model.get("overlays") || {});
    if (picture.ahead) stage.dataset.labkitDrawnAhead = String(Number(stage.dataset.labkitDrawnAhead || 0) + 1);
    if (picture.sketched) stage.dataset.labkitSketched = String(Number(stage.dataset.labkitSketched || 0) + 1);
    if (!picture.quiet) sceneShown(stage); // the kernel's picture of a sketch shown is the same picture: not new
  }
  function show(picture) { // the text at once, as the message comes; the picture in the next frame
    // a picture not painted yet that was new to the page makes the one that replaces it new too
    next = picture.quiet && next && !next.quiet ? { ...picture, quiet: false } : picture;
    if (settled()) takeCorners(picture.scene);
    if (picture.readout !== undefined) {
      showReadout(picture);
      if (dragging === null) live.textContent = picture.status;
    }
    schedule();
  }
  // a picture drawn ahead shows the corners of the last drag drawn: none is shown while a drag is on its way
  const ahead = sceneAhead(model, stage, show, () => (settled() ? { shape: model.get("ack") } : null));
  function fromKernel() {
    const scene = model.get("scene") || {};
    const fields = Object.fromEntries(["readout", "worst", "alt", "status"].map((name) => [name, model.get(name)]));
    const picture = { scene, ...fields, values: scene.values, background: scene.background };
    const drag = scene.values ? scene.values.shape : undefined, at = sentMoved.get(drag);
    if (at === undefined ? settled() : at === moved) takeCorners(scene); // it shows every move made
    if (at !== undefined) {
      for (const k of [...sentMoved.keys()]) if (k <= drag) sentMoved.delete(k);
      if (sketched) {
        if (at < sketched) return; // older than the mesh sketched on the page: the answer to a newer move comes
        const same = at === sketched;
        sketched = 0;
        if (same) { // the kernel's picture of the sketch on the page
          ahead.note(picture);
          show({ ...picture, quiet: true });
          return;
        }
      }
    } else if (sketched && (drag < seq || queued.length)) {
      return; // a scene of a drag older than those on their way (a slider's, or the pixel ratio's): theirs come
    }
    ahead.fromKernel(picture);
  }
  function schedule() { // the next frame, once the newest background is decoded
    if (painting) return;
    painting = true;
    sceneDecoded(() => ready).then(() => requestAnimationFrame(paint));
  }
  function reportRatio() {
    const ratio = window.devicePixelRatio || 1;
    if (media) media.removeEventListener("change", reportRatio);
    media = window.matchMedia(`(resolution: ${ratio}dppx)`);
    media.addEventListener("change", reportRatio);
    if (model.get("pixel_ratio") !== ratio) {
      model.set("pixel_ratio", ratio);
      model.save_changes();
    }
  }
  function showReadout(picture) {
    fillReadout(readout, picture.readout || "");
    readout.style.borderColor = picture.worst <= 0 ? "#d62728" : "#767676";
    img.alt = picture.alt;
  }
  // the live region changes once a drag ends, not at every step of it (a screen reader would queue them all)
  function announce() {
    if (dragging === null) live.textContent = model.get("status");
  }

  model.on("change:background", showBackground);
  model.on("change:scene", fromKernel);
  // the answer to the drag on its way (an older one, late after `lost`, is not: the page is not settled by it)
  model.on("change:ack", () => { if (model.get("ack") >= seq) answered(); });
  model.on("change:status", announce);
  model.on("change:selected", () => { // set by the kernel (a drag's handle)
    if (model.get("selected") !== selected) { selected = model.get("selected"); draw(); }
  });
  model.on("change:handles", () => {
    if (settled()) { positions = model.get("handles").map((p) => p.slice()); draw(); }
  });
  model.on("change:frame", draw);
  showBackground();
  fromKernel();
  showReadout({ readout: model.get("readout"), worst: model.get("worst"), alt: model.get("alt") });
  announce();
  draw();
  reportRatio();
  return () => {
    alive = false;
    ahead.dispose();
    if (media) media.removeEventListener("change", reportRatio);
    if (url) URL.revokeObjectURL(url);
    clearTimeout(timer);
  };
}

// The readout, one block per line; a narrow box wraps a `Corner(...)` line only between its items
// (`ds=[1.2, -0.3],`), never inside a list, and the wrapped part is indented under the line's start.
function fillReadout(box, text) {
  box.replaceChildren(...text.split("\n").map((line) => {
    const row = document.createElement("div");
    row.style.cssText = "padding-left:4ch; text-indent:-4ch";
    line.split(/(?<=,) (?![^[]*\])/).forEach((item, k) => { // at ", " outside brackets
      const span = document.createElement("span");
      span.style.whiteSpace = "nowrap";
      span.textContent = item;
      row.append(...(k ? [" ", span] : [span]));
    });
    return row;
  }));
}

export default { render };
