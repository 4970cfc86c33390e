"""The class as the LMS hands it over: one folder or one zip becomes a list of students.

Nothing is graded here, and nothing is written anywhere but the grader's
`workspace`: a zip (the class's, or a student's) is unpacked there by
:func:`unpack`, which refuses what a hostile zip does (leaving the folder,
links, devices, bombs); a Canvas or Moodle download's loose files are
grouped into one folder per student there. The class folder is only read,
and no link is ever followed while reading it.

The layouts recognised (:func:`find_class` tells them apart by their names):

``folders``
    ``CLASS/<student>/…/*.ipynb``: a folder per student, its notebooks at any
    depth (within :data:`MAX_DEPTH`); a notebook at the top of ``CLASS`` is a
    student of its own, named after the file (``alice.ipynb`` is ``alice``),
    as ``labkit grade`` names it. A zip in a student's folder is unpacked.
``nbgrader``
    ``COURSE/submitted/<student>/<assignment>/*.ipynb`` (or ``submitted/``
    itself): the student's id is the name, and the path is the assignment's
    folder, so nbgrader's ``timestamp.txt`` stays where :mod:`~labkit.grading.store.late`
    looks for it. With several assignments, ``assignment=`` picks one.
``canvas``
    Canvas's "Download Submissions": a flat folder of files named
    ``{name}_{userid}_{fileid}_{original name}``, late ones
    ``{name}_LATE_{userid}_{fileid}_{original name}``. The files are grouped per
    student by user id (read as :mod:`.lms_names` reads it, never from the
    parts a student chooses) into a folder each, under their original names;
    the student's name is ``{name}``, the LMS id ``{userid}``.
``moodle``
    Moodle's "Download all submissions": folders
    ``{Full Name}_{participant id}_assignsubmission_{plugin}_`` (``file``,
    ``onlinetext``), or, with "Download submissions in folders" off, flat files
    ``{Full Name}_{participant id}_assignsubmission_{plugin}_{original name}``.
    The name is ``{Full Name}_{participant id}``, so two students of one name
    stay apart; the LMS id is the participant id.

A zip given as the class (as Canvas and Moodle hand out their downloads) is a
container, read as one of these: its members are sorted out by student from
the LMS's part of their names before anything is written, and each student's
are checked and unpacked into the workspace on that student's own budget
(:class:`UnpackLimits`, counted over all of the student's files and zips). A
member that breaks a rule makes its student one who could not be graded;
nothing a student uploads refuses the class. A zip whose top holds just one
folder without notebooks of its own (a folder zipped whole) is read from that
folder. With a roster (``find_class(roster=...)``), a student the LMS gives an
id the roster has takes the roster's name for it.

What the LMSs write, as this module relies on it
-------------------------------------------------

Canvas. The names in its download zip: the student's sortable name
("Lovelace, Ada"), lower-cased with everything but letters, digits and ``_``
dropped (``lovelaceada``); ``LATE`` after it when Canvas counts the
submission late; the Canvas user id; the id of the file (often called the
submission id); and the file's display name. Sources: the assignment zipper
of instructure/canvas-lms (``lib/content_zipper.rb``: ``get_filename``,
``add_upload_submission``, ``sanitize_user_name``; see :mod:`.lms_names`), the
naming code of its quiz-submissions zipper (``question_attachment_filename``),
and names of real
downloads quoted in the README of mikewesthad/canvas-unzipper
(``smithbob_340934_208490284_BobsWork.zip``) and in instructure/canvas-lms issue
#2406 (``studenttest_3143_207797_zipsubmission.zip``). When a student uploads
a file whose name they already used in the assignment, Canvas renames the new
file ``name-1.ext``, then ``name-2.ext`` (students' reports of it:
nus-cs2103-AY2223S2/forum #361 and nus-cs2103-AY2324S1/forum #459, IIC1253
issues #26 and #34), so a number of one or two digits before the extension
marks a re-upload: of the files one student has under one original name, the
highest number is the newest and the only one kept, under the original name
(the notes say so). The download holds the latest submission's files, so a
lone ``02_convergence-1.ipynb`` is named back ``02_convergence.ipynb`` too. A
group assignment names the files after the group in place of the student,
which reads the same way (the group is the "student"). For anonymous grading
this module assumes, without a source that shows it, ``anon`` (or
``anonymous``) and an anonymous id that need not be a number
(``anon_Ab3dE_98765_…``): the student is then ``anon_Ab3dE`` and the LMS id
``Ab3dE``; anything else not in the pattern is a note, never a student.

Moodle. ``mod/assign``'s download (``locallib.php``, ``download_submissions``,
and the ``downloader`` class of recent versions) prefixes each file with the
student's full name in which every ``_`` became a space, then ``_`` and the
student's participant id (``get_uniqueid_for_user``: the id blind marking
shows, not the user's id), passed through ``clean_filename``. With folders (the
default since Moodle 3.1) each submission plugin of the student gets a folder
``{prefix}_assignsubmission_{plugin}_``, holding the files as uploaded; without,
each file is ``{prefix}_assignsubmission_{plugin}_{file name}``. Blind marking
writes "Participant" for the name; team submissions the group's name. Because
the full name holds no ``_``, the first ``_<digits>_assignsubmission_`` ends it.

The student's name is data: it is never used as a path; what is created for a
student on disk is named with :func:`~labkit.grading.store.report.safe_name`.
"""

from __future__ import annotations

import copy
import dataclasses
import os
import re
import shutil
import stat
import tempfile
import zipfile
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path

from ...errors import InputError
from ..store.report import one_line, safe_name
from .lms_names import canvas_readings, resolve_canvas

MAX_FILES = 5_000  # entries looked at in one folder walk (as scoring's walk of a submission)
MAX_DEPTH = 8  # folder levels looked into
MAX_NAME = 255  # bytes of one file or folder name in a zip (what file systems take)
SPARE = 256 << 20  # bytes the class zip leaves free where it is unpacked
LONG_TOP = 200  # bytes of a class zip's top-level name beyond which it is written under a short name
RATIO_FLOOR = 1 << 20  # the compression ratio is checked for members that grow past this many bytes
CHUNK = 1 << 16
IGNORED = {"__MACOSX", ".ipynb_checkpoints", "__pycache__", "Thumbs.db", "desktop.ini"}
SHOWN = 4  # file names listed in a "holds no notebook" failure
FIX = (
    "Only this student is left out: ask them for their notebooks as plain .ipynb files (or an ordinary zip of "
    "them), grade those alone and combine the runs with `labkit merge`."
)

