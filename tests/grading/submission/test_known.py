"""Known code (labkit's, scipy's, the solutions') recognised in a graded part however it is renamed, and a
part built on it held for a person: never an independent correct solution (labkit.grading.submission.known).

The copies are made from labkit's installed source (tests/copies.py), the independent solutions are two
complete solutions written from the lab text and the student release alone (tests/data/independent), and
the catalog's correct variations are planted into the instructor notebooks (tests/catalog.py).
"""

import csv
import json
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from catalog import CORRECT, plant
from conftest import sandbox_or_skip
from copies import REWRITES, exec_compressed, module_source

from labkit import grading
from labkit.exercises.registry import LAB
from labkit.grading.options import GradeOptions
from labkit.grading.store import report, rubric
from labkit.grading.store.model import PartResult
from labkit.grading.submission import fingerprint, known, scan
from labkit.grading.submission.scoring import (
    _rescore,
    exercises_in,
    hold_dependents,
    judge_known,
    known_sources,
    read_cells,
    registry_graded,
)
from labkit.student_notebooks import paths

ROOT = Path(__file__).resolve().parents[3]
NOTEBOOKS = ROOT / "notebooks"
INDEPENDENT = ROOT / "tests" / "data" / "independent"
STYLES = sorted(p.name for p in INDEPENDENT.iterdir() if p.is_dir())
# plain Python (loops, lists, math) shares little with labkit's vectorised code, so fewer of its parts are judged
# at all; it is graded whole (full marks, nothing held) by benchmarks/bench_grading_styles.py, which times it
PLAIN = {"plain_loops"}
SHARES = {}  # the largest share of each kind of honest work, shown in the test run's summary (conftest.py)


@pytest.fixture(scope="module")
def given():
    return known.own_reader([c for p in paths() for c in read_cells(Path(str(p)))[0]])


def _parts(cells, markdown):
    """(exercise, part, the definitions judged for it) of every part with a refusal, as the grader judges them."""
    for number in exercises_in(markdown, LAB):
        for part in LAB.exercises[number].parts:
            if part.refused is None:
                continue
            reached = scan.reached_sources(cells, part.scanned)
            yield number, part.name, [(n, t) for n, t in reached if n in part.scanned or n not in registry_graded(LAB)]


def _best(corpus, definitions, given):
    """(share, shared) of the best known units for these definitions, whatever the thresholds (None: nothing
    of the part's own code is in any known source)."""
    found = known.match(corpus, definitions, given, threshold=0.0, minimum=0)
    return None if found is None else (found.share, found.shared)


def _note(key, value, largest=True):
    SHARES[key] = max(SHARES.get(key, value), value) if largest else min(SHARES.get(key, value), value)


# -- the normalised text and its fingerprints -----------------------------------------------------------------


def test_names_docstrings_comments_and_layout_do_not_change_the_normalised_text():
    one = 'def area(width, height):\n    """The area."""\n    # width times height\n    return width * height\n'
    two = "def surface(a,b):  return a*b"
    assert fingerprint.normalise(one)[0] == fingerprint.normalise(two)[0]
    assert fingerprint.normalise(one)[0] != fingerprint.normalise(two.replace("*", "+"))[0]  # what the code does counts
    assert (
        fingerprint.normalise("np.diff(x)")[0] != fingerprint.normalise("np.cumsum(x)")[0]
    )  # so does the routine called


def test_each_normalised_character_points_at_its_token_in_the_source():
    text = "value = np.searchsorted(knots, 'left')  # done"
    normalised, where = fingerprint.normalise(text)
    for char, at in zip(normalised, where):
        assert char in "VFOS" or text[at] == char


def test_fingerprints_are_the_same_in_every_process():
    text = module_source("labkit.bilinear")
    here = fingerprint.fingerprints(fingerprint.normalise(text)[0])[0].tolist()
    code = (
        "import sys, json; sys.path.insert(0, 'tests'); from copies import module_source; "
        "from labkit.grading.submission import fingerprint; "
        "print(json.dumps(fingerprint.fingerprints(fingerprint.normalise(module_source('labkit.bilinear'))[0])[0].tolist()))"
    )
    there = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert json.loads(there.stdout) == here and len(here) > 50


