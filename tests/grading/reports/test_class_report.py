"""The class report (`labkit report OUT`): what report.html says about a class, and what it never does.

The class here is built from SubmissionGrade objects whose failed checks are made by the grader's own
functions (labkit.exercises.result.call with the sandbox's exceptions, the registry's missing name, the
scan's refusal, the run's problems), so the report reads the kind codes the grader sets where it makes them,
never their wording (tests/grading/submission/test_kinds.py).
The page in a real browser (no request leaves the machine, axe-core finds no serious violation) is
tests/browser/test_class_report_browser.py.
"""

import dataclasses
import hashlib
import json
import statistics
import subprocess
import sys
import types
from html.parser import HTMLParser
from pathlib import Path

import pytest

from labkit.cli import main
from labkit.exercises.registry import LAB, _missing
from labkit.exercises.result import CheckResult, call
from labkit.grading.reports import class_report, similarity
from labkit.grading.reports.similarity import Pair
from labkit.grading.sandbox import remote
from labkit.grading.store import late
from labkit.grading.store.names import shown_name
from labkit.grading.store.report import ProblemText, SubmissionGrade, merge, write_report
from labkit.grading.store.rubric import default, load
from labkit.grading.submission import scoring

HOSTILE = "<script>alert(1)</script>"
HTML_HINT = 'divide by <b>h</b><img src=x onerror="alert(2)"> & not by 2'
ABSOLUTE = "absolute error instead of relative: divide by the maximum of |f|"
DRIVER = "test_pherm_interpolate"


# ------------------------------------------------------------------ checks as the grader records them


def passed(part):
    result = CheckResult(part)
    result.step("the values at the lab's points", True)
    return result.as_dict()


def slip(part, hint):
    return CheckResult(part).fail("the values at the lab's points", "off by 3.1e-01", hint).as_dict()


def called(part, exception):
    """The check of a part whose function raised `exception` when the grader called it."""

    def student(*args):
        raise exception

    result = CheckResult(part)
    call(result, f"{part}(...) runs", student)
    return result.as_dict()


def own_timeout(message):
    """An exception of a class the student named Timeout, raised in the notebook itself (no sandbox)."""

    class Timeout(Exception):
        grader_kind = "timeout"  # posing as one of the grader's own errors does not make it one

    return Timeout(message)


def timed_out(part):
    return called(part, remote.CellTimeout("interrupted: it ran longer than the time limit"))


def raised(part):
    trace = 'File "<cell>", line 4, in eval_pherm\n    d = 2 / (xk1 - xk)\n'
    return called(part, remote.StudentError("ZeroDivisionError", "float division by zero", None, trace))


def refused_call(part):
    return called(part, remote.StudentError("Refused", "", "scipy.interpolate.CubicHermiteSpline"))


def refused_scan(part):
    return scoring._own_code(passed(part), [(part, 2, "labkit.piecewise.eval_pherm")])


def crashed(part, why):
    return called(part, remote.WorkerError(why))


def ended(code, out_of_memory=False):
    """The grader's words for a notebook process that ended (labkit.grading.sandbox.remote.NotebookHandle._ended)."""
    fake = types.SimpleNamespace(
        process=types.SimpleNamespace(poll=lambda: code), box=types.SimpleNamespace(out_of_memory=lambda: out_of_memory)
    )
    return remote.NotebookHandle._ended(fake)


def cells_raised(name, *errors, output_chars=0):
    """The problems of a notebook whose cells raised (labkit.grading.submission.scoring's), as the worker answers a run: an
    error (cell, kind, message) of the student's, or (cell, kind, message, True) one the worker stopped at its
    time limit (labkit.grading.sandbox.worker marks those ``"timeout": True``)."""
    ran = {
        "errors": [
            {"cell": cell, "kind": kind, "message": message, "traceback": "", "timeout": bool(own)}
            for cell, kind, message, *own in errors
        ],
        "output_chars": output_chars,
    }
    return scoring._run_problems(name, ran)


STOPPED = "interrupted: it ran longer than the time limit"  # the worker's words for a cell it stopped


def grade(name, checks=None, problems=(), failure=None, rubric=None):
    """A submission: `checks` maps (exercise, part) to a check; the exercise's other parts pass."""
    rubric = rubric or default()
    results = {}
    for number in sorted({n for n, _ in checks or {}}):
        exercise = LAB.exercises[number]
        parts = [
            {**checks.get((number, part.name), passed(part.name)), "name": part.name, "weight": part.weight}
            for part in exercise.parts
        ]
        points = sum(p["weight"] for p in parts if p["passed"])
        results[number] = {
            "exercise": number,
            "passed": points == exercise.points,
            "points": points,
            "fraction": points / exercise.points,
            "defined": True,
            "checks": parts,
        }
    return SubmissionGrade(name, results, list(problems), 20261122, rubric, failure)


def full(number):
    return {(number, part.name): passed(part.name) for part in LAB.exercises[number].parts}