REUPLOAD = re.compile(r"^(?P<stem>.+)-(?P<number>[1-9][0-9]?)(?P<ext>\.[^.]+)?$", re.DOTALL)
# Moodle's full name holds no "_" (it writes a space for each): the first _<id>_assignsubmission_ ends it
MOODLE_FOLDER = re.compile(r"^(?P<name>[^_]+)_(?P<pid>[0-9]+)_assignsubmission_(?P<plugin>[a-z0-9]+)_$", re.DOTALL)
MOODLE_FILE = re.compile(
    r"^(?P<name>[^_]+)_(?P<pid>[0-9]+)_assignsubmission_(?P<plugin>[a-z0-9]+)_(?P<file>.+)$", re.DOTALL
)
LAYOUTS = "a folder per student, nbgrader's submitted/, Canvas's or Moodle's download (a folder or its zip)"


@dataclass(frozen=True)
class UnpackLimits:
    """What :func:`unpack` extracts at most from one zip, the zips inside it included; in :func:`find_class`,
    what one student's files and zips may hold in all (the class's zip is only a container).

    Attributes
    ----------
    max_total : int
        Bytes written in all (512 MiB).
    max_members : int
        Members, directories included (2000).
    max_ratio : float
        Uncompressed over compressed size of one member, for members that grow past 1 MiB (100).
    max_member : int
        Bytes of one member (64 MiB).
    max_depth : int
        Levels of zips inside the zip unpacked (2: a zip in a zip in the zip).

    Examples
    --------
    >>> UnpackLimits().max_members, UnpackLimits(max_depth=0).max_depth
    (2000, 0)
    """

    max_total: int = 512 << 20
    max_members: int = 2000
    max_ratio: float = 100.0
    max_member: int = 64 << 20
    max_depth: int = 2

    def __post_init__(self):
        for name in ("max_total", "max_members", "max_member", "max_ratio"):
            if not getattr(self, name) > 0:
                raise InputError(f"UnpackLimits.{name} must be positive, not {getattr(self, name)!r}.")
        if self.max_depth < 0:
            raise InputError(f"UnpackLimits.max_depth must be 0 or more, not {self.max_depth!r}.")


@dataclass(frozen=True)
class Student:
    """One student of the class, as the LMS's layout gives them.

    Attributes
    ----------
    name : str
        The submission's name (what grades.csv, the feedback files and the roster use).
    path : Path or None
        A folder or one .ipynb to grade (possibly in the workspace); None when nothing can be graded.
    failure : str or None
        Why it cannot be graded; None when it can.
    layout : str
        The layout it was found in: ``"folders"``, ``"nbgrader"``, ``"canvas"`` or ``"moodle"``.
    lms_id : str or None
        The LMS's own id when the layout carries one (Canvas's user id, Moodle's participant id).
    marked_late : bool
        The LMS marked it late in the download (Canvas's ``LATE``).
    """

    name: str
    path: Path | None
    failure: str | None
    layout: str
    lms_id: str | None = None
    marked_late: bool = False
    # how the LMS names this student's files, for handing feedback back (labkit.grading.reports.delivery):
    # Canvas's download prefix of one of the submission's files, "{name}[_LATE]_{user id}_{file id}"
    lms_file: str | None = None


@dataclass
class Intake:
    """The students found in what the LMS gave, in name order, and what to tell the instructor.

    Attributes
    ----------
    students : list of Student
    layout : str
        The layout recognised (see the module's documentation).
    notes : list of str
        Printable lines: files ignored, re-uploads, zips unpacked.
    """

    students: list[Student]
    layout: str
    notes: list[str] = field(default_factory=list)

    @property
    def gradable(self) -> list[Student]:
        """The students with something to grade."""
        return [s for s in self.students if s.path is not None]


# ---------------------------------------------------------------------------------------------- zips


class _Budget:
    """What one :func:`unpack` call has spent, its nested zips included."""

    def __init__(self, limits):
        self.limits = limits
        self.members = 0
        self.total = 0
        self.in_class = False  # the student's files came in the class zip (counted as they were unpacked)


def unpack(zip_path: str | os.PathLike, into: str | os.PathLike, limits: UnpackLimits = UnpackLimits()) -> list[Path]:
    """Extract `zip_path` into the folder `into`, refusing whatever could harm, and return the files written.

    A member is never extracted when its name is absolute, has a drive letter
    or a ``..``, or when it is a link or a device; the members, the bytes of
    each and of all, and each member's compression ratio are bounded by
    `limits`, counted on the bytes actually decompressed (the sizes a zip
    declares are checked first, and never trusted). A zip inside is unpacked
    in its place (``work.zip`` into a folder ``work``), to ``limits.max_depth``
    levels, on the same budget. ``__MACOSX/`` is skipped. Any refusal raises
    ``ValueError`` naming the zip and the rule, after removing what this call
    wrote; nothing is ever written outside `into`, and no existing file is
    overwritten.

    Examples
    --------
    >>> import io, pathlib, tempfile, zipfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> with zipfile.ZipFile(folder / "work.zip", "w") as z:
    ...     z.writestr("lab/02_convergence.ipynb", "{}")
    >>> [p.relative_to(folder).as_posix() for p in unpack(folder / "work.zip", folder / "out")]
    ['out/lab/02_convergence.ipynb']
    >>> with zipfile.ZipFile(folder / "evil.zip", "w") as z:
    ...     z.writestr("../evil.ipynb", "{}")
    >>> unpack(folder / "evil.zip", folder / "out2")
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: evil.zip: member '../evil.ipynb' leaves the folder; labkit never extracts it.
    """
    return _unpack_top(zip_path, into, limits, True)


def _unpack_top(zip_path, into, limits, nested, depth=0, budget=None):
    into = Path(into)
    created_root = None if os.path.lexists(into) else into
    while created_root is not None and not os.path.lexists(created_root.parent):
        created_root = created_root.parent  # the first folder this call creates, removed again on failure
    written: list[Path] = []
    made: list[Path] = []
    try:
        if created_root is not None:
            into.mkdir(parents=True)
        elif not stat.S_ISDIR(os.lstat(into).st_mode):
            raise InputError(f"{into} is not a folder to unpack into.")
        budget = budget if budget is not None else _Budget(limits)
        _unpack(Path(zip_path), into, budget, depth, written, made, _text(Path(zip_path).name), nested)
    except BaseException:
        _undo(created_root, written, made)
        raise
    return sorted(p for p in written if os.path.lexists(p))


def _undo(root, written, made):
    if root is not None:
        shutil.rmtree(root, ignore_errors=True)
        return
    for path in reversed(written):
        try:
            os.unlink(path)
        except OSError:
            pass
    for path in reversed(made):
        try:
            os.rmdir(path)
        except OSError:
            pass


def _member_parts(name, label, skip=0):
    """The parts of a member's name, or ValueError when it would leave the folder (or a part past the first
    `skip` is longer than a file system takes)."""
    shown = one_line(name, 120)
    text = name.replace("\\", "/")
    if text.startswith("/") or re.match(r"^[A-Za-z]:", text) or "\x00" in text:
        raise InputError(f"{label}: member {shown!r} has an absolute path; labkit never extracts it.")
    parts = [p for p in text.split("/") if p not in ("", ".")]
    if ".." in parts:
        raise InputError(f"{label}: member {shown!r} leaves the folder; labkit never extracts it.")
    if any(len(p.encode("utf-8", "surrogateescape")) > MAX_NAME for p in parts[skip:]):
        raise InputError(
            f"{label}: member {shown!r} has a name longer than {MAX_NAME} bytes, more than a file system "
            "takes; rename it shorter."
        )
    return parts


