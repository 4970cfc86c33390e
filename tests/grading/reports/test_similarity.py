"""Similar code between submissions: a renamed, re-wrapped copy is flagged, independent solutions are not, the
release's stubs are never evidence, the shared lines are the copied ones, hostile sources are bounded, the
grader keeps each graded function's source in its results, and no grade depends on any of it."""

import io
import itertools
import json
import os
from pathlib import Path

import numpy as np
import pytest
from catalog import PHERM_LOOPS, PHERM_SEARCH, Planted, plant
from conftest import sandbox_or_skip
from copies import renamed_cells

from labkit import grading
from labkit.exercises.registry import LAB
from labkit.grading.reports import similarity
from labkit.grading.reports.similarity import DEFAULT_THRESHOLD, Pair, similar_pairs
from labkit.grading.store.report import SubmissionGrade, read_results, write_csv
from labkit.grading.submission.fingerprint import NOISE, normalise
from labkit.grading.submission.scan import MAX_CODE_BYTES, MAX_SOURCE_CHARS, function_sources, reached_function_sources
from labkit.grading.submission.scoring import exercises_in, graded_functions, read_cells, registry_graded
from labkit.student_notebooks import paths

DOC = '''    """Piecewise cubic Hermite interpolant of (xdata, ydata) with slopes ypdata, at xval.

    xdata: increasing data points; ydata, ypdata: values and derivatives at them;
    xval: points where the interpolant is wanted (points outside use the end pieces).
    """
'''
HEAD = "def eval_pherm(xdata, ydata, ypdata, xval):\n" + DOC
STUB = HEAD + "    # YOUR CODE HERE\n    raise NotImplementedError()"
# the instructor's solution (notebooks/02_convergence.ipynb)
BODY = """    xdata, ydata, ypdata = (np.asarray(a, dtype=float) for a in (xdata, ydata, ypdata))
    xval = np.asarray(xval, dtype=float)
    k = labkit.bracket(xdata, xval)
    xk, xk1 = xdata[k], xdata[k + 1]
    h1 = (xval - xk1) ** 2 * (3 * xk - xk1 - 2 * xval) / (xk - xk1) ** 3
    h2 = (xval - xk) * (xval - xk1) ** 2 / (xk - xk1) ** 2
    h3 = (xval - xk) ** 2 * (3 * xk1 - xk - 2 * xval) / (xk1 - xk) ** 3
    h4 = (xval - xk1) * (xval - xk) ** 2 / (xk1 - xk) ** 2
    return ydata[k] * h1 + ypdata[k] * h2 + ydata[k + 1] * h3 + ypdata[k + 1] * h4
"""
ORIGINAL = HEAD + BODY
# the same, variables renamed, comments added, spacing changed, lines re-wrapped
COPY_BODY = """    # convert everything to float arrays first
    xdata, ydata, ypdata = (np.asarray(arr, dtype=float)
                            for arr in (xdata, ydata, ypdata))
    t = np.asarray(xval,
                   dtype=float)
    i = labkit.bracket(xdata,t)   # interval of each point
    left, right = xdata[i], xdata[i+1]

    # the four basis functions
    b1 = (t-right)**2*(3*left-right-2*t)/(left-right)**3
    b2 = (t-left)*(t-right)**2/(left-right)**2
    b3 = (t-left)**2*(3*right-left-2*t)/(right-left)**3
    b4 = (t-right)*(t-left)**2/(right-left)**2
    return (ydata[i]*b1 + ypdata[i]*b2
            + ydata[i+1]*b3 + ypdata[i+1]*b4)
"""
COPY = HEAD + COPY_BODY
# written independently: MATLAB-style, one point at a time, the basis in the local variable t
LOOP = (
    HEAD
    + """    n = len(xdata)
    yval = np.zeros(len(xval))
    for j in range(len(xval)):
        # walk along the data to the interval of xval[j]
        i = 0
        while i < n - 2 and xval[j] > xdata[i + 1]:
            i = i + 1
        h = xdata[i + 1] - xdata[i]
        t = (xval[j] - xdata[i]) / h
        yval[j] = ((2 * t**3 - 3 * t**2 + 1) * ydata[i] + (t**3 - 2 * t**2 + t) * h * ypdata[i]
                   + (-2 * t**3 + 3 * t**2) * ydata[i + 1] + (t**3 - t**2) * h * ypdata[i + 1])
    return yval
"""
)
# own interval search (lines 6-11), then the instructor's basis and combination copied, renamed (lines 12-17)
PARTIAL = (
    HEAD
    + """    yval = []
    for x in xval:
        m = 0
        while m + 2 < len(xdata) and xdata[m + 1] < x:
            m += 1
        a, b = xdata[m], xdata[m + 1]
        g1 = (x - b) ** 2 * (3 * a - b - 2 * x) / (a - b) ** 3
        g2 = (x - a) * (x - b) ** 2 / (a - b) ** 2
        g3 = (x - a) ** 2 * (3 * b - a - 2 * x) / (b - a) ** 3
        g4 = (x - b) * (x - a) ** 2 / (b - a) ** 2
        yval.append(ydata[m] * g1 + ypdata[m] * g2 + ydata[m + 1] * g3 + ypdata[m + 1] * g4)
    return yval
"""
)
PARTIAL_COPIED = set(range(11, 17))  # from `a, b = ...` to the combination (0-based)


