// The browser side of labkit.plots.labels.label_sliders (an anywidget module, drawn as nothing).
// ipywidgets draws a slider's handle (role="slider") with no accessible name: its description sits in a
// separate <label> that is not tied to it, so a screen reader says "slider" and axe-core reports
// aria-input-field-name. This module finds the box it was put in and gives every slider handle in it the
// slider's description as its aria-label, again whenever the box's sliders are drawn anew.
function render({ el }) {
  let observer = null, timer = null, tries = 0;
  function label(box) {
    for (const slider of box.querySelectorAll(".widget-slider")) {
      const handle = slider.querySelector(".noUi-handle");
      const name = (slider.querySelector(".widget-label")?.textContent || "").trim();
      if (handle && name && handle.getAttribute("aria-label") !== name) handle.setAttribute("aria-label", name);
    }
  }
  function attach() {
    const box = el.parentElement && el.parentElement.closest(".widget-box");
    if (!box) { // not in the page yet: the box draws its children before it is attached
      if (tries++ < 100) timer = setTimeout(attach, 100);
      return;
    }
    label(box);
    observer = new MutationObserver(() => label(box));
    observer.observe(box, { childList: true, subtree: true, characterData: true });
  }
  attach();
  return () => { clearTimeout(timer); if (observer) observer.disconnect(); };
}

export default { render };
