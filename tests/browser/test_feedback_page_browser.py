"""A student's feedback page in a real browser: feedback/<submission>.html opened from disk in headless Chromium
(Debian's), on a phone's screen, driven by Playwright.

It checks that the page asks for nothing (every URL is file: or data:), that a student's name and texts holding
markup are shown as text and never run, that the total is the first thing on the page and the score table comes
before any failed step, that nothing is wider than a phone's screen, and that axe-core (bundled with
axe-playwright-python, injected into the page) finds no violation.

Run alone: ``.venv/bin/python -m pytest tests/browser/test_feedback_page_browser.py -s``.
"""

import pytest
from feedback_sample import HOSTILE, sample_grade
from jupyterlab_session import CHROMIUM, CHROMIUM_FLAGS, skip_without_chromium

from labkit.grading.store import feedback

playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
axe_playwright = pytest.importorskip("axe_playwright_python.sync_playwright", reason="axe-playwright-python is missing")
skip_without_chromium()
PHONE = {"width": 360, "height": 740}


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    path = tmp_path_factory.mktemp("feedback") / "feedback.html"
    path.write_text(feedback.html(feedback.build(sample_grade(HOSTILE))), encoding="utf-8")
    with playwright_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        context = browser.new_context(viewport=PHONE, is_mobile=True)
        requested, errors = [], []

        def guard(route):
            requested.append(route.request.url)
            route.continue_() if route.request.url.startswith(("file:", "data:")) else route.abort()

        context.route("**/*", guard)
        page = context.new_page()
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.on("dialog", lambda dialog: errors.append(f"a dialog opened: {dialog.message}") or dialog.dismiss())
        page.goto(path.as_uri())
        page.wait_for_load_state("load")
        page.requested, page.errors = requested, errors
        yield page
        browser.close()


def test_the_page_asks_for_nothing_and_runs_none_of_the_students_text(page):
    assert all(url.startswith("file:") for url in page.requested) and len(page.requested) == 1
    assert page.errors == [] and page.locator("script").count() == 0
    errors = page.inner_text("section[aria-labelledby=errors]")
    assert HOSTILE in page.inner_text("h1") and HOSTILE in errors  # shown as text


def test_the_total_comes_first_then_the_score_table_then_the_slips(page):
    text = page.inner_text("main")
    assert text.startswith("Total: 16 / 100 points")
    assert text.index("Points per exercise") < text.index("yprime has the wrong sign") < text.index("n_data")
    rows = page.locator("table tbody tr")
    assert rows.count() == 15 and rows.nth(1).inner_text().split() == ["3", "6", "/", "15", "partly"]
    assert "2 cells still raise NotImplementedError" in page.inner_text("section[aria-labelledby=errors]")


def test_nothing_is_wider_than_a_phone(page):
    width = page.evaluate("document.documentElement.scrollWidth")
    assert width <= PHONE["width"], f"the page is {width} px wide on a {PHONE['width']} px screen"


def test_axe_finds_no_violation(page):
    results = axe_playwright.Axe().run(page)
    violations = results.response["violations"]
    print(f"\naxe-core {results.response.get('testEngine', {}).get('version', '?')}: {len(violations)} violation(s)")
    assert not violations, results.generate_report()