def test_every_shared_run_of_thirty_normalised_characters_shares_a_fingerprint(rng):
    alphabet = np.array(list("V=+*()[],:.0123456789"))
    for _ in range(40):
        shared = "".join(rng.choice(alphabet, 30))
        one = "".join(rng.choice(alphabet, int(rng.integers(0, 80)))) + shared
        two = shared + "".join(rng.choice(alphabet, int(rng.integers(0, 80))))
        first, second = fingerprint.fingerprints(one)[0], fingerprint.fingerprints(two)[0]
        assert np.intersect1d(first, second).size, (one, two)


# -- copies are recognised ------------------------------------------------------------------------------------

COPIED = [  # (module, the modules it imports that the copier pastes too, the graded names, the exercise)
    ("labkit.piecewise", (), ("eval_pherm",)),
    ("labkit.splines", ("labkit.piecewise",), ("ccspline", "ncspline")),
    ("labkit.bilinear", (), ("eval_pbilin",)),
    ("labkit.monotone", ("labkit.piecewise",), ("pchip",)),
    ("labkit.patches", (), ("patch",)),
]


@pytest.mark.parametrize("rename", [True, False], ids=["renamed", "docstrings-deleted"])
@pytest.mark.parametrize(("module", "also", "names"), COPIED, ids=[c[0] for c in COPIED])
def test_a_copy_of_labkits_code_is_recognised_and_named(module, also, names, rename, given):
    corpus = known_sources(LAB)
    cells = [module_source(m, rename) for m in also] + [module_source(module, rename, drop=also)]
    for name in names:
        found = known.match(corpus, scan.reached_sources(cells, [name]), given)
        assert found is not None, (module, name, _best(corpus, scan.reached_sources(cells, [name]), given))
        assert found.share >= known.THRESHOLD and found.shared >= known.MIN_SHARED
        assert found.source.startswith(module + ".") or any(found.source.startswith(m + ".") for m in also)
        assert found.lines and all(mine for mine, _ in found.lines) and found.public
        form = "renamed" if rename else "docstrings deleted"
        _note(f"copies of labkit ({form}): smallest share", found.share, largest=False)
        _note(f"copies of labkit ({form}): fewest fingerprints shared", found.shared, largest=False)


def test_a_copy_moved_into_helpers_is_recognised_through_the_graded_function(given):
    wrapper = (
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    x, y, yp, xv = (np.asarray(v, dtype=float) for v in (xdata, ydata, ypdata, xval))\n"
        "    return _hermite_eval(x, y, yp, xv)"
    )
    cells = [module_source("labkit.piecewise"), wrapper]
    found = known.match(known_sources(LAB), scan.reached_sources(cells, ["eval_pherm"]), given)
    assert found is not None and found.definition != "eval_pherm" and found.source.startswith("labkit.piecewise.")


def test_a_copy_of_the_solutions_is_recognised_only_when_they_are_given(given):
    cells = read_cells(NOTEBOOKS / "03_meshes.ipynb")[0]  # the solutions, leaked whole
    reached = scan.reached_sources(cells, ["coons"])
    found = known.match(known_sources(LAB, NOTEBOOKS), reached, given)
    assert found is not None and found.source == "03_meshes.ipynb: coons" and not found.public
    assert known.match(known_sources(LAB), reached, given) is None


def test_the_solutions_folder_must_hold_notebooks(tmp_path):
    with pytest.raises(ValueError, match="holds no instructor notebooks"):
        known_sources(LAB, tmp_path)


