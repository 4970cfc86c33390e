"""The class as the LMS hands it over: one folder or one zip becomes a list of students.

Only the grader's `workspace` is written, no link is followed, and a student's name is data, never a path. A class
zip is sorted out by student before anything is written, each student on their own budget: a member that breaks a
rule leaves its student ungraded, never the class.
"""

from __future__ import annotations

import os
import shutil
import stat
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path

from ...errors import InputError
from ..store.report import one_line, safe_name
from . import systems, unzip
from .unzip import LIMITS, Budget, UnpackLimits, as_text, free, size_text

MAX_FILES = 5_000  # entries looked at in one folder walk (as scoring's walk of a submission)
MAX_DEPTH = 8  # folder levels looked into
SPARE = 256 << 20  # bytes the class zip leaves free where it is unpacked
LONG_TOP = 200  # bytes of a class zip's top-level name beyond which it is written under a short name
IGNORED = {"__MACOSX", ".ipynb_checkpoints", "__pycache__", "Thumbs.db", "desktop.ini"}
SHOWN = 4  # file names listed in a "holds no notebook" failure
FIX = (
    "Only this student is left out: ask them for their notebooks as plain .ipynb files (or an ordinary zip of "
    "them), grade those alone and combine the runs with `labkit merge`."
)


@dataclass(frozen=True)
class Student:
    """One student: the submission's `name`, the `path` to grade or None and the `failure` why not, the `layout`
    (the LMS's name, or ``listed``), the LMS's id, its late mark, and how it names the student's files."""

    name: str
    path: Path | None
    failure: str | None
    layout: str
    lms_id: str | None = None
    marked_late: bool = False
    lms_file: str | None = None


@dataclass
class Intake:
    """The students found in what the LMS gave, in name order, the layout, and notes for the instructor."""

    students: list[Student]
    layout: str
    notes: list[str] = field(default_factory=list)

    @property
    def gradable(self) -> list[Student]:
        return [s for s in self.students if s.path is not None]


def entries(folder):
    """The entries of `folder` worth looking at, in name order; links never followed."""
    try:
        with os.scandir(folder) as found:
            return sorted((e for e in found if not (e.name.startswith(".") or e.name in IGNORED)), key=lambda e: e.name)
    except OSError:
        return []


def walk(folder, notes=None):
    """The regular files under `folder` (no links, no hidden files), bounded in files and depth."""
    found, todo, seen = [], [(Path(folder), 0)], 0
    while todo:
        current, depth = todo.pop()
        for entry in entries(current):
            seen += 1
            if seen > MAX_FILES:
                raise InputError(f"{_shown(folder)} holds more than {MAX_FILES} files; a submission is a few.")
            if entry.is_symlink() and notes is not None:  # (a link is neither a folder nor a file below)
                notes.append(f"ignored {one_line(as_text(entry.path))}: a link (links are never followed)")
            elif entry.is_dir(follow_symlinks=False) and depth < MAX_DEPTH:
                todo.append((Path(entry.path), depth + 1))
            elif entry.is_file(follow_symlinks=False):
                found.append(Path(entry.path))
    return sorted(found)


def safe_part(original):
    """An original file name from an LMS as one file name to create: its own, unless it could not be one."""
    text = original.replace("/", "_").replace("\\", "_").replace("\x00", "_")
    if not text or text.startswith(".") or len(text.encode("utf-8", "surrogateescape")) > 200:
        _, dot, ext = text.rpartition(".")
        return safe_name(text) + (f".{ext}" if dot and ext.isalnum() and len(ext) <= 10 else "")
    return text


def _no_notebook(names):
    names = sorted({one_line(n, 80) for n in names})
    if not names:
        return "holds no notebook (it is empty)"
    more = f" and {len(names) - SHOWN} more" if len(names) > SHOWN else ""
    return f"holds no notebook (it holds {', '.join(names[:SHOWN])}{more})"