def _unpack(zip_path, into, budget, depth, written, made, label, nested=True):
    limits = budget.limits
    if depth > limits.max_depth:
        raise InputError(f"{label}: a zip nested more than {limits.max_depth} deep; labkit never extracts deeper.")
    try:
        archive = zipfile.ZipFile(zip_path)
    except (zipfile.BadZipFile, OSError, UnicodeDecodeError, ValueError, EOFError) as exc:
        raise InputError(f"{label}: not a zip labkit can read ({one_line(exc, 120)}).") from None
    with archive:
        infos = archive.infolist()
        budget.members += len(infos)
        if budget.members > limits.max_members:
            raise InputError(
                f"{label}: more than {limits.max_members} members; labkit extracts at most {limits.max_members} "
                "for one student."
            )
        plan = _checked(infos, budget, label)
        inner = []
        for info, parts, is_dir, shown in plan:
            target = into.joinpath(*parts)
            _make_dirs(into, parts if is_dir else parts[:-1], made, label, shown)
            if is_dir:
                continue
            _extract(archive, info, target, budget, label, shown, written)
            if nested and target.suffix.lower() == ".zip":
                inner.append((target, shown))
    for target, shown in inner:
        if depth + 1 > limits.max_depth:
            raise InputError(
                f"{label}: member {shown!r} is a zip nested more than {limits.max_depth} deep; "
                "labkit never extracts deeper."
            )
        folder = _free(target.with_suffix(""))
        folder.mkdir()
        made.append(folder)
        _unpack(target, folder, budget, depth + 1, written, made, f"{label}/{shown}")
        os.unlink(target)
        written.remove(target)


def _checked(infos, budget, label, parts_of=None):
    """[(info, parts, is_dir, shown)] of the members `infos` to extract, after every check that their names and
    declared sizes allow on `budget` (ValueError naming the first that fails)."""
    plan, seen, declared = [], set(), 0
    for info in infos:
        parts = _member_parts(info.filename, label) if parts_of is None else parts_of(info)
        is_dir = _member_kind(info, label)
        if not parts or parts[0] == "__MACOSX":
            continue
        shown, key = one_line(info.filename, 120), "/".join(parts)
        if key in seen:
            raise InputError(f"{label}: member {shown!r} appears twice; labkit extracts each name once.")
        seen.add(key)
        if not is_dir:
            declared += _declared(info, label, shown, budget.limits)
            if budget.total + declared > budget.limits.max_total:
                raise InputError(
                    f"{label}: more than {_size(budget.limits.max_total)} uncompressed; "
                    f"labkit extracts at most {_size(budget.limits.max_total)} for one student."
                )
        plan.append((info, parts, is_dir, shown))
    return plan


def _member_kind(info, label):
    """Whether the member is a folder; ValueError for a link, a device, a pipe or an encrypted member."""
    shown = one_line(info.filename, 120)
    mode = info.external_attr >> 16
    kind = stat.S_IFMT(mode)
    if stat.S_ISLNK(mode):
        raise InputError(f"{label}: member {shown!r} is a symbolic link; labkit never extracts links.")
    if kind and kind not in (stat.S_IFREG, stat.S_IFDIR):
        raise InputError(f"{label}: member {shown!r} is a device or a pipe; labkit never extracts those.")
    if info.flag_bits & 0x1:
        raise InputError(f"{label}: member {shown!r} is encrypted; labkit cannot read it.")
    return info.is_dir() or kind == stat.S_IFDIR


def _declared(info, label, shown, limits):
    if info.file_size > limits.max_member:
        raise InputError(
            f"{label}: member {shown!r} is larger than {_size(limits.max_member)} "
            f"({_size(info.file_size)}); labkit extracts at most {_size(limits.max_member)} a file."
        )
    _check_ratio(label, shown, info.file_size, info.compress_size, limits)
    return info.file_size


def _check_ratio(label, shown, size, compressed, limits):
    if size > RATIO_FLOOR and size > limits.max_ratio * max(compressed, 1):
        raise InputError(
            f"{label}: member {shown!r} is compressed more than {limits.max_ratio:g} times (a zip bomb?); "
            f"labkit never extracts it."
        )


def _make_dirs(into, parts, made, label, shown):
    folder = into
    for part in parts:
        folder = folder / part
        try:
            os.mkdir(folder)
            made.append(folder)
        except FileExistsError:
            if not stat.S_ISDIR(os.lstat(folder).st_mode):
                raise InputError(f"{label}: member {shown!r} is inside a file of the zip; labkit refuses it.") from None
        except OSError as exc:
            raise InputError(f"{label}: member {shown!r} cannot be written ({one_line(exc, 120)}).") from None


def _extract(archive, info, target, budget, label, shown, written):
    limits = budget.limits
    try:
        descriptor = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o600)
    except OSError as exc:
        raise InputError(f"{label}: member {shown!r} cannot be written ({one_line(exc, 120)}).") from None
    written.append(target)
    size = 0
    # Read as if the member were larger than any limit, so that the bytes it really holds are counted
    # (zipfile would stop at the size it declares); the declared size is then checked against them.
    probe = copy.copy(info)
    probe.file_size = max(info.file_size, limits.max_member, limits.max_total) + 1
    try:
        with os.fdopen(descriptor, "wb") as out, archive.open(probe) as source:
            while chunk := source.read(CHUNK):
                size += len(chunk)
                if size > limits.max_member:
                    raise InputError(
                        f"{label}: member {shown!r} grows past {_size(limits.max_member)} while extracting; "
                        f"labkit extracts at most {_size(limits.max_member)} a file."
                    )
                if budget.total + size > limits.max_total:
                    raise InputError(
                        f"{label}: more than {_size(limits.max_total)} uncompressed while extracting; "
                        f"labkit extracts at most {_size(limits.max_total)} for one student."
                    )
                _check_ratio(label, shown, size, info.compress_size, limits)
                out.write(chunk)
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, NotImplementedError, RuntimeError) as exc:
        raise InputError(f"{label}: member {shown!r} cannot be read ({one_line(exc, 120)}).") from None
    if size != info.file_size:
        raise InputError(
            f"{label}: member {shown!r} declares {info.file_size} bytes but holds {size}; labkit refuses the zip."
        )
    budget.total += size


def _free(path):
    """`path`, or the first of ``path~1``, ``path~2``… that does not exist."""
    candidate, number = path, 0
    while os.path.lexists(candidate):
        number += 1
        candidate = path.with_name(f"{path.name}~{number}")
    return candidate