def test_the_cache_is_used_and_a_broken_cache_entry_is_computed_again(tmp_path, monkeypatch):
    monkeypatch.setenv("LABKIT_CACHE", str(tmp_path))
    path = ROOT / "labkit" / "bilinear.py"
    first, _ = known._module_entry("labkit.bilinear", path)
    files = list((tmp_path / "known").glob("*.json"))
    assert len(files) == 1 and first["hashes"]

    def never(*args):
        raise AssertionError("the cached fingerprints were computed again")

    with monkeypatch.context() as patched:
        patched.setattr(known, "_entry", never)
        assert known._module_entry("labkit.bilinear", path)[0] == first  # read from the cache
    files[0].write_text("{not json")
    again, _ = known._module_entry("labkit.bilinear", path)
    assert again == first
    assert known._module_entry("labkit.splines", path)[1] != known._module_entry("labkit.bilinear", path)[1]


def test_a_cache_entry_is_readable_by_its_owner_only(tmp_path, monkeypatch):
    """The cache keeps the solutions' code (an instructor notebook's units with their text): never world-readable,
    whatever the umask."""
    monkeypatch.setenv("LABKIT_CACHE", str(tmp_path))
    old = os.umask(0o022)
    try:
        known._module_entry("labkit.bilinear", ROOT / "labkit" / "bilinear.py")
    finally:
        os.umask(old)
    (entry,) = (tmp_path / "known").glob("*.json")
    assert entry.stat().st_mode & 0o777 == 0o600


# -- honest work is never held --------------------------------------------------------------------------------


def _judged(corpus, cells, markdown, given):
    """{(exercise, part): (share, shared)} of every part with a refusal whose code is in a known source."""
    found = {(n, p): _best(corpus, d, given) for n, p, d in _parts(cells, markdown)}
    return {key: value for key, value in found.items() if value is not None}


def _never_held(judged):
    held = {k: v for k, v in judged.items() if v[0] >= known.THRESHOLD and v[1] >= known.MIN_SHARED}
    assert not held, held


@pytest.mark.parametrize("style", STYLES)
def test_an_independent_solution_is_never_held(style, given):
    corpus = known_sources(LAB, NOTEBOOKS)  # the solutions given too: the strictest comparison
    judged, parts = {}, 0
    for path in sorted((INDEPENDENT / style).glob("*.ipynb")):
        cells, markdown = read_cells(path)
        parts += len(list(_parts(cells, markdown)))
        judged.update(_judged(corpus, cells, markdown, given))
    # every refused part of the lab judged; some share a little
    assert parts >= 25 and len(judged) >= (1 if style in PLAIN else 5)
    _never_held(judged)
    _note("independent solutions: largest share", max(v[0] for v in judged.values()))
    _note("independent solutions: most fingerprints shared", max(v[1] for v in judged.values()))


def test_the_instructor_solutions_are_not_held_against_labkit(given):
    judged = {}
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        judged.update(_judged(known_sources(LAB), *read_cells(path), given))
    _never_held(judged)
    _note("instructor notebooks against labkit and scipy: most fingerprints shared", max(v[1] for v in judged.values()))


@pytest.mark.parametrize("entry", CORRECT, ids=lambda e: e.name)
def test_a_correct_variation_of_the_catalog_is_not_held(entry, tmp_path, given):
    judged = _judged(known_sources(LAB), *read_cells(plant(entry, tmp_path)), given)
    judged = {k: v for k, v in judged.items() if not entry.full or k[0] in entry.full}
    _never_held(judged)
    if judged:
        _note("catalog's correct variations: most fingerprints shared", max(v[1] for v in judged.values()))


