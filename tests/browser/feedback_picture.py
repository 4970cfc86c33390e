"""The picture of a student's feedback page in docs/instructors.md: the feedback.html of a made-up student
(tests/feedback_sample.py), opened from disk in Debian's Chromium at a phone's width and photographed from the
top: the total, the score table and the first failed parts.

Run: ``.venv/bin/python tests/browser/feedback_picture.py [docs/images/feedback-page.png]``.
"""

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from feedback_sample import sample_grade
from jupyterlab_session import CHROMIUM_FLAGS
from playwright.sync_api import sync_playwright

from labkit.grading.store import feedback

ROOT = Path(__file__).resolve().parents[2]
PICTURE = ROOT / "docs" / "images" / "feedback-page.png"


def photograph(target=PICTURE, width=420, height=1500):
    """Write ada's feedback page and photograph its first `height` pixels at `width`."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "ada.html"
        path.write_text(feedback.html(feedback.build(sample_grade("ada"))), encoding="utf-8")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True, args=CHROMIUM_FLAGS)
            page = browser.new_page(viewport={"width": width, "height": height})
            page.route(
                "**/*", lambda route: route.continue_() if route.request.url.startswith("file:") else route.abort()
            )
            page.goto(path.as_uri())
            Path(target).parent.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=str(target))
            browser.close()
    return Path(target)


if __name__ == "__main__":
    print(f"wrote {photograph(sys.argv[1] if len(sys.argv) > 1 else PICTURE)}")
