"""labkit.grading.lms.intake: each LMS layout built in tmp_path, and zips that try to harm."""

import io
import os
import stat
import tempfile
import warnings
import zipfile
from pathlib import Path

import nbformat
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from labkit.grading.lms.intake import Intake, Student, find_class
from labkit.grading.lms.unzip import UnpackLimits, unpack

MiB = 1 << 20


def notebook_text(tag="x = 1"):
    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_code_cell(tag))
    return nbformat.writes(nb)


def write_notebook(path, tag="x = 1"):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(notebook_text(tag), encoding="utf-8")
    return path


def zip_bytes(members):
    """A zip in memory of {name: text or bytes}."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return buffer.getvalue()


def snapshot(root, skip=None):
    """Every entry under `root` (not following links): path, type and size and mtime of files."""
    found = {}
    for folder, dirs, files in os.walk(root):
        if skip is not None and Path(folder).resolve() == Path(skip).resolve():
            dirs[:] = []
            continue
        for name in dirs + files:
            path = Path(folder, name)
            if skip is not None and path.resolve() == Path(skip).resolve():
                continue
            info = os.lstat(path)
            found[str(path.relative_to(root))] = (stat.S_IFMT(info.st_mode), info.st_size, info.st_mtime_ns)
    return found


def by_name(intake):
    return {s.name: s for s in intake.students}


def notebooks_of(student):
    assert student.path is not None, student.failure
    return sorted(p for p in Path(student.path).rglob("*.ipynb"))


@pytest.fixture
def workspace(tmp_path):
    return tmp_path / "workspace"


def find_untouched(tmp_path, path, workspace, **kwargs):
    """find_class, asserting that nothing outside the workspace changed."""
    before = snapshot(tmp_path, skip=workspace)
    intake = find_class(path, workspace, **kwargs)
    assert snapshot(tmp_path, skip=workspace) == before
    for student in intake.students:
        assert (student.path is None) == (student.failure is not None), student
    return intake


# ------------------------------------------------------------------------------------------- folders


def test_a_folder_per_student(tmp_path, workspace):
    cls = tmp_path / "class"
    write_notebook(cls / "alice" / "lab" / "deeper" / "02_convergence.ipynb")
    write_notebook(cls / "bob" / "03_meshes.ipynb")
    write_notebook(cls / "bob" / ".ipynb_checkpoints" / "03_meshes-checkpoint.ipynb")
    (cls / "carol").mkdir()
    (cls / "carol" / "work.txt").write_text("no notebook")
    (cls / "carol" / "notes.pdf").write_bytes(b"%PDF-1.4")
    (cls / "__MACOSX").mkdir()
    (cls / ".git").mkdir()
    write_notebook(cls / "-dash.ipynb")
    (cls / "README.txt").write_text("hello")
    (cls / "empty").mkdir()
    intake = find_untouched(tmp_path, cls, workspace)
    assert isinstance(intake, Intake) and intake.layout == "folders"
    assert [s.name for s in intake.students] == ["-dash", "alice", "bob", "carol", "empty"]
    students = by_name(intake)
    assert students["alice"].path == cls / "alice"
    assert students["-dash"].path == cls / "-dash.ipynb"
    assert students["carol"] == Student(
        "carol", None, "holds no notebook (it holds notes.pdf, work.txt)", "folders", None, False
    )
    assert students["empty"].failure == "holds no notebook (it is empty)"
    assert all(s.layout == "folders" and s.lms_id is None and not s.marked_late for s in intake.students)
    assert any("README.txt" in note for note in intake.notes)


def test_a_students_zip_is_unpacked_in_the_workspace(tmp_path, workspace):
    cls = tmp_path / "class"
    (cls / "alice").mkdir(parents=True)
    (cls / "alice" / "work.zip").write_bytes(zip_bytes({"lab/02_convergence.ipynb": notebook_text("alice")}))
    (cls / "bob").mkdir()
    (cls / "bob" / "work.zip").write_bytes(zip_bytes({"notes.pdf": b"%PDF"}))
    write_notebook(cls / "carol" / "a.ipynb")
    intake = find_untouched(tmp_path, cls, workspace)
    students = by_name(intake)
    alice = students["alice"]
    assert Path(alice.path).resolve().is_relative_to(workspace.resolve())
    [nb] = notebooks_of(alice)
    assert "alice" in nb.read_text() and nb.name == "02_convergence.ipynb"
    assert students["bob"].path is None and students["bob"].failure == "holds no notebook (it holds work.zip)"
    assert students["carol"].path == cls / "carol"


def test_links_are_never_followed(tmp_path, workspace):
    outside = tmp_path / "outside"
    write_notebook(outside / "secret.ipynb")
    cls = tmp_path / "class"
    write_notebook(cls / "alice" / "a.ipynb")
    os.symlink(outside, cls / "mallory")
    os.symlink(outside / "secret.ipynb", cls / "alice" / "linked.ipynb")
    os.symlink(outside, cls / "alice" / "linked_folder")
    intake = find_untouched(tmp_path, cls, workspace)
    # mallory, a link, is a student with nothing labkit will read: a "could not be graded" row, never a gap
    assert [(s.name, s.failure) for s in intake.students] == [
        ("alice", None),
        ("mallory", "is a link, and links are never followed"),
    ]
    with pytest.raises(ValueError, match="symbolic link"):
        os.symlink(cls, tmp_path / "class-link")
        find_class(tmp_path / "class-link", workspace)


def test_the_workspace_may_not_be_inside_the_class(tmp_path):
    write_notebook(tmp_path / "class" / "alice" / "a.ipynb")
    with pytest.raises(ValueError, match="workspace"):
        find_class(tmp_path / "class", tmp_path / "class" / "tmp")


def test_nothing_fits_or_layouts_mixed(tmp_path, workspace):
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="holds no students.*expected"):
        find_class(tmp_path / "empty", workspace)
    (tmp_path / "files").mkdir()
    (tmp_path / "files" / "notes.pdf").write_bytes(b"%PDF")
    with pytest.raises(ValueError, match=r"holds no students \(notes.pdf\)"):
        find_class(tmp_path / "files", workspace)
    mixed = tmp_path / "mixed"
    write_notebook(mixed / "lovelaceada_1815_98765_02_convergence.ipynb")
    write_notebook(mixed / "alice" / "a.ipynb")
    with pytest.raises(ValueError, match="mixes layouts.*1 file.*Canvas.*1 other folder"):
        find_class(mixed, workspace)
    (tmp_path / "notes.pdf").write_bytes(b"%PDF")
    with pytest.raises(ValueError, match="neither a folder nor a zip"):
        find_class(tmp_path / "notes.pdf", workspace)


# ------------------------------------------------------------------------------------------- nbgrader


def nbgrader_course(root, assignments):
    for student, names in assignments.items():
        for assignment in names:
            folder = root / "submitted" / student / assignment
            write_notebook(folder / f"{assignment}.ipynb", f"{student} {assignment}")
            (folder / "timestamp.txt").write_text("2026-12-01 23:59:59.123456 UTC")
    return root


def test_nbgrader_one_assignment(tmp_path, workspace):
    course = nbgrader_course(tmp_path / "course", {"alice": ["lab8"], "bob": ["lab8"]})
    (course / "source" / "lab8").mkdir(parents=True)  # the rest of a course root is not looked at
    for where in (course, course / "submitted"):
        intake = find_untouched(tmp_path, where, workspace)
        assert intake.layout == "nbgrader"
        assert [(s.name, s.path) for s in intake.students] == [
            ("alice", course / "submitted" / "alice" / "lab8"),
            ("bob", course / "submitted" / "bob" / "lab8"),
        ]
        assert all(s.layout == "nbgrader" and s.failure is None for s in intake.students)


def test_nbgrader_several_assignments_need_one_named(tmp_path, workspace):
    course = nbgrader_course(tmp_path / "course", {"alice": ["lab8", "lab9"], "bob": ["lab8"], "carol": ["lab9"]})
    with pytest.raises(ValueError, match=r"several assignments \(lab8, lab9\).*--assignment NAME"):
        find_class(course, workspace)
    intake = find_untouched(tmp_path, course, workspace, assignment="lab9")
    assert [(s.name, s.path) for s in intake.students] == [
        ("alice", course / "submitted" / "alice" / "lab9"),
        ("carol", course / "submitted" / "carol" / "lab9"),
    ]
    assert any("bob" in n and "lab9" in n for n in intake.notes)
    with pytest.raises(ValueError, match="lab10.*lab8, lab9"):
        find_class(course, workspace, assignment="lab10")


def test_nbgrader_zip_keeps_timestamp(tmp_path, workspace):
    course = tmp_path / "course"
    folder = course / "submitted" / "alice" / "lab8"
    folder.mkdir(parents=True)
    (folder / "timestamp.txt").write_text("2026-12-01 23:59:59 UTC")
    (folder / "lab8.zip").write_bytes(zip_bytes({"lab8.ipynb": notebook_text()}))
    [alice] = find_untouched(tmp_path, course, workspace).students
    assert (Path(alice.path) / "timestamp.txt").read_text() == "2026-12-01 23:59:59 UTC"
    assert [p.name for p in notebooks_of(alice)] == ["lab8.ipynb"]


# ------------------------------------------------------------------------------------------- Canvas


def canvas_download(folder):
    folder.mkdir(parents=True)
    (folder / "lovelaceada_1815_98765_02_convergence.ipynb").write_text(notebook_text("first upload"))
    (folder / "lovelaceada_1815_98770_02_convergence-1.ipynb").write_text(notebook_text("second upload"))
    (folder / "lovelaceada_1815_98771_02_convergence-2.ipynb").write_text(notebook_text("newest upload"))
    (folder / "hoppergrace_LATE_1906_98766_03_meshes.ipynb").write_text(notebook_text("grace"))
    (folder / "turingalan_1912_98767_work.zip").write_bytes(
        zip_bytes({"work/02_convergence.ipynb": notebook_text("alan"), "__MACOSX/._x": b"junk"})
    )
    (folder / "noetheremmy_1882_98768_notes.pdf").write_bytes(b"%PDF")
    (folder / "knuthdon_1938_98769_evil.zip").write_bytes(zip_bytes({"../../evil.ipynb": notebook_text()}))
    (folder / "anon_Ab3dE_98772_04_splines.ipynb").write_text(notebook_text("anonymous"))
    (folder / "README.txt").write_text("not a submission")
    return folder


def check_canvas(intake, workspace):
    assert intake.layout == "canvas"
    assert [s.name for s in intake.students] == [
        "anon_Ab3dE",
        "hoppergrace",
        "knuthdon",
        "lovelaceada",
        "noetheremmy",
        "turingalan",
    ]
    students = by_name(intake)
    assert all(s.layout == "canvas" for s in intake.students)
    assert {s.name: s.lms_id for s in intake.students} == {
        "anon_Ab3dE": "Ab3dE",
        "hoppergrace": "1906",
        "knuthdon": "1938",
        "lovelaceada": "1815",
        "noetheremmy": "1882",
        "turingalan": "1912",
    }
    assert [s.name for s in intake.students if s.marked_late] == ["hoppergrace"]
    [ada] = notebooks_of(students["lovelaceada"])
    assert ada.name == "02_convergence.ipynb" and "newest upload" in ada.read_text()
    assert any("lovelaceada" in n and "newest" in n and "02_convergence-1.ipynb" in n for n in intake.notes)
    [grace] = notebooks_of(students["hoppergrace"])
    assert grace.name == "03_meshes.ipynb"
    [alan] = notebooks_of(students["turingalan"])
    assert alan.relative_to(students["turingalan"].path).as_posix() == "work/work/02_convergence.ipynb"
    assert "alan" in alan.read_text()
    assert students["noetheremmy"].failure == "holds no notebook (it holds notes.pdf)"
    knuth = students["knuthdon"]
    assert knuth.path is None and "'../../evil.ipynb' leaves the folder" in knuth.failure
    assert any("README.txt" in n for n in intake.notes)
    for student in intake.gradable:
        assert Path(student.path).resolve().is_relative_to(workspace.resolve())
    assert not list(workspace.parent.rglob("evil.ipynb"))


def test_canvas_flat_folder(tmp_path, workspace):
    folder = canvas_download(tmp_path / "class")
    check_canvas(find_untouched(tmp_path, folder, workspace), workspace)


def test_canvas_as_one_zip(tmp_path, workspace):
    folder = canvas_download(tmp_path / "download")
    archive = tmp_path / "class" / "submissions.zip"
    archive.parent.mkdir()
    with zipfile.ZipFile(archive, "w") as z:
        for path in sorted(folder.iterdir()):
            z.write(path, path.name)
    intake = find_untouched(tmp_path, archive, workspace)
    check_canvas(intake, workspace)
    assert any("submissions.zip" in n and "unpacked" in n for n in intake.notes)


def test_canvas_namesakes_are_told_apart_by_their_user_id(tmp_path, workspace):
    folder = tmp_path / "class"
    write_notebook(folder / "smithjohn_101_1_a.ipynb")
    write_notebook(folder / "smithjohn_202_2_a.ipynb")
    write_notebook(folder / "doejane_303_3_a.ipynb")
    intake = find_class(folder, workspace)
    assert [(s.name, s.lms_id) for s in intake.students] == [
        ("doejane", "303"),
        ("smithjohn_101", "101"),
        ("smithjohn_202", "202"),
    ]
    assert any("names several Canvas students" in note for note in intake.notes)


def test_a_class_is_told_from_one_students_folder(tmp_path):
    from labkit.grading.lms.intake import is_class

    write_notebook(tmp_path / "class" / "alice" / "a.ipynb")
    write_notebook(tmp_path / "canvas" / "smithjohn_101_1_a.ipynb")
    (tmp_path / "class.zip").write_bytes(b"PK")
    assert is_class(tmp_path / "class") and is_class(tmp_path / "canvas") and is_class(tmp_path / "class.zip")
    assert not is_class(tmp_path / "class" / "alice") and not is_class(tmp_path / "class" / "alice" / "a.ipynb")


def test_numbered_files_without_their_plain_name_are_all_kept_as_named(tmp_path, workspace):
    folder = tmp_path / "class"
    write_notebook(folder / "lovelaceada_1815_98770_02_convergence-1.ipynb")
    write_notebook(folder / "lovelaceada_1815_98771_part-1.ipynb")  # two notebooks, not two uploads of one
    write_notebook(folder / "lovelaceada_1815_98772_part-2.ipynb")
    write_notebook(folder / "lovelaceada_1815_98770_lab-2024.ipynb")
    [ada] = find_untouched(tmp_path, folder, workspace).students
    assert [p.name for p in notebooks_of(ada)] == [
        "02_convergence-1.ipynb",
        "lab-2024.ipynb",
        "part-1.ipynb",
        "part-2.ipynb",
    ]


def test_a_folder_with_notebooks_of_its_own_and_folders_of_notebooks_is_refused(tmp_path):
    from labkit.grading.lms.intake import is_class

    write_notebook(tmp_path / "mixed" / "alice" / "a.ipynb")
    write_notebook(tmp_path / "mixed" / "dave.ipynb")
    with pytest.raises(ValueError, match="could be a class or one student's work"):
        is_class(tmp_path / "mixed")


# ------------------------------------------------------------------------------------------- Moodle


def test_moodle_folders(tmp_path, workspace):
    cls = tmp_path / "class"
    write_notebook(cls / "Ada Lovelace_12345_assignsubmission_file_" / "02_convergence.ipynb", "ada one")
    (cls / "Ada Lovelace_12345_assignsubmission_onlinetext_").mkdir()
    (cls / "Ada Lovelace_12345_assignsubmission_onlinetext_" / "onlinetext.html").write_text("<p>hi</p>")
    write_notebook(cls / "Ada Lovelace_12399_assignsubmission_file_" / "02_convergence.ipynb", "ada two")
    (cls / "Grace Hopper_23456_assignsubmission_file_").mkdir()
    (cls / "Grace Hopper_23456_assignsubmission_file_" / "work.zip").write_bytes(
        zip_bytes({"02_convergence.ipynb": notebook_text("grace")})
    )
    (cls / "Alan Turing_34567_assignsubmission_file_").mkdir()
    (cls / "Alan Turing_34567_assignsubmission_file_" / "notes.pdf").write_bytes(b"%PDF")
    intake = find_untouched(tmp_path, cls, workspace)
    assert intake.layout == "moodle"
    assert [(s.name, s.lms_id) for s in intake.students] == [
        ("Ada Lovelace_12345", "12345"),
        ("Ada Lovelace_12399", "12399"),
        ("Alan Turing_34567", "34567"),
        ("Grace Hopper_23456", "23456"),
    ]
    students = by_name(intake)
    assert "ada one" in notebooks_of(students["Ada Lovelace_12345"])[0].read_text()
    assert "ada two" in notebooks_of(students["Ada Lovelace_12399"])[0].read_text()
    assert students["Ada Lovelace_12399"].path == cls / "Ada Lovelace_12399_assignsubmission_file_"
    grace = students["Grace Hopper_23456"]
    assert Path(grace.path).resolve().is_relative_to(workspace.resolve())
    assert "grace" in notebooks_of(grace)[0].read_text()
    assert students["Alan Turing_34567"].failure == "holds no notebook (it holds notes.pdf)"
    assert all(s.layout == "moodle" and not s.marked_late for s in intake.students)


def test_moodle_flat_and_as_a_zip(tmp_path, workspace):
    archive = tmp_path / "moodle.zip"
    archive.write_bytes(
        zip_bytes(
            {
                "Ada Lovelace_12345_assignsubmission_file_02_convergence.ipynb": notebook_text("ada"),
                "Ada Lovelace_12345_assignsubmission_onlinetext_onlinetext.html": "<p/>",
                "Alan Turing_34567_assignsubmission_file_notes.pdf": b"%PDF",
            }
        )
    )
    intake = find_untouched(tmp_path, archive, workspace)
    assert intake.layout == "moodle"
    ada, alan = intake.students
    assert (ada.name, ada.lms_id) == ("Ada Lovelace_12345", "12345")
    assert [p.name for p in notebooks_of(ada)] == ["02_convergence.ipynb"]
    assert alan.failure == "holds no notebook (it holds notes.pdf)"


def test_a_class_zip_of_a_zipped_folder(tmp_path, workspace):
    archive = tmp_path / "class.zip"
    archive.write_bytes(
        zip_bytes({"class/alice/a.ipynb": notebook_text(), "class/bob/work.zip": zip_bytes({"b.ipynb": "{}"})})
    )
    intake = find_untouched(tmp_path, archive, workspace)
    assert intake.layout == "folders" and [s.name for s in intake.students] == ["alice", "bob"]
    assert [p.name for p in notebooks_of(intake.students[1])] == ["b.ipynb"]


# ------------------------------------------------------------------------------------------- zip safety


@pytest.mark.parametrize(
    "member, rule",
    [
        ("../evil.ipynb", "leaves the folder"),
        ("a/../../evil.ipynb", "leaves the folder"),
        ("..\\evil.ipynb", "leaves the folder"),
        ("/etc/x", "absolute path"),
        ("C:/x.ipynb", "absolute path"),
    ],
)
def test_zip_slip(tmp_path, member, rule):
    archive = tmp_path / "work.zip"
    archive.write_bytes(zip_bytes({"fine.ipynb": "{}", member: "{}"}))
    before = snapshot(tmp_path)
    with pytest.raises(ValueError, match=f"work.zip: member .* {rule}; labkit never extracts it"):
        unpack(archive, tmp_path / "out")
    assert snapshot(tmp_path) == before  # the partial extraction is removed too


def test_symlink_and_device_members(tmp_path):
    for mode, rule in ((stat.S_IFLNK | 0o777, "symbolic link"), (stat.S_IFCHR | 0o600, "device")):
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w") as z:
            info = zipfile.ZipInfo("link.ipynb")
            info.create_system = 3
            info.external_attr = mode << 16
            z.writestr(info, "/etc/passwd")
        (tmp_path / "work.zip").write_bytes(buffer.getvalue())
        with pytest.raises(ValueError, match=f"work.zip: member 'link.ipynb' is a {rule}"):
            unpack(tmp_path / "work.zip", tmp_path / "out")
        assert not os.path.lexists(tmp_path / "out")


@pytest.fixture(scope="module")
def bomb(tmp_path_factory):
    """A zip of one 200 MiB member of zeros (about 200 KiB), written streamed."""
    path = tmp_path_factory.mktemp("bomb") / "bomb.zip"
    chunk = bytes(MiB)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z, z.open("zeros.ipynb", "w") as member:
        for _ in range(200):
            member.write(chunk)
    return path


def lying(bomb, into):
    """The bomb with its sizes declared as 1000 bytes, in the local header and the central directory."""
    data = bytearray(bomb.read_bytes())
    local = data.index(b"PK\x03\x04")
    central = data.index(b"PK\x01\x02")
    data[local + 22 : local + 26] = (1000).to_bytes(4, "little")
    data[central + 24 : central + 28] = (1000).to_bytes(4, "little")
    into.write_bytes(bytes(data))
    with zipfile.ZipFile(into) as z:
        assert z.getinfo("zeros.ipynb").file_size == 1000
    return into


def test_a_zip_bomb_with_honest_sizes_is_refused_before_extracting(tmp_path, bomb):
    assert bomb.stat().st_size < 2 * MiB
    with pytest.raises(ValueError, match="bomb.zip: member 'zeros.ipynb' is larger than 64 MiB"):
        unpack(bomb, tmp_path / "out")
    assert not os.path.lexists(tmp_path / "out")


@pytest.mark.parametrize(
    "limits, rule",
    [
        (UnpackLimits(), "is compressed more than 100 times"),
        (UnpackLimits(max_ratio=1e9), "grows past 64 MiB while extracting"),
        (UnpackLimits(max_ratio=1e9, max_total=8 * MiB), "more than 8 MiB uncompressed while extracting"),
    ],
)
def test_a_zip_bomb_that_lies_trips_while_extracting(tmp_path, bomb, limits, rule):
    archive = lying(bomb, tmp_path / "bomb.zip")
    match = rule if rule.startswith("more than") else f"member 'zeros.ipynb' {rule}"
    with pytest.raises(ValueError, match=f"bomb.zip: {match}"):
        unpack(archive, tmp_path / "out", limits)
    assert not os.path.lexists(tmp_path / "out")  # the partial file is removed


def test_nothing_larger_than_the_limit_lands_on_disk(tmp_path, bomb, monkeypatch):
    """Watch the file while it is written: it never grows past the member limit."""
    archive = lying(bomb, tmp_path / "bomb.zip")
    limits = UnpackLimits(max_ratio=1e9, max_member=4 * MiB)
    target = tmp_path / "out" / "zeros.ipynb"
    largest = []
    real_fdopen = os.fdopen

    def watched(*args, **kwargs):
        handle = real_fdopen(*args, **kwargs)
        real = handle.write

        def write(data):
            count = real(data)
            handle.flush()
            largest.append(os.lstat(target).st_size)
            return count

        handle.write = write
        return handle

    monkeypatch.setattr(os, "fdopen", watched)
    with pytest.raises(ValueError, match="grows past 4 MiB while extracting"):
        unpack(archive, tmp_path / "out", limits)
    assert largest and max(largest) <= 4 * MiB
    assert not os.path.lexists(tmp_path / "out")


def test_too_many_members(tmp_path):
    archive = tmp_path / "many.zip"
    archive.write_bytes(zip_bytes({f"f{i}.txt": "x" for i in range(30)}))
    with pytest.raises(ValueError, match="many.zip: more than 10 members"):
        unpack(archive, tmp_path / "out", UnpackLimits(max_members=10))
    assert len(unpack(archive, tmp_path / "out")) == 30


def test_nested_zips_to_max_depth(tmp_path):
    inner = zip_bytes({"x.ipynb": notebook_text()})
    for name in ("d", "c", "b"):
        inner = zip_bytes({f"{name}.zip": inner})
    archive = tmp_path / "a.zip"
    archive.write_bytes(inner)  # a.zip > b.zip > c.zip > d.zip > x.ipynb
    with pytest.raises(ValueError, match="a.zip/b.zip/c.zip: member 'd.zip' is a zip nested more than 2 deep"):
        unpack(archive, tmp_path / "out")
    assert not os.path.lexists(tmp_path / "out")
    files = unpack(archive, tmp_path / "out", UnpackLimits(max_depth=3))
    assert [p.relative_to(tmp_path / "out").as_posix() for p in files] == ["b/c/d/x.ipynb"]
    # the members of the nested zips count towards the same budget
    with pytest.raises(ValueError, match="more than 3 members"):
        unpack(archive, tmp_path / "out2", UnpackLimits(max_depth=3, max_members=3))


def test_a_class_zip_counts_as_one_level(tmp_path, workspace):
    student = zip_bytes({"work.zip": zip_bytes({"x.ipynb": notebook_text()})})  # a zip in the student's zip
    archive = tmp_path / "class.zip"
    archive.write_bytes(zip_bytes({"lovelaceada_1815_1_work.zip": student, "hoppergrace_1906_2_a.ipynb": "{}"}))
    ada, grace = find_untouched(tmp_path, archive, workspace, limits=UnpackLimits(max_depth=1)).students[::-1]
    assert grace.failure is None
    assert ada.path is None and "nested more than 1 deep" in ada.failure
    ada = by_name(find_class(archive, tmp_path / "ws2"))["lovelaceada"]
    assert [p.name for p in notebooks_of(ada)] == ["x.ipynb"]


def test_names_that_are_not_utf8(tmp_path):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as z:
        z.writestr("cafX.ipynb", "{}")
    data = buffer.getvalue().replace(b"cafX", b"caf\x82")  # cp437's e acute, no UTF-8 flag
    (tmp_path / "old.zip").write_bytes(data)
    [path] = unpack(tmp_path / "old.zip", tmp_path / "out")
    assert path.name == "caf\u00e9.ipynb" and path.read_text() == "{}"
    flagged = bytearray(data)
    for signature, offset in ((b"PK\x03\x04", 7), (b"PK\x01\x02", 9)):
        at = flagged.index(signature) + offset
        flagged[at] |= 0x08  # bit 11 of the flags: "the name is UTF-8", which it is not
    (tmp_path / "bad.zip").write_bytes(bytes(flagged))
    with pytest.raises(ValueError, match="bad.zip: not a zip labkit can read"):
        unpack(tmp_path / "bad.zip", tmp_path / "out2")


def test_damaged_and_duplicate(tmp_path):
    (tmp_path / "junk.zip").write_bytes(b"PK\x03\x04 not really")
    with pytest.raises(ValueError, match="junk.zip: not a zip labkit can read"):
        unpack(tmp_path / "junk.zip", tmp_path / "out")
    buffer = io.BytesIO()
    with pytest.warns(UserWarning), zipfile.ZipFile(buffer, "w") as z:
        z.writestr("a.ipynb", "{}")
        z.writestr("a.ipynb", "{}")
    (tmp_path / "twice.zip").write_bytes(buffer.getvalue())
    with pytest.raises(ValueError, match="twice.zip: member 'a.ipynb' appears twice"):
        unpack(tmp_path / "twice.zip", tmp_path / "out")


NAME_PARTS = st.sampled_from(["a", "b.ipynb", "..", ".", "", "C:", "\\", "~", "__MACOSX", "é", "/"])


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(names=st.lists(st.lists(NAME_PARTS, min_size=1, max_size=5).map("/".join), min_size=1, max_size=4))
def test_any_member_names_stay_inside(tmp_path, names):
    root = Path(tempfile.mkdtemp(dir=tmp_path))
    archive = root / "work.zip"
    buffer = io.BytesIO()
    with warnings.catch_warnings(), zipfile.ZipFile(buffer, "w") as z:
        warnings.simplefilter("ignore", UserWarning)  # a name twice: unpack refuses it
        for i, name in enumerate(names):
            z.writestr(zipfile.ZipInfo(name or "x"), str(i))
    archive.write_bytes(buffer.getvalue())
    outside = snapshot(root)
    try:
        files = unpack(archive, root / "deep" / "out")
    except ValueError as exc:
        assert "work.zip" in str(exc)
        assert snapshot(root) == outside
        return
    for path in files:
        assert path.resolve().is_relative_to((root / "deep" / "out").resolve())
    assert {k for k in snapshot(root) if not k.startswith("deep")} == set(outside)