# short honest versions in the forms the lab's text suggests: what a formula dictates comes out alike from
# everyone (each passes its own check, below)
HONEST = """
def complete_system(xdata, ydata, y1p, ynp):
    h = np.diff(xdata)
    secants = np.diff(ydata) / h
    main = np.concatenate(([h[0] / 3], (h[:-1] + h[1:]) / 3, [h[-1] / 3]))
    A = np.diag(main) + np.diag(h / 6, 1) + np.diag(h / 6, -1)
    D = np.concatenate(([secants[0] - y1p], np.diff(secants), [ynp - secants[-1]]))
    return A, D

def ccspline(xdata, ydata, y1p, ynp):
    A, D = complete_system(xdata, ydata, y1p, ynp)
    M = np.linalg.solve(A, D)
    h = np.diff(xdata)
    sprime = -h / 3 * M[:-1] - h / 6 * M[1:] + np.diff(ydata) / h
    return np.append(sprime, ynp)

def coons(A, B, C, D, s, t):
    out = []
    for c in range(2):
        bottom = labkit.eval_pherm([0, 1], [A.point[c], B.point[c]], [A.ds[c], B.ds[c]], s)
        bottom_t = labkit.eval_pherm([0, 1], [A.dt[c], B.dt[c]], [A.dsdt[c], B.dsdt[c]], s)
        top = labkit.eval_pherm([0, 1], [D.point[c], C.point[c]], [D.ds[c], C.ds[c]], s)
        top_t = labkit.eval_pherm([0, 1], [D.dt[c], C.dt[c]], [D.dsdt[c], C.dsdt[c]], s)
        grid = np.zeros((len(s), len(t)))
        for i in range(len(s)):
            grid[i, :] = labkit.eval_pherm([0, 1], [bottom[i], top[i]], [bottom_t[i], top_t[i]], t)
        out.append(grid)
    return out[0], out[1]

def eval_pherm(xdata, ydata, ypdata, xval):
    xdata = np.asarray(xdata, dtype=float)
    ydata = np.asarray(ydata, dtype=float)
    ypdata = np.asarray(ypdata, dtype=float)
    xval = np.asarray(xval, dtype=float)
    k = labkit.bracket(xdata, xval)
    xk, xk1 = xdata[k], xdata[k + 1]
    h1 = (xval - xk1) ** 2 * (3 * xk - xk1 - 2 * xval) / (xk - xk1) ** 3
    h2 = (xval - xk) * (xval - xk1) ** 2 / (xk - xk1) ** 2
    h3 = (xval - xk) ** 2 * (3 * xk1 - xk - 2 * xval) / (xk1 - xk) ** 3
    h4 = (xval - xk1) * (xval - xk) ** 2 / (xk1 - xk) ** 2
    return ydata[k] * h1 + ypdata[k] * h2 + ydata[k + 1] * h3 + ypdata[k + 1] * h4

def test_pbilin_interpolate(ndata, f=labkit.runge2d, interpolate=labkit.eval_pbilin):
    xdata = np.linspace(0, 5, ndata)
    ydata = np.linspace(0, 5, ndata)
    xtest = np.linspace(0, 5, 401)
    ytest = np.linspace(0, 5, 401)
    X, Y = np.meshgrid(xtest, ytest, indexing="ij")
    exact = f(X, Y)
    return np.max(np.abs(interpolate(f, xdata, ydata, xtest, ytest) - exact)) / np.max(np.abs(exact))
"""


def test_short_honest_code_in_the_forms_the_lab_suggests_is_never_held(given):
    from labkit.exercises import bilinear, experiments, hermite, patches, splines

    namespace = {"np": np, "labkit": __import__("labkit")}
    exec(HONEST, namespace)
    assert splines.check_ccspline(namespace["ccspline"], namespace["complete_system"]).passed
    assert patches.check_coons(namespace["coons"]).passed
    assert hermite.check_eval_pherm(namespace["eval_pherm"]).passed
    assert experiments.check_driver(bilinear.BILINEAR, namespace["test_pbilin_interpolate"]).passed
    cells = ["import numpy as np\nimport labkit", HONEST]
    for corpus in (known_sources(LAB), known_sources(LAB, NOTEBOOKS)):
        for name in ("complete_system", "ccspline", "coons", "eval_pherm", "test_pbilin_interpolate"):
            reached = [(n, t) for n, t in scan.reached_sources(cells, [name]) if n == name]
            assert known.match(corpus, reached, given) is None, (name, _best(corpus, reached, given))
            best = _best(corpus, reached, given)
            if best:
                _note("short honest code: most fingerprints shared", best[1])


# -- what a held part does to the grade -------------------------------------------------------------------------


