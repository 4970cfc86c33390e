"""Adding an LMS is adding one module: a toy LMS written into the package's path is found by the discovery the
real ones go through, and then intake recognises its download (a folder and a zip), the run record and
`labkit feedback` name its files, and the export writes its grade file, with no other edit."""

import csv
import io
import sys
import zipfile

import nbformat
import pytest

import labkit.grading.lms as lms
from labkit import cli
from labkit.grading.lms import delivery
from labkit.grading.lms.intake import find_class
from labkit.grading.store.report import SubmissionGrade, read_results, write_report

TOY = """
import re
from pathlib import Path

from labkit.grading.lms import Lms
from labkit.grading.lms.exports import check_outputs, match, start, write, write_summary
from labkit.grading.lms.intake import entries
from labkit.grading.lms.roster import read_roster

NAME = re.compile(r"^(?P<assignment>[^_]+)_(?P<user>[a-z0-9]+)_attempt_(?P<when>[0-9-]+)_(?P<file>.+)$")


class Toy(Lms):
    name = "toy"
    rank = 30
    download = "Toy's download"
    counted = "file(s) named as Toy names them"
    keys = ("username",)
    steps = "upload it in Toy's feedback page"

    def claims(self, name, kind):
        return kind == "file" and NAME.match(name) is not None

    def owners(self, tops, builder):
        return {name: ("toy", NAME.match(name)["user"]) for name, kind in tops if self.claims(name, kind)}

    def students(self, root, builder, assignment):
        files = {}
        for entry in entries(root):
            found = NAME.match(builder.name(entry))
            if found and entry.is_file(follow_symlinks=False):
                files.setdefault(found["user"], []).append((Path(found["file"]), Path(entry.path)))
        return [builder.from_files(user, pieces, "toy", user, key=("toy", user)) for user, pieces in files.items()]

    def feedback_names(self, name, entry):
        return [f"{entry['lms id']}_feedback.html"]

    def export(self, grades, roster, out, force=False):
        by_name, export = start(grades, out, "Toy", "points")
        ids = read_roster(roster)
        check_outputs(export, [roster], force)
        rows = [["username", "points"]]
        for value, name in match(export, by_name, ids).items():
            rows.append([value, by_name[name].total])
            export.exported[name] = (value, by_name[name].total)
        write(rows, out)
        write_summary(export, ids, by_name)
        return export


LMS = Toy()
"""


def notebook_text(tag):
    notebook = nbformat.v4.new_notebook()
    notebook.cells.append(nbformat.v4.new_code_cell(f"x = {tag!r}"))
    return nbformat.writes(notebook)


def zip_bytes(members):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, text in members.items():
            archive.writestr(name, text)
    return buffer.getvalue()


FILES = {
    "lab8_ada_attempt_2026-12-01_02_convergence.ipynb": "ada",
    "lab8_bob_attempt_2026-12-02_02_convergence.ipynb": "bob",
    "lab8_bob_attempt_2026-12-02_notes.txt": "bob's notes",
}


@pytest.fixture
def toy(tmp_path, monkeypatch):
    """The toy LMS's module in a folder of its own, put on labkit.grading.lms's path (as a module dropped into
    labkit/grading/lms/ would be)."""
    folder = tmp_path / "dropped"
    folder.mkdir()
    (folder / "toy.py").write_text(TOY, encoding="utf-8")
    monkeypatch.setattr(lms, "__path__", [*lms.__path__, str(folder)])
    yield
    sys.modules.pop("labkit.grading.lms.toy", None)


def test_the_discovery_finds_the_toy_lms_in_its_rank(toy):
    assert [system.name for system in lms.systems()] == ["nbgrader", "moodle", "canvas", "toy", "folders"]
    assert lms.named("toy").keys == ("username",)