class Builder:
    """Turns one student's files (a folder, loose files, zips) into a Student, writing only in the workspace;
    an LMS's ``students`` reads its download with it, and tells the instructor in ``notes``."""

    def __init__(self, workspace, limits, notes, zip_depth, roster_ids=()):
        self.workspace = workspace
        self.limits = limits
        self.notes = notes
        self.zip_depth = zip_depth  # 1 when the class came as a zip: a student's zip is one level in
        self.budgets: dict = {}  # a student's key -> the Budget all their zips share (the class zip's included)
        self.refused: dict = {}  # a student's key -> why the class zip's members of theirs were not extracted
        self.aliases: dict = {}  # a name written in the workspace -> the class zip's own (too long to write)
        self.roster_ids = roster_ids  # the roster's ids, which settle whose a file is when its name reads two ways

    def budget(self, key):
        """The budget of the student `key` (fresh for one seen first): every limit is per student, in total."""
        return self.budgets.setdefault(key, Budget(self.limits))

    def name(self, entry):
        """An entry's name as the LMS gave it."""
        return self.aliases.get(entry.name) or as_text(entry.name)

    def on_disk(self, name):
        """The name a class zip's top-level `name` is written under."""
        return next((alias for alias, given in self.aliases.items() if given == name), name)

    def refusal(self, student, key):
        """`student` as one who could not be graded when the class zip's members of theirs were refused, or None."""
        why = self.refused.get(key)
        return None if why is None else replace(student, path=None, failure=why)

    def from_folder(self, name, folder, layout, lms_id=None, late=False, keep=(), key=None):
        """A student whose work is the folder `folder` (read only): graded in place unless it holds zips."""
        who, key = Student(name, None, None, layout, lms_id, late), key or (layout, name)
        if refused := self.refusal(who, key):
            return refused
        try:
            files = walk(folder, self.notes)
        except ValueError as exc:
            return replace(who, failure=f"{exc} {FIX}")
        pieces = [(f.relative_to(folder), f) for f in files]
        if any(f.suffix.lower() == ".zip" for f in files):
            return self._assemble(who, key, pieces, [r.as_posix() for r, _ in pieces], keep)
        if not any(f.suffix == ".ipynb" for f in files):
            return replace(who, failure=_no_notebook(as_text(r.as_posix()) for r, _ in pieces))
        return replace(who, path=Path(folder))

    def from_files(self, name, pieces, layout, lms_id=None, late=False, key=None):
        """A student given as loose files: `pieces` pairs the name to give each with its path."""
        who, key = Student(name, None, None, layout, lms_id, late), key or (layout, name)
        shown = [as_text(relative.as_posix()) for relative, _ in pieces]
        return self.refusal(who, key) or self._assemble(who, key, pieces, shown)

    def _assemble(self, who, key, given, shown, keep=()):
        """`who` with their notebooks (and files named in `keep`) copied and their zips unpacked in the workspace."""
        zips = [(relative, path) for relative, path in given if path.suffix.lower() == ".zip"]
        pieces = [(relative, path) for relative, path in given if path.suffix == ".ipynb" or path.name in keep]
        if not pieces and not zips:
            return replace(who, failure=_no_notebook(shown))
        target = free(self.workspace / "students" / safe_name(who.name))
        target.mkdir(parents=True)
        try:
            self._fill(who.name, target, pieces, zips, key)
            failure = None if any(f.suffix == ".ipynb" for f in walk(target)) else _no_notebook(shown)
        except (ValueError, OSError) as exc:
            failure = f"{one_line(as_text(str(exc)), 400)} {FIX}"
        if failure is not None:
            shutil.rmtree(target, ignore_errors=True)
            return replace(who, failure=failure)
        return replace(who, path=target)

    def _fill(self, name, target, pieces, zips, key):
        """Copy the student's notebooks into `target` and unpack their zips there, all on the student's budget."""
        budget, limits = self.budget(key), self.limits
        for relative, path in pieces:
            destination = free(target / relative)
            destination.parent.mkdir(parents=True, exist_ok=True)
            size = os.lstat(path).st_size
            shown = one_line(as_text(str(relative)))
            if size > limits.max_member:
                raise InputError(f"{shown} is larger than {size_text(limits.max_member)}; labkit does not copy it.")
            shutil.copyfile(path, destination, follow_symlinks=False)
            budget.total += 0 if budget.in_class else size  # the class zip's members were counted when unpacked
            if budget.total > limits.max_total:
                most = size_text(limits.max_total)
                raise InputError(f"{shown}: more than {most} in all; labkit takes at most {most} from one student.")
        for relative, archive in zips:
            folder = free(target / relative.parent / safe_part(relative.stem))
            folder.parent.mkdir(parents=True, exist_ok=True)
            unzip.unpack(archive, folder, limits, self.zip_depth, budget)
            self.notes.append(f"{one_line(name, 80)}: unpacked {one_line(as_text(relative.as_posix()), 80)}")


def _kind(entry):
    if entry.is_symlink():
        return "link"
    return "dir" if entry.is_dir(follow_symlinks=False) else "file" if entry.is_file(follow_symlinks=False) else ""