def _size(n):
    for unit in ("bytes", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:g} {unit}" if unit == "bytes" else f"{n:.4g} {unit}"
        n /= 1024
    return f"{n} GiB"  # pragma: no cover


# ---------------------------------------------------------------------------------------------- the class zip


def _class_zip(path, root, builder):
    """Unpack the class's zip into the folder `root` student by student, each on their own budget; its layout.

    The zip is a container: its members are sorted out by whose they are (from the LMS's part of their names)
    before anything is written, and each student's are checked and extracted on that student's budget. A member
    that breaks a rule refuses its student only (``builder.refused``), never the class."""
    label = _text(path.name)
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError, UnicodeDecodeError, ValueError, EOFError) as exc:
        raise InputError(f"{label}: not a zip labkit can read ({one_line(exc, 120)}).") from None
    with archive:
        members = [(i, _loose_parts(i.filename)) for i in archive.infolist()]
        members, prefix = _unwrap([(i, p) for i, p in members if p and p[0] not in ("__MACOSX", "..")])
        tops = _zip_tops(members, builder)
        layout = _detect_tops(sorted(tops.values()), label)
        groups = _by_owner(layout, members, tops, builder)
        plans = {key: _student_plan(key, items, builder, label, len(prefix)) for key, items in groups.items()}
        _check_space(plans, root, label)
        for key, plan in plans.items():
            if plan is not None:
                _extract_student(archive, key, plan, root, builder, label)
            _placeholder(root, key, groups[key], layout, builder)
    return layout


def _loose_parts(name):
    return [p for p in name.replace("\\", "/").split("/") if p not in ("", ".")]


def _unwrap(members):
    """The members without the folders all of them are in (a folder zipped whole), and those folders' names."""
    prefix: list[str] = []
    while members and all(len(p) > 1 or i.is_dir() for i, p in members):
        top = members[0][1][0]
        if any(p[0] != top for _, p in members) or top == "submitted" or MOODLE_FOLDER.match(top):
            break
        if any(len(p) == 2 and p[1].endswith(".ipynb") and not _lms_named(p[1]) for _, p in members):
            break  # a student's folder, not a folder around the class
        prefix.append(top)
        members = [(i, p[1:]) for i, p in members if len(p) > 1]
    return members, prefix


def _lms_named(name):
    return bool(MOODLE_FILE.match(name) or canvas_readings(name))


def _zip_tops(members, builder):
    """{name: (name, kind)} of the top of the class zip, as the LMS gave them; a name too long to write gets a
    short one on disk (``builder.aliases``)."""
    kinds: dict = {}
    for info, parts in members:
        folder = len(parts) > 1 or info.is_dir()
        kinds[parts[0]] = "dir" if folder or kinds.get(parts[0]) == "dir" else "file"
    for number, name in enumerate(sorted(kinds)):
        if len(name.encode("utf-8", "surrogateescape")) > LONG_TOP or name == "..":
            suffix = Path(name).suffix if len(Path(name).suffix) <= 10 else ""
            builder.aliases[f"long-name-{number}{suffix}"] = name
    return {name: (name, kind) for name, kind in kinds.items()}


def _by_owner(layout, members, tops, builder):
    """{student's key: [(info, parts)]} of the members that are a student's; the rest are named in the notes."""
    owners = _owners(layout, tops, builder)
    groups: dict = {}
    ignored = set()
    for info, parts in members:
        if layout == "nbgrader":
            key = ("nbgrader", parts[1]) if parts[0] == "submitted" and len(parts) > 1 else None
        else:
            key = owners.get(parts[0])
        if key is None and not (layout == "canvas" and canvas_readings(parts[0])):  # (those have their note)
            ignored.add(parts[0] if layout != "nbgrader" or parts[0] != "submitted" else "/".join(parts[:2]))
            continue
        if key is not None:
            groups.setdefault(key, []).append((info, parts))
    for name in sorted(ignored):
        builder.notes.append(f"ignored {one_line(name)}: not a student's, in {layout}'s layout")
    return groups


def _owners(layout, tops, builder):
    """{top-level name: the key of the student it belongs to} by the LMS's part of the names."""
    files = [name for name, kind in tops.values() if kind == "file"]
    if layout == "canvas":
        chosen, said = resolve_canvas(files, builder.roster_ids)
        builder.notes += said
        builder.canvas_noted = True  # the files filed to no one are never unpacked: their notes are said here
        return {name: ("canvas", r.uid) for name, r in chosen.items() if r is not None}
    if layout == "moodle":
        found = {}
        for name, kind in tops.values():
            match = (MOODLE_FOLDER if kind == "dir" else MOODLE_FILE).match(name)
            if match:
                found[name] = ("moodle", match["name"], match["pid"])
        return found
    return {name: ("folders", name) for name, kind in tops.values() if kind == "dir" or name.endswith(".ipynb")}


def _student_plan(key, items, builder, label, skip):
    """The checked members of one student (see :func:`_checked`), or None when one breaks a limit (then
    ``builder.refused[key]`` says why)."""
    budget = builder.budget(key)
    budget.in_class = True
    budget.members += len(items)
    disk = {name: alias for alias, name in builder.aliases.items()}
    parts_of = {id(info): parts for info, parts in items}

    def checked_parts(info):
        _member_parts(info.filename, label, skip + 1)  # refuses what leaves the folder, and too long a name
        parts = parts_of[id(info)]
        return [disk.get(parts[0], parts[0]), *parts[1:]]

    try:
        if budget.members > budget.limits.max_members:
            raise InputError(
                f"{label}: more than {budget.limits.max_members} members are this student's; labkit extracts at "
                f"most {budget.limits.max_members} for one student."
            )
        return _checked([info for info, _ in items], budget, label, checked_parts)
    except ValueError as exc:
        builder.refused[key] = f"{exc} {FIX}"
        return None


def _check_space(plans, root, label):
    """ValueError when the students' members would not fit in the free space of `root`, naming the largest."""
    sizes = {key: sum(info.file_size for info, *_ in plan) for key, plan in plans.items() if plan is not None}
    try:
        free = shutil.disk_usage(root).free
    except OSError:
        return
    if sum(sizes.values()) + SPARE <= free:
        return
    largest = sorted(sizes, key=lambda key: -sizes[key])[:SHOWN]
    shown = ", ".join(f"{_shown_key(key)} ({_size(sizes[key])})" for key in largest)
    raise InputError(
        f"{label} unpacks to {_size(sum(sizes.values()))}, and only {_size(free)} is free in {root} (labkit keeps "
        f"{_size(SPARE)} spare); the largest students are {shown}. Free some space, or grade those students apart."
    )


def _shown_key(key):
    """A student's key as the instructor knows them: a folder's name, Canvas's user id, Moodle's prefix."""
    if key[0] == "canvas":
        return f"Canvas user {one_line(key[1], 40)}"
    return one_line("_".join(key[1:]), 64)