def _grades(sources, function="eval_pherm"):
    return [SubmissionGrade(name, sources={function: text}) for name, text in sources.items()]


def _pairs(sources, **options):
    return [(p.first, p.second) for p in similar_pairs(_grades(sources), **options)]


def test_a_renamed_and_reformatted_copy_is_flagged_with_the_copied_lines_marked():
    pairs = similar_pairs(_grades({"zoe": COPY, "ada": ORIGINAL}))
    assert len(pairs) == 1
    pair = pairs[0]
    assert isinstance(pair, Pair) and (pair.function, pair.first, pair.second) == ("eval_pherm", "ada", "zoe")
    assert DEFAULT_THRESHOLD <= pair.score <= 1.0
    assert pair.first_lines == tuple(ORIGINAL.split("\n")) and pair.second_lines == tuple(COPY.split("\n"))
    # every line of code of the bodies is shared; the stub's def line and docstring (the release's), the blank
    # line and the comments are not
    body = len(HEAD.split("\n")) - 1
    code = {n for n, line in enumerate(COPY.split("\n")) if n >= body and line.strip() and "# " not in line[:8]}
    assert pair.shared_first == set(range(body, body + BODY.count("\n")))
    assert pair.shared_second == code
    assert {COPY.split("\n")[n].strip() for n in pair.shared_second} >= {"t = np.asarray(xval,", "dtype=float)"}


def test_independent_correct_solutions_are_not_flagged():
    independent = {
        "instructor": ORIGINAL,
        "matlab loop": LOOP,
        "catalog loop": HEAD + PHERM_LOOPS,  # tests/catalog.py CORRECT
        "catalog searchsorted": HEAD + PHERM_SEARCH,
    }
    assert _pairs(independent) == []
    # they are compared: the loops of the catalog share the instructor's basis formulas, below the threshold
    scores = {(p.first, p.second): p.score for p in similar_pairs(_grades(independent), threshold=0.01)}
    assert 0.5 < scores[("catalog loop", "instructor")] < DEFAULT_THRESHOLD and max(scores.values()) < DEFAULT_THRESHOLD
    # with the copy among them, the copy is the one pair flagged
    assert _pairs({**independent, "zoe": COPY}) == [("instructor", "zoe")]


def test_the_shared_lines_point_at_the_copied_lines_only():
    [pair] = similar_pairs(_grades({"ada": ORIGINAL, "dee": PARTIAL}), threshold=0.3, release=[STUB])
    assert pair.shared_second == PARTIAL_COPIED, [pair.second_lines[n] for n in sorted(pair.shared_second)]
    lines = ORIGINAL.split("\n")
    assert {lines[n].split("=")[0].strip() for n in pair.shared_first} == {
        "xk, xk1",
        "h1",
        "h2",
        "h3",
        "h4",
        "return ydata[k] * h1 + ypdata[k] * h2 + ydata[k + 1] * h3 + ypdata[k + 1] * h4",
    }


