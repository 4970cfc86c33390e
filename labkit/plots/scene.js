// Draws an explorer's scene (labkit/plots/scene.py) on a <canvas> in the figure's device pixels: the kernel
// sends the changing artists as data (lines, polygons, a colour-mapped image, pixel patches of a title or a
// colour bar) and this draws them over the background picture. Shared by image.js and editor.js (the kernel
// puts this file before theirs).
function sceneBytes(value) {
  // a binary buffer of the widget's state arrives as a DataView (or an ArrayBuffer)
  if (!value) return new Uint8Array(0);
  if (value instanceof ArrayBuffer) return new Uint8Array(value);
  return new Uint8Array(value.buffer, value.byteOffset, value.byteLength);
}
function sceneFloats(value, Type = Float32Array) { // little-endian floats (Float64Array for doubles)
  const bytes = sceneBytes(value);
  const copy = new Uint8Array(bytes.length); // aligned for Type
  copy.set(bytes);
  return new Type(copy.buffer);
}
function sceneColor(c) {
  return c ? `rgba(${c[0]},${c[1]},${c[2]},${c[3]})` : null;
}
function sceneClip(ctx, clip) {
  if (!clip) return;
  ctx.beginPath();
  ctx.rect(clip[0], clip[1], clip[2], clip[3]);
  ctx.clip();
}
function sceneLine(ctx, item) {
  const xy = sceneFloats(item.xy);
  if (item.stroke) {
    ctx.beginPath();
    let pen = false;
    for (let k = 0; k < xy.length; k += 2) {
      const x = xy[k], y = xy[k + 1];
      if (!Number.isFinite(x) || !Number.isFinite(y)) { pen = false; continue; }
      if (pen) ctx.lineTo(x, y); else { ctx.moveTo(x, y); pen = true; }
    }
    ctx.strokeStyle = sceneColor(item.stroke);
    ctx.lineWidth = item.width;
    ctx.lineCap = item.cap;
    ctx.lineJoin = item.join;
    ctx.setLineDash(item.dashes);
    ctx.lineDashOffset = item.offset;
    ctx.stroke();
    ctx.setLineDash([]);
  }
  const m = item.marker;
  if (!m) return;
  const outline = sceneFloats(m.outline);
  ctx.lineWidth = m.width;
  ctx.lineJoin = "miter";
  ctx.lineCap = "butt";
  for (let k = 0; k < xy.length; k += 2) {
    const x = xy[k], y = xy[k + 1];
    if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
    ctx.beginPath();
    let at = 0;
    for (const count of m.counts) {
      for (let j = 0; j < count; j++) {
        const px = x + outline[2 * (at + j)], py = y + outline[2 * (at + j) + 1];
        if (j === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py);
      }
      if (m.closed) ctx.closePath();
      at += count;
    }
    if (m.fill) { ctx.fillStyle = sceneColor(m.fill); ctx.fill(); }
    if (m.stroke && m.width > 0) { ctx.strokeStyle = sceneColor(m.stroke); ctx.stroke(); }
  }
}
function sceneHatch(ctx, xy, start, count, hatch) {
  let left = Infinity, right = -Infinity, top = Infinity, bottom = -Infinity;
  for (let j = 0; j < count; j++) {
    const x = xy[2 * (start + j)], y = xy[2 * (start + j) + 1];
    left = Math.min(left, x); right = Math.max(right, x); top = Math.min(top, y); bottom = Math.max(bottom, y);
  }
  ctx.save();
  ctx.clip();
  ctx.beginPath();
  const s = hatch.spacing, h = bottom - top;
  for (let x = Math.floor((left - h) / s) * s; x <= right; x += s) { // lines rising to the right ("/")
    ctx.moveTo(x, bottom);
    ctx.lineTo(x + h, top);
  }
  ctx.strokeStyle = sceneColor(hatch.stroke);
  ctx.lineWidth = hatch.width;
  ctx.stroke();
  ctx.restore();
}
function scenePolygons(ctx, item) {
  const xy = sceneFloats(item.xy), faces = sceneBytes(item.faces);
  let at = 0;
  ctx.lineJoin = "miter";
  item.counts.forEach((count, k) => {
    ctx.beginPath();
    for (let j = 0; j < count; j++) {
      const x = xy[2 * (at + j)], y = xy[2 * (at + j) + 1];
      if (j === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
    }
    ctx.closePath();
    if (item.face_count) {
      const f = 4 * (item.face_count === 1 ? 0 : k);
      if (faces[f + 3] > 0) {
        ctx.fillStyle = `rgba(${faces[f]},${faces[f + 1]},${faces[f + 2]},${faces[f + 3] / 255})`;
        ctx.fill();
      }
    }
    if (item.edge && item.width > 0) {
      ctx.strokeStyle = sceneColor(item.edge);
      ctx.lineWidth = item.width;
      ctx.stroke();
    }
    if (item.hatch) sceneHatch(ctx, xy, at, count, item.hatch);
    at += count;
  });
}
function sceneImage(ctx, item) {
  const [w, h] = item.size;
  if (!w || !h) return;
  const source = document.createElement("canvas");
  source.width = w;
  source.height = h;
  const pixels = sceneBytes(item.rgba);
  source.getContext("2d").putImageData(new ImageData(new Uint8ClampedArray(pixels), w, h), 0, 0);
  ctx.imageSmoothingEnabled = item.smooth;
  ctx.drawImage(source, item.box[0], item.box[1], item.box[2], item.box[3]);
  ctx.imageSmoothingEnabled = true;
}
function scenePatch(ctx, item) {
  const [x, y, w, h] = item.box;
  if (!w || !h) return;
  ctx.putImageData(new ImageData(new Uint8ClampedArray(sceneBytes(item.rgba)), w, h), x, y);
}
// an overlay's pixels (the widget's `overlays` trait, by the item's id) with their transparency, blended over
// what is drawn under them; each overlay is turned into a canvas once and kept while its pixels stay the same
const sceneOverlayCanvases = new WeakMap();
function sceneOverlay(ctx, item, overlays) {
  const overlay = overlays && overlays[item.id];
  if (!overlay) return;
  const [x, y, w, h] = overlay.box;
  if (!w || !h) return;
  let source = sceneOverlayCanvases.get(overlay);
  if (!source) {
    source = document.createElement("canvas");
    source.width = w;
    source.height = h;
    const pixels = new Uint8ClampedArray(sceneBytes(overlay.rgba));
    source.getContext("2d").putImageData(new ImageData(pixels, w, h), 0, 0);
    sceneOverlayCanvases.set(overlay, source);
  }
  ctx.drawImage(source, x, y);
}
function sceneText(ctx, item) {
  ctx.font = item.font;
  ctx.fillStyle = sceneColor(item.fill);
  ctx.textAlign = item.align;
  ctx.textBaseline = "alphabetic";
  ctx.translate(item.x, item.y);
  if (item.angle) ctx.rotate((-item.angle * Math.PI) / 180);
  ctx.fillText(item.text, 0, 0);
}
// a new picture is on the page: called inside the requestAnimationFrame that drew it, this waits for the end
// of that frame's rendering (a message posted now is handled after it), then raises `node`'s
// data-labkit-shown and notes the time in data-labkit-shown-at (performance.now(), the clock of an event's
// timeStamp): the browser test and benchmarks/bench_browser_latency.py time a move to its picture shown
function sceneShown(node) {
  const channel = new MessageChannel();
  channel.port1.onmessage = () => {
    channel.port1.close();
    node.dataset.labkitShownAt = String(performance.now());
    node.dataset.labkitShown = String(Number(node.dataset.labkitShown) + 1);
  };
  channel.port2.postMessage(null);
}
// a promise of the newest of a widget's background decodes (`current()` gives the one now): the change events of
// one message come in any order, so a background set after its scene replaces the decode its paint waited for
function sceneDecoded(current) {
  const waited = current();
  return waited.then(() => (waited === current() ? undefined : sceneDecoded(current)));
}
// draw `items` on `canvas` (already the size of the picture in device pixels), cleared first, over `under` (a
// background decoded ahead, an ImageBitmap) if given; `overlays` holds the pixels the overlay items name
function drawScene(canvas, items, overlays, under) {
  const ctx = canvas.getContext("2d");
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (under) ctx.drawImage(under, 0, 0);
  for (const item of items) if (item.kind === "patch") scenePatch(ctx, item); // opaque boxes: under the data
  for (const item of items) {
    if (item.kind === "patch") continue;
    ctx.save();
    sceneClip(ctx, item.clip);
    if (item.kind === "line") sceneLine(ctx, item);
    else if (item.kind === "polygons") scenePolygons(ctx, item);
    else if (item.kind === "image") sceneImage(ctx, item);
    else if (item.kind === "text") sceneText(ctx, item);
    else if (item.kind === "overlay") sceneOverlay(ctx, item, overlays);
    ctx.restore();
  }
}
// whether two pictures show the same controls' values ({name: value}; numbers equal to 1e-9 relative): a picture
// drawn ahead is shown when the controls reach its values (image.js, editor.js)
function sameValues(a, b) {
  if (!a || !b) return false;
  const names = Object.keys(b);
  if (Object.keys(a).length !== names.length) return false;
  for (const name of names) {
    const x = a[name], y = b[name];
    if (typeof x === "number" && typeof y === "number") {
      if (!(Math.abs(x - y) <= 1e-9 * Math.max(1, Math.abs(x), Math.abs(y)))) return false;
    } else if (x !== y) return false;
  }
  return true;
}
// Pictures drawn ahead (labkit.plots.explorers.AHEAD) for one widget (image.js, editor.js). After a slider's move
// the kernel also sends the pictures of its next moves (`ahead`: each with the values it shows, the background it
// was drawn from, `base`, and the one it lies on; the next move's may lie on a new one, `picture`, decoded here as
// it comes). This keeps the newest of them and watches the controls' models (`controls`: name -> [model id, the
// attribute holding the value]); when the controls reach a kept picture's values, and the page shows its base, it
// is shown at once, without waiting for the kernel. A scene from the kernel is shown unless it is the one on the
// page already (drawn ahead) or older than it. `show(picture)` paints a picture in the next frame; `extra()` gives
// what else keys a picture (the editor's last drag drawn), or null while the values are in flux; `node` gets
// data-labkit-kept.
const AHEAD_KEPT = 12; // pictures drawn ahead kept, newest first
function sceneAhead(model, node, show, extra) {
  const controls = {};
  let kept = [], latest = null, alive = true;
  function controlsNow() { // null while a control's model is still on its way (or the front end gives none)
    const values = {};
    for (const name of Object.keys(model.get("controls") || {})) {
      if (!controls[name]) return null;
      values[name] = controls[name].model.get(controls[name].attribute);
    }
    return values;
  }
  function valuesNow() {
    const more = extra(), values = more && controlsNow();
    return values ? { ...values, ...more } : null;
  }
  function offer(picture) {
    latest = picture;
    show(picture);
  }
  function fromKernel(picture) {
    const scene = picture.scene, now = valuesNow();
    if (latest && latest.background === scene.background && scene.values) {
      if (sameValues(scene.values, latest.values)) return; // on the page already, drawn ahead
      if (now && sameValues(latest.values, now) && !sameValues(scene.values, now)) return; // older than the page
    }
    offer(picture);
  }
  function fromAhead() {
    const now = valuesNow();
    if (!alive || !now || (latest && sameValues(latest.values, now))) return;
    // a picture drawn from the background on the page (a new background of its own decoded first)
    const shown = latest ? latest.background : (model.get("scene") || {}).background;
    const entry = kept.find((e) => e.base === shown && sameValues(e.values, now) && (!e.picture || e.bitmap));
    if (entry) offer({ ...entry, ahead: true });
  }
  function keep() {
    for (const entry of model.get("ahead") || []) {
      kept = [entry, ...kept.filter((e) => !sameValues(e.values, entry.values))].slice(0, AHEAD_KEPT);
      if (!entry.picture) continue;
      entry.blob = new Blob([sceneBytes(entry.picture)], { type: "image/png" });
      createImageBitmap(entry.blob)
        .then((bitmap) => { entry.bitmap = bitmap; fromAhead(); })
        .catch(() => {}); // not decoded: that move waits for the kernel
    }
    node.dataset.labkitKept = String(kept.length);
    fromAhead();
  }
  function watch() {
    for (const [name, [id, attribute]] of Object.entries(model.get("controls") || {})) {
      if (controls[name]) continue;
      // without the control's model (a front end that gives none) the pictures come from the kernel, as ever
      const manager = model.widget_manager;
      if (!manager || typeof manager.get_model !== "function") return;
      Promise.resolve()
        .then(() => manager.get_model(id))
        .then((control) => {
          if (!alive || !control || controls[name]) return;
          controls[name] = { model: control, attribute };
          control.on(`change:${attribute}`, fromAhead);
        })
        .catch(() => {});
    }
  }
  model.on("change:ahead", keep);
  model.on("change:controls", watch);
  watch();
  return {
    fromKernel,
    fromAhead,
    controlsNow,
    note(picture) { latest = picture; }, // a picture shown without offer(): the one on the page now
    dispose() {
      alive = false;
      for (const c of Object.values(controls)) c.model.off(`change:${c.attribute}`, fromAhead);
    },
  };
}