@pytest.fixture
def grades():
    """Eight submissions: every kind of outcome once or more, one hostile name, one not graded."""
    return [
        grade("ann", {**full(2), **full(3), **full(4)}),
        grade("ben", {**full(2), (3, DRIVER): slip(DRIVER, ABSOLUTE), **full(4)}),
        grade("cleo", {(2, "eval_pherm"): raised("eval_pherm"), (3, DRIVER): slip(DRIVER, ABSOLUTE)}),
        grade(
            "dev",
            {(2, "eval_pherm"): refused_call("eval_pherm"), (3, DRIVER): slip(DRIVER, ABSOLUTE)},
            problems=cells_raised("02_convergence.ipynb", (2, "NameError", "name 'xk' is not defined")),
        ),
        grade(
            "eve",
            {
                (2, "eval_pherm"): called("eval_pherm", NotImplementedError()),
                (3, "runge"): _missing("runge").as_dict(),
                (4, "limacon_derivatives"): timed_out("limacon_derivatives"),
            },
            problems=[
                ProblemText.one("01_limacon.ipynb: stopped after the submission's time limit of 600 s.", "timeout"),
                *cells_raised("02_convergence.ipynb", (7, "Timeout", STOPPED, True)),
            ],
        ),
        grade(HOSTILE, {(2, "eval_pherm"): slip("eval_pherm", HTML_HINT)}),
        grade("finn", failure="its grading ran out of memory (the grader's limit of 3072 MiB) and was stopped"),
        grade(
            "gus",
            {(2, "eval_pherm"): refused_scan("eval_pherm"), (3, DRIVER): crashed(DRIVER, ended(-9))},
            problems=[
                ProblemText.one(f"03_meshes.ipynb: {ended(3)} while running its cells.", "crash"),
                *cells_raised("04_splines.ipynb", output_chars=250_000),
            ],
        ),
    ]


class Page(HTMLParser):
    """What the report's HTML holds: every tag with its attributes, the text by section, the <pre> lines."""

    def __init__(self, text):
        super().__init__(convert_charrefs=True)
        self.tags, self.text, self.marked, self.section = [], {}, [], None
        self._in_mark = False
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.tags.append((tag, attrs))
        if tag == "section":
            self.section = attrs.get("aria-labelledby")
        self._in_mark = self._in_mark or tag == "mark"

    def handle_endtag(self, tag):
        if tag == "mark":
            self._in_mark = False

    def handle_data(self, data):
        self.text.setdefault(self.section, []).append(data)
        if self._in_mark:
            self.marked.append(data)

    def words(self, section):
        return " ".join(" ".join(self.text.get(section, [])).split())


def page_of(grades, pairs=None, **options):
    return class_report.render(class_report.summarise(grades), pairs, **options)


# ------------------------------------------------------------------ reading the grader's codes