def _held_grade(rubric_object=None):
    """A submission whose exercise 2 passed but is held: it matched labkit's eval_pherm."""
    held = {"definition": "eval_pherm", "source": "labkit.piecewise.eval_pherm", "share": 0.93,
            "lines": [["q1 = np.diff(q0)", "h = np.diff(x)"]]}  # fmt: skip
    checks = [{"name": "eval_pherm", "passed": True, "hint": "wait", "weight": 10, "steps": [], "held": held}]
    results = {2: {"exercise": 2, "defined": True, "checks": checks, "points": 0, "passed": False, "fraction": 0.0}}
    return report.SubmissionGrade("ada", results=results, rubric=rubric_object or rubric.default())


def test_a_held_part_earns_nothing_until_the_rubric_releases_it(tmp_path):
    grade = _held_grade()
    assert grade.points[2] == 0 and grade.held()[0][:2] == (2, "eval_pherm")
    feedback = grade.feedback()
    assert "HELD" in feedback and "labkit.piecewise.eval_pherm" in feedback
    assert "q1 = np.diff(q0)" in feedback and "h = np.diff(x)" in feedback
    path = tmp_path / "rubric.toml"
    path.write_text(rubric.DEFAULT.read_text() + '\n[held]\nrelease = {"ada" = [2]}\n')
    released = _held_grade(rubric.load(path))
    assert released.points[2] == 10 and "released" in released.feedback() and "HELD" not in released.feedback()
    assert rubric.default().differences(released.rubric) == ["the held parts its [held] table releases"]
    report.write_csv(tmp_path / "grades.csv", [grade])
    with open(tmp_path / "grades.csv", newline="") as handle:
        row = next(csv.DictReader(handle))
    assert row["exercise 2"] == "0" and "labkit.piecewise.eval_pherm" in row[report.CSV_HELD]


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ('[held]\nrelease = ["ada"]\n', "must be a table of submission names"),
        ('[held]\nrelease = {"ada" = 2}\n', "must be a list of exercise numbers"),
        ('[held]\nrelease = {"ada" = [99]}\n', "labkit does not grade"),
        ("[held]\nkeep = 1\n", "has one key, release"),
    ],
)
def test_a_bad_held_table_is_refused_with_what_to_write(tmp_path, table, message):
    path = tmp_path / "rubric.toml"
    path.write_text(rubric.DEFAULT.read_text() + "\n" + table)
    with pytest.raises(ValueError, match=message):
        rubric.load(path)


def test_a_run_is_released_by_merging_it_under_a_rubric_that_releases(tmp_path):
    out = tmp_path / "run"
    report.write_report(out, [_held_grade()])
    path = tmp_path / "released.toml"
    path.write_text(rubric.DEFAULT.read_text() + '\n[held]\nrelease = {"ada" = [2]}\n')
    merged = report.merge([out], tmp_path / "released", rubric=path)
    assert merged[0].points[2] == 10
    with open(tmp_path / "released" / "grades.csv", newline="") as handle:
        assert next(csv.DictReader(handle))["exercise 2"] == "10"


# -- graded for real, honest classmates and copiers in one run ----------------------------------------------------


