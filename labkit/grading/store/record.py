"""A grading run's record, ``record.json``: what was graded, under which rubric and seed, by which labkit, and each
result file's SHA-256 (the fields of :class:`RunRecord`).

Every output folder labkit writes holds one, written by the grader alone and replaced whole each time it changes,
with the rubric's TOML copied to ``rubric.toml`` beside it for a person to read. Every later command reads the
folder through it: it takes the recorded rubric when none is given and refuses one that grades differently
(:func:`rubric_for`), and reads a result file only when the record names it with that hash (:func:`results`). So
a file the run did not write (a submission's code writing into the folder, where the sandbox is switched off) is
never read as a grade, and nothing a submission can write changes what the record says it graded.
"""

import hashlib
import json
import os
from dataclasses import asdict, dataclass, field
from datetime import datetime
from pathlib import Path

from ...errors import InputError
from . import rubric as rubrics
from .late import read_small

RECORD = "record.json"
RUBRIC_COPY = "rubric.toml"
FORMAT = "labkit-run/1"
MAX_RESULT = 32 * 1024**2  # bytes of one submission's result file, as the grader accepts it
MAX_RECORD = 256 * 1024**2  # bytes of a record (a few hundred bytes per submission)
MAX_HASHED = 1024**3  # bytes of a submission's notebooks hashed; beyond that only their sizes count
KINDS = ("grade", "merge")
TABLES = ("times", "flags", "known", "variants", "delivery")  # the record's optional tables, empty when left out


@dataclass
class RunRecord:
    """The record of one output folder; ``record.json`` holds its fields (:meth:`as_dict`)."""

    kind: str  # one of KINDS: "grade" (a grading run, resumable) or "merge"
    labkit: str  # the version that graded
    seed: int | list[int] | None  # the run's seed (a list of seeds for a merge)
    rubric: dict  # the rubric in force, in full: its TOML as JSON data, the [late] table and its extensions included
    rubric_text: str | None = None  # its TOML text
    # each submission graded: {"result": its result file's name, "sha256": that file's hash, "content": the
    # digest of its notebooks (content_digest) or None}
    submissions: dict = field(default_factory=dict)
    times: dict = field(default_factory=dict)  # source ("csv", "exchange") -> {name: ISO time}: the times given
    flags: dict = field(default_factory=dict)  # the run's switches that change grades ("times from submission", ...)
    # the known sources graded parts were compared with (labkit.grading.submission.known):
    # {"digest": ..., "solutions": path}
    known: dict = field(default_factory=dict)
    # the students' own data (labkit.exercises.variants): {"digest": the variants file's (never its secret),
    # "students": {name: {exercise: {parameter: value}}}}, empty for a run without variants
    variants: dict = field(default_factory=dict)
    # how the class came (labkit.grading.lms.delivery): {"layout": "canvas", "moodle", "folders", "nbgrader" or
    # "listed", "students": {name: what names that student's files in the LMS}}; empty for a run before it
    delivery: dict = field(default_factory=dict)

    def given_times(self, source):
        """{name: datetime} of the times the run was given from `source` (``"csv"``: ``--times``; ``"exchange"``)."""
        return {name: datetime.fromisoformat(when) for name, when in self.times.get(source, {}).items()}

    def as_dict(self) -> dict:
        """The record as ``record.json``'s data: its fields, named with spaces."""
        return {"format": FORMAT, **{name.replace("_", " "): value for name, value in asdict(self).items()}}

    def rubric_object(self, folder):
        """The recorded rubric, read again (its source named after `folder`)."""
        source = f"the rubric recorded in {Path(folder) / RECORD}"
        found = rubrics.from_dict(self.rubric, source)
        return found if self.rubric_text is None else rubrics.replace(found, text=self.rubric_text)


def new(kind, labkit, seed, rubric):
    """A record of `kind` for a run under `rubric` (a Rubric that knows its data), with no submission yet."""
    if rubric.data is None or rubrics.from_dict(rubric.data, rubric.source).differences(rubric):
        raise InputError(
            "the rubric was made or changed in code, not read from TOML, so a run cannot record it as it grades: "
            "read it with labkit.grading.store.rubric.load (or from_dict)."
        )
    return RunRecord(kind, labkit, seed, rubric.data, rubric.text)