@pytest.mark.parametrize(
    "check, outcome",
    [
        (passed("eval_pherm"), "passed"),
        (slip("eval_pherm", ABSOLUTE), "slip"),
        (called("eval_pherm", NotImplementedError()), "not done"),
        (_missing("eval_pherm").as_dict(), "not done"),
        (timed_out("eval_pherm"), "timeout"),
        (raised("eval_pherm"), "raised"),
        (called("eval_pherm", ValueError("shapes (4,) (5,)")), "raised"),
        (refused_call("eval_pherm"), "refused"),
        (refused_scan("eval_pherm"), "refused"),
        (crashed("eval_pherm", ended(-9)), "crash"),
        (crashed("eval_pherm", ended(1)), "crash"),
        (crashed("eval_pherm", ended(None, out_of_memory=True)), "crash"),
        (crashed("eval_pherm", ended(None)), "crash"),
        (called("eval_pherm", remote.CallEnded("WorkerError", ended(7))), "crash"),  # the supervisor's, for a call
        (called("eval_pherm", remote.Tampered("Tampered", "the notebook used threads")), "tampered"),
        (scoring._voided(LAB.exercises[2].parts[0], "it patched labkit.check"), "tampered"),
        # a student's exceptions, whatever their names or words, are errors raised
        (called("eval_pherm", ValueError("it ran past the time limit")), "raised"),
        (called("eval_pherm", ValueError("killed by SIGKILL")), "raised"),
        (called("eval_pherm", ValueError("not implemented yet")), "raised"),
        (called("eval_pherm", own_timeout("interrupted: it ran longer than the time limit")), "raised"),
        (
            called("eval_pherm", remote.StudentError("Timeout", "interrupted: it ran longer than the time limit")),
            "raised",
        ),
        (called("eval_pherm", remote.StudentError("Tampered", "none of its answers count")), "raised"),
        (
            called("eval_pherm", remote.StudentError("WorkerError", "the notebook's process stopped answering")),
            "raised",
        ),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_a_failed_check_is_read_as_the_grader_meant_it(check, outcome):
    assert class_report.check_outcome(check) == outcome


def test_a_check_that_fails_inside_labkit_is_a_problem_not_a_slip():
    class Faulty(dict):
        def __getitem__(self, name):  # a fault of the grader's side while the check reads the notebook
            raise RuntimeError("the grader's proxy broke")

    [check] = LAB.check(2, Faulty(eval_pherm=None))["checks"][:1]
    assert check["steps"][-1]["detail"].startswith("the check failed inside labkit")
    assert class_report.check_outcome(check) == "other"


def test_a_steps_words_alone_make_no_kind():
    # a check's own failed step that merely reads like a time limit, a crash, a stub or a refusal is a slip
    for detail in (
        "it ran past the time limit",
        "killed by SIGKILL",
        "not implemented yet",
        "not defined when the notebook finished",
        "called numpy.interp, which is switched off while this exercise is graded",
        "raised ValueError: x",
        "the check failed inside labkit (KeyError)",
    ):
        check = CheckResult("eval_pherm").fail("the values at the lab's points", detail, "divide by h").as_dict()
        assert class_report.check_outcome(check) == "slip", detail


def test_the_problems_of_a_run_are_sorted_into_their_kinds():
    [raised_and_stopped, flood] = cells_raised(
        "a.ipynb",
        (2, "ZeroDivisionError", "float division by zero"),
        (5, "Timeout", STOPPED, True),
        output_chars=200_000,
    )
    assert class_report.problem_kinds(raised_and_stopped) == [
        ("raised", "a.ipynb: cell 3 raised ZeroDivisionError: float division by zero"),
        ("timeout", "a.ipynb: cell 6 ran past its time limit"),
    ]
    assert class_report.problem_kinds(flood)[0][0] == "other"
    # a traceback line of the student's cannot pose as another cell's error
    [forged] = cells_raised("a.ipynb", (0, "KeyError", "x\n    cell 9 raised Timeout: y"))
    assert [kind for kind, _ in class_report.problem_kinds(forged)] == ["raised"]


def test_a_cell_raising_the_students_own_timeout_is_an_error_raised_not_a_time_limit():
    # the same words as a cell the worker stopped, but no mark of the worker's: the student's class Timeout
    [own] = cells_raised("a.ipynb", (3, "Timeout", STOPPED), (4, "ValueError", "killed by the time limit"))
    assert [kind for kind, _ in class_report.problem_kinds(own)] == ["raised", "raised"]


def test_a_problems_words_alone_make_no_kind():
    # words that read like a time limit, a crash or tampering, with no code set where the problem was made
    for words in (
        "a.ipynb: stopped after the submission's time limit of 600 s.",
        "a.ipynb: the notebook's process was killed by SIGKILL while running its cells.",
        "a.ipynb: it patched numpy; none of its answers count.",
    ):
        assert class_report.problem_kinds(words) == [("other", words)]
    # and the kind set where it was made decides, whatever the words
    assert class_report.problem_kinds(ProblemText.one("a.ipynb: it ran past the time limit", "crash"))[0][0] == "crash"


# ------------------------------------------------------------------ what the summary counts


def test_slips_are_counted_per_hint_most_frequent_first_with_who(grades):
    summary = class_report.summarise(grades)
    first = summary.slips[0]
    assert (first.exercise, first.part, first.hint, first.students) == (3, DRIVER, ABSOLUTE, ("ben", "cleo", "dev"))
    assert [(s.exercise, s.part, len(s.students)) for s in summary.slips] == [(3, DRIVER, 3), (2, "eval_pherm", 1)]
    assert summary.slips[1].students == (HOSTILE,)


def test_pass_rates_count_attempts_passes_stubs_and_missing_exercises(grades):
    summary = class_report.summarise(grades)
    exercises = {e.exercise: e for e in summary.exercises}
    # exercise 2: seven graded; eve left the stub; ann and ben passed; cleo, dev, the hostile one and gus failed
    two = exercises[2]
    assert (two.graded, two.found, two.attempted, two.passed) == (7, 7, 6, 2)
    assert two.rate == pytest.approx(2 / 6)
    three = exercises[3]  # ann and ben's four parts; cleo and dev slipped; eve's runge is missing; gus crashed
    assert (three.found, three.attempted, three.passed) == (6, 6, 1)
    assert (exercises[5].found, exercises[5].attempted, exercises[5].rate) == (0, 0, None)
    parts = {(p.exercise, p.part): p for p in summary.parts}
    driver = parts[(3, DRIVER)]
    assert (driver.passed, driver.slipped, driver.problem, driver.not_done, driver.missing) == (2, 3, 1, 0, 1)
    runge = parts[(3, "runge")]
    assert (runge.passed, runge.not_done, runge.attempted) == (5, 1, 5)
    assert [p.part for p in summary.parts if p.exercise == 14] == [part.name for part in LAB.exercises[14].parts]
    assert sum(p.weight for p in summary.parts if p.exercise == 3) == pytest.approx(default().points[3])


def test_problems_name_who_and_what_by_kind(grades):
    problems = class_report.summarise(grades).problems
    who = {kind: [row.student for row in rows] for kind, rows in problems.items()}
    assert who == {
        "timeout": ["eve"],
        "crash": ["gus"],
        "raised": ["cleo", "dev"],
        "refused": ["dev", "gus"],
        "not graded": ["finn"],
        "other": ["gus"],
    }
    eve = problems["timeout"][0].texts
    assert eve == (
        "exercise 4, limacon_derivatives: limacon_derivatives(...) runs: "
        "interrupted: it ran longer than the time limit",
        "01_limacon.ipynb: stopped after the submission's time limit of 600 s.",
        "02_convergence.ipynb: cell 8 ran past its time limit",
    )
    gus = {row.student: row.texts for row in problems["refused"]}["gus"]
    assert "reaches for labkit.piecewise.eval_pherm" in gus[0]
    assert any("killed by SIGKILL" in text for text in problems["crash"][0].texts)
    assert any("exited with status 3" in text for text in problems["crash"][0].texts)
    assert "250,000 characters" in problems["other"][0].texts[0]


def test_the_most_failed_list_counts_failed_parts_and_keeps_stubs_apart(grades):
    most = class_report.summarise(grades).most_failed
    assert [(s.student, len(s.failed), s.not_done) for s in most] == [
        ("cleo", 2, 0),  # two failed parts each, and 9 points each: by name
        ("dev", 2, 0),
        ("gus", 2, 0),
        (HOSTILE, 1, 0),  # one failed part: the lowest total first
        ("eve", 1, 2),
        ("ben", 1, 0),
    ]
    assert most[2].failed == ("2 eval_pherm", f"3 {DRIVER}") and most[4].failed == ("4 limacon_derivatives",)
    assert "ann" not in [s.student for s in most] and "finn" not in [s.student for s in most]


# ------------------------------------------------------------------ the page


def test_the_page_shows_the_slips_the_rates_the_problems_and_the_most_failed(grades):
    html = page_of(grades)
    page = Page(html)
    slips = page.words("slips")
    assert f"{ABSOLUTE}: 3 students" in slips and "ben, cleo, dev" in slips
    rates = page.words("pass-rates")
    assert "2 10 7 6 2 33% 29%" in rates  # exercise, points, found, attempted, passed, rate of attempted, of graded
    assert f"{DRIVER} 6 2 3 1 0 1 33%" in rates  # points, passed, with a hint, problem, not done, not found, rate
    problems = page.words("problems")
    for heading in ("Time limits: 1 student", "Crashes: 1 student", "Errors raised: 2 students", "Could not be graded"):
        assert heading in problems
    assert "the grader's limit of 3072 MiB" in problems
    assert page.words("most-failed").startswith("The most failed parts The 6 students")
    assert "gus 2 0 9 2 eval_pherm, 3 test_pherm_interpolate" in page.words("most-failed")
    assert "Not computed (no search here)" in page_of(grades, similarity_note="no search here")


def test_names_hints_and_problems_are_escaped(grades):
    html = page_of(grades)
    assert HOSTILE not in html and "<img src=x" not in html and "<b>h</b>" not in html
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    assert "divide by &lt;b&gt;h&lt;/b&gt;&lt;img src=x onerror=&#34;alert(2)&#34;&gt; &amp; not by 2" in html
    assert [tag for tag, _ in Page(html).tags].count("script") == 1  # the page's own, nothing of a student's
    assert HOSTILE in Page(html).words("most-failed")  # the name is shown, as text


def test_long_and_control_character_names_are_bounded_and_printable(grades):
    grades[1].name = "x" * 10_000 + "\x1b[31m\u202e"
    html = page_of(grades)
    assert "x" * class_report.MAX_NAME not in html and "\x1b" not in html and "\u202e" not in html
    shown = shown_name(grades[1].name, class_report.MAX_NAME)
    assert len(shown) == class_report.MAX_NAME and shown.startswith("x" * 40) and shown in html


def test_two_long_names_sharing_a_beginning_never_look_alike_in_the_report(grades):
    grades[1].name, grades[2].name = "x" * 230 + "ada", "x" * 230 + "fermat"
    html = page_of(grades)
    one, two = (shown_name(g.name, class_report.MAX_NAME) for g in grades[1:3])
    assert one != two and one in html and two in html


def test_every_figure_says_in_numbers_what_it_shows(grades):
    page = Page(page_of(grades))
    images = [attrs for tag, attrs in page.tags if tag == "img"]
    assert len(images) == 3
    for attrs in images:
        assert attrs["src"].startswith("data:image/png;base64,") and attrs["alt"].strip()
    totals = [g.total for g in grades if g.graded]
    histogram, exercises, parts = (attrs["alt"] for attrs in images)
    assert histogram.startswith(f"Histogram of 7 totals: median {statistics.median(totals):g}, ")
    assert f"lowest {min(totals):g}, highest {max(totals):g}" in histogram
    assert "exercise 2 33% of 6; exercise 3 17% of 6;" in exercises and "exercise 5 nobody attempted it" in exercises
    assert f"exercise 3 {DRIVER} 33% of 6" in parts


def test_the_page_asks_for_nothing_outside_itself(grades):
    pairs = [Pair("eval_pherm", "ann", "ben", 0.9, ("a = 1",), ("a = 1",), frozenset({0}), frozenset({0}))]
    html = page_of(grades, pairs)
    page = Page(html)
    for tag, attrs in page.tags:
        for name in ("src", "href", "srcset", "data", "action", "poster"):
            value = attrs.get(name)
            if value is not None:
                assert value.startswith(("#", "data:image/png;base64,")), (tag, name, value[:80])
        assert tag not in ("link", "iframe", "object", "embed", "base", "form")
    assert "http://" not in html and "https://" not in html and "url(" not in html and "@import" not in html
    assert ("html", {"lang": "en"}) in page.tags


def test_the_page_is_built_for_keyboards_screen_readers_and_print(grades):
    page = Page(page_of(grades))
    tags = page.tags
    assert tags[0] == ("html", {"lang": "en"})
    skip = next(attrs for tag, attrs in tags if tag == "a")
    assert skip == {"class": "skip", "href": "#main"} and ("main", {"id": "main", "tabindex": "-1"}) in tags
    headers = [attrs.get("scope") for tag, attrs in tags if tag == "th"]
    assert headers and set(headers) <= {"col", "row"}
    assert [tag for tag, _ in tags].count("h1") == 1
    assert sum(tag == "details" for tag, _ in tags) >= 2
    html = page_of(grades)
    assert ":focus-visible" in html and "@media print" in html and "beforeprint" in html
    assert all(attrs.get("tabindex", "-1") == "-1" for _, attrs in tags)  # nothing forced into the tab order


def test_similar_code_is_shown_side_by_side_with_the_shared_lines_marked(grades):
    first = ("def eval_pherm(x, y, yp, xv):", "    k = bracket(x, xv)", "    # mine < yours & theirs", "    return k")
    second = ("def eval_pherm(x, y, yp, xv):", "    idx = bracket(x, xv)", "    # mine < yours & theirs")
    pair = Pair("eval_pherm", "ann", HOSTILE, 0.91, first, second, frozenset({0, 2}), frozenset({0, 2}))
    other = Pair("coons", "ben", "cleo", 0.85, ("a = 1",), ("a = 1",), frozenset({0}), frozenset({0}))
    html = page_of(grades, [other, pair], threshold=0.8)
    page = Page(html)
    similar = page.words("similar")
    assert "Similarity never changes a grade" in similar and "for a person to judge" in similar
    assert similar.index("<script>alert(1)</script> – ann: 1 of 1 graded functions alike") < similar.index(
        "ben – cleo: 1 of 1 graded functions alike"
    )
    assert "eval_pherm , similarity 0.91: 2 of 4 lines and 2 of 3 shared" in similar
    assert page.marked == [first[0], first[2], second[0], second[2], "a = 1", "a = 1"]
    assert "&lt; yours &amp; theirs</mark>" in html and "k = bracket" in similar and "return k" in similar
    assert sum(tag == "pre" for tag, _ in page.tags) == 4
    assert "No pair of submissions is similar at the threshold 0.80" in page_of(grades, [])


def test_similar_code_is_bounded(grades):
    lines = tuple(f"line {i} " + "y" * 500 for i in range(1000))
    shared = (frozenset(range(1000)), frozenset({5, 2000, -1}))
    pairs = [
        Pair("eval_pherm", f"s{k}", f"t{k}", 1.0, lines, lines, *shared) for k in range(class_report.MAX_PAIRS + 3)
    ]
    html = page_of(grades, pairs)
    assert html.count('<article class="pair"') == class_report.MAX_PAIRS
    assert (
        "and 3 pairs with fewer functions alike" in html and f"and {1000 - class_report.MAX_LINES} more lines" in html
    )
    assert "y" * (class_report.MAX_LINE + 1) not in html
    assert "1000 of 1000 lines and 1 of 1000 shared" in html
    many = [Pair(f"f{k}", "ann", "ben", 1.0, ("a",), ("a",), frozenset({0}), frozenset({0})) for k in range(300)]
    assert page_of(grades, many).count("<details><summary><code>") == class_report.MAX_PAIRS  # one pair, bounded


# ------------------------------------------------------------------ late work


def late_class():
    """Six graded submissions and one not graded, under the lab's rubric with a late rule: 10% of the points per
    started day, at most 50%, 15 minutes' grace, due 2026-12-01 23:59 (+01:00); cleo has 48 hours more."""
    rule = late.from_dict(
        {
            "deadline": "2026-12-01T23:59:00+01:00",
            "per": "day",
            "percent": 10,
            "cap": 50,
            "grace": 15,
            "extensions": {"cleo": 48, "zed": 24},
        }
    )
    rubric = dataclasses.replace(default(), late=rule)
    everything = {key: check for n in (2, 3, 4, *SPLINES) for key, check in full(n).items()}  # 100 points
    required = {**full(2), **full(3), **full(4)}  # 40 points

    def at(name, checks, when=None, source=late.FROM_CSV):
        g = grade(name, checks, rubric=rubric)
        g.time = None if when is None else late.SubmissionTime(late.parse_deadline(when), source)
        return g

    return [
        at("ann", everything, "2026-12-01T22:00:00+01:00"),  # 100, on time
        at("ben", everything, "2026-12-03T08:00:00+01:00"),  # 100, 1 day 8 h 1 min late: 2 started days, 20%: 80
        at("cleo", required, "2026-12-02T23:00:00+01:00"),  # 40, a day after the deadline, within her extension
        at("dev", required),  # 40, no time: not penalised
        at(HOSTILE, full(2), "2026-12-02T03:00:00+01:00", late.FROM_NBGRADER),  # 10, 3 h 1 min late: 10%: 9
        at("gus", required, "2026-12-02T00:09:00+01:00"),  # 40, 10 minutes late: within the grace
        grade("finn", failure="its grading crashed twice", rubric=rubric),
    ]


SPLINES = (10, 11, 12, 13, 14, 15)


def test_the_late_view_says_who_was_late_by_how_much_and_what_it_cost(tmp_path):
    grades = late_class()
    summary = class_report.summarise(grades)
    view = summary.late
    assert [e.student for e in view.late] == ["ben", HOSTILE]
    assert [(e.units, e.percent, e.penalty, e.total) for e in view.late] == [(2, 20, 20, 80), (1, 10, 1, 9)]
    assert [e.student for e in view.on_time] == ["ann", "cleo", "gus"] and [e.student for e in view.within_grace] == [
        "gus"
    ]
    assert [e.student for e in view.extended] == ["cleo"] and [e.student for e in view.unknown] == ["dev"]
    assert [e.student for e in view.student_supplied] == [HOSTILE] and view.penalty == 21
    assert view.unused_extensions == ["zed"]

    html = class_report.render(summary)
    page = Page(html)
    words = page.words("late")
    assert words.startswith("Late work The rubric's rule: late work: due 2026-12-01T23:59:00+01:00, with 15 minutes")
    for figure in (
        "graded submissions 6",
        "on time 3 (1 within the grace)",
        "late 2",
        "points taken off, in all 21",
        "with an extension 1",
        "no known time (not penalised) 1",
        "a time the student supplied 1",
    ):
        assert figure in words, figure
    assert (
        "ben 2026-12-01T23:59:00+01:00 2026-12-03T08:00:00+01:00 the --times file 1 day 8 h 1 min "
        "2 started days 20% 20 100 80" in words
    )
    assert f"{HOSTILE} 2026-12-01T23:59:00+01:00 2026-12-02T03:00:00+01:00 {late.FROM_NBGRADER} 3 h 1 min" in words
    assert "1 started day 10% 1 10 9" in words
    assert "Extensions: 1 submission" in words
    assert "cleo 2026-12-03T23:59:00+01:00 2026-12-02T23:00:00+01:00 on time" in words
    assert "names 1 submission this run has no graded result for (a misspelt name?): zed" in words
    assert "No known time: 1 submission" in words and "dev no submission time: not penalised" in words
    assert "Times the student supplied: 1 submission" in words
    assert f"{HOSTILE} {late.FROM_NBGRADER} 2026-12-02T03:00:00+01:00 late by 3 h 1 min" in words
    assert "finn" not in words  # not graded: no lateness
    # escaped, like every name on the page; headed tables; listed in the navigation
    assert HOSTILE not in html and [tag for tag, _ in page.tags].count("script") == 1
    assert ("a", {"href": "#late"}) in page.tags and ("h2", {"id": "late"}) in page.tags
    late_section = html[
        html.index('<section aria-labelledby="late">') : html.index('<section aria-labelledby="pass-rates">')
    ]
    assert late_section.count("<table>") + late_section.count('<table class="narrow">') == late_section.count(
        "<caption>"
    )
    assert late_section.count('<th scope="row">') >= 6 + 2 + 1 + 1 + 1

    # the totals are grades.csv's: after the penalty
    totals = [g.total for g in grades if g.graded]
    assert totals == [100, 80, 40, 40, 9, 40] and summary.totals == {g.name: g.total for g in grades if g.graded}
    figures = page.words("totals")
    assert f"mean {statistics.fmean(totals):.1f}" in figures and "mean 51.5" in figures  # before the penalty: 55.0
    assert "full credit (100) or more 1" in figures  # ben's 100 is 80 after it
    assert "after the late penalty" in figures
    # and the page written by `labkit report` from a results folder says the same
    rubric = tmp_path / "course.toml"
    rubric.write_text(
        (Path(class_report.__file__).parents[1] / "store" / "rubric.toml").read_text()
        + '\n[late]\ndeadline = "2026-12-01T23:59:00+01:00"\nper = "day"\npercent = 10\ncap = 50\ngrace = 15\n'
        + "[late.extensions]\ncleo = 48\nzed = 24\n"
    )
    assert load(rubric) == grades[0].rubric
    for grade in grades:
        grade.rubric = load(rubric)  # as the run read it: its record keeps the rubric's own text
    write_report(tmp_path, grades)
    assert main(["report", str(tmp_path), "--quiet"]) == 0  # the recorded rubric: no --rubric needed
    assert main(["report", str(tmp_path), "--rubric", str(rubric), "--quiet"]) == 0
    written = Page((tmp_path / "report.html").read_text())
    assert "points taken off, in all 21" in written.words("late") and "mean 51.5" in written.words("totals")


def test_without_a_late_table_the_report_has_no_late_section(grades):
    page = Page(page_of(grades))
    assert "late" not in page.text and ("a", {"href": "#late"}) not in page.tags
    assert class_report.summarise(grades).late is None


# ------------------------------------------------------------------ writing it, and bad input


def snapshot(folder):
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_report_reads_a_real_results_folder_and_changes_nothing_else(grades, tmp_path, capsys):
    write_report(tmp_path, grades)
    (tmp_path / "seed.txt").write_text("20261122\n")
    before = snapshot(tmp_path)
    assert main(["report", str(tmp_path)]) == 0
    assert "report.html: 8 submission(s)" in capsys.readouterr().out
    after = snapshot(tmp_path)
    assert {k: v for k, v in after.items() if k != "report.html"} == before and "report.html" in after
    read = class_report.read(tmp_path)
    assert (tmp_path / "report.html").read_text() == page_of(read, similarity.similar_pairs(read))
    assert main(["report", str(tmp_path), "--quiet"]) == 0 and capsys.readouterr().out == ""
    assert sorted(snapshot(tmp_path)) == sorted(after)  # replaced, no temporary file left
    read_back = class_report.summarise(class_report.read(tmp_path))
    summary = class_report.summarise(grades)
    assert read_back.slips == summary.slips and read_back.parts == summary.parts
    assert read_back.totals == summary.totals and read_back.problems == summary.problems


def test_report_reads_merged_runs(grades, tmp_path):
    write_report(tmp_path / "job1", grades[:4])
    write_report(tmp_path / "job2", grades[4:])
    merge([tmp_path / "job1", tmp_path / "job2"], tmp_path / "merged")
    assert main(["report", str(tmp_path / "merged"), "--quiet"]) == 0
    html = (tmp_path / "merged" / "report.html").read_text()
    assert "8 submissions, 7 graded, 1 could not be graded" in html
    assert f"{ABSOLUTE}: <strong>3 students</strong>" in html


def test_the_cli_uses_the_similarity_search_when_labkit_has_one(grades, tmp_path, monkeypatch):
    write_report(tmp_path, grades)
    asked = []

    def search(found, threshold, progress=None):
        asked.append(([g.name for g in found], threshold))
        return [Pair("coons", "ann", "ben", 0.97, ("x = 1",), ("x = 1",), frozenset({0}), frozenset({0}))]

    monkeypatch.setattr(similarity, "similar_pairs", search, raising=False)
    assert main(["report", str(tmp_path), "--similarity-threshold", "0.6", "--quiet"]) == 0
    assert asked == [(sorted(g.name for g in grades), 0.6)]
    assert "coons</code>, similarity 0.97" in (tmp_path / "report.html").read_text()
    monkeypatch.undo()  # the real search: these grades kept no sources, so there is nothing to compare
    assert main(["report", str(tmp_path), "--quiet"]) == 0
    assert "Not computed" not in (tmp_path / "report.html").read_text()


def test_the_report_is_written_without_pygments_and_says_why_similar_code_was_not_computed(tmp_path, monkeypatch):
    from class_results import synthetic_class, synthetic_sources

    grades = synthetic_class(12, seed=3)
    sources, _ = synthetic_sources([g.name for g in grades if g.graded], seed=3, copies=2)
    for g in grades:
        g.sources = {function: by_student[g.name] for function, by_student in sources.items() if g.name in by_student}
    write_report(tmp_path, grades)
    # the similarity search's tokeniser not installed: every import of it fails
    for name in [name for name in sys.modules if name == "pygments" or name.startswith("pygments.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "pygments", None)
    assert main(["report", str(tmp_path), "--quiet"]) == 0
    assert similarity.similar_pairs(grades) is None and "pygments" in similarity.unavailable()
    page = Page((tmp_path / "report.html").read_text())
    similar = page.words("similar")
    assert "Not computed (the similarity search needs pygments, which cannot be imported here" in similar
    assert "pip install 'labkit[grade]'" in similar
    assert "12 submissions" in page.words(None)  # the rest of the page is there
    assert page.words("totals").startswith("Totals")


@pytest.mark.parametrize("threshold", ["0", "-0.5", "1.5", "nan"])
def test_the_cli_refuses_a_threshold_outside_0_to_1(grades, tmp_path, capsys, threshold):
    write_report(tmp_path, grades)
    assert main(["report", str(tmp_path), "--similarity-threshold", threshold]) == 2
    assert "--similarity-threshold is a similarity above 0 and at most 1" in capsys.readouterr().err
    assert not (tmp_path / "report.html").exists()


def test_the_cli_refuses_a_missing_or_empty_folder(tmp_path, capsys):
    assert main(["report", str(tmp_path / "nowhere")]) == 2
    assert "nowhere is not a folder: give the --out folder of a `labkit grade` run" in capsys.readouterr().err
    assert main(["report", str(tmp_path)]) == 2
    assert "has no run record (record.json)" in capsys.readouterr().err
    assert not (tmp_path / "report.html").exists() and not (tmp_path / "nowhere").exists()


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "labkit.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=Path(__file__).resolve().parents[2],
    )


def test_results_of_another_labkit_version_are_refused_and_changed_results_never_read(grades, tmp_path):
    write_report(tmp_path, grades)
    record = tmp_path / "record.json"
    original = record.read_bytes()
    before = snapshot(tmp_path)
    record.write_text(json.dumps({**json.loads(original), "labkit": "0.0.1"}))
    run = _cli("report", str(tmp_path))
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    assert "was graded by labkit 0.0.1" in run.stderr and "grade those submissions again" in run.stderr
    record.write_bytes(original)
    assert snapshot(tmp_path) == before and not (tmp_path / "report.html").exists()
    # a result edited after the run (another course's exercise added, say) is not what the run wrote: never read
    path = sorted((tmp_path / "results").glob("*.json"))[0]
    data = json.loads(path.read_bytes())
    path.write_text(json.dumps({**data, "results": {**data["results"], "17": {"fraction": 1.0, "checks": []}}}))
    run = _cli("report", str(tmp_path), "--quiet")
    assert run.returncode == 1 and "Traceback" not in run.stderr, run.stderr
    assert f"not read: {path}: changed since the run wrote it" in run.stderr
    html = (tmp_path / "report.html").read_text()
    assert f"{len(grades) - 1} submission" in html and data["name"] not in html


def test_results_of_another_rubric_need_that_rubric(grades, tmp_path, capsys):
    text = 'title = "bilinear only"\nrequired = [16]\n[points]\n16 = 20\n'
    (tmp_path / "bilinear.toml").write_text(text)
    rubric = load(tmp_path / "bilinear.toml")
    out = tmp_path / "out"
    write_report(
        out, [grade(g.name, {**full(16), (16, "runge2d"): slip("runge2d", "h")}, rubric=rubric) for g in grades[:3]]
    )
    # the run's record names its rubric: the report needs no --rubric, and refuses one that grades otherwise
    assert main(["report", str(out), "--quiet"]) == 0
    html = (out / "report.html").read_text()
    assert "Class report: bilinear only" in html and "Full credit is 20 points" in html
    assert main(["report", str(out), "--rubric", str(tmp_path / "bilinear.toml"), "--quiet"]) == 0
    (tmp_path / "other.toml").write_text(text.replace("16 = 20", "16 = 10"))
    assert main(["report", str(out), "--rubric", str(tmp_path / "other.toml")]) == 2
    err = capsys.readouterr().err
    assert "differs from it in its exercises, groups or points" in err and "leave --rubric out" in err


def test_bad_input_to_the_module_says_what_to_fix(grades, tmp_path):
    with pytest.raises(ValueError, match="no submissions to report on"):
        class_report.summarise([])
    with pytest.raises(ValueError, match="SubmissionGrade objects"):
        class_report.summarise([{"name": "ann"}])
    with pytest.raises(ValueError, match="Pair objects"):
        class_report.write(tmp_path, grades, [("ann", "ben", 0.9)])
    bad = Pair("f", "a", "b", 1.5, (), (), frozenset(), frozenset())
    with pytest.raises(ValueError, match="from 0 to 1"):
        class_report.write(tmp_path, grades, [bad])
    with pytest.raises(ValueError, match="threshold"):
        class_report.write(tmp_path, grades, None, threshold=0)
    with pytest.raises(ValueError, match="is not a folder"):
        class_report.write(tmp_path / "nowhere", grades)
    (tmp_path / "report.html").mkdir()
    (tmp_path / "report.html" / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match="is not a plain file: move it away"):
        class_report.write(tmp_path, grades)
    assert (tmp_path / "report.html" / "keep.txt").read_text() == "mine"
    with pytest.raises(ValueError, match="'zed' for exercise 2 has no list of checks"):
        class_report.summarise([SubmissionGrade("zed", {2: {**full(2), "checks": "none"}})])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.html"]  # no temporary file left


def test_result_files_that_are_not_plain_files_or_too_large_are_never_read(grades, tmp_path, monkeypatch):
    from labkit.grading.store import record

    write_report(tmp_path, grades)
    fifo = tmp_path / "results" / "zz.json"
    import os

    os.mkfifo(fifo)  # reading it would wait forever
    read = class_report.read(tmp_path)
    assert len(read) == len(grades) and [path.name for path, _ in read.refused] == ["zz.json"]
    fifo.unlink()
    named = sorted((tmp_path / "results").glob("*.json"))[0]
    os.unlink(named)
    os.mkfifo(named)  # even a file the record names is opened without waiting, and refused as no plain file
    read = class_report.read(tmp_path)
    assert len(read) == len(grades) - 1 and "is not a file" in read.refused[0][1]
    os.unlink(named)
    write_report(tmp_path, grades)
    monkeypatch.setattr(record, "MAX_RESULT", 100)
    with pytest.raises(ValueError, match="no result their records vouch for"):
        class_report.read(tmp_path)  # every result is larger than the limit: none is read


def test_the_cli_help_names_the_options_and_their_defaults(capsys):
    with pytest.raises(SystemExit) as exit:
        main(["report", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert exit.value.code == 0 and "usage: labkit report" in text
    assert f"(default {similarity.DEFAULT_THRESHOLD})" in text and "--rubric" in text and "--quiet" in text


def test_three_identical_submissions_are_three_rows_one_per_pair_with_their_functions_on_demand(grades):
    names, functions = ("ada", "fermat", "gauss"), ("eval_pherm", "runge")
    code = ("def f(x):", "    return x")
    pairs = [
        Pair(function, a, b, 1.0, code, code, frozenset({0, 1}), frozenset({0, 1}))
        for function in functions
        for k, a in enumerate(names)
        for b in names[k + 1 :]
    ]
    three = [
        SubmissionGrade(name, {}, rubric=grades[0].rubric, sources={f: "\n".join(code) for f in (*functions, "pchip")})
        for name in names
    ]
    page = Page(page_of([*grades, *three], pairs, threshold=0.8))
    similar = page.words("similar")
    assert "3 pairs of students" in similar
    for a, b in (("ada", "fermat"), ("ada", "gauss"), ("fermat", "gauss")):
        assert f"{a} – {b}: 2 of 3 graded functions alike" in similar
    assert sum(tag == "details" for tag, _ in page.tags) >= 6  # each function, on demand


def test_copies_name_whose_data_a_notebook_holds_and_flag_the_solutions_markers():
    from labkit.exercises.registry import LAB
    from labkit.grading.reports.similarity import find_copies

    exercise = next(e for e in LAB if e.params)
    param = exercise.params[0].name
    number = exercise.number
    students = {"ada": {str(number): {param: 1.25}}, "fermat": {str(number): {param: 1.75}}}
    holder = SubmissionGrade("fermat", {number: {"fraction": 0.0, "passed": False, "checks": [],
                                                "other_variant": {param: [1.25, 1.75]}}})  # fmt: skip
    marked = SubmissionGrade("gauss", {}, sources={"runge": "def runge(x):\n    ### BEGIN SOLUTION\n    return x"})
    found = find_copies([holder, marked], students)
    assert found.holder_lines() == [f"fermat holds ada's data for exercise {number}"]
    assert found.marked == [("gauss", ("runge",))]
