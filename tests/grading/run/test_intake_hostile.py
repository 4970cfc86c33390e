"""One student's upload never stops the class, and nobody's file lands in a classmate's folder: the hostile
uploads of issue 44, in a Canvas zip, a Canvas folder and a Moodle folder, each with honest classmates."""

import time
import zipfile
from pathlib import Path

import pytest
from test_intake import notebook_text, zip_bytes

from labkit.grading.lms.canvas import canvas_readings, resolve_canvas
from labkit.grading.lms.intake import UnpackLimits, find_class

HONEST = {"alice": "1001", "bob": "1002"}
LONG = "l" * 240 + ".ipynb"


def honest_files():
    return {
        "alice_1001_55_02_convergence.ipynb": notebook_text("alice's own work"),
        "alice_1001_56_06_bilinear.ipynb": notebook_text("alice's bilinear"),
        "bob_1002_57_06_bilinear.ipynb": notebook_text("bob's own work"),
    }


def hostile_files():
    """{file name: content} of the hostile students, one case each (Canvas's names)."""
    files = {
        "sam_2001_60_spaces.txt": " " * (3 << 20),  # compresses more than 100 times
        "sam_2001_61_06_bilinear.ipynb": notebook_text("sam"),
        f"lena_2002_62_{LONG}": notebook_text("lena's long name"),
        "mo_2003_63_notes_12_assignsubmission_file_x.ipynb": notebook_text("mo"),
        "alice_1001_9_00_2005_70_06_bilinear.ipynb": notebook_text("impostor"),  # names herself alice_1001_9_00
        "alice_2006_71_06_bilinear.ipynb": notebook_text("namesake"),  # renamed herself Alice
    }
    files.update({f"many_2004_{5000 + i}_f{i}.txt": b"x" for i in range(2001)})  # over 2000 members
    files.update({f"few_2007_{8000 + i}_f{i}.txt": b"x" for i in range(1999)})  # under: graded
    files["few_2007_9999_06_bilinear.ipynb"] = notebook_text("few")
    return files


def check_honest(intake):
    students = {s.lms_id: s for s in intake.students}
    for login, uid in HONEST.items():
        student = students[uid]
        assert student.failure is None, student.failure
        texts = sorted(path.read_text() for path in Path(student.path).rglob("*.ipynb"))
        assert all(f"{login}'s" in text for text in texts) and texts, texts
        assert not any("impostor" in text or "namesake" in text for text in texts)


def check_hostile(intake):
    students = {s.lms_id: s for s in intake.students}
    assert "zip bomb" in students["2001"].failure and "Only this student is left out" in students["2001"].failure
    assert "more than 2000 members" in students["2004"].failure
    assert students["2007"].failure is None  # 1999 files and a notebook: within one student's limit
    lena = list(Path(students["2002"].path).rglob("*.ipynb"))
    assert len(lena) == 1 and "lena's long name" in lena[0].read_text()
    assert students["2003"].failure is None and students["2003"].name == "mo"
    assert "2005" not in students  # the impostor's file is filed to no one
    assert any("alice_1001_9_00_2005_70" in n and "filed to no one" in n for n in intake.notes)
    namesake = students["2006"]
    assert namesake.failure is None and namesake.name != students["1001"].name


def test_a_hostile_canvas_zip_refuses_only_its_students(tmp_path):
    (tmp_path / "submissions.zip").write_bytes(zip_bytes(honest_files() | hostile_files()))
    intake = find_class(tmp_path / "submissions.zip", tmp_path / "work")
    assert intake.layout == "canvas"
    check_honest(intake)
    check_hostile(intake)