def _extract_student(archive, key, plan, root, builder, label):
    """Write one student's checked members under `root` on their budget; on a refusal remove them again."""
    budget, written, made = builder.budget(key), [], []
    try:
        for info, parts, is_dir, shown in plan:
            _make_dirs(root, parts if is_dir else parts[:-1], made, label, shown)
            if not is_dir:
                _extract(archive, info, root.joinpath(*parts), budget, label, shown, written)
    except ValueError as exc:
        _undo(None, written, made)
        builder.refused[key] = f"{exc} {FIX}"


def _placeholder(root, key, items, layout, builder):
    """For a refused student, empty stand-ins of what names them at the top, so that the layout finds them."""
    if key not in builder.refused:
        return
    disk = {name: alias for alias, name in builder.aliases.items()}
    depth = 3 if layout == "nbgrader" else 1
    folders = {tuple(p[:depth]) for info, p in items if len(p) > depth or (len(p) == depth and info.is_dir())}
    files = {tuple(p) for _, p in items if len(p) == 1 and depth == 1} - folders
    for parts in sorted(folders)[:SHOWN]:
        (root / disk.get(parts[0], parts[0])).joinpath(*parts[1:]).mkdir(parents=True, exist_ok=True)
    for (name,) in sorted(files)[:SHOWN]:
        target = root / disk.get(name, name)
        if not os.path.lexists(target):
            target.touch()


# ---------------------------------------------------------------------------------------------- folders


def _text(name):
    """A file name as text: bytes that are not UTF-8 spelled out as escapes (as scoring names submissions)."""
    return name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def _skipped(name):
    return name.startswith(".") or name in IGNORED


def _entries(folder):
    """The entries of `folder` worth looking at, in name order; links never followed."""
    try:
        with os.scandir(folder) as found:
            entries = [e for e in found if not _skipped(e.name)]
    except OSError:
        return []
    return sorted(entries, key=lambda e: e.name)


def _walk(folder, notes=None):
    """The regular files under `folder` (no links, no hidden files), bounded in files and depth."""
    found, todo, seen = [], [(Path(folder), 0)], 0
    while todo:
        current, depth = todo.pop()
        for entry in _entries(current):
            seen += 1
            if seen > MAX_FILES:
                raise InputError(f"{_text(str(folder))} holds more than {MAX_FILES} files; a submission is a few.")
            if entry.is_symlink():
                if notes is not None:
                    notes.append(f"ignored {one_line(_text(entry.path))}: a link (links are never followed)")
                continue
            if entry.is_dir(follow_symlinks=False):
                if depth < MAX_DEPTH:
                    todo.append((Path(entry.path), depth + 1))
            elif entry.is_file(follow_symlinks=False):
                found.append(Path(entry.path))
    return sorted(found)


def _listing(names):
    names = sorted({one_line(n, 80) for n in names})
    if not names:
        return "it is empty"
    shown = ", ".join(names[:SHOWN])
    return f"it holds {shown}" + (f" and {len(names) - SHOWN} more" if len(names) > SHOWN else "")


def _no_notebook(names):
    return f"holds no notebook ({_listing(names)})"


class _Builder:
    """Turns one student's files (a folder, loose files, zips) into a Student, writing only in the workspace."""

    def __init__(self, workspace, limits, notes, zip_depth):
        self.workspace = workspace
        self.limits = limits
        self.notes = notes
        self.zip_depth = zip_depth  # 1 when the class came as a zip: a student's zip is one level in
        self.budgets: dict = {}  # a student's key -> the _Budget all their zips share (the class zip's included)
        self.refused: dict = {}  # a student's key -> why the class zip's members of theirs were not extracted
        self.aliases: dict = {}  # a name written in the workspace -> the class zip's own (too long to write)
        self.roster_ids: tuple = ()  # the roster's ids, which settle a Canvas file name read two ways
        self.canvas_noted = False  # the class zip's plan told already how each Canvas file name was read

    def budget(self, key):
        """The budget of the student `key` (fresh for one seen first): every limit is per student, in total."""
        return self.budgets.setdefault(key, _Budget(self.limits))

    def name(self, entry):
        """An entry's name as the LMS gave it."""
        return self.aliases.get(entry.name) or _text(entry.name)

    def refusal(self, name, layout, key, lms_id=None, late=False):
        """The student `key` as one who could not be graded, when the class zip's members of theirs were refused."""
        why = self.refused.get(key)
        return None if why is None else Student(name, None, why, layout, lms_id, late)

    def folder_for(self, name):
        folder = _free(self.workspace / "students" / safe_name(name))
        folder.mkdir(parents=True)
        return folder

    def from_folder(self, name, folder, layout, lms_id=None, late=False, keep=(), key=None):
        """A student whose work is the folder `folder` (read only): graded in place unless it holds zips."""
        key = key if key is not None else (layout, name)
        if refused := self.refusal(name, layout, key, lms_id, late):
            return refused
        try:
            files = _walk(folder, self.notes)
        except ValueError as exc:
            return Student(name, None, f"{exc} {FIX}", layout, lms_id, late)
        relative = [f.relative_to(folder).as_posix() for f in files]
        zips = [f for f in files if f.suffix.lower() == ".zip"]
        if not zips:
            if not any(f.suffix == ".ipynb" for f in files):
                return Student(name, None, _no_notebook(_text(r) for r in relative), layout, lms_id, late)
            return Student(name, Path(folder), None, layout, lms_id, late)
        pieces = [(f.relative_to(folder), f) for f in files if f.suffix == ".ipynb" or f.name in keep]
        zips = [(f.relative_to(folder), f) for f in zips]
        return self._assemble(name, (pieces, zips, relative), layout, lms_id, late, key)

    def from_files(self, name, pieces, layout, lms_id=None, late=False, key=None):
        """A student given as loose files: `pieces` pairs the name to give each with its path."""
        key = key if key is not None else (layout, name)
        if refused := self.refusal(name, layout, key, lms_id, late):
            return refused
        zips = [(relative, path) for relative, path in pieces if path.suffix.lower() == ".zip"]
        shown = [_text(relative.as_posix()) for relative, _ in pieces]
        gradable = [(relative, path) for relative, path in pieces if path.suffix == ".ipynb"]
        return self._assemble(name, (gradable, zips, shown), layout, lms_id, late, key)

    def _assemble(self, name, given, layout, lms_id, late, key):
        pieces, zips, shown = given
        if not pieces and not zips:
            return Student(name, None, _no_notebook(shown), layout, lms_id, late)
        target = self.folder_for(name)
        try:
            self._fill(name, target, pieces, zips, key)
            if not any(f.suffix == ".ipynb" for f in _walk(target)):
                shutil.rmtree(target, ignore_errors=True)
                return Student(name, None, _no_notebook(shown), layout, lms_id, late)
        except (ValueError, OSError) as exc:
            shutil.rmtree(target, ignore_errors=True)
            return Student(name, None, f"{one_line(_text(str(exc)), 400)} {FIX}", layout, lms_id, late)
        return Student(name, target, None, layout, lms_id, late)

    def _fill(self, name, target, pieces, zips, key):
        """Copy the student's notebooks into `target` and unpack their zips there, all on the student's budget."""
        budget = self.budget(key)
        for relative, path in pieces:
            destination = _free(target / relative)
            destination.parent.mkdir(parents=True, exist_ok=True)
            size = os.lstat(path).st_size
            if size > self.limits.max_member:
                raise InputError(
                    f"{one_line(_text(str(relative)))} is larger than {_size(self.limits.max_member)}; "
                    "labkit does not copy it."
                )
            shutil.copyfile(path, destination, follow_symlinks=False)
            budget.total += 0 if budget.in_class else size  # the class zip's members were counted when unpacked
            if budget.total > self.limits.max_total:
                raise InputError(
                    f"{one_line(_text(str(relative)))}: more than {_size(self.limits.max_total)} in all; "
                    f"labkit takes at most {_size(self.limits.max_total)} from one student."
                )
        for relative, archive in zips:
            folder = _free(target / relative.parent / _safe_part(relative.stem))
            folder.parent.mkdir(parents=True, exist_ok=True)
            _unpack_top(archive, folder, self.limits, True, self.zip_depth, budget)
            self.notes.append(f"{one_line(name, 80)}: unpacked {one_line(_text(relative.as_posix()), 80)}")


