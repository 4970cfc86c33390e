"""The safe unzip: what a hostile zip does (leave the folder, links, devices, bombs) refused, on a budget per
student (:class:`Budget`, which the class intake keeps for each student)."""

from __future__ import annotations

import copy
import os
import re
import stat
import zipfile
import zlib
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ..store.report import one_line

MAX_NAME = 255  # bytes of one file or folder name in a zip (what file systems take)
RATIO_FLOOR = 1 << 20  # the compression ratio is checked for members that grow past this many bytes
CHUNK = 1 << 16


@dataclass(frozen=True)
class UnpackLimits:
    """What one student's files and zips may hold in all: bytes, members (folders included), the compression
    ratio of a member past 1 MiB, bytes of one member, levels of zips inside the zip."""

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


LIMITS = UnpackLimits()


@dataclass
class Budget:
    """What one student has spent, nested zips included (``in_class``: counted as the class zip was unpacked)."""

    limits: UnpackLimits
    members: int = 0
    total: int = 0
    in_class: bool = False


def unpack(
    zip_path: str | os.PathLike, into: str | os.PathLike, limits: UnpackLimits = LIMITS, depth=0, budget=None
) -> list[Path]:
    """Extract `zip_path` into `into` (its zips in their place, `depth` levels in, on `budget`), refusing whatever
    could harm with a ValueError after removing what it wrote; the files written.

    >>> import pathlib, tempfile, zipfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> with zipfile.ZipFile(folder / "work.zip", "w") as z:
    ...     z.writestr("../evil.ipynb", "{}")
    >>> unpack(folder / "work.zip", folder / "out")
    Traceback (most recent call last):
    ...
    labkit.errors.InputError: work.zip: member '../evil.ipynb' leaves the folder; labkit never extracts it.
    """
    into = Path(into)
    made = [p for p in (*reversed(into.parents), into) if not os.path.lexists(p)]  # what this call creates
    written: list[Path] = []
    try:
        if not made and not stat.S_ISDIR(os.lstat(into).st_mode):
            raise InputError(f"{into} is not a folder to unpack into.")
        into.mkdir(parents=True, exist_ok=True)
        _unpack(Path(zip_path), into, budget or Budget(limits), depth, written, made, as_text(Path(zip_path).name))
    except BaseException:
        undo(written, made)
        raise
    return sorted(p for p in written if os.path.lexists(p))


def undo(written, made):
    """Remove what a refused unzip wrote: its files, then its folders."""
    for remove, paths in ((os.unlink, written), (os.rmdir, made)):
        for path in reversed(paths):
            with suppress(OSError):
                remove(path)


def open_zip(path, label):
    """The zip `path`, opened; ValueError naming `label` when it is none labkit can read."""
    try:
        return zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError, UnicodeDecodeError, ValueError, EOFError) as exc:
        raise InputError(f"{label}: not a zip labkit can read ({one_line(exc, 120)}).") from None


def refused(label, shown, why):
    """The InputError for the member `shown` of the zip `label`."""
    return InputError(f"{label}: member {shown!r} {why}")


def _member(info, label, skip):
    """(the parts of a member's name, whether it is a folder, its name shown); ValueError when the name leaves the
    folder or a part past `skip` is too long, and for a link, a device, a pipe or an encrypted member."""
    shown = one_line(info.filename, 120)
    text = info.filename.replace("\\", "/")
    if text.startswith("/") or re.match(r"^[A-Za-z]:", text) or "\x00" in text:
        raise refused(label, shown, "has an absolute path; labkit never extracts it.")
    parts = [p for p in text.split("/") if p not in ("", ".")]
    if ".." in parts:
        raise refused(label, shown, "leaves the folder; labkit never extracts it.")
    if any(len(p.encode("utf-8", "surrogateescape")) > MAX_NAME for p in parts[skip:]):
        raise refused(
            label, shown, f"has a name longer than {MAX_NAME} bytes, more than a file system takes; rename it."
        )
    mode = info.external_attr >> 16
    kind = stat.S_IFMT(mode)
    if stat.S_ISLNK(mode):
        raise refused(label, shown, "is a symbolic link; labkit never extracts links.")
    if kind and kind not in (stat.S_IFREG, stat.S_IFDIR):
        raise refused(label, shown, "is a device or a pipe; labkit never extracts those.")
    if info.flag_bits & 0x1:
        raise refused(label, shown, "is encrypted; labkit cannot read it.")
    return parts, info.is_dir() or kind == stat.S_IFDIR, shown


def _over_total(label, limits, when=""):
    most = size_text(limits.max_total)
    return InputError(f"{label}: more than {most} uncompressed{when}; labkit extracts at most {most} for one student.")


def _unpack(zip_path, into, budget, depth, written, made, label):
    limits = budget.limits
    if depth > limits.max_depth:
        raise InputError(f"{label}: a zip nested more than {limits.max_depth} deep; labkit never extracts deeper.")
    with open_zip(zip_path, label) as archive:
        plan = checked([(info, None) for info in archive.infolist()], budget, label)
        inner = write_plan(archive, plan, into, budget, label, (written, made))
    for target, shown in inner:
        if depth + 1 > limits.max_depth:
            raise refused(label, shown, f"is a zip nested more than {limits.max_depth} deep; labkit never goes deeper.")
        folder = free(target.with_suffix(""))
        folder.mkdir()
        made.append(folder)
        _unpack(target, folder, budget, depth + 1, written, made, f"{label}/{shown}")
        os.unlink(target)
        written.remove(target)