@pytest.mark.slow  # starts a sandbox
def test_independent_solutions_earn_everything_and_copies_are_held_in_one_run(tmp_path):
    sandbox_or_skip()
    subs = [INDEPENDENT / style for style in STYLES if style not in PLAIN]
    copier = tmp_path / "copier"  # the solutions, leaked whole
    copier.mkdir()
    shutil.copy(NOTEBOOKS / "03_meshes.ipynb", copier / "03_meshes.ipynb")
    options = GradeOptions(solutions=str(NOTEBOOKS), jobs=2)
    out = tmp_path / "out"
    graded = grading.grade([*subs, copier], out, options, progress=False)
    by_name = {g.name: g for g in graded}
    for style in (s for s in STYLES if s not in PLAIN):
        assert by_name[style].total == rubric.default().maximum, by_name[style].feedback()
        assert by_name[style].held() == []
    held = {(n, p) for n, p, _, _ in by_name["copier"].held()}
    assert (5, "coons") in held and by_name["copier"].points[5] == 0, by_name["copier"].feedback()
    feedback = by_name["copier"].feedback()
    assert "HELD" in feedback and "03_meshes.ipynb: coons" in feedback
    solution = read_cells(NOTEBOOKS / "03_meshes.ipynb")[0]
    assert "| " not in feedback.split("HELD")[1].split("Exercise")[0]  # the solutions' lines are not shown
    record = json.loads((out / "record.json").read_text())
    assert record["known"]["solutions"] == str(NOTEBOOKS) and record["known"]["digest"]
    assert solution  # (read as the grader reads it)
    # a resumed run compares with the same sources, recorded: without --solutions they are used again
    again = grading.grade([*subs, copier], out, GradeOptions(jobs=2), progress=False)
    assert {(n, p) for n, p, _, _ in {g.name: g for g in again}["copier"].held()} == held
    assert json.loads((out / "record.json").read_text())["known"] == record["known"]
    # other solutions are other known sources: the run is not resumed under them
    other = tmp_path / "other-solutions"
    other.mkdir()
    shutil.copy(NOTEBOOKS / "02_convergence.ipynb", other / "02_convergence.ipynb")
    with pytest.raises(ValueError, match="other known sources"):
        grading.grade([*subs, copier], out, GradeOptions(solutions=str(other), jobs=2), progress=False)


def _part(number, name):
    return next(p for p in LAB.exercises[number].parts if p.name == name)


def test_the_grader_holds_a_passed_part_whose_code_is_labkits_and_keeps_one_that_failed(given):
    cells = [module_source("labkit.piecewise")]
    part, options = _part(2, "eval_pherm"), GradeOptions()
    passed = {"name": "eval_pherm", "passed": True, "hint": "", "weight": 10, "steps": []}
    held = judge_known(passed, part, cells, LAB, options)
    assert held["held"]["source"].startswith("labkit.piecewise.") and held["passed"]
    assert [s["step"] for s in held["steps"]] == [report.HELD_STEP]
    failed = {**passed, "passed": False}
    assert judge_known(failed, part, cells, LAB, options) is failed  # no points to hold
    honest = read_cells(INDEPENDENT / "style_a" / "02_convergence.ipynb")[0]
    assert judge_known(passed, part, honest, LAB, options) is passed
    verdict = _rescore({"exercise": 2, "checks": [held]}, LAB)
    assert verdict["points"] == 0 and not verdict["passed"]


def test_a_release_pays_only_the_held_part_of_a_partly_passed_exercise(tmp_path):
    grade = _held_grade()
    other = PartResult("other", False, 10, "h")  # worth as much
    grade.results[2] = replace(grade.results[2], parts=(*grade.results[2].parts, other))
    path = tmp_path / "rubric.toml"
    path.write_text(rubric.DEFAULT.read_text() + '\n[held]\nrelease = {"ada" = [2]}\n')
    grade.rubric = rubric.load(path)
    assert grade.points[2] == 5  # half of exercise 2's 10 points: the released half
    assert "released: your instructor looked at eval_pherm" in grade.feedback()


def test_the_class_report_lists_a_held_part_side_by_side(tmp_path):
    from labkit.grading.reports import class_report

    honest = report.SubmissionGrade("bartholomew", results={}, rubric=rubric.default())
    copier = _held_grade()
    copier.results[2].parts[0].held["lines"].append(["x = a < b & c  # </pre><script>", "y"])
    page = class_report.render(class_report.summarise([copier, honest]), [])
    section = page[page.index('<h2 id="held">') :]
    section = section[: section.index("</section>")]
    assert "ada" in section and "labkit.piecewise.eval_pherm" in section and "93%" in section
    assert "q1 = np.diff(q0)" in section and "h = np.diff(x)" in section and "bartholomew" not in section
    assert "<script>" not in section and "a &lt; b &amp; c" in section


# -- one further rewrite of a copy (issue 47): compared by what the code does -----------------------------------