# ---------------------------------------------------------------------------------------------- layouts


def _folders(root, builder, notes):
    students = []
    for entry in _entries(root):
        name = builder.name(entry)
        if entry.is_symlink():  # a student all the same, with nothing labkit will read: never a silent gap
            students.append(Student(name, None, "is a link, and links are never followed", "folders"))
        elif entry.is_dir(follow_symlinks=False):
            students.append(builder.from_folder(name, Path(entry.path), "folders", key=("folders", name)))
        elif entry.is_file(follow_symlinks=False) and name.endswith(".ipynb"):
            student = name[: -len(".ipynb")]
            refused = builder.refusal(student, "folders", ("folders", name))
            students.append(refused or Student(student, Path(entry.path), None, "folders"))
        else:
            notes.append(f"ignored {one_line(name)}: not a student's folder or notebook")
    return students


def _nbgrader(submitted, assignment, builder, notes):
    found = {}  # student -> {assignment: folder}
    for entry in _entries(submitted):
        name = _text(entry.name)
        if entry.is_symlink() or not entry.is_dir(follow_symlinks=False):
            notes.append(f"ignored {one_line(name)} in submitted/: not a student's folder")
            continue
        found[name] = {}
        for inner in _entries(entry.path):
            if inner.is_dir(follow_symlinks=False) and not inner.is_symlink():
                found[name][_text(inner.name)] = Path(inner.path)
            else:
                notes.append(f"ignored {one_line(name)}/{one_line(_text(inner.name))}: not an assignment's folder")
    assignments = sorted({a for per in found.values() for a in per})
    if not assignments:
        raise InputError(
            f"{_text(str(submitted))} holds no assignment folders: nbgrader's layout is "
            "submitted/<student>/<assignment>/*.ipynb."
        )
    if assignment is None:
        if len(assignments) > 1:
            raise InputError(
                f"{_text(str(submitted))} holds several assignments ({_names(assignments)}); "
                "pass --assignment NAME to grade one."
            )
        assignment = assignments[0]
    elif assignment not in assignments:
        raise InputError(
            f"no student of {_text(str(submitted))} submitted {one_line(assignment, 60)!r}; "
            f"the assignments there are {', '.join(one_line(a, 60) for a in assignments)}."
        )
    students, missing = [], []
    for name, per in found.items():
        if assignment in per:
            key = ("nbgrader", name)
            students.append(builder.from_folder(name, per[assignment], "nbgrader", keep=("timestamp.txt",), key=key))
        else:
            missing.append(name)
    if missing:
        notes.append(
            f"{len(missing)} student(s) in submitted/ without {one_line(assignment, 60)!r}: "
            + ", ".join(one_line(m, 64) for m in sorted(missing)[:10])
            + (" …" if len(missing) > 10 else "")
        )
    return students


def _names(names):
    return ", ".join(one_line(n, 64) for n in names)


def _canvas_match(name):
    """Whether `name` reads as Canvas names a submission's file (one reading or more)."""
    return bool(canvas_readings(name))


def _canvas_files(root, builder, notes):
    """{file name as Canvas gave it: (its Reading, path)} of the download's files whose owner is settled."""
    files = {}
    for entry in _entries(root):
        name = builder.name(entry)
        if entry.is_file(follow_symlinks=False) and not entry.is_symlink() and canvas_readings(name):
            files[name] = Path(entry.path)
        else:
            notes.append(f"ignored {one_line(name)}: not named as Canvas names a submission's file")
    chosen, said = resolve_canvas(files, builder.roster_ids)
    notes += [] if builder.canvas_noted else said
    return {name: (reading, files[name]) for name, reading in chosen.items() if reading is not None}


def _canvas(root, builder, notes):
    groups: dict = {}  # user id -> {"logins": {login}, "late": bool, "files": {original: [(number, path, given, fid)]}}
    for name, (reading, path) in _canvas_files(root, builder, notes).items():
        group = groups.setdefault(reading.uid, {"logins": set(), "late": False, "files": {}})
        group["logins"].add(reading.login)
        group["late"] |= reading.late
        original, number = reading.file, 0
        again = REUPLOAD.match(original)
        if again:
            original, number = again["stem"] + (again["ext"] or ""), int(again["number"])
        group["files"].setdefault(original, []).append((number, path, reading.file, reading.fid))
        group["prefix"] = name[: len(name) - len(reading.file) - 1]  # "{login}[_LATE]_{uid}_{fid}", Canvas's own
    logins = [min(group["logins"]) for group in groups.values()]
    students = []
    for (uid, group), login in zip(groups.items(), logins):
        if logins.count(login) > 1 or len(group["logins"]) > 1:  # namesakes: the user id parts them
            said = f"{one_line(login, 80)} names several Canvas students: each is named {one_line(login, 60)}_ID"
            notes += [] if said in notes else [said]
            login = f"{login}_{uid}"
        pieces = _canvas_pieces(login, group["files"], notes)
        student = builder.from_files(login, pieces, "canvas", uid, group["late"], key=("canvas", uid))
        students.append(replace(student, lms_file=group["prefix"]))
    return students


