"""Known code (labkit's, scipy's, the solutions') recognised in a graded part however it is renamed, and a
part built on it held for a person: never an independent correct solution (labkit.grading.known).

The copies are made from labkit's installed source (tests/copies.py), the independent solutions are two
complete solutions written from the lab text and the student release alone (tests/data/independent), and
the catalog's correct variations are planted into the instructor notebooks (tests/catalog.py).
"""

import csv
import json
import subprocess
import sys
from pathlib import Path

import nbformat
import numpy as np
import pytest
from catalog import CORRECT, plant
from conftest import sandbox_or_skip
from copies import module_source, renamed_cells

from labkit import grading
from labkit.exercises.registry import LAB
from labkit.grading import known, report, rubric, scan
from labkit.grading.options import GradeOptions
from labkit.grading.scoring import exercises_in, known_sources, read_cells, registry_graded
from labkit.student_notebooks import paths

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
INDEPENDENT = ROOT / "tests" / "data" / "independent"
STYLES = sorted(p.name for p in INDEPENDENT.iterdir() if p.is_dir())
SHARES = {}  # the largest share of each kind of honest work, shown in the test run's summary (conftest.py)


@pytest.fixture(scope="module")
def given():
    return known.release_grams([c for p in paths() for c in read_cells(Path(str(p)))[0]])


def _parts(cells, markdown):
    """(exercise, part, the definitions judged for it) of every part with a refusal, as the grader judges them."""
    for number in exercises_in(markdown, LAB):
        for part in LAB.exercises[number].parts:
            if part.refused is None:
                continue
            reached = scan.reached_sources(cells, part.scanned)
            yield number, part.name, [(n, t) for n, t in reached if n in part.scanned or n not in registry_graded(LAB)]


def _best_share(corpus, definitions, given):
    """The share the best known source has of these definitions, whatever the threshold (0 when none)."""
    found = known.match(corpus, definitions, given, threshold=0.0)
    return 0.0 if found is None else found.share


# -- the normalised text and its fingerprints -----------------------------------------------------------------


def test_names_docstrings_comments_and_layout_do_not_change_the_normalised_text():
    one = 'def area(width, height):\n    """The area."""\n    # width times height\n    return width * height\n'
    two = "def surface(a,b):  return a*b"
    assert known.normalise(one)[0] == known.normalise(two)[0]
    assert known.normalise(one)[0] != known.normalise(two.replace("*", "+"))[0]  # what the code does counts
    assert known.normalise("np.diff(x)")[0] != known.normalise("np.cumsum(x)")[0]  # so does the routine called


def test_each_normalised_character_points_at_its_token_in_the_source():
    text = "value = np.searchsorted(knots, 'left')  # done"
    normalised, where = known.normalise(text)
    for char, at in zip(normalised, where):
        assert char in "VFOS" or text[at] == char


def test_fingerprints_are_the_same_in_every_process():
    text = module_source("labkit.bilinear")
    here = known.fingerprints(known.normalise(text)[0])[0].tolist()
    code = (
        "import sys, json; sys.path.insert(0, 'tests'); from copies import module_source; "
        "from labkit.grading import known; "
        "print(json.dumps(known.fingerprints(known.normalise(module_source('labkit.bilinear'))[0])[0].tolist()))"
    )
    there = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert json.loads(there.stdout) == here and len(here) > 50


def test_every_shared_run_of_thirty_normalised_characters_shares_a_fingerprint(rng):
    alphabet = np.array(list("V=+*()[],:.0123456789"))
    for _ in range(40):
        shared = "".join(rng.choice(alphabet, 30))
        one = "".join(rng.choice(alphabet, int(rng.integers(0, 80)))) + shared
        two = shared + "".join(rng.choice(alphabet, int(rng.integers(0, 80))))
        first, second = known.fingerprints(one)[0], known.fingerprints(two)[0]
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
        assert found is not None and found.share >= known.THRESHOLD, (module, name)
        assert found.source.startswith(module + ".") or any(found.source.startswith(m + ".") for m in also)
        assert found.lines and all(mine for mine, _ in found.lines)
        SHARES[f"smallest share of a copy ({'renamed' if rename else 'docstrings deleted'})"] = min(
            found.share, SHARES.get(f"smallest share of a copy ({'renamed' if rename else 'docstrings deleted'})", 1)
        )


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
    cells = renamed_cells(read_cells(NOTEBOOKS / "04_splines.ipynb")[0])
    with_them, without = known_sources(LAB, NOTEBOOKS), known_sources(LAB)
    found = known.match(with_them, scan.reached_sources(cells, ["ccspline"]), given)
    assert found is not None and found.source.startswith("04_splines.ipynb: ")
    assert _best_share(without, scan.reached_sources(cells, ["ccspline"]), given) < known.THRESHOLD