def _packaged_stubs():
    found = {}
    names = [name for exercise in LAB for name in graded_functions(exercise)]
    for path in paths():
        found.update(function_sources(read_cells(path)[0], names))
    return found


def test_the_release_stub_shared_by_everyone_is_never_flagged():
    stubs = _packaged_stubs()
    assert {"eval_pherm", "runge", "coons", "ncspline", "eval_pbilin"} <= set(stubs)
    assert stubs["eval_pherm"].strip() == STUB
    grades = [SubmissionGrade(name, sources=dict(stubs)) for name in ("ada", "bo", "cy")]
    assert similar_pairs(grades, threshold=0.0) == []
    # against no release, the very same stubs are what everyone shares (but a stub shorter than one fingerprint,
    # runge's one-line call, which is never evidence)
    long_enough = {name for name, stub in stubs.items() if len(normalise(stub)[0]) >= NOISE}
    assert long_enough >= {"eval_pherm", "coons", "ncspline", "eval_pbilin"}
    assert {p.function for p in similar_pairs(grades, release=[])} == long_enough


def test_a_student_who_left_the_stub_gets_no_pairs():
    stubs = _packaged_stubs()
    grades = _grades({"ada": ORIGINAL, "zoe": COPY, "sam": stubs["eval_pherm"], "sue": STUB, "lee": LOOP})
    found = similar_pairs(grades, threshold=0.0)
    assert found and not [p for p in found if {"sam", "sue"} & {p.first, p.second}]
    assert [(p.first, p.second) for p in found if p.score >= DEFAULT_THRESHOLD] == [("ada", "zoe")]


def test_a_stub_after_given_code_leaves_nothing_behind():
    # winnowing picks a source's first fingerprints from partial windows, which the release cell, with code
    # before the stub, does not pick: every run of the release is boilerplate, not only its fingerprints
    for n in range(12):
        cell = f"xs = np.linspace(0.0, {n + 2}.0, {10 * n + 1})\nplt.plot(xs, np.sin({n} * xs))\n\n\n{STUB}\n"
        assert similarity._version("sam", STUB, similarity.boilerplate([cell]).hashes) is None, cell
        assert similar_pairs(_grades({"sam": STUB, "sue": STUB}), threshold=0.0, release=[cell]) == []


def test_a_release_given_by_the_caller_is_boilerplate(tmp_path):
    given = "    table = np.vander(np.linspace(0.0, 1.0, 17), 4, increasing=True)[:, ::-1] @ coefficients\n"
    ada = "def fit(coefficients):\n" + given + "    return table.sum() / len(table)\n"
    bo = (
        "def fit(coefficients):\n"
        + given
        + "    out = 0\n    for v in table:\n        out = max(out, abs(v))\n    return out\n"
    )
    grades = _grades({"ada": ada, "bo": bo}, "fit")
    assert [(p.first, p.second) for p in similar_pairs(grades, threshold=0.3, release=[])] == [("ada", "bo")]
    assert similar_pairs(grades, threshold=0.0, release=["def fit(coefficients):\n" + given]) == []
    # a release folder of notebooks (read as the grader reads them)
    import nbformat

    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("def fit(coefficients):\n" + given)])
    nbformat.write(nb, tmp_path / "given.ipynb")
    assert similar_pairs(grades, threshold=0.0, release=tmp_path) == []
    assert similar_pairs(grades, threshold=0.0, release=tmp_path / "given.ipynb") == []


@pytest.mark.parametrize("threshold", [-0.1, 1.5, float("nan"), "0.8", True, None])
def test_a_threshold_that_is_not_a_share_is_refused(threshold):
    with pytest.raises(ValueError, match="threshold must be a number from 0 to 1"):
        similar_pairs(_grades({"ada": ORIGINAL}), threshold=threshold)