def test_a_hostile_canvas_folder_refuses_only_its_students(tmp_path):
    folder = tmp_path / "download"
    folder.mkdir()
    for name, content in (honest_files() | hostile_files()).items():
        if len(name.encode()) <= 255:  # (a file system takes no longer name; the zip above holds it)
            (folder / name).write_bytes(content.encode() if isinstance(content, str) else content)
    # three zips of 1700 tiny files each: every zip is within the limits, the student is not
    for letter in "abc":
        (folder / f"zed_2008_{ord(letter)}_{letter}.zip").write_bytes(
            zip_bytes({f"{letter}{i}.txt": b"y" for i in range(1700)} | {f"{letter}.ipynb": notebook_text()})
        )
    intake = find_class(folder, tmp_path / "work")
    check_honest(intake)
    students = {s.lms_id: s for s in intake.students}
    assert "more than 2000 members" in students["2008"].failure
    assert "2005" not in students and students["2006"].failure is None
    assert "holds no notebook" in students["2004"].failure  # loose files other than notebooks are not copied


def test_one_budget_across_all_of_a_students_zips(tmp_path):
    """Three zips of 3 MiB each, within a 4 MiB limit one by one, not together: the student is refused having
    written at most the limit, and a classmate is unpacked."""
    folder = tmp_path / "download"
    folder.mkdir()
    block = bytes(range(256)) * 4096  # 1 MiB that does not compress
    for letter in "abc":
        (folder / f"zed_2008_{ord(letter)}_{letter}.zip").write_bytes(
            zip_bytes({f"{letter}{i}.bin": block for i in range(3)} | {f"{letter}.ipynb": notebook_text()})
        )
    (folder / "bob_1002_57_06_bilinear.ipynb").write_text(notebook_text("bob's own work"))
    limits = UnpackLimits(max_total=4 << 20)
    intake = find_class(folder, tmp_path / "work", limits=limits)
    zed, bob = sorted(intake.students, key=lambda s: s.name, reverse=True)
    assert "more than 4 MiB" in zed.failure and bob.failure is None
    written = sum(p.stat().st_size for p in (tmp_path / "work").rglob("*") if p.is_file())
    assert written < (4 << 20) + 100_000


def test_a_moodle_folder_with_hostile_names(tmp_path):
    folder = tmp_path / "moodle"
    ada = folder / "Ada Lovelace_11_assignsubmission_file_"
    ada.mkdir(parents=True)
    (ada / "06_bilinear.ipynb").write_text(notebook_text("ada's own work"))
    # a student whose file names itself as Ada's participant id
    (folder / "Eve Evans_12_assignsubmission_file_Ada Lovelace_11_assignsubmission_file_x.ipynb").write_text(
        notebook_text("impostor")
    )
    (folder / "Max Many_13_assignsubmission_file_").mkdir()
    for i in range(5001):
        (folder / "Max Many_13_assignsubmission_file_" / f"f{i}.txt").write_bytes(b"x")
    (folder / f"Lena Long_14_assignsubmission_file_{'l' * 200}.ipynb").write_text(notebook_text("lena"))
    intake = find_class(folder, tmp_path / "work")
    students = {s.lms_id: s for s in intake.students}
    assert intake.layout == "moodle"
    [work] = Path(students["11"].path).rglob("*.ipynb")
    assert "ada's own work" in work.read_text()
    assert "impostor" in next(Path(students["12"].path).rglob("*.ipynb")).read_text()
    assert "more than 5000 files" in students["13"].failure
    assert students["14"].failure is None


def test_the_roster_id_decides_never_the_display_name(tmp_path):
    (tmp_path / "submissions.zip").write_bytes(zip_bytes(honest_files() | hostile_files()))
    roster = {"alice": "1001", "bob": "1002", "mallory": "2006", "imp": "2005"}
    intake = find_class(tmp_path / "submissions.zip", tmp_path / "work", roster=roster)
    students = {s.lms_id: s for s in intake.students}
    assert students["1001"].name == "alice" and students["2006"].name == "mallory"
    check_honest(intake)
    assert all(s.name not in roster for s in intake.students if s.lms_id not in roster.values())