def checked(members, budget, label, skip=0):
    """[(info, parts, is_dir, shown)] of `members` ([(info, the parts to write it under, or None for its name's)]),
    once their number, names (past `skip` parts) and declared sizes fit `budget` (their number counted in it)."""
    budget.members += len(members)
    if budget.members > budget.limits.max_members:
        most = budget.limits.max_members
        raise InputError(f"{label}: more than {most} members; labkit extracts at most {most} for one student.")
    plan, seen, declared = [], set(), 0
    for info, given in members:
        parts, is_dir, shown = _member(info, label, skip)  # refuses whatever could harm, before it is written
        parts = parts if given is None else given
        if not parts or parts[0] == "__MACOSX":
            continue
        key = "/".join(parts)
        if key in seen:
            raise refused(label, shown, "appears twice; labkit extracts each name once.")
        seen.add(key)
        if not is_dir:
            _check_size(label, shown, info.file_size, info.compress_size, budget.limits)
            declared += info.file_size
            if budget.total + declared > budget.limits.max_total:
                raise _over_total(label, budget.limits)
        plan.append((info, parts, is_dir, shown))
    return plan


def _check_size(label, shown, size, compressed, limits, growing=False):
    """ValueError when a member of `size` bytes (`compressed` in the zip) is too large or compressed too much."""
    if size > limits.max_member:
        most = size_text(limits.max_member)
        grows = f"grows past {most} while extracting" if growing else f"is larger than {most} ({size_text(size)})"
        raise refused(label, shown, f"{grows}; labkit extracts at most {most} a file.")
    if size > RATIO_FLOOR and size > limits.max_ratio * max(compressed, 1):
        ratio = f"{limits.max_ratio:g}"
        raise refused(label, shown, f"is compressed more than {ratio} times (a zip bomb?); labkit never extracts it.")


def write_plan(archive, plan, into, budget, label, undo_lists):
    """Write the checked members `plan` under `into` (recording them in `undo_lists`); [(a zip written, shown)]."""
    (written, made), inner = undo_lists, []
    for info, parts, is_dir, shown in plan:
        make_dirs(into, parts if is_dir else parts[:-1], made, label, shown)
        if not is_dir:
            target = into.joinpath(*parts)
            extract(archive, info, target, budget, label, shown, written)
            if target.suffix.lower() == ".zip":
                inner.append((target, shown))
    return inner


def make_dirs(into, parts, made, label, shown):
    folder = into
    for part in parts:
        folder = folder / part
        try:
            os.mkdir(folder)
            made.append(folder)
        except FileExistsError:
            if not stat.S_ISDIR(os.lstat(folder).st_mode):
                raise refused(label, shown, "is inside a file of the zip; labkit refuses it.") from None
        except OSError as exc:
            raise refused(label, shown, f"cannot be written ({one_line(exc, 120)}).") from None


def extract(archive, info, target, budget, label, shown, written):
    limits = budget.limits
    try:
        descriptor = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o600)
    except OSError as exc:
        raise refused(label, shown, f"cannot be written ({one_line(exc, 120)}).") from None
    written.append(target)
    size = 0
    # read past the size the member declares (zipfile stops there), so that the bytes it really holds are counted
    probe = copy.copy(info)
    probe.file_size = max(info.file_size, limits.max_member, limits.max_total) + 1
    try:
        with os.fdopen(descriptor, "wb") as out, archive.open(probe) as source:
            while chunk := source.read(CHUNK):
                size += len(chunk)
                _check_size(label, shown, size, info.compress_size, limits, growing=True)
                if budget.total + size > limits.max_total:
                    raise _over_total(label, limits, " while extracting")
                out.write(chunk)
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, NotImplementedError, RuntimeError) as exc:
        raise refused(label, shown, f"cannot be read ({one_line(exc, 120)}).") from None
    if size != info.file_size:
        raise refused(label, shown, f"declares {info.file_size} bytes but holds {size}; labkit refuses the zip.")
    budget.total += size


def free(path):
    """`path`, or the first of ``path~1``, ``path~2``… that does not exist."""
    candidate, number = path, 0
    while os.path.lexists(candidate):
        number += 1
        candidate = path.with_name(f"{path.name}~{number}")
    return candidate


def size_text(n):
    """Bytes for a person: ``512 bytes``, ``64 MiB``."""
    for unit in ("bytes", "KiB", "MiB"):
        if n < 1024:
            return f"{n:g} {unit}" if unit == "bytes" else f"{n:.4g} {unit}"
        n /= 1024
    return f"{n:.4g} GiB"


def as_text(name):
    """A file name as text: bytes that are not UTF-8 spelled out as escapes (as scoring names submissions)."""
    return name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
