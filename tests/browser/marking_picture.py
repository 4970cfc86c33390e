"""The picture of the marking page in docs/instructors.md: the marking.html of a made-up run of three
students (the instructor notebooks' model answer beside them), opened from disk in Debian's Chromium.

Run: ``.venv/bin/python tests/browser/marking_picture.py [docs/images/marking.png]``.
"""

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from jupyterlab_session import CHROMIUM_FLAGS
from playwright.sync_api import sync_playwright

from labkit.grading.reports import marking
from labkit.grading.store import report, rubric

ROOT = Path(__file__).resolve().parents[2]
PICTURE = ROOT / "docs" / "images" / "marking.png"
ANSWERS = [
    "The table's rates tend to **4**: the error falls like $h^4$, against $h^2$ for piecewise linear.",
    "Order 4, because the cubic matches $f'$ at the nodes.",
    "It converges faster.",
]


def photograph(target=PICTURE, height=700):
    """Write the marking page of a made-up run and photograph its first `height` pixels."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "marked.toml"
        path.write_text(rubric.DEFAULT.read_text() + "\n[answers]\nexercise3-answer-1 = 5\n")
        marked = rubric.load(path)
        check = {"name": "part", "passed": True, "hint": "", "weight": 10, "steps": []}
        verdict = {"exercise": 3, "defined": True, "checks": [check], "points": 0, "passed": True, "fraction": 1.0}
        grades = [
            report.SubmissionGrade(name, {3: verdict}, [], 7, marked, answers={"exercise3-answer-1": text})
            for name, text in zip(("ada", "grace", "alan"), ANSWERS, strict=True)
        ]
        report.write_report(Path(tmp) / "run", grades)
        page_path = marking.write_page(Path(tmp) / "run", marker="picture")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True, args=CHROMIUM_FLAGS)
            page = browser.new_page(viewport={"width": 1100, "height": height})
            page.route(
                "**/*",
                lambda route: route.continue_() if route.request.url.startswith(("file:", "data:")) else route.abort(),
            )
            page.goto(page_path.as_uri())
            page.keyboard.press("1")
            Path(target).parent.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=str(target))
            browser.close()
    return Path(target)


if __name__ == "__main__":
    print(photograph(*sys.argv[1:2]))
