"""`labkit grade` on what instructors really have: a forgotten `/*`, a folder holding only a zip, a folder with no
notebook, a submission named like an option, and a result file that a submission wrote into an output folder.
Each is graded (or refused) with honest classmates in the same run."""

import json
import shutil
import zipfile

import pytest
from catalog import Planted, plant
from conftest import sandbox_or_skip
from small_class import SLIP, cli, rows

from labkit.grading.store import late
from labkit.grading.store.report import SubmissionGrade, file_stem, safe_name
from labkit.grading.store.rubric import default

SOLVED = Planted("as handed out", "06_bilinear.ipynb", ())


@pytest.fixture(scope="module")
def submissions(tmp_path_factory):
    sandbox_or_skip()
    root = tmp_path_factory.mktemp("intake") / "submissions"
    plant(SOLVED, root / "alice")
    plant(SLIP, root / "bob")
    made = plant(SOLVED, root.parent / "scratch" / "carol")
    (root / "carol").mkdir()
    with zipfile.ZipFile(root / "carol" / "work.zip", "w") as archive:  # as Moodle often hands it over
        archive.write(made, "lab8/06_bilinear.ipynb")
    (root / "dave").mkdir()
    (root / "dave" / "notes.pdf").write_bytes(b"%PDF-1.4")
    return root


@pytest.mark.slow  # starts a sandbox
def test_a_class_folder_given_without_its_star_is_graded_as_the_class(submissions, tmp_path):
    out = tmp_path / "g"
    run = cli("grade", submissions, "--out", out, "--quiet")
    assert run.returncode == 1, run.stderr  # dave: could not be graded
    found = rows(out)
    assert sorted(found) == ["alice", "bob", "carol", "dave"]  # one row per student, not one called "submissions"
    assert (found["alice"]["total"], found["bob"]["total"], found["carol"]["total"]) == ("8", "7", "8")
    assert found["dave"]["total"] == "" and found["dave"]["status"].startswith("not graded: holds no notebook")
    assert "it holds notes.pdf" in found["dave"]["status"]
    assert "could not grade dave: holds no notebook (it holds notes.pdf)" in run.stderr
    assert sorted(p.name for p in (submissions / "carol").iterdir()) == ["work.zip"]  # never unpacked in place
    assert not list(out.glob(".labkit-unpacked-*"))
    feedback = (out / "feedback" / f"{file_stem('dave')}.txt").read_text()
    assert "could not be graded" in feedback and "nothing of this submission was scored" in feedback


@pytest.mark.slow  # starts a sandbox
def test_submissions_listed_one_by_one_open_their_zips_too(submissions, tmp_path):
    out = tmp_path / "g"
    run = cli("grade", submissions / "carol", submissions / "dave", submissions / "alice", "--out", out, "--quiet")
    assert run.returncode == 1, run.stderr
    found = rows(out)
    assert (found["carol"]["total"], found["alice"]["total"], found["dave"]["total"]) == ("8", "8", "")


@pytest.mark.slow  # starts a sandbox
def test_a_submission_named_like_an_option_is_refused_and_the_docs_way_grades_it(submissions, tmp_path):
    here = tmp_path / "class"
    shutil.copytree(submissions / "alice", here / "--sandbox=none")
    shutil.copytree(submissions / "bob", here / "bob")
    out = tmp_path / "g"
    run = cli("grade", "--sandbox=none", "bob", "--out", out, cwd=here)  # what `labkit grade * --out ../g` gives
    assert run.returncode == 2 and "is an option, and also a file or folder here" in run.stderr
    assert "labkit grade --out OUT -- *" in run.stderr and not out.exists()
    run = cli("grade", "--out", out, "--quiet", "--", "--sandbox=none", "bob", cwd=here)
    assert run.returncode == 0, run.stderr
    assert rows(out)["'--sandbox=none"]["total"] == "8"  # a name is data: its CSV cell is neutralised
    record = json.loads((out / "record.json").read_text())
    assert sorted(record["submissions"]) == ["--sandbox=none", "bob"]


