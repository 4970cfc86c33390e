"""The class report in a real browser: report.html opened from disk in headless Chromium (Debian's, never a
downloaded one), driven by Playwright.

It checks that no request leaves the machine (every URL the page asks for is file: or data:), that every
picture has loaded and has an alt text, that the keyboard reaches the skip link and the page's details,
that the print layout hides the navigation and shows closed lists, and that axe-core (bundled with
axe-playwright-python, injected into the page, no network) finds no serious or critical violation. The axe
summary is printed (``-s``).

Run alone: ``.venv/bin/python -m pytest tests/browser/test_class_report_browser.py -s``.
"""

import pytest
from class_results import class_with_pairs
from jupyterlab_session import CHROMIUM, CHROMIUM_FLAGS, skip_without_chromium

from labkit.grading.reports import class_report

HOSTILE = "<script>alert(1)</script>"
playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
axe_playwright = pytest.importorskip("axe_playwright_python.sync_playwright", reason="axe-playwright-python is missing")
skip_without_chromium()


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("class")
    grades, pairs = class_with_pairs(40, seed=3, extra_names=(HOSTILE,))
    return class_report.write(out, grades, pairs)


@pytest.fixture(scope="module")
def page(report):
    with playwright_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        context = browser.new_context(viewport={"width": 1280, "height": 900})
        requested, refused, errors = [], [], []

        def guard(route):
            url = route.request.url
            requested.append(url)
            if url.startswith(("file:", "data:")):
                route.continue_()
            else:
                refused.append(url)
                route.abort()

        context.route("**/*", guard)
        page = context.new_page()
        page.on("request", lambda request: requested.append(request.url))
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.on("dialog", lambda dialog: errors.append(f"a dialog opened: {dialog.message}") or dialog.dismiss())
        page.goto(report.as_uri())
        page.wait_for_load_state("load")
        page.requested, page.refused, page.errors = requested, refused, errors
        yield page
        browser.close()


def test_nothing_leaves_the_machine_and_every_picture_loads_with_an_alt_text(page, report):
    assert page.requested and all(url.startswith(("file:", "data:")) for url in page.requested), page.requested
    assert not page.refused and not page.errors, (page.refused, page.errors)
    images = page.eval_on_selector_all(
        "img", "nodes => nodes.map(n => [n.getAttribute('alt') || '', n.complete && n.naturalWidth > 0])"
    )
    assert len(images) == 3
    for alt, loaded in images:
        assert alt.strip() and loaded
    assert page.locator("text=<script>alert(1)</script>").count() >= 1  # the hostile name is text, not a script
    assert page.locator("mark").count() > 0 and page.locator("article.pair").count() == 4


def test_the_keyboard_reaches_the_skip_link_and_the_lists(page):
    page.keyboard.press("Tab")
    focused = page.evaluate(
        "() => { const e = document.activeElement; const s = getComputedStyle(e); const r = e.getBoundingClientRect();"
        " return [e.className, s.outlineStyle, r.left >= 0 && r.top >= 0 && r.width > 0]; }"
    )
    assert focused == ["skip", "solid", True]  # visible when focused, with a visible focus ring
    page.keyboard.press("Enter")
    assert page.evaluate("() => location.hash") == "#main"
    page.locator("details summary").first.focus()
    page.keyboard.press("Enter")
    assert page.evaluate("() => document.querySelector('details').open")


def test_print_hides_the_navigation_and_shows_every_list(page):
    closed = page.locator("details:not([open]) ul").first
    assert closed.count() and not closed.is_visible()  # on screen, a closed list is closed
    page.emulate_media(media="print")
    try:
        assert page.evaluate("() => getComputedStyle(document.querySelector('nav')).display") == "none"
        assert closed.is_visible()  # printed, it shows (the page's print style)
    finally:
        page.emulate_media(media="screen")


def test_axe_finds_no_serious_or_critical_violation(page):
    results = axe_playwright.Axe().run(page)
    violations = results.response["violations"]
    print(f"\naxe-core {results.response.get('testEngine', {}).get('version', '?')}: {len(violations)} violation(s)")
    for violation in violations:
        print(f"  {violation['id']} ({violation['impact']}): {len(violation['nodes'])} node(s) - {violation['help']}")
    print(f"  {len(results.response.get('passes', []))} rules passed")
    serious = [v for v in violations if v["impact"] in ("serious", "critical")]
    assert not serious, results.generate_report()
    assert all(url.startswith(("file:", "data:")) for url in page.requested)