def test_bad_grades_and_releases_are_refused(tmp_path):
    with pytest.raises(ValueError, match="not a SubmissionGrade"):
        similar_pairs(["ada"])
    with pytest.raises(ValueError, match="grades must be a list of SubmissionGrade"):
        similar_pairs(None)
    with pytest.raises(ValueError, match="both named 'ada'"):
        similar_pairs(_grades({"ada": ORIGINAL}) + _grades({"ada": COPY}))
    with pytest.raises(ValueError, match="not function names and source texts"):
        similar_pairs([SubmissionGrade("ada", sources={"eval_pherm": 3})])
    with pytest.raises(ValueError, match="a list of code texts"):
        similar_pairs(_grades({"ada": ORIGINAL}), release=3)
    with pytest.raises(ValueError, match="a list of code texts"):
        similar_pairs(_grades({"ada": ORIGINAL}), release=[b"def f(): pass"])
    with pytest.raises(ValueError, match="does not exist"):
        similar_pairs(_grades({"ada": ORIGINAL}), release=tmp_path / "missing")
    with pytest.raises(ValueError, match="contains no notebooks"):
        similar_pairs(_grades({"ada": ORIGINAL}), release=tmp_path)


def test_pairs_come_most_similar_first_and_never_within_one_student():
    half = HEAD + "\n".join(BODY.split("\n")[:5]) + "\n    return h1 * ydata[k] - 7 * np.sum(xval ** 5) / len(xdata)\n"
    sources = {"ada": ORIGINAL, "zoe": COPY, "bo": half, "lee": LOOP}
    found = similar_pairs(_grades(sources), threshold=0.2)
    scores = {(p.first, p.second): p.score for p in found}
    assert scores[("ada", "zoe")] > scores[("ada", "bo")] > 0.6  # bo copied the first half of ada's
    assert [p.score for p in found] == sorted((p.score for p in found), reverse=True)
    assert found[0].score > found[-1].score and all(p.first < p.second for p in found)
    # another function of the same students is compared on its own
    grades = _grades(sources)
    for grade in grades:
        grade.sources["runge"] = "def runge(x):\n    return 1 / (1 + x**2), -2 * x / (1 + x**2) ** 2\n"
    both = similar_pairs(grades, threshold=0.2)
    assert [p for p in both if p.function == "eval_pherm"] == found
    runge = [p for p in both if p.function == "runge"]
    assert len(runge) == 6 and all(p.score == 1.0 for p in runge)
    assert both == sorted(both, key=lambda p: (-p.score, p.function, p.first, p.second))


def test_the_vectorised_scores_are_the_share_of_code_covered_by_shared_fingerprints():
    sources = [ORIGINAL, COPY, LOOP, PARTIAL, HEAD + PHERM_LOOPS, HEAD + PHERM_SEARCH, ORIGINAL.replace("xk", "q")]
    hashes = similarity.boilerplate().hashes
    versions = [similarity._version(str(k), text, hashes) for k, text in enumerate(sources)]
    scores = similarity.shares(versions)
    for i, one in enumerate(versions):
        mine = {c for p in one.positions for c in range(p, p + NOISE)}
        for j, other in enumerate(versions):
            if i != j:
                theirs = set(other.hashes.tolist())
                shared = {c for p, h in zip(one.positions, one.hashes) if h in theirs for c in range(p, p + NOISE)}
                assert scores[i, j] == pytest.approx(len(shared) / len(mine), abs=1e-12), (i, j)
    assert np.all(np.diag(scores) == 0) and scores.max() > 0.9


def test_the_pairs_flagged_are_among_copydetects_and_include_its_near_copies():
    # copydetect (labkit's test extra only) as an outside reference: it reads names, attributes and brackets
    # more coarsely, so it scores honest loops higher; every pair flagged here it flags too
    copydetect = pytest.importorskip("copydetect")
    half = HEAD + "\n".join(BODY.split("\n")[:5]) + "\n    return h1 * ydata[k] - 7 * np.sum(xval ** 5) / len(xdata)\n"
    sources = {"ada": ORIGINAL, "zoe": COPY, "lee": LOOP, "dee": PARTIAL, "cat": HEAD + PHERM_LOOPS}
    sources |= {"sea": HEAD + PHERM_SEARCH, "ren": ORIGINAL.replace("xk", "q"), "bo": half}
    ours = {(p.first, p.second) for p in similar_pairs(_grades(sources), release=[])}
    prints = {
        n: copydetect.CodeFingerprint("a.py", NOISE, 6, fp=io.StringIO(t), language="python")
        for n, t in sources.items()
    }
    theirs = {
        pair: max(copydetect.compare_files(*map(prints.get, pair))[1])
        for pair in itertools.combinations(sorted(sources), 2)
    }
    assert {pair for pair, score in theirs.items() if score >= 0.95} <= ours
    assert ours <= {pair for pair, score in theirs.items() if score >= DEFAULT_THRESHOLD}
    assert ours == {("ada", "ren"), ("ada", "zoe"), ("ren", "zoe")}