def _named(name, kind):
    """Whether an LMS that names its students' entries (every one but a folder per student) claims `name`."""
    return any(lms.claims(name, kind) for lms in systems() if not lms.rest)


def detect(root):
    """The LMS whose download the folder `root` is; ValueError saying what is there when none or several fit."""
    for lms in systems():
        if lms.whole(root):
            return lms
    return detect_tops([(as_text(e.name), _kind(e)) for e in entries(root)], as_text(str(root)))


def detect_tops(tops, where):
    """The LMS of a download whose top holds `tops` ([(name, kind)]): a sole LMS's name decides; a name several
    claim is the lowest rank's when it is all they have; a ``rest`` LMS takes what no one claims."""
    found = systems()
    for lms in found:
        if lms.sole and any(lms.claims(name, kind) for name, kind in tops):
            return lms
    rivals = [lms for lms in found if not lms.sole and not lms.rest]
    claimed = {lms: {(n, k) for n, k in tops if lms.claims(n, k)} for lms in rivals}
    taken = set().union(*claimed.values())
    claimed |= {lms: {(n, k) for n, k in tops if (n, k) not in taken and lms.claims(n, k)} for lms in found if lms.rest}
    shared = {top for lms in rivals for top in claimed[lms] if any(top in claimed[o] for o in rivals if o is not lms)}
    fits = [lms for lms in rivals if claimed[lms] - shared]
    if not fits and shared:
        fits = [next(lms for lms in rivals if claimed[lms] & shared)]
    fits += [lms for lms in found if lms.rest and claimed[lms]]
    if len(fits) == 1:
        return fits[0]
    expected = ", ".join(lms.download for lms in found[:-1]) + f" or {found[-1].download} (a folder or its zip)"
    if not fits:
        shown = ", ".join(one_line(name, 64) for name, _ in tops[:SHOWN]) or "nothing"
        raise InputError(f"{one_line(where)} holds no students ({shown}); expected {expected} (docs/instructors.md).")
    what = ", ".join(lms.described(sorted(claimed[lms])) for lms in found if lms in claimed)
    raise InputError(f"{one_line(where)} mixes layouts ({what}); expected one of {expected}. Give one of them only.")


def is_class(path: str | os.PathLike) -> bool:
    """Whether `path` is a class (a zip, or a folder of an LMS's layout) rather than one student's notebooks;
    ValueError for a folder of both notebooks (not named as an LMS names them) and folders of notebooks."""
    path = Path(path)
    if os.path.islink(path):
        return False
    if not os.path.isdir(path):
        return os.path.isfile(path) and path.suffix.lower() == ".zip"
    loose, folders = False, False
    for entry in entries(path):
        name = as_text(entry.name)
        if entry.is_file(follow_symlinks=False) and name.endswith(".ipynb"):
            loose = loose or not _named(name, "file")
        elif entry.is_dir(follow_symlinks=False):
            try:
                folders = folders or any(f.suffix == ".ipynb" for f in walk(Path(entry.path)))
            except ValueError:
                folders = True
    if loose and folders:
        raise InputError(
            f"{_shown(path)} holds notebooks and folders of notebooks, so it could be a class or one student's work: "
            f"list a class's students (labkit grade --out OUT -- {_shown(path, 60)}/*), or one student's notebooks."
        )
    return not loose


def _class_zip(path, root, builder):
    """Unpack the class's zip into the folder `root` student by student, each on their own budget; its LMS."""
    label = as_text(path.name)
    with unzip.open_zip(path, label) as archive:
        members = [
            (i, [p for p in i.filename.replace("\\", "/").split("/") if p not in ("", ".")]) for i in archive.infolist()
        ]
        members, prefix = _unwrap([(i, p) for i, p in members if p and p[0] not in ("__MACOSX", "..")])
        tops = _zip_tops(members, builder)
        lms = detect_tops(sorted(tops), label)
        groups = _by_owner(lms, members, tops, builder)
        plans = {key: _student_plan(key, items, builder, label, len(prefix)) for key, items in groups.items()}
        _check_space(lms, plans, root, label)
        for key, plan in plans.items():
            written, made = [], []
            try:
                if plan is not None:
                    unzip.write_plan(archive, plan, root, builder.budget(key), label, (written, made))
            except ValueError as exc:
                unzip.undo(written, made)  # a refused student's members are removed again
                builder.refused[key] = f"{exc} {FIX}"
            if key in builder.refused:
                _placeholder(root, groups[key], lms.depth, builder)
    return lms