def write(folder, record):
    """Write `record` into `folder` (``record.json``, replaced whole; ``rubric.toml`` beside it)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    replace_text(folder / RECORD, json.dumps(record.as_dict(), indent=1))
    if record.rubric_text is not None:
        replace_text(folder / RUBRIC_COPY, record.rubric_text)


def replace_text(path, text, mode=None):
    """Write `text` into `path` as UTF-8, exactly (no newline translation), replacing it whole: a process killed
    meanwhile leaves the earlier file or none, and two processes writing it at once never share a partial file.
    The file gets `mode` (e.g. 0o600 for one only its owner may read), or the umask's when None. Every file of a
    run folder is written through it."""
    partial = path.with_name(f".{path.name}.{os.getpid()}.partial")
    try:
        flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW
        descriptor = os.open(partial, flags, 0o666 if mode is None else mode)
        with open(descriptor, "wb") as handle:
            if mode is not None:
                os.fchmod(descriptor, mode)  # exactly `mode`, whatever the umask
            handle.write(text.encode("utf-8"))
        os.replace(partial, path)
    except BaseException:
        partial.unlink(missing_ok=True)
        raise


def note(record, name, path, text, content=None):
    """Enter submission `name`'s result file `path` into `record`, with the SHA-256 of `text`, what the grader
    wrote there (never read back from the folder), and `content`, its notebooks' :func:`content_digest`."""
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    record.submissions[name] = {"result": path.name, "sha256": digest, "content": content}


def read(folder) -> RunRecord:
    """The record of output folder `folder`; InputError when it has none or it is not one."""
    folder = Path(folder)
    path = folder / RECORD
    try:
        raw = read_small(path, MAX_RECORD)
    except FileNotFoundError:
        raise InputError(
            f"{folder} has no run record ({RECORD}): it was not written by `labkit grade` of this version (an older "
            "labkit wrote none). Grade the class again into a new --out."
        ) from None
    try:
        data = json.loads(raw.decode("utf-8"))
        tables = _check(data)
    except (UnicodeDecodeError, ValueError) as exc:
        raise InputError(
            f"{path} is not a labkit run record ({str(exc)[:200]}); grade the class again into a new --out."
        ) from None
    return RunRecord(
        data["kind"], str(data.get("labkit")), data.get("seed"), data["rubric"], data.get("rubric text"),
        data["submissions"], *tables,
    )  # fmt: skip