ROOT = Path(__file__).resolve().parents[3]


def _notebook_sources(folder, rewrite=list):
    """{graded function: its source} of a folder of notebooks, as the grader keeps them."""
    found = {}
    for path in sorted(folder.glob("*.ipynb")):
        cells, markdown = read_cells(path)
        names = [n for number in exercises_in(markdown, LAB) for n in graded_functions(LAB.exercises[number])]
        found.update(reached_function_sources(rewrite(cells), names, registry_graded(LAB)))
    return found


def test_independent_solutions_are_never_similar_to_the_solutions_or_each_other_but_a_disguised_copy_is():
    independent = ROOT / "tests" / "data" / "independent"
    folders = {p.name: p for p in sorted(independent.iterdir()) if p.is_dir()} | {"instructor": ROOT / "notebooks"}
    grades = [SubmissionGrade(name, sources=_notebook_sources(folder)) for name, folder in folders.items()]
    assert len(grades) == 6 and all(len(g.sources) >= 15 for g in grades)
    # the one pair flagged is no false alarm: plain_loops and style_b hold the same exercise 5 word for word
    found = similar_pairs(grades)
    assert {(p.function, p.first, p.second) for p in found} == {
        ("mirror", "plain_loops", "style_b"),
        ("two_patches", "plain_loops", "style_b"),
    }
    assert all(p.first_lines == p.second_lines for p in found)
    assert (
        max(p.score for p in similar_pairs(grades, threshold=0.0) if p.first_lines != p.second_lines)
        < DEFAULT_THRESHOLD
    )
    # the solutions renamed, their docstrings gone, a statement added to each function and the cells reordered
    disguised = _notebook_sources(ROOT / "notebooks", lambda cells: renamed_cells(cells)[::-1])
    copier = SubmissionGrade("copier", sources={f: "# my own work\n" + text for f, text in disguised.items()})
    flagged = similar_pairs([*grades, copier])
    assert {(p.first, p.second) for p in flagged if "copier" in (p.first, p.second)} == {("copier", "instructor")}
    assert {p.function for p in flagged if p.first == "copier"} == set(disguised)


def test_similarity_never_changes_a_grade(tmp_path):
    results = {
        2: {"exercise": 2, "passed": True, "points": 5, "fraction": 1.0, "defined": True, "checks": []},
        3: {"exercise": 3, "passed": False, "points": 3, "fraction": 0.5, "defined": True, "checks": []},
    }
    grades = [
        SubmissionGrade(name, json.loads(json.dumps(results)), seed=7, sources={"eval_pherm": text})
        for name, text in (("ada", ORIGINAL), ("zoe", COPY), ("lee", LOOP))
    ]
    before = [g.as_dict() for g in grades]
    write_csv(tmp_path / "before.csv", grades)
    assert len(similar_pairs(grades)) == 1
    write_csv(tmp_path / "after.csv", grades)
    assert [g.as_dict() for g in grades] == before
    assert (tmp_path / "after.csv").read_bytes() == (tmp_path / "before.csv").read_bytes()
    # the class without the copy: the others' grades are the same
    write_csv(tmp_path / "without.csv", [grades[0], grades[2]])
    rows = (tmp_path / "before.csv").read_text().splitlines()
    assert (tmp_path / "without.csv").read_text().splitlines() == [rows[0], rows[1], rows[3]]