def test_the_solutions_folder_must_hold_notebooks(tmp_path):
    with pytest.raises(ValueError, match="holds no instructor notebooks"):
        known_sources(LAB, tmp_path)


def test_the_cache_is_used_and_a_broken_cache_entry_is_computed_again(tmp_path, monkeypatch):
    monkeypatch.setenv("LABKIT_CACHE", str(tmp_path))
    path = ROOT / "labkit" / "bilinear.py"
    first, _ = known._module_entry("labkit.bilinear", path)
    files = list((tmp_path / "known").glob("*.json"))
    assert len(files) == 1 and first["hashes"]
    files[0].write_text("{not json")
    again, _ = known._module_entry("labkit.bilinear", path)
    assert again == first


# -- honest work is never held --------------------------------------------------------------------------------


def _shares(corpus, cells, markdown, given):
    return {(n, p): _best_share(corpus, d, given) for n, p, d in _parts(cells, markdown)}


@pytest.mark.parametrize("style", STYLES)
def test_an_independent_solution_is_never_held(style, given):
    corpus = known_sources(LAB, NOTEBOOKS)  # the solutions given too: the strictest comparison
    shares = {}
    for path in sorted((INDEPENDENT / style).glob("*.ipynb")):
        shares.update(_shares(corpus, *read_cells(path), given))
    assert len(shares) >= 25  # every refused part of the lab was judged
    assert max(shares.values()) < known.THRESHOLD, {k: v for k, v in shares.items() if v >= known.THRESHOLD}
    SHARES[f"largest share, independent {style}"] = max(shares.values())


def test_the_instructor_solutions_are_not_held_against_labkit(given):
    shares = {}
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        shares.update(_shares(known_sources(LAB), *read_cells(path), given))
    assert max(shares.values()) < known.THRESHOLD
    SHARES["largest share, instructor notebooks against labkit and scipy"] = max(shares.values())


@pytest.mark.parametrize("entry", CORRECT, ids=lambda e: e.name)
def test_a_correct_variation_of_the_catalog_is_not_held(entry, tmp_path, given):
    cells, markdown = read_cells(plant(entry, tmp_path))
    shares = _shares(known_sources(LAB), cells, markdown, given)
    shares = {k: v for k, v in shares.items() if not entry.full or k[0] in entry.full}
    assert all(v < known.THRESHOLD for v in shares.values()), shares
    key = "largest share, catalog's correct variations"
    SHARES[key] = max([SHARES.get(key, 0.0), *shares.values()])


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


def test_independent_solutions_earn_everything_and_copies_are_held_in_one_run(tmp_path):
    sandbox_or_skip()
    subs = [INDEPENDENT / style for style in STYLES]
    copier = tmp_path / "copier"
    copier.mkdir()
    nb = nbformat.read(NOTEBOOKS / "04_splines.ipynb", as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    for cell, text in zip(code, renamed_cells([c.source for c in code])):
        cell.source = text
    nbformat.write(nb, copier / "04_splines.ipynb")
    options = GradeOptions(solutions=str(NOTEBOOKS))
    graded = grading.grade([*subs, copier], tmp_path / "out", jobs=2, progress=False, options=options)
    by_name = {g.name: g for g in graded}
    for style in STYLES:
        assert by_name[style].total == rubric.default().maximum, by_name[style].feedback()
        assert by_name[style].held() == []
    held = {(n, p) for n, p, _, _ in by_name["copier"].held()}
    assert (10, "ccspline") in held and by_name["copier"].points[10] == 0, by_name["copier"].feedback()
    record = json.loads((tmp_path / "out" / "record.json").read_text())
    assert record["known"]["solutions"] == str(NOTEBOOKS) and record["known"]["digest"]


def test_the_class_report_lists_a_held_part_side_by_side(tmp_path):
    from labkit.grading import class_report

    honest = report.SubmissionGrade("bartholomew", results={}, rubric=rubric.default())
    page = class_report.render(class_report.summarise([_held_grade(), honest]), [])
    section = page[page.index('<h2 id="held">') :]
    section = section[: section.index("</section>")]
    assert "ada" in section and "labkit.piecewise.eval_pherm" in section and "93%" in section
    assert "q1 = np.diff(q0)" in section and "h = np.diff(x)" in section and "bartholomew" not in section