def _check(data) -> list[dict]:
    """A record's optional tables (:data:`TABLES`, each {} when left out); InputError saying what is wrong with
    the record's data, when anything is."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"its format is not {FORMAT}")
    if data.get("kind") not in KINDS:
        raise InputError(f"its kind is not one of {', '.join(KINDS)}")
    submissions = data.get("submissions")
    if not isinstance(submissions, dict) or not isinstance(data.get("rubric"), dict):
        raise InputError("it has no submissions or no rubric")
    for name, entry in submissions.items():
        if not isinstance(entry, dict) or not all(isinstance(entry.get(k), str) for k in ("result", "sha256")):
            raise InputError(f"its entry for {str(name)[:80]!r} has no result file and hash")
        if Path(entry["result"]).name != entry["result"] or not entry["result"].endswith(".json"):
            raise InputError(f"its entry for {str(name)[:80]!r} names a result outside results/")
    text, seed, grade = data.get("rubric text"), data.get("seed"), data["kind"] == "grade"
    if text is not None and not isinstance(text, str):
        raise InputError("its rubric text is not text")
    tables = [data.get(key) or {} for key in TABLES]
    times, flags, known, variants, delivery = tables
    if not isinstance(times, dict) or not all(
        isinstance(given, dict) and all(isinstance(v, str) and _aware(v) for v in given.values())
        for given in times.values()
    ):
        raise InputError("its times are not times with a UTC offset")
    whole = isinstance(seed, int) and not isinstance(seed, bool)
    listed = isinstance(seed, list) and all(isinstance(s, int) and not isinstance(s, bool) for s in seed)
    if not (seed is None or (whole if grade else listed)):
        raise InputError(f"its seed is not {'a number' if grade else 'a list of numbers'}")
    if not isinstance(flags, dict) or not all(isinstance(v, bool) for v in flags.values()):
        raise InputError("its flags are not true or false")
    if not isinstance(known, dict) or not all(v is None or isinstance(v, str) for v in known.values()):
        raise InputError("its known sources are not named by text")
    if not isinstance(variants, dict) or not isinstance(variants.get("students", {}), dict):
        raise InputError("its variants are not a table of students")
    if not isinstance(delivery, dict) or not isinstance(delivery.get("students", {}), dict):
        raise InputError("its delivery is not a table of students")
    return tables


def _aware(text):
    """Whether `text` is an ISO 8601 time with a UTC offset."""
    try:
        return datetime.fromisoformat(text).utcoffset() is not None
    except ValueError:
        return False


def results(folder, record):
    """The result files of `folder` that its `record` vouches for, read: ({name: (path, data)}, refused).

    `refused` lists as (path, why), not yet printable, every file of ``results/`` not read (one the record does not
    name, one whose hash differs, one that is not a plain file) and every result the record names that is missing.
    InputError when a vouched-for file is not JSON."""
    folder = Path(folder)
    by_file = {entry["result"]: name for name, entry in record.submissions.items()}
    found, refused = {}, []
    present = sorted(os.listdir(folder / "results")) if (folder / "results").is_dir() else []
    for file_name in present:
        if not file_name.endswith(".json") or file_name.startswith("."):
            continue
        path = folder / "results" / file_name
        name = by_file.get(file_name)
        if name is None:
            refused.append((path, "the run's record names no such result (that run never graded it)"))
            continue
        try:
            raw = read_small(path, MAX_RESULT)
        except (OSError, ValueError) as exc:
            refused.append((path, str(exc)))
            continue
        if hashlib.sha256(raw).hexdigest() != record.submissions[name]["sha256"]:
            refused.append((path, "changed since the run wrote it (its hash is not the record's)"))
            continue
        try:
            data = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, ValueError) as exc:
            raise InputError(f"{path} is not JSON ({exc}).") from None
        if not isinstance(data, dict) or data.get("name") != name:
            refused.append((path, f"it is not the result of the submission the record names ({name[:80]!r})"))
            continue
        found[name] = (path, data)
    for name, entry in record.submissions.items():
        if name not in found and entry["result"] not in present:
            refused.append((folder / "results" / entry["result"], f"missing (the result of {name[:80]!r})"))
    return found, refused


def content_digest(notebooks, base=None):
    """A digest of a submission's notebooks: their paths (relative to `base`) and bytes, in path order.

    The same notebooks give the same digest wherever they lie, so a resumed run knows which submissions
    changed. At most :data:`MAX_HASHED` bytes are read; beyond that a notebook counts by its size.

    >>> import pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "a.ipynb").write_text("{}")
    >>> first = content_digest([folder / "a.ipynb"], folder)
    >>> _ = (folder / "a.ipynb").write_text("{ }")
    >>> first == content_digest([folder / "a.ipynb"], folder)
    False
    """
    digest, budget = hashlib.sha256(), MAX_HASHED
    for path in sorted(Path(p) for p in notebooks):
        relative = path.relative_to(base) if base is not None and path.is_relative_to(base) else Path(path.name)
        digest.update(b"\0file\0" + relative.as_posix().encode("utf-8", "surrogateescape") + b"\0")
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
        except OSError as exc:
            digest.update(f"unreadable {exc.errno}".encode())
            continue
        try:
            digest.update(str(os.fstat(fd).st_size).encode() + b"\0")
            while budget > 0:
                chunk = os.read(fd, min(1 << 20, budget))
                if not chunk:
                    break
                digest.update(chunk)
                budget -= len(chunk)
        finally:
            os.close(fd)
    return digest.hexdigest()


def rubric_for(folders, given, command):
    """The rubric `command` scores the output `folders` with: their recorded one, which all must share.

    `given` (a Rubric, a TOML path, or None) is the one the instructor named; one that grades otherwise
    (:meth:`.rubric.Rubric.differences`) is refused saying how to score under it, as `command` shows what was graded."""
    records = [(Path(folder), read(folder)) for folder in folders]
    first_folder, first = records[0]
    recorded = first.rubric_object(first_folder)
    for folder, record in records[1:]:
        other = record.rubric_object(folder)
        if differ := recorded.differences(other):
            raise InputError(
                f"{folder} was graded under the rubric {other.title!r} and {first_folder} under {recorded.title!r} "
                f"({' and '.join(differ)} differ): results of different rubrics are not read "
                "together. Grade again under one rubric; when only the [late] or [held] tables differ, merge them "
                "under one (labkit merge ... --rubric FILE --out NEW)."
            )
    if given is None:
        return recorded
    chosen = given if isinstance(given, rubrics.Rubric) else rubrics.load(given)
    differ = recorded.differences(chosen)
    if differ:
        file = given if not isinstance(given, rubrics.Rubric) else "FILE"
        raise InputError(
            f"{first_folder} was graded under the rubric recorded in {first_folder / RECORD} "
            f"({recorded.title!r}), and {chosen.source} differs from it in {' and '.join(differ)}; {command} shows "
            f"grades.csv as graded, so leave --rubric out. To score the class under {chosen.source}: "
            f"`labkit merge {first_folder} --rubric {file} --out NEW` when only the [late] or [held] "
            f"table differs, else grade again with it into a new --out."
        )
    return recorded