def test_hostile_sources_are_bounded_and_do_not_crash():
    huge = "def eval_pherm(x):\n" + "    y = x * 2 + 1  # again\n" * 300_000
    escapes = "def eval_pherm(x\udcff):\r\n    \x1b[31m = 1\u202e\x00\r\n    return \udcff + '\ud800'\r\n" * 20
    broken = "def eval_pherm(x:\n    return ((((\n" + "    ]]] else lambda :: '''\n" * 50
    sources = {"h1": huge, "h2": huge[::1], "e1": escapes, "e2": escapes, "b1": broken, "b2": broken, "x": "\x00" * 9}
    found = similar_pairs(_grades(sources), threshold=0.5)
    assert {(p.first, p.second) for p in found} >= {("h1", "h2"), ("e1", "e2"), ("b1", "b2")}
    for pair in found:
        for lines in (pair.first_lines, pair.second_lines):
            text = "\n".join(lines)
            assert len(text) <= MAX_SOURCE_CHARS
            text.encode("utf-8")  # no lone surrogate left: the bytes that were not UTF-8 are spelled out
            assert "\x1b" not in text and "\x00" not in text and "\r" not in text and "\u202e" not in text
        assert max(pair.shared_first | pair.shared_second) < max(len(pair.first_lines), len(pair.second_lines))
    escaped = next(p for p in found if p.first == "e1")
    assert "\\udcff" in escaped.first_lines[0] and len(escaped.first_lines) == 61


def test_the_source_of_each_graded_function_is_read_without_running_it():
    cells = [
        "%%bash\ndef eval_pherm(x):\n    return 1",  # another program's cell
        "import numpy as np\n\n@decorate\ndef eval_pherm(x):\r\n    return x\r\n\nprint(1)",
        "def runge(x:\n    return",  # does not parse: defines nothing
        "if True:\n    def runge(x):\n        return 1 / (1 + x**2)\n",
        "def coons(a):\n    return a\ncoons = 3\n",  # rebound: not a function written here
        "def ccspline(x):\n" + "    y = x  # a long line\n" * 5000,
        "def mirror(a):\n    return a\n",  # not asked for
    ]
    found = function_sources(cells, ["eval_pherm", "runge", "coons", "ccspline", "ncspline"])
    assert found["eval_pherm"] == "@decorate\ndef eval_pherm(x):\n    return x"
    assert found["runge"] == "    def runge(x):\n        return 1 / (1 + x**2)"
    assert set(found) == {"eval_pherm", "runge", "ccspline"}
    assert len(found["ccspline"]) <= MAX_SOURCE_CHARS and found["ccspline"].endswith("# a long line")
    assert function_sources(["def f():\n    pass\n", "x = 1" + " " * MAX_CODE_BYTES], ["f"]) == {}
    assert function_sources(["def f(:\n" * 10_000, "(" * 200_000], ["f"]) == {}
    # the graded names of an exercise are its names and those its parts scan
    assert set(graded_functions(LAB.exercises[3])) == {"errors_pherm", "rate_pherm", "runge", "test_pherm_interpolate"}


def test_results_keep_the_sources_and_old_results_still_load():
    grade = SubmissionGrade("ada", seed=1, sources={"eval_pherm": ORIGINAL})
    data = json.loads(json.dumps(grade.as_dict()))
    assert data["sources"] == {"eval_pherm": ORIGINAL}
    assert SubmissionGrade.from_dict(data).sources == {"eval_pherm": ORIGINAL}
    del data["sources"]
    assert SubmissionGrade.from_dict(data).sources == {}
    data["sources"] = {"eval_pherm": "x" * (5 * MAX_SOURCE_CHARS) + "\x1b"}
    assert SubmissionGrade.from_dict(data).sources["eval_pherm"] == "x" * MAX_SOURCE_CHARS
    for bad in ([1, 2], {"eval_pherm": 3}, "text"):
        data["sources"] = bad
        with pytest.raises(ValueError, match="not a labkit grade result"):
            SubmissionGrade.from_dict(data, "ada.json")