def _canvas_pieces(login, files, notes):
    """[(name to give, path)] of one student's files: of a file uploaded again, the newest only."""
    pieces = []
    for original, versions in sorted(files.items()):
        if not any(number == 0 for number, *_ in versions):
            # no file of that very name: `part-1` and `part-2` may be two notebooks, not two uploads of one
            pieces += [(Path(_safe_part(given)), path) for _, path, given, _ in versions]
            continue
        versions.sort(key=lambda v: (int(v[3]), v[0]))  # file ids grow with each upload: the last is newest
        number, path, given, _ = versions[-1]
        if len(versions) > 1:
            dropped = ", ".join(one_line(v[2], 80) for v in versions[:-1])
            notes.append(
                f"{one_line(login, 80)}: kept {one_line(given, 80)} (the newest upload) as "
                f"{one_line(original, 80)}; older: {dropped}"
            )
        pieces.append((Path(_safe_part(original)), path))
    return pieces


def _safe_part(original):
    """An original file name from an LMS as one file name to create: its own, unless it could not be one."""
    text = original.replace("/", "_").replace("\\", "_").replace("\x00", "_")
    if text in ("", ".", "..") or text.startswith(".") or len(text.encode("utf-8", "surrogateescape")) > 200:
        stem, dot, ext = text.rpartition(".")
        return safe_name(text) + (f".{ext}" if dot and ext.isalnum() and len(ext) <= 10 else "")
    return text


def _moodle(root, builder, notes):
    folders, loose = {}, {}  # (name, pid) -> [folders] / [(original, path)]
    for entry in _entries(root):
        name = builder.name(entry)
        if entry.is_symlink():
            notes.append(f"ignored {one_line(name)}: a link (links are never followed)")
            continue
        if entry.is_dir(follow_symlinks=False) and (match := MOODLE_FOLDER.match(name)):
            folders.setdefault((match["name"], match["pid"]), []).append(Path(entry.path))
        elif entry.is_file(follow_symlinks=False) and (match := MOODLE_FILE.match(name)):
            loose.setdefault((match["name"], match["pid"]), []).append((match["file"], Path(entry.path)))
        else:
            notes.append(f"ignored {one_line(name)}: not named as Moodle names a submission")
    students = []
    for key in sorted(set(folders) | set(loose)):
        name = f"{key[0]}_{key[1]}"
        if key in folders and key not in loose and len(folders[key]) == 1:
            students.append(builder.from_folder(name, folders[key][0], "moodle", key[1], key=("moodle", *key)))
            continue
        pieces = [(Path(_safe_part(original)), path) for original, path in loose.get(key, [])]
        for folder in folders.get(key, []):
            try:
                files = _walk(folder, notes)
            except ValueError as exc:
                notes.append(one_line(exc, 300))
                files = []
            pieces += [(f.relative_to(folder), f) for f in files]
        students.append(builder.from_files(name, pieces, "moodle", key[1], key=("moodle", *key)))
    return students


def _detect(root):
    """The layout of the folder `root`, or ValueError saying what is there."""
    entries = _entries(root)
    if os.path.basename(os.path.normpath(root)) == "submitted" and entries:
        if all(e.is_dir(follow_symlinks=False) for e in entries) and any(
            any(i.is_dir(follow_symlinks=False) for i in _entries(e.path)) for e in entries
        ):
            return "nbgrader"
    return _detect_tops([(_text(e.name), _kind(e)) for e in entries], _text(str(root)))


def _kind(entry):
    if entry.is_symlink():
        return "link"
    return "dir" if entry.is_dir(follow_symlinks=False) else "file" if entry.is_file(follow_symlinks=False) else ""


def _detect_tops(tops, where):
    """The layout of a class whose top holds `tops` ([(name, "dir" | "file" | "link")]), looking only at the
    parts of names the LMS writes; ValueError saying what is there when none fits, or several do."""
    if any(name == "submitted" and kind == "dir" for name, kind in tops):
        return "nbgrader"
    dirs = [name for name, kind in tops if kind == "dir"]
    files = [name for name, kind in tops if kind == "file"]
    moodle = [n for n in dirs if MOODLE_FOLDER.match(n)] + [n for n in files if MOODLE_FILE.match(n)]
    canvas = [n for n in files if _canvas_match(n)]
    either = set(moodle) & set(canvas)  # a Canvas name a student made look like Moodle's, or the reverse
    other_dirs = [n for n in dirs if not MOODLE_FOLDER.match(n)]
    named = set(canvas) | set(moodle)
    notebooks = [n for n in files if n.endswith(".ipynb") and n not in named]
    kinds = {
        "moodle": len(moodle) > len(either) or (bool(either) and len(canvas) == len(either)),
        "canvas": len(canvas) > len(either),
        "folders": bool(other_dirs or notebooks),
    }
    found = [k for k, v in kinds.items() if v]
    if len(found) == 1:
        return found[0]
    if not found:
        shown = ", ".join(one_line(name, 64) for name, _ in tops[:SHOWN]) or "nothing"
        raise InputError(f"{one_line(where)} holds no students ({shown}); expected {LAYOUTS}: see docs/instructors.md.")
    what = (
        f"{len(moodle)} named as Moodle names submissions, {len(canvas)} file(s) named as Canvas names them, "
        f"{len(other_dirs)} other folder(s) and {len(notebooks)} other notebook(s)"
    )
    raise InputError(
        f"{one_line(where)} mixes layouts ({what}); expected one of {LAYOUTS}. "
        "Give a folder that holds one of them only."
    )


def _by_roster(students, roster, notes):
    """The students named by the roster wherever the LMS gave them an id the roster has (the id decides, never a
    display name); one whose id it lacks keeps a name no roster entry has."""
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
            notes.append(
                f"{one_line(student.name, 80)} (LMS id {one_line(student.lms_id, 40)}) is not on the roster: "
                f"graded as {one_line(name, 80)}"
            )
        renamed.append(dataclasses.replace(student, name=name))
    return sorted(renamed, key=lambda s: (s.name.casefold(), s.name))


def _inside(path, folder):
    try:
        Path(path).resolve().relative_to(Path(folder).resolve())
    except ValueError:
        return False
    return True


def is_class(path: str | os.PathLike) -> bool:
    """Whether `path` is a whole class (a zip, or a folder in one of the layouts) rather than one student's work.

    A folder that holds notebooks itself, not named as Canvas or Moodle name a download's files, is one
    student's submission (``labkit grade submitted/alice``); so is a notebook. Every other folder, and every
    zip, is a class. A folder that holds both notebooks of its own and folders of notebooks is refused
    with a ValueError: which of the two it is cannot be told.

    >>> import pathlib, tempfile
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> (root / "alice").mkdir(); _ = (root / "alice" / "02_convergence.ipynb").write_text("{}")
    >>> is_class(root), is_class(root / "alice"), is_class(root / "alice" / "02_convergence.ipynb")
    (True, False, False)
    """
    path = Path(path)
    try:
        info = os.lstat(path)
    except OSError:
        return False
    if stat.S_ISREG(info.st_mode):
        return path.suffix.lower() == ".zip"
    if not stat.S_ISDIR(info.st_mode):
        return False
    loose, folders = False, False
    for entry in _entries(path):
        name = _text(entry.name)
        if entry.is_file(follow_symlinks=False) and name.endswith(".ipynb"):
            loose = loose or (not MOODLE_FILE.match(name) and not _canvas_match(name))
        elif entry.is_dir(follow_symlinks=False) and not _skipped(entry.name):
            try:
                folders = folders or any(f.suffix == ".ipynb" for f in _walk(Path(entry.path)))
            except ValueError:
                folders = True
    if loose and folders:
        raise InputError(
            f"{one_line(_text(str(path)))} holds notebooks of its own and folders of notebooks, so it could be a "
            "class or one student's work: for a class, list its students (labkit grade --out OUT -- "
            f"{one_line(_text(str(path)), 60)}/*); for one student, give the notebooks one by one."
        )
    return not loose


