"""The marking page in a real browser: marking.html opened from disk in headless Chromium (Debian's, never a
downloaded one), driven by Playwright with the keyboard only.

Thirty answers are marked by keyboard, the page is reloaded (the marks survive in localStorage), marks.csv is
downloaded and imported, and the totals of grades.csv are checked. No request leaves the machine, no script a
student wrote runs, and axe-core finds no serious or critical violation. How long marking the thirty took is
printed (``-s``), never asserted.

Run alone: ``.venv/bin/python -m pytest tests/browser/test_marking_browser.py -s``.
"""

import csv
import time

import pytest
from jupyterlab_session import CHROMIUM, CHROMIUM_FLAGS, skip_without_chromium

from labkit.grading.reports import marking
from labkit.grading.store import marks, report, rubric

playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
axe_playwright = pytest.importorskip("axe_playwright_python.sync_playwright", reason="axe-playwright-python is missing")
skip_without_chromium()

HOSTILE = '<img src=x onerror="alert(1)"><script>alert(2)</script> $h^4$ **bold**'
COUNT = 30


def _run(tmp_path):
    path = tmp_path / "marked.toml"
    path.write_text(rubric.DEFAULT.read_text() + "\n[answers]\nexercise3-answer-1 = 5\n")
    marked = rubric.load(path)
    check = {"name": "part", "passed": True, "hint": "", "weight": 10, "steps": []}
    grades = [
        report.SubmissionGrade(
            f"student{k:02d}",
            {3: {"exercise": 3, "defined": True, "checks": [check], "points": 0, "passed": True, "fraction": 1.0}},
            [],
            7,
            marked,
            answers={"exercise3-answer-1": HOSTILE if k == 0 else f"The order is $h^{k % 5}$."},
        )
        for k in range(COUNT)
    ]
    out = tmp_path / "run"
    report.write_report(out, grades)
    return out


def test_thirty_answers_marked_by_keyboard_survive_a_reload_and_reach_grades_csv(tmp_path):
    out = _run(tmp_path)
    page_path = marking.write_page(out, marker="tester")
    with playwright_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        context = browser.new_context(viewport={"width": 1280, "height": 900}, accept_downloads=True)
        requested, errors = [], []
        context.route("**/*", lambda route: (requested.append(route.request.url), route.continue_()))
        page = context.new_page()
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.on("dialog", lambda dialog: errors.append(f"a dialog opened: {dialog.message}") or dialog.dismiss())
        page.goto(page_path.as_uri())
        page.wait_for_load_state("load")
        assert "30 of 30 left" in page.text_content("#progress")  # only the answer worth points, and only as written
        order = []
        start = time.perf_counter()
        for k in range(COUNT):
            order.append(page.text_content("#who"))
            page.keyboard.press(str(k % 6))
            if k == 0:
                page.keyboard.press("c")
                page.keyboard.type("Say why.")
                page.keyboard.press("Escape")
            page.keyboard.press("j")
        took = time.perf_counter() - start
        print(f"\nmarking {COUNT} answers by keyboard took {took:.2f} s in headless Chromium")
        assert sorted(order) == [f"student{k:02d}" for k in range(COUNT)] and order != sorted(order)  # shuffled
        page.reload()
        page.wait_for_load_state("load")
        assert "0 of 30 left" in page.text_content("#progress")  # the marks survived the reload
        assert not errors, errors
        with page.expect_download() as download:
            page.keyboard.press("Tab")
            page.keyboard.press("Enter")  # the download button, by keyboard
        saved = tmp_path / "marks.csv"
        download.value.save_as(saved)
        assert all(url.startswith(("file:", "data:", "blob:")) for url in requested), requested
        browser.close()
    with open(saved, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == COUNT and {r["comment"] for r in rows} == {"", "Say why."}
    assert marks.import_marks(out, saved) == COUNT
    given = {name: k % 6 for k, name in enumerate(order)}
    with open(out / "grades.csv", newline="") as handle:
        totals = {row["submission"]: row["total"] for row in csv.DictReader(handle)}
    # digit 5 is the most the answer is worth; a 5 gives 15 + 5
    assert totals == {name: report.points_text(15 + min(points, 5)) for name, points in given.items()}


def test_no_student_script_runs_and_axe_finds_nothing_serious(tmp_path):
    out = _run(tmp_path)
    page_path = marking.write_page(out, marker="tester")
    with playwright_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        context = browser.new_context(bypass_csp=True)  # axe is injected; the page's own policy is checked below
        page = context.new_page()
        dialogs = []
        page.on("dialog", lambda dialog: dialogs.append(dialog.message) or dialog.dismiss())
        page.goto(page_path.as_uri())
        seen = False
        for _ in range(COUNT):  # past every answer of the first item, the hostile one among them
            if page.text_content("#who") == "student00":
                seen = True
                assert "<script>alert(2)</script>" in page.text_content("#answer")  # shown as text
                assert page.locator("#answer script, #answer img").count() == 0
                assert (
                    page.locator("#answer math").count() == 1 and page.locator("#answer strong").count() == 1
                )  # typeset
            page.keyboard.press("j")
        assert seen and not dialogs
        results = axe_playwright.Axe().run(page)
        serious = [v for v in results.response["violations"] if v.get("impact") in ("serious", "critical")]
        print(f"\naxe-core: {len(results.response['violations'])} violation(s), {len(serious)} serious or critical")
        assert not serious, [v["id"] for v in serious]
        browser.close()
