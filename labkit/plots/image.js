// The browser side of the explorers' picture (labkit.plots.explorers.ExplorerImage, an anywidget module).
// The kernel renders the PNG at `ratio` times its CSS size (2x: sharp on HiDPI screens and when the page
// is zoomed); the <img> is shown at that CSS size, never wider than the output area, and its alt text is
// the figure's description in numbers, updated with every new picture.
function render({ model, el }) {
  const img = document.createElement("img");
  img.className = "labkit-explorer-image";
  img.draggable = false;
  img.style.cssText = "display:block; max-width:100%; height:auto";
  let url = null;

  function showImage() {
    const blob = new Blob([model.get("value")], { type: "image/png" });
    const old = url;
    url = URL.createObjectURL(blob);
    img.src = url;
    if (old) URL.revokeObjectURL(old);
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

  model.on("change:value", showImage);
  model.on("change:css_size", showSize);
  model.on("change:description", showDescription);
  showSize();
  showDescription();
  showImage();
  el.appendChild(img);
  return () => { if (url) URL.revokeObjectURL(url); };
}

export default { render };
