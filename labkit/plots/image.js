// The browser side of the explorers' picture (labkit.plots.explorers.ExplorerImage, an anywidget module;
// scene.js, which draws a scene, comes before this file). The kernel renders what does not change with a
// move (axes, ticks, labels, legend) as a background PNG at the page's devicePixelRatio, which this module
// reports in `pixel_ratio`; every move sends the changing artists as a scene, drawn here on a <canvas> over
// the background in the same device pixels (the background itself drawn first on the canvas, decoded as it comes,
// so the canvas holds the whole picture). Both are shown at the figure's CSS size, never wider than the
// output area; the <img>'s alt text is the figure's description in numbers, updated with every move.
// Paints happen inside requestAnimationFrame, at most one a frame, always of the newest picture (the ones that
// arrived in between are never drawn); each paint raises data-labkit-shown once its frame is rendered. Nothing
// goes back to the kernel: a second message per move would cost a second trip (see explorers.py).
// Pictures drawn ahead (scene.js's sceneAhead): a key press that brings the controls to the values of a picture
// the kernel sent ahead shows it in the next frame, without waiting for the kernel.
function render({ model, el }) {
  const box = document.createElement("div");
  box.className = "labkit-explorer-picture";
  box.style.cssText = "position:relative; display:inline-block; max-width:100%; line-height:0";
  box.dataset.labkitShown = "0";
  const img = document.createElement("img");
  img.className = "labkit-explorer-image";
  img.draggable = false;
  img.style.cssText = "display:block; max-width:100%; height:auto";
  const canvas = document.createElement("canvas");
  canvas.className = "labkit-explorer-canvas";
  canvas.setAttribute("aria-hidden", "true"); // the <img>'s alt describes the whole picture
  canvas.style.cssText = "position:absolute; left:0; top:0; width:100%; height:100%; pointer-events:none";
  box.append(img, canvas);
  let url = null, ready = Promise.resolve(), queued = false, alive = true, media = null;
  let next = null;
  // the backgrounds decoded (ImageBitmaps, by number, the newest few): each picture is painted over its own on the
  // canvas, so what the <img> shows (the kernel's last, or one sent ahead) never puts a picture on another's axes
  const decoded = new Map();
  function keepDecoded(number, bitmap) {
    decoded.delete(number);
    decoded.set(number, bitmap);
    while (decoded.size > 4) decoded.delete(decoded.keys().next().value);
  }

  function showBackground() {
    const bytes = sceneBytes(model.get("background"));
    if (!bytes.length) return;
    const blob = new Blob([bytes], { type: "image/png" }), number = (model.get("scene") || {}).background;
    const decoding = createImageBitmap(blob).then((bitmap) => keepDecoded(number, bitmap)).catch(() => {});
    showPicture(URL.createObjectURL(blob), decoding);
  }
  function showPicture(src, decoding) {
    const old = url;
    url = src;
    img.src = url;
    // the scene waits for its background, so both show in one frame
    ready = Promise.all([img.decode().catch(() => {}), decoding]);
    if (old) ready.then(() => URL.revokeObjectURL(old));
  }
  function paint() {
    queued = false;
    if (!alive || !next) return;
    const picture = next;
    next = null;
    const scene = picture.scene;
    const [width, height] = scene.size || [0, 0];
    if (canvas.width !== width) canvas.width = width;
    if (canvas.height !== height) canvas.height = height;
    const under = picture.bitmap || decoded.get(scene.background); // its own background, or transparent: the <img>
    drawScene(canvas, scene.items || [], picture.overlays || model.get("overlays") || {}, under);
    // for the tests: how many pictures were drawn ahead, and how many are kept (data-labkit-kept)
    if (picture.ahead) box.dataset.labkitDrawnAhead = String(Number(box.dataset.labkitDrawnAhead || 0) + 1);
    sceneShown(box);
  }
  function show(picture) {
    next = picture;
    img.alt = picture.description;
    schedule();
    // drawn ahead on a background of its own: painted with it on the canvas, and the <img> takes it for what follows
    if (picture.bitmap) {
      keepDecoded(picture.background, picture.bitmap);
      showPicture(URL.createObjectURL(picture.blob), null);
    }
  }
  const ahead = sceneAhead(model, box, show, () => ({}));
  function fromKernel() {
    const scene = model.get("scene") || {};
    ahead.fromKernel({ scene, description: model.get("description"), values: scene.values, background: scene.background });
  }
  function schedule() { // the next frame, once the newest background is decoded (one drawn ahead already is)
    if (queued) return;
    queued = true;
    (next && next.bitmap ? Promise.resolve() : sceneDecoded(() => ready)).then(() => requestAnimationFrame(paint));
  }
  function showSize() {
    const [width, height] = model.get("css_size");
    img.width = width; // the attributes also reserve the space (and aspect) before the picture loads
    img.height = height;
    img.style.width = width + "px";
  }
  function showDescription() {
    img.alt = model.get("description");
  }
  // the kernel draws at the page's pixel ratio: say it now and whenever it changes (zoom, another screen)
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

  model.on("change:background", showBackground);
  model.on("change:scene", fromKernel);
  model.on("change:css_size", showSize);
  showSize();
  showDescription();
  showBackground();
  fromKernel();
  el.appendChild(box);
  reportRatio();
  return () => {
    alive = false;
    ahead.dispose();
    if (media) media.removeEventListener("change", reportRatio);
    if (url) URL.revokeObjectURL(url);
  };
}

export default { render };