def _unwrap(members):
    """The members without the folders all of them are in (a folder zipped whole), and those folders' names."""
    prefix: list[str] = []
    while members and all(len(p) > 1 or i.is_dir() for i, p in members):
        top = members[0][1][0]
        if any(p[0] != top for _, p in members) or _named(top, "dir"):
            break
        if any(len(p) == 2 and p[1].endswith(".ipynb") and not _named(p[1], "file") for _, p in members):
            break  # a student's folder, not a folder around the class
        prefix.append(top)
        members = [(i, p[1:]) for i, p in members if len(p) > 1]
    return members, prefix


def _zip_tops(members, builder):
    """[(name, kind)] of the top of the class zip; a name too long to write gets a short one (``builder.aliases``)."""
    kinds: dict = {}
    for info, parts in members:
        folder = len(parts) > 1 or info.is_dir()
        kinds[parts[0]] = "dir" if folder or kinds.get(parts[0]) == "dir" else "file"
    for number, name in enumerate(sorted(kinds)):
        if len(name.encode("utf-8", "surrogateescape")) > LONG_TOP or name == "..":
            suffix = Path(name).suffix if len(Path(name).suffix) <= 10 else ""
            builder.aliases[f"long-name-{number}{suffix}"] = name
    return list(kinds.items())


def _by_owner(lms, members, tops, builder):
    """{student's key: [(info, parts)]} of the members that are a student's; the rest are named in the notes."""
    owners = lms.owners(tops, builder)
    groups: dict = {}
    ignored = set()
    for info, parts in members:
        key = lms.owner(parts, owners)
        if key is not None:
            groups.setdefault(key, []).append((info, parts))
        elif parts[0] not in owners:  # (a name in owners without a student has its note already)
            ignored.add(parts[0])
    builder.notes += [f"ignored {one_line(name)}: not a student's, in {lms.name}'s layout" for name in sorted(ignored)]
    return groups


def _student_plan(key, items, builder, label, skip):
    """The checked members of one student, or None when one breaks a limit (``builder.refused[key]`` says why)."""
    budget = builder.budget(key)
    budget.in_class = True
    on_disk = [(info, [builder.on_disk(parts[0]), *parts[1:]]) for info, parts in items]
    try:  # a name at the top too long to write has a short one on disk, so its length is not refused
        return unzip.checked(on_disk, budget, label, skip + 1)
    except ValueError as exc:
        builder.refused[key] = f"{exc} {FIX}"
        return None


def _check_space(lms, plans, root, label):
    """ValueError when the students' members would not fit in the free space of `root`, naming the largest."""
    sizes = {key: sum(info.file_size for info, *_ in plan) for key, plan in plans.items() if plan is not None}
    try:
        free_bytes = shutil.disk_usage(root).free
    except OSError:
        return
    if sum(sizes.values()) + SPARE <= free_bytes:
        return
    largest = sorted(sizes, key=lambda key: -sizes[key])[:SHOWN]
    shown = ", ".join(f"{lms.shown(key)} ({size_text(sizes[key])})" for key in largest)
    raise InputError(
        f"{label} unpacks to {size_text(sum(sizes.values()))}, only {size_text(free_bytes)} is free in {root} (with "
        f"{size_text(SPARE)} spare); the largest students are {shown}. Free some space, or grade those apart."
    )


def _placeholder(root, items, depth, builder):
    """For a refused student, empty stand-ins of what names them at the top, so that the layout finds them."""
    folders = {tuple(p[:depth]) for info, p in items if len(p) > depth or (len(p) == depth and info.is_dir())}
    files = {tuple(p) for _, p in items if len(p) == 1 and depth == 1} - folders
    for parts in sorted(folders)[:SHOWN]:
        (root / builder.on_disk(parts[0])).joinpath(*parts[1:]).mkdir(parents=True, exist_ok=True)
    for (name,) in sorted(files)[:SHOWN]:
        target = root / builder.on_disk(name)
        if not os.path.lexists(target):
            target.touch()