@pytest.mark.slow  # starts a sandbox
@pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")
def test_graded_results_carry_the_sources_and_a_copy_costs_no_points(tmp_path):
    sandbox_or_skip()
    ada = plant(Planted("ada", "02_convergence.ipynb", ()), tmp_path / "ada")
    zoe = plant(Planted("zoe", "02_convergence.ipynb", ((BODY, COPY_BODY),)), tmp_path / "zoe")
    out = tmp_path / "out"
    options = grading.GradeOptions(cell_timeout=30, total_timeout=300, seed=5, jobs=2)
    graded = grading.grade([ada.parent, zoe.parent], out, options, progress=False)
    assert [g.name for g in graded] == ["ada", "zoe"] and all(g.graded for g in graded)
    assert graded[0].points == graded[1].points and graded[0].points[2] == LAB.points[2] > 0
    assert graded[0].points[3] == LAB.points[3]
    data = json.loads(next((out / "results").glob("ada-*.json")).read_text(encoding="utf-8"))
    assert set(data["sources"]) == {"eval_pherm", "runge", "test_pherm_interpolate"}
    assert data["sources"]["eval_pherm"] == HEAD + "    ### BEGIN SOLUTION\n" + BODY.rstrip("\n")
    csv_before = (out / "grades.csv").read_bytes()
    grades = read_results([out])
    assert grades[1].sources["eval_pherm"] == HEAD + "    ### BEGIN SOLUTION\n" + COPY_BODY.rstrip("\n")
    flagged = {p.function: p for p in similar_pairs(grades)}
    assert flagged["eval_pherm"].score >= DEFAULT_THRESHOLD
    assert (flagged["eval_pherm"].first, flagged["eval_pherm"].second) == ("ada", "zoe")
    assert flagged["runge"].score == 1.0  # the rest of the notebook is the same
    write_csv(out / "again.csv", grades)  # after the search: the same grades.csv
    assert (out / "again.csv").read_bytes() == csv_before


def test_what_much_of_the_class_writes_alike_is_not_evidence_but_a_copy_among_them_still_is():
    # 30 students write the obvious runge alike (independently); two of them also share a renamed copy of a
    # longer eval_pherm, and the rest write that one their own way
    obvious = "def runge(x):\n    y = 1 / (1 + x**2)\n    return y, -2 * x * y**2\n"
    grades = [SubmissionGrade(f"s{k:02d}", sources={"runge": obvious}) for k in range(30)]
    grades[0].sources["eval_pherm"], grades[1].sources["eval_pherm"] = ORIGINAL, COPY
    grades[2].sources["eval_pherm"] = LOOP
    pairs = similar_pairs(grades)
    assert [(p.function, p.first, p.second) for p in pairs] == [("eval_pherm", "s00", "s01")]
    # in a small group the same runge is still shown: it is the class's common code that is set aside
    few = similar_pairs(grades[:4])
    assert {p.function for p in few} == {"runge", "eval_pherm"}


def test_a_copy_moved_into_a_helper_is_compared_where_the_graded_function_uses_it():
    # issue 47: the recorded source was the wrapper alone, so the copied lines in the helper were never compared
    wrapper = HEAD + "    return _hermite(xdata, ydata, ypdata, xval)\n"
    helper = "def _hermite(xdata, ydata, ypdata, xval):\n" + COPY_BODY
    cells = ["import numpy as np\nimport labkit", helper, wrapper]
    recorded = reached_function_sources(cells, ["eval_pherm"])["eval_pherm"]
    assert "b1 = (t-right)" in recorded and recorded.startswith(HEAD.split("\n")[0])
    assert function_sources(cells, ["eval_pherm"])["eval_pherm"] not in (recorded, "")  # the wrapper alone
    pairs = similar_pairs(_grades({"ada": ORIGINAL, "bo": recorded, "cy": (HEAD + PHERM_SEARCH)}))
    assert [(p.first, p.second) for p in pairs] == [("ada", "bo")]
    honest = reached_function_sources([(HEAD + PHERM_SEARCH)], ["eval_pherm"])["eval_pherm"]
    assert (
        honest == function_sources([(HEAD + PHERM_SEARCH)], ["eval_pherm"])["eval_pherm"]
    )  # nothing reached: as before
    graded = reached_function_sources(
        cells + ["def driver(n):\n    return eval_pherm(n, n, n, n)"], ["driver"], ["eval_pherm"]
    )
    assert "_hermite" not in graded["driver"]  # another graded function is compared in its own entry