@pytest.mark.parametrize("as_zip", [False, True])
def test_intake_recognises_its_download_and_feedback_and_export_find_it(toy, tmp_path, as_zip):
    cls = tmp_path / "class"
    cls.mkdir()
    for name, tag in FILES.items():
        (cls / name).write_text(notebook_text(tag) if name.endswith(".ipynb") else tag, encoding="utf-8")
    if as_zip:
        (tmp_path / "class.zip").write_bytes(zip_bytes({n: (cls / n).read_text() for n in FILES}))
        cls = tmp_path / "class.zip"
    intake = find_class(cls, tmp_path / "work")
    assert intake.layout == "toy"
    assert [(s.name, s.lms_id, s.failure) for s in intake.students] == [("ada", "ada", None), ("bob", "bob", None)]
    assert sorted(p.name for p in intake.students[1].path.iterdir()) == ["02_convergence.ipynb"]

    out = tmp_path / "grades"
    write_report(
        out, [SubmissionGrade(s.name, {2: {"fraction": 1.0, "passed": True, "checks": []}}) for s in intake.students]
    )
    delivery.remember(out, intake)
    path, members, notes = delivery.write_upload(out)
    assert notes == [] and sorted(members) == ["ada_feedback.html", "bob_feedback.html"]
    with zipfile.ZipFile(path) as archive:
        assert b"Total: 10 / 100 points" in archive.read("ada_feedback.html")
    assert lms.named(delivery.layout_of(out)).steps == "upload it in Toy's feedback page"

    roster = tmp_path / "roster.csv"
    roster.write_text("submission,id\nada,ada\nbob,bob\n", encoding="utf-8")
    export = lms.named("toy").export(read_results([out]), roster, tmp_path / "toy.csv")
    with open(tmp_path / "toy.csv", encoding="utf-8", newline="") as handle:
        assert list(csv.reader(handle)) == [["username", "points"], ["ada", "10.0"], ["bob", "10.0"]]
    assert export.listed == 0 and export.exported == {"ada": ("ada", 10.0), "bob": ("bob", 10.0)}


def test_the_command_line_takes_it_by_name(toy, tmp_path):
    out = tmp_path / "grades"
    write_report(out, [SubmissionGrade("ada", {2: {"fraction": 1.0, "passed": True, "checks": []}})])
    delivery.remember(out, find_class(_toy_class(tmp_path), tmp_path / "work"))
    assert cli.main(["feedback", out, "--layout", "toy"]) == 0
    with zipfile.ZipFile(out / "feedback-upload.zip") as archive:
        assert archive.namelist() == ["ada_feedback.html"]
    (tmp_path / "roster.csv").write_text("submission,id\nada,ada7\n", encoding="utf-8")
    assert cli.main(["export", out, "--lms", "toy", "--roster", tmp_path / "roster.csv"]) == 0
    with open(tmp_path / "grades-toy.csv", encoding="utf-8", newline="") as handle:
        assert list(csv.reader(handle)) == [["username", "points"], ["ada7", "10.0"]]


def test_an_lms_no_module_names_is_refused_with_the_names(tmp_path, capsys):
    out = tmp_path / "grades"
    write_report(out, [SubmissionGrade("ada", {2: {"fraction": 1.0, "passed": True, "checks": []}})])
    assert cli.main(["feedback", out, "--layout", "toy"]) == 2
    assert "canvas" in capsys.readouterr().err and not (out / "feedback-upload.zip").exists()


def test_canvas_by_name_asks_for_its_gradebook(tmp_path, capsys):
    """Canvas's export fills in a gradebook, so `--lms canvas` without one says how to give it (exit 2, no file),
    instead of failing inside the export."""
    out = tmp_path / "grades"
    write_report(out, [SubmissionGrade("ada", {2: {"fraction": 1.0, "passed": True, "checks": []}})])
    (tmp_path / "roster.csv").write_text("submission,id\nada,7\n", encoding="utf-8")
    assert cli.main(["export", out, "--lms", "canvas", "--roster", tmp_path / "roster.csv"]) == 2
    assert "--canvas GRADEBOOK.csv" in capsys.readouterr().err
    assert not (tmp_path / "grades-canvas.csv").exists()


def _toy_class(tmp_path):
    cls = tmp_path / "class"
    cls.mkdir()
    name = next(iter(FILES))
    (cls / name).write_text(notebook_text("ada"), encoding="utf-8")
    return cls


def test_without_the_module_its_download_is_not_recognised(tmp_path):
    (tmp_path / "class").mkdir()
    for name in FILES:
        (tmp_path / "class" / name).write_text("{}", encoding="utf-8")
    intake = find_class(tmp_path / "class", tmp_path / "work")
    assert intake.layout == "folders" and all(s.lms_id is None for s in intake.students)