def find_class(
    path: str | os.PathLike,
    workspace: str | os.PathLike,
    *,
    assignment: str | None = None,
    limits: UnpackLimits = UnpackLimits(),
    roster: dict[str, str] | None = None,
) -> Intake:
    """The students of the class in `path`, one folder or one zip as the LMS gave it.

    Parameters
    ----------
    path : path-like
        The class: a folder, or a zip, in one of the layouts of the module's documentation.
    workspace : path-like
        A folder the caller owns (and deletes): every zip is unpacked there and every folder made
        there; nothing is written anywhere else. It must not be inside `path`.
    assignment : str, optional
        nbgrader's assignment to take when students have several.
    limits : UnpackLimits
        What one student's zips may hold, in all (:func:`unpack`); the class's zip is only a container.
    roster : dict, optional
        {submission name: LMS id} (``--roster``): a student the LMS gives an id is named as the roster names
        that id, whatever their display name; one whose id is not on it never takes a roster name.

    Returns
    -------
    Intake
        The students in name order; one that cannot be graded has ``path=None`` and the reason in
        ``failure``. One student's upload never stops the others.

    Raises
    ------
    ValueError
        When no layout fits, the layouts are mixed, two students would share a name, nbgrader's
        students have several assignments and `assignment` is None, the class's zip cannot be read, or
        there is no room to unpack it.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> top = pathlib.Path(tempfile.mkdtemp())
    >>> for student in ("bob", "alice"):
    ...     (top / "class" / student).mkdir(parents=True)
    ...     _ = (top / "class" / student / "02_convergence.ipynb").write_text("{}")
    >>> (top / "class" / "carol").mkdir()
    >>> _ = (top / "class" / "carol" / "notes.pdf").write_bytes(b"%PDF")
    >>> intake = find_class(top / "class", top / "work")
    >>> intake.layout, [(s.name, s.failure) for s in intake.students]
    ('folders', [('alice', None), ('bob', None), ('carol', 'holds no notebook (it holds notes.pdf)')])
    """
    path, workspace = Path(path), Path(workspace)
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        raise InputError(f"{one_line(_text(str(path)))} does not exist.") from None
    if stat.S_ISLNK(info.st_mode):
        raise InputError(f"{one_line(_text(str(path)))} is a symbolic link; give the folder or zip itself.")
    if stat.S_ISDIR(info.st_mode) and _inside(workspace, path):
        raise InputError(
            f"the workspace {one_line(_text(str(workspace)))} is inside the class folder; "
            "labkit writes nothing there: give a workspace elsewhere."
        )
    workspace.mkdir(parents=True, exist_ok=True)
    own = Path(tempfile.mkdtemp(prefix="intake-", dir=workspace))
    notes: list[str] = []
    builder = _Builder(own, limits, notes, 1 if stat.S_ISREG(info.st_mode) else 0)
    builder.roster_ids = tuple(roster.values()) if roster else ()
    root, layout = _class_root(path, info, own, builder)
    students = _students(layout, root, builder, assignment)
    if assignment is not None and layout != "nbgrader":
        notes.append(f"--assignment {one_line(assignment, 60)} ignored: only nbgrader's layout has assignments")
    students = _by_roster(students, roster, notes) if roster else students
    _one_name_each(students)
    students.sort(key=lambda s: (s.name.casefold(), s.name))
    return Intake(students, layout, notes)


def _class_root(path, info, own, builder):
    """(the folder to read the class from, its layout): the class folder itself, or its zip unpacked in `own`."""
    if stat.S_ISDIR(info.st_mode):
        return path, _detect(path)
    if not stat.S_ISREG(info.st_mode) or path.suffix.lower() != ".zip":
        raise InputError(f"{one_line(_text(str(path)))} is neither a folder nor a zip; give the class as one.")
    root = own / "class"
    root.mkdir()
    layout = _class_zip(path, root, builder)
    builder.notes.append(f"unpacked {one_line(_text(path.name))} into the workspace, each student's files on their own")
    return root, layout


def _students(layout, root, builder, assignment):
    if layout == "nbgrader":
        submitted = root if root.name == "submitted" and not (root / "submitted").is_dir() else root / "submitted"
        return _nbgrader(submitted, assignment, builder, builder.notes)
    reader = {"canvas": _canvas, "moodle": _moodle}.get(layout, _folders)
    return reader(root, builder, builder.notes)


def _one_name_each(students):
    by_name: dict = {}
    for student in students:
        if student.name in by_name:
            other = by_name[student.name]
            raise InputError(
                f"two students are both named {one_line(student.name, 80)!r} "
                f"({_origin(other)} and {_origin(student)}); rename one so that each name is one student."
            )
        by_name[student.name] = student


def find_students(paths, workspace, *, limits: UnpackLimits = UnpackLimits()) -> Intake:
    """The students of submissions listed one by one (``labkit grade alice/ bob/ carol.ipynb``).

    Each folder is one student, named after it, whose zips are unpacked into `workspace` (as in
    :func:`find_class`); a folder with no notebook, even in its zips, is a student with nothing to grade.
    A notebook, a link or a path that is neither is passed on as it is, for the grader to take or refuse.
    """
    workspace = Path(workspace)
    workspace.mkdir(parents=True, exist_ok=True)
    notes: list[str] = []
    builder = _Builder(Path(tempfile.mkdtemp(prefix="listed-", dir=workspace)), limits, notes, 0)
    students = []
    for path in map(Path, paths):
        name = path.stem if path.suffix == ".ipynb" else path.name
        name = name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
        try:
            folder = stat.S_ISDIR(os.lstat(path).st_mode)
        except OSError:
            folder = False
        if folder:
            students.append(builder.from_folder(name, path, "listed"))
        else:
            students.append(Student(name, path, None, "listed"))
    return Intake(students, "listed", notes)


def _origin(student):
    if student.lms_id is not None:
        return f"{student.layout} id {one_line(student.lms_id, 40)}"
    return one_line(_text(str(student.path)), 120) if student.path is not None else student.layout
