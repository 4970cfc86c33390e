"""The picture of the class report in docs/instructors.md: the report.html of a small made-up class
(tests/class_results.py), opened from disk in Debian's Chromium and photographed from the top: the
header, the totals and the pass rates.

Run: ``.venv/bin/python tests/browser/report_picture.py [docs/images/class-report.png]``.
"""

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from class_results import class_with_pairs
from jupyterlab_session import CHROMIUM_FLAGS
from playwright.sync_api import sync_playwright

from labkit.grading.reports import class_report

ROOT = Path(__file__).resolve().parents[2]
PICTURE = ROOT / "docs" / "images" / "class-report.png"


def photograph(target=PICTURE, students=24, height=1250):
    """Write the class report of `students` made-up students and photograph its first `height` pixels."""
    grades, pairs = class_with_pairs(students, seed=7)
    with tempfile.TemporaryDirectory() as tmp:
        page_path = class_report.write(tmp, grades, pairs)
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True, args=CHROMIUM_FLAGS)
            page = browser.new_page(viewport={"width": 1200, "height": height})
            page.route(
                "**/*",
                lambda route: route.continue_() if route.request.url.startswith(("file:", "data:")) else route.abort(),
            )
            page.goto(page_path.as_uri())
            Path(target).parent.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=str(target))
            browser.close()
    return Path(target)


if __name__ == "__main__":
    print(f"wrote {photograph(sys.argv[1] if len(sys.argv) > 1 else PICTURE)}")
