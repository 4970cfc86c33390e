"""labkit feedback end to end: a Canvas zip class and a Moodle folder class are graded, their feedback written as
the upload zip of their LMS, and the zips read back as Canvas's and Moodle's importers read them."""

import re
import shutil
import zipfile
from html.parser import HTMLParser

import nbformat
import pytest
from catalog import NOTEBOOKS, Planted, plant
from conftest import sandbox_or_skip
from small_class import cli

from labkit import grading
from labkit.grading.store import record as records

NOTEBOOK = "01_limacon.ipynb"
SEED = "20261205"


def _release():
    return grading.release_notebook(nbformat.read(NOTEBOOKS / NOTEBOOK, as_version=4))


def _partly(folder):
    """The release with the data and derivatives of Exercise 4 written (the instructor's code, its markers
    dropped), its plot left as released: the hidden tests are not in it, as in a student's notebook."""
    solved, release = nbformat.read(NOTEBOOKS / NOTEBOOK, as_version=4), _release()
    written = 0
    for mine, theirs in zip(release.cells, solved.cells):
        if mine.cell_type == "code" and "NotImplementedError" in mine.source and "ax4" not in mine.source:
            mine.source = "\n".join(line for line in theirs.source.splitlines() if "### " not in line)
            written += 1
    assert written == 2
    folder.mkdir(parents=True)
    nbformat.write(release, folder / NOTEBOOK)
    return folder / NOTEBOOK


def _canvas_zip(tmp):
    """Canvas's download: solved, untouched, partly done, a copy of the solved one, and a late solved one."""
    work, files = tmp / "canvas-work", {}
    files["lovelaceada_101_9001"] = plant(Planted("solved", NOTEBOOK, ()), work / "ada")
    nbformat.write(_release(), work / "untouched.ipynb")
    files["turingalan_102_9002"] = work / "untouched.ipynb"
    files["gaussfriedrich_103_9003"] = _partly(work / "carl")
    files["fermatpierre_104_9004"] = files["lovelaceada_101_9001"]  # a copy of ada's
    files["hoppergrace_LATE_105_9005"] = plant(Planted("solved", NOTEBOOK, ()), work / "grace")
    archive = tmp / "submissions.zip"
    with zipfile.ZipFile(archive, "w") as zipped:
        for prefix, path in files.items():
            zipped.write(path, f"{prefix}_{NOTEBOOK}")
    return archive


def _moodle_folder(tmp):
    """Moodle's download, in folders: a solved submission and an untouched one."""
    folder = tmp / "moodle"
    plant(Planted("solved", NOTEBOOK, ()), folder / "Ada Lovelace_201_assignsubmission_file_")
    untouched = folder / "Alan Turing_202_assignsubmission_file_"
    untouched.mkdir(parents=True)
    nbformat.write(_release(), untouched / NOTEBOOK)
    return folder


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    """The two classes graded, and `labkit feedback` run on each: {lms: (output folder, the upload zip)}."""
    sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("delivery")
    found = {}
    for lms, given in (("canvas", _canvas_zip(tmp)), ("moodle", _moodle_folder(tmp))):
        out = tmp / f"{lms}-grades"
        run = cli("grade", given, "--out", out, "--seed", SEED, "--jobs", "2", "--quiet")
        assert run.returncode == 0, run.stderr
        done = cli("feedback", out)
        assert done.returncode == 0, done.stderr
        found[lms] = (out, out / "feedback-upload.zip")
    return found


class _Text(HTMLParser):
    """The text of a page, in order."""

    def __init__(self):
        super().__init__()
        self.parts = []

    def handle_data(self, data):
        if data.strip() and self.lasttag not in ("style", "title"):
            self.parts.append(data.strip())


def _page_text(html):
    parser = _Text()
    parser.feed(html)
    return " ".join(parser.parts)


def _totals(out):
    import csv

    with open(out / "grades.csv", newline="", encoding="utf-8") as handle:
        return {row["submission"]: row["total"] for row in csv.DictReader(handle)}