@pytest.mark.parametrize("form", sorted(REWRITES))
@pytest.mark.parametrize(("module", "also", "names"), COPIED, ids=[c[0] for c in COPIED])
def test_a_copy_rewritten_once_more_is_still_recognised(module, also, names, form, given):
    corpus = known_sources(LAB)
    cells = [module_source(m) for m in also] + [module_source(module, drop=also)]
    cells = [REWRITES[form](cell) for cell in cells]
    for name in names:
        reached = scan.reached_sources(cells, [name])
        found = known.match(corpus, reached, given)
        assert found is not None, (form, module, name, _best(corpus, reached, given))
        assert found.source.startswith(module + ".") or any(found.source.startswith(m + ".") for m in also)
        _note(f"copies rewritten ({form}): smallest share", found.share, largest=False)
        _note(f"copies rewritten ({form}): fewest fingerprints shared", found.shared, largest=False)


@pytest.mark.parametrize("form", sorted(REWRITES))
def test_each_rewrite_comes_back_to_the_code_it_rewrote(form):
    text = module_source("labkit.bilinear")
    plain = sorted(t for _, t in fingerprint.units([("m", text)]) if t.startswith("def "))
    rewritten = sorted(t for _, t in fingerprint.units([("m", REWRITES[form](text))]) if t.startswith("def "))
    assert len(plain) >= 3 and plain == rewritten  # every function of the module, written as it was


def test_a_loop_that_fills_a_list_or_a_sum_reads_as_the_comprehension_it_equals():
    looped = (
        "def f(xs):\n    out = []\n    for x in xs:\n        if x > 0:\n            out.append(x * x)\n    return out"
    )
    assert fingerprint.canonical(looped) == fingerprint.canonical("def f(xs):\n    return [x * x for x in xs if x > 0]")
    summed = "def g(v):\n    s = 0.0\n    for k in range(len(v)):\n        s += v[k] ** 2\n    return s"
    assert fingerprint.canonical(summed) == fingerprint.canonical(
        "def g(v):\n    return sum(v[k] ** 2 for k in range(len(v)))"
    )
    # what the loop computes still counts: another element, filter or start is other code
    assert fingerprint.canonical(looped) != fingerprint.canonical(looped.replace("x * x", "x + x"))
    assert fingerprint.canonical(looped) != fingerprint.canonical(looped.replace("x > 0", "x < 0"))
    assert fingerprint.canonical(summed) != fingerprint.canonical(summed.replace("s = 0.0", "s = 1.0"))
    assert "for k" in fingerprint.canonical(summed.replace("s += v[k] ** 2", "s += v[k] ** 2\n        print(s)"))


def test_what_the_normalisation_keeps_is_what_the_code_does():
    one = "def f(x):\n    y = x * 2\n    return y + 1"
    assert fingerprint.canonical(one) != fingerprint.canonical(one.replace("* 2", "* 3"))
    assert fingerprint.canonical(one) != fingerprint.canonical(one.replace("y + 1", "x + 1"))  # y is read: kept
    assert fingerprint.canonical("def f(:") == "def f(:"  # not Python: as it is


def test_a_class_of_staticmethods_is_judged_method_by_method():
    box = "class K:\n    @staticmethod\n    def a(x):\n        return x * 2 + 1\n    def b(self, y):\n        return y"
    assert [name for name, _ in fingerprint.units([("K", box)])] == ["K.a", "K.b"]


def test_a_copy_run_from_a_compressed_string_is_refused_with_why():
    blob = exec_compressed(module_source("labkit.piecewise"))
    found = scan.run_strings([blob], ["eval_pherm"])
    assert found and "exec" in found[0][2] and "cannot be read" in found[0][2]
    assert scan.run_strings([blob, module_source("labkit.piecewise")], ["eval_pherm"]) == []  # defined after
    assert scan.run_strings(['x = eval("1 + 2")', "def eval_pherm(): pass"], ["eval_pherm"]) == []  # a literal
    helper = ["def load(s):\n    exec(s, globals())", "load(open('copy.txt').read())"]
    assert "in load" in scan.run_strings(helper, ["eval_pherm"])[0][2]