def find_class(
    path: str | os.PathLike,
    workspace: str | os.PathLike,
    *,
    assignment: str | None = None,
    limits: UnpackLimits = LIMITS,
    roster: dict[str, str] | None = None,
) -> Intake:
    """The students of the class in `path` (a folder or zip of one LMS), in name order; one that cannot be graded
    has ``path=None`` and the reason in ``failure``, and never stops the others. Everything is written in
    `workspace`, never inside `path`. `assignment` is nbgrader's to take; `roster` ({submission: LMS id}) names
    a student whose LMS id it has. ValueError when the layout is unclear, two students share a name, or the zip
    has no room."""
    path, workspace = Path(path), Path(workspace)
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        raise InputError(f"{_shown(path)} does not exist.") from None
    if stat.S_ISLNK(info.st_mode):
        raise InputError(f"{_shown(path)} is a symbolic link; give the folder or zip itself.")
    if stat.S_ISDIR(info.st_mode) and workspace.resolve().is_relative_to(path.resolve()):
        raise InputError(f"the workspace {_shown(workspace)} is inside the class folder: give a workspace elsewhere.")
    workspace.mkdir(parents=True, exist_ok=True)
    own = Path(tempfile.mkdtemp(prefix="intake-", dir=workspace))
    builder = Builder(own, limits, [], 1 if stat.S_ISREG(info.st_mode) else 0, tuple(roster.values()) if roster else ())
    root, lms = _class_root(path, info, own, builder)
    students = lms.students(root, builder, assignment)
    if assignment is not None and not lms.assignments:
        builder.notes.append(f"--assignment {one_line(assignment, 60)} ignored: only nbgrader's layout has assignments")
    students = _by_roster(students, roster, builder.notes) if roster else students
    _one_name_each(students)
    students.sort(key=lambda s: (s.name.casefold(), s.name))
    return Intake(students, lms.name, builder.notes)


def _class_root(path, info, own, builder):
    """(the folder to read the class from, its LMS): the class folder itself, or its zip unpacked in `own`."""
    if stat.S_ISDIR(info.st_mode):
        return path, detect(path)
    if not stat.S_ISREG(info.st_mode) or path.suffix.lower() != ".zip":
        raise InputError(f"{_shown(path)} is neither a folder nor a zip; give the class as one.")
    root = own / "class"
    root.mkdir()
    lms = _class_zip(path, root, builder)
    builder.notes.append(f"unpacked {one_line(as_text(path.name))} into the workspace, each student's files apart")
    return root, lms


def _by_roster(students, roster, notes):
    """The students named by the roster from their LMS id (never a display name), or a name no roster entry has."""
    names = {key: name for name, key in roster.items()}
    with_ids = [s for s in students if s.lms_id is not None]
    if not any(s.lms_id in names for s in with_ids):
        if with_ids:
            notes.append("the roster's ids are none of the LMS's ids in the download: students matched by name")
        return students
    renamed = []
    for student in students:
        name = names.get(student.lms_id) if student.lms_id is not None else student.name
        if name is None:
            name = student.name if student.name not in roster else f"{student.name}_{student.lms_id}"
            who = f"{one_line(student.name, 80)} (LMS id {one_line(student.lms_id, 40)})"
            notes.append(f"{who} is not on the roster: graded as {one_line(name, 80)}")
        renamed.append(replace(student, name=name))
    return renamed


def _one_name_each(students):
    by_name: dict = {}
    for student in students:
        if student.name in by_name:
            origins = f"{_origin(by_name[student.name])} and {_origin(student)}"
            raise InputError(f"two students are both named {one_line(student.name, 80)!r} ({origins}); rename one.")
        by_name[student.name] = student


def _origin(student):
    if student.lms_id is not None:
        return f"{student.layout} id {one_line(student.lms_id, 40)}"
    return _shown(student.path, 120) if student.path is not None else student.layout


def _shown(path, width=200):
    """A path for a message: one printable line."""
    return one_line(as_text(str(path)), width)


def find_students(paths, workspace, *, limits: UnpackLimits = LIMITS) -> Intake:
    """The students of submissions listed one by one (``labkit grade alice/ bob/ carol.ipynb``): each folder is
    one (its zips unpacked in `workspace`); anything else is passed on as it is, for the grader to take or refuse."""
    workspace = Path(workspace)
    workspace.mkdir(parents=True, exist_ok=True)
    builder = Builder(Path(tempfile.mkdtemp(prefix="listed-", dir=workspace)), limits, [], 0)
    students = []
    for path in map(Path, paths):
        name = as_text(path.stem if path.suffix == ".ipynb" else path.name)
        folder = not os.path.islink(path) and os.path.isdir(path)
        students.append(builder.from_folder(name, path, "listed") if folder else Student(name, path, None, "listed"))
    return Intake(students, "listed", builder.notes)