@pytest.mark.slow  # starts a sandbox
def test_times_inside_a_submission_count_only_when_asked_and_are_marked_student_supplied(submissions, tmp_path):
    rubric = tmp_path / "course.toml"
    rubric.write_text(
        default().text + '\n[late]\ndeadline = "2026-12-01T23:59:00+01:00"\nper = "day"\npercent = 10\ncap = 50\n'
    )
    late_one = tmp_path / "class" / "bob"
    shutil.copytree(submissions / "bob", late_one)
    (late_one / "timestamp.txt").write_text("2026-11-30 12:00:00 UTC")  # written by the student: "on time"
    out = tmp_path / "g"
    run = cli("grade", late_one, "--rubric", rubric, "--out", out, "--quiet")
    assert run.returncode == 0, run.stderr
    assert rows(out)["bob"]["lateness"] == "no submission time: not penalised"  # never read unasked
    run = cli("grade", late_one, "--rubric", rubric, "--out", tmp_path / "g2", "--quiet", "--times-from-submission")
    row = rows(tmp_path / "g2")["bob"]
    assert row["time source"] == late.FROM_NBGRADER and "student-supplied" in row["time source"]
    feedback = (tmp_path / "g2" / "feedback" / f"{file_stem('bob')}.txt").read_text()
    assert "student-supplied" in feedback
    again = cli("grade", late_one, "--out", tmp_path / "g2", "--quiet")  # resumed: the run's own choice holds
    assert again.returncode == 0, again.stderr
    assert rows(tmp_path / "g2")["bob"]["time source"] == late.FROM_NBGRADER


@pytest.mark.slow  # starts a sandbox
def test_a_result_a_submission_writes_into_its_own_output_folder_is_never_merged(submissions, tmp_path):
    """The pod deployment of docs/scaling.md: one run per student, --sandbox none, then `labkit merge`."""
    forged = SubmissionGrade("bob", {}, [], 1, default()).as_dict()  # bob with nothing at all
    out_alice, out_bob = tmp_path / "out-alice", tmp_path / "out-bob"
    target = out_alice / "results" / f"{safe_name('bob')}.json"
    text = json.dumps(forged)
    attack = (
        "import hashlib, json, pathlib\n"
        f"target = pathlib.Path({str(target)!r})\n"
        "target.parent.mkdir(parents=True, exist_ok=True)\n"
        f"target.write_text({text!r})\n"
        "record = target.parent.parent / 'record.json'\n"
        "data = json.loads(record.read_text())\n"
        "data['submissions']['bob'] = {'result': target.name, 'content': None,\n"
        "    'sha256': hashlib.sha256(target.read_bytes()).hexdigest()}\n"
        "record.write_text(json.dumps(data))\n"
    )
    evil = tmp_path / "pods" / "alice"
    ready = 'labkit.ready("0.1")'
    plant(Planted("writes a result for bob", "06_bilinear.ipynb", ((ready, f"{ready}\n{attack}"),)), evil)
    first = cli("grade", submissions / "bob", "--out", out_bob, "--quiet", "--seed", "5")
    assert first.returncode == 0, first.stderr
    pod = cli("grade", evil, "--sandbox", "none", "--out", out_alice, "--quiet", "--seed", "5")
    assert pod.returncode == 0, pod.stderr
    assert target.exists()  # the attack ran: the file is there
    assert sorted(json.loads((out_alice / "record.json").read_text())["submissions"]) == ["alice"]
    merged = cli("merge", out_bob, out_alice, "--out", tmp_path / "final", "--quiet")
    assert merged.returncode == 1 and f"not read: {target}" in merged.stderr
    assert "record names no such result" in merged.stderr and "replaced" not in merged.stdout
    assert rows(tmp_path / "final")["bob"]["total"] == rows(out_bob)["bob"]["total"] == "7"