def _passed(part):
    return {"name": part.name, "passed": True, "hint": "", "weight": part.weight, "steps": []}


def test_a_plot_drawn_with_a_copy_is_held():

    copy = module_source("labkit.piecewise")
    plot = "fig, ax4 = plt.subplots()\nt = np.linspace(0, 1, 5)\nax4.plot(t, eval_pherm(t, t, t, t))"
    part = _part(4, "ax4")
    held = judge_known(_passed(part), part, [copy, plot], LAB, GradeOptions())
    assert held["held"]["source"].startswith("labkit.piecewise.")
    honest = "fig, ax4 = plt.subplots()\nt = np.linspace(0, 1, 5)\nax4.plot(t, labkit.eval_pherm(t, t, t, t))"
    assert "held" not in judge_known(_passed(part), part, [honest], LAB, GradeOptions())


def test_a_part_built_on_a_held_definition_is_held_with_it():
    cells = [module_source("labkit.piecewise"), "def test_pherm_interpolate(n, f):\n    return eval_pherm(n, f, f, n)"]
    held_check = judge_known(_passed(_part(2, "eval_pherm")), _part(2, "eval_pherm"), cells, LAB, GradeOptions())
    results = {
        2: {"exercise": 2, "checks": [held_check]},
        3: {"exercise": 3, "checks": [_passed(p) for p in LAB.exercises[3].parts]},
    }
    hold_dependents(results, LAB, cells)
    three = {c["name"]: c for c in results[3]["checks"]}
    assert "held" not in three["runge"] and three["test_pherm_interpolate"]["held"]["through"] == "eval_pherm"
    assert results[3]["points"] == _part(3, "runge").weight


def test_a_part_built_on_code_run_from_a_string_earns_nothing():
    cells = [
        exec_compressed(module_source("labkit.piecewise")),
        "def test_pherm_interpolate(n):\n    return eval_pherm(n)",
    ]
    results = {3: {"exercise": 3, "checks": [_passed(p) for p in LAB.exercises[3].parts]}}
    hold_dependents(results, LAB, cells)
    driver = {c["name"]: c for c in results[3]["checks"]}["test_pherm_interpolate"]
    assert not driver["passed"] and "cannot be read" in driver["steps"][-1]["detail"]


def _with_cell(folder, notebook, source):
    """The instructor notebook `notebook` with a code cell `source` added at its end, in `folder`."""
    import nbformat

    nb = nbformat.read(NOTEBOOKS / notebook, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(source))
    folder.mkdir(parents=True)
    nbformat.write(nb, folder / notebook)
    return folder


@pytest.mark.slow  # grades a class in the sandbox
def test_rewritten_and_string_run_copies_are_held_or_refused_in_one_run_with_honest_classmates(tmp_path):
    sandbox_or_skip()
    copy = module_source("labkit.piecewise")
    forms = {form: rewrite(copy) for form, rewrite in REWRITES.items()} | {"exec": exec_compressed(copy)}
    subs = [_with_cell(tmp_path / form, "02_convergence.ipynb", cell) for form, cell in forms.items()]
    subs += [INDEPENDENT / style for style in STYLES]
    graded = {g.name: g for g in grading.grade(subs, tmp_path / "out", GradeOptions(jobs=2), progress=False)}
    for style in STYLES:
        assert graded[style].total == rubric.default().maximum and not graded[style].held(), graded[style].feedback()
    for form in forms:
        grade = graded[form]
        if form == "exec":  # run after every definition: it may have redefined any of them, so none is graded
            assert grade.points[2] == grade.points[3] == 0 and not grade.held(), grade.feedback()
            assert "runs a string built at run time as code (exec)" in grade.feedback()
            assert "code run from a string is never graded" in grade.feedback()
        else:
            assert grade.points[2] == 0 and grade.points[3] == _part(3, "runge").weight, (form, grade.feedback())
            held = {part for number, part, _, _ in grade.held() if number in (2, 3)}
            assert held == {"eval_pherm", "test_pherm_interpolate", "errors_pherm", "rate_pherm"}, grade.feedback()
