// Print every details element open, and close again those that were closed: print shows every list.
addEventListener("beforeprint", () => { for (const d of document.querySelectorAll("details")) {
  if (!d.open) { d.dataset.printed = "1"; d.open = true; } } });
addEventListener("afterprint", () => { for (const d of document.querySelectorAll("details[data-printed]")) {
  d.open = false; delete d.dataset.printed; } });