@pytest.mark.parametrize(
    "name, uids",
    [
        ("ada_1001_9_lab.ipynb", ["1001"]),
        ("ada_LATE_1001_98765_02_convergence.ipynb", ["1001"]),  # a display name starting 02_ is no id
        ("ada_1001_9_00_2002_77_x.ipynb", ["1001", "2002"]),
        ("Ada_1001_9_x.ipynb", []),  # Canvas lower-cases the name
        ("ada lovelace_1001_9_x.ipynb", []),  # and keeps only word characters
        ("LATE_anon_Ab3dE_77_x.ipynb", ["Ab3dE"]),
    ],
)
def test_canvas_readings(name, uids):
    assert [r.uid for r in canvas_readings(name)] == uids


def test_a_reading_another_file_of_the_user_contradicts_is_ruled_out():
    names = ["ada_1001_5_a.ipynb", "ada_1001_6_hw_7_8_b.ipynb", "ada_1001_6_hw_7_9_c.ipynb"]
    chosen, notes = resolve_canvas(names + ["bo_7_1_z.ipynb"])  # user 7 is "bo": ada_1001_6_hw cannot be user 7
    assert {chosen[n].uid for n in names} == {"1001"}
    assert len(notes) == 2 and all("filed under user 1001" in n for n in notes)


def test_a_class_of_1000_students_comes_in_from_one_zip(tmp_path):
    """1000 generated students with six small notebooks each: one zip's intake, nobody refused (the time is
    printed, never asserted: see benchmarks/)."""
    notebook = notebook_text()
    with zipfile.ZipFile(tmp_path / "class.zip", "w", zipfile.ZIP_DEFLATED) as archive:
        for student in range(1000):
            for number in range(1, 7):
                name = f"student{student}_{10_000 + student}_{100_000 + 6 * student + number}_0{number}_lab.ipynb"
                archive.writestr(name, notebook)
    start = time.perf_counter()
    intake = find_class(tmp_path / "class.zip", tmp_path / "work")
    seconds = time.perf_counter() - start
    print(f"intake of 1000 students x 6 notebooks: {seconds:.1f} s")
    assert len(intake.students) == 1000 and not [s for s in intake.students if s.failure]
    assert all(len(list(Path(s.path).glob("*.ipynb"))) == 6 for s in intake.students)


def test_too_little_space_names_the_largest_students(tmp_path, monkeypatch):
    import shutil
    from collections import namedtuple

    files = {f"big_3001_{i}_b{i}.bin": bytes(range(256)) * 4096 for i in range(1, 4)} | honest_files()
    (tmp_path / "class.zip").write_bytes(zip_bytes(files))
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(1 << 40, 0, 258 << 20))  # 2 MiB over the spare
    with pytest.raises(
        ValueError, match=r"the largest students are Canvas user 3001 \(3 MiB\), Canvas user 1001"
    ) as refused:
        find_class(tmp_path / "class.zip", tmp_path / "work")
    assert "Free some space" in str(refused.value)
    assert not [p for p in (tmp_path / "work").rglob("*") if p.is_file()]  # nothing was unpacked


def test_a_zipped_canvas_folder_and_members_that_leave_it(tmp_path):
    members = {f"download/{name}": data for name, data in honest_files().items()}
    members["../evil.ipynb"] = notebook_text("evil")
    (tmp_path / "canvas.zip").write_bytes(zip_bytes(members))
    intake = find_class(tmp_path / "canvas.zip", tmp_path / "work")
    assert intake.layout == "canvas" and {s.lms_id for s in intake.gradable} == {"1001", "1002"}
    folders = {
        "class/alice/06_bilinear.ipynb": notebook_text("alice's own work"),
        "class/bob/../../evil.ipynb": notebook_text("evil"),  # bob's member leaves his folder: bob's refusal only
        "class/carol/" + "c" * 256 + ".ipynb": notebook_text("carol"),  # too long a name inside her folder
    }
    (tmp_path / "folders.zip").write_bytes(zip_bytes(folders))
    students = {s.name: s for s in find_class(tmp_path / "folders.zip", tmp_path / "work2").students}
    assert students["alice"].failure is None and "leaves the folder" in students["bob"].failure
    assert "longer than 255 bytes" in students["carol"].failure and "rename it" in students["carol"].failure
    assert not list(tmp_path.rglob("evil.ipynb"))