def _canvas_ids(member):
    """What Canvas's re-upload reads from a file name: the first two all-digit pieces between `_`."""
    return [piece for piece in member.split("/")[-1].split("_") if re.fullmatch(r"\d+", piece)][:2]


def test_canvas_feedback_is_named_for_re_upload_and_begins_with_the_total(graded):
    out, upload = graded["canvas"]
    totals = _totals(out)
    with zipfile.ZipFile(upload) as archive:
        members = {m: archive.read(m).decode("utf-8") for m in archive.namelist()}
    # each student's file carries that student's own user id and the id of their own submitted file
    expected = {"lovelaceada": ("101", "9001"), "turingalan": ("102", "9002"), "gaussfriedrich": ("103", "9003"),
                "fermatpierre": ("104", "9004"), "hoppergrace": ("105", "9005")}  # fmt: skip
    assert len(members) == len(expected) == len(totals)
    for name, ids in expected.items():
        member = next(m for m in members if m.startswith(f"{name}_"))
        assert tuple(_canvas_ids(member)) == ids and "/" not in member and member.endswith(".html")
        text = _page_text(members[member])
        assert text.startswith(f"Total: {totals[name]} / "), text[:200]
    assert next(m for m in members if m.startswith("hoppergrace_")).startswith("hoppergrace_LATE_105_9005_")


def test_an_untouched_release_says_not_done_for_every_part_and_shows_no_traceback(graded):
    out, _ = graded["canvas"]
    text = (out / "feedback" / "turingalan.txt").read_text()
    assert text.startswith("Total: 0 / 100 points\nFeedback for turingalan\n")
    assert "Traceback" not in text and 'File "' not in text and "line " not in text
    assert "slip" not in text and "hint:" not in text
    table = [line for line in text.splitlines() if re.match(r"\s+\d+\s+\d", line)]
    assert table and all(line.endswith("not done") for line in table)
    assert "cells still raise NotImplementedError" in text
    assert len(text.splitlines()) < 60  # 291 lines before


def test_a_partly_done_student_reads_the_plot_as_not_done_and_no_stub_error(graded):
    out, _ = graded["canvas"]
    text = (out / "feedback" / "gaussfriedrich.txt").read_text()
    assert "ax4" in text and re.search(r"ax4 \([\d.]+ points?\): not done: draw the plot on `ax4`", text), text
    assert "10*(nintervals+1)" not in text  # the slip's hint of a plot that was drawn
    assert "Traceback" not in text
    assert text.index("ax4") < text.index("1 cell still raises NotImplementedError")  # errors last
    assert "What went wrong" not in text  # the tests' cell after the plot is as released: not the student's error


def test_moodle_feedback_is_named_by_participant_id_for_the_zip_import(graded):
    out, upload = graded["moodle"]
    totals = _totals(out)
    with zipfile.ZipFile(upload) as archive:
        members = {m: archive.read(m).decode("utf-8") for m in archive.namelist()}
    assert sorted(members) == [
        "Ada Lovelace_201_assignfeedback_file_/feedback.html",
        "Alan Turing_202_assignfeedback_file_/feedback.html",
    ]
    for member, page in members.items():
        # importziplib.php: the path part split at "_" into at most 5: name, participant id, plugin type, plugin
        name, pid, kind, plugin, _ = member.split("/")[0].split("_", 4)
        assert pid.isdigit() and (kind, plugin) == ("assignfeedback", "file")
        assert _page_text(page).startswith(f"Total: {totals[f'{name}_{pid}']} / ")
    assert records.read(out).delivery["layout"] == "moodle"


def test_a_folder_class_gets_a_feedback_page_in_each_students_folder(graded, tmp_path):
    out, _ = graded["canvas"]
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    done = cli("feedback", copy, "--layout", "folders")
    assert done.returncode == 0, done.stderr
    with zipfile.ZipFile(copy / "feedback-upload.zip") as archive:
        assert sorted(archive.namelist()) == sorted(f"{name}/feedback.html" for name in _totals(out))
