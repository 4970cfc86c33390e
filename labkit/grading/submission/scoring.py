"""Grading one submission on the grader's (trusted) side: its notebooks read (JSON only, nothing run), their code
cells run in a sandboxed worker, each exercise's checks run here through proxies into it
(:mod:`labkit.grading.sandbox.remote`). A part reaching for a refused reference fails (:mod:`.scan`); one whose code
is mostly code the student has on disk (:mod:`.known`), or is built on such code, is held for a person.

``python -m labkit.grading.submission.scoring SPEC`` grades one submission in a process of its own
(:mod:`labkit.grading.run.processes`) and writes its result file.
"""

import contextlib
import functools
import json
import os
import stat
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from ...errors import InputError
from ...exercises.model import sections
from ...exercises.registry import LAB, Registry
from ...exercises.registry import load as load_registry
from ...exercises.result import CRASH, NOT_DONE, OTHER, RAISED, REFUSED, TAMPERED, TIMEOUT, VARIANT
from ...notebook import prompt_numbers
from ..options import GradeOptions
from ..sandbox import backends, remote, timings
from ..store import rubric as rubrics
from ..store.model import ExerciseResult
from ..store.record import replace_text
from ..store.report import HELD_STEP, ProblemText, SubmissionGrade, one_line, printable
from . import known, refusals, scan

OUTPUT_LIMIT = 100_000  # characters a notebook may print before its feedback says so
SHOWN_ERRORS = 12  # failing cells named in the feedback (a bare release has up to 10 per notebook)
MAX_NOTEBOOK_BYTES = 10 * 1024**2  # a lab notebook with its pictures is a few megabytes
MAX_NOTEBOOKS = 20  # notebooks graded per submission
MAX_FILES = 5_000  # entries looked at in one submission folder
MAX_DEPTH = 8  # folder levels looked into
MAX_ANSWER = 4_000  # characters of one answer in words kept for the instructor


def read_cells(path, answers=None, registry=LAB):
    """(code, markdown) cell sources of a notebook file, or a ValueError saying why it is not one (size checked
    first, no link followed). Answers in words (markdown with an answer's grade id) go into `answers`, if given."""
    path = Path(path)
    info = os.lstat(path)
    if stat.S_ISLNK(info.st_mode):
        raise InputError(f"{path.name} is a symbolic link; links are never followed.")
    if info.st_size > MAX_NOTEBOOK_BYTES:
        raise InputError(
            f"{path.name} is {info.st_size / 1024**2:.1f} MB, more than the "
            f"{MAX_NOTEBOOK_BYTES // 1024**2} MB a lab notebook needs (clear its outputs and hand it in "
            "again); it was not graded."
        )
    with os.fdopen(os.open(path, os.O_RDONLY | os.O_NOFOLLOW), "rb") as handle:
        raw = handle.read(MAX_NOTEBOOK_BYTES + 1)
    if len(raw) > MAX_NOTEBOOK_BYTES:
        raise InputError(f"{path.name} is more than {MAX_NOTEBOOK_BYTES // 1024**2} MB; it was not graded.")
    try:
        nb = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise InputError(f"{path.name} is not a text file, so not a notebook.") from None
    except (ValueError, RecursionError) as exc:
        raise InputError(f"{path.name} is not a valid notebook (not JSON: {str(exc)[:200]}).") from None
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list) or nb.get("nbformat") != 4:
        raise InputError(f"{path.name} is not a valid notebook (no list of cells in nbformat 4).")
    code, markdown = [], []
    for cell in nb["cells"]:
        source = cell.get("source", "") if isinstance(cell, dict) else None
        if isinstance(source, list) and all(isinstance(line, str) for line in source):
            source = "".join(source)
        if not isinstance(source, str):
            raise InputError(f"{path.name} is not a valid notebook (a cell without text).")
        kind = cell.get("cell_type")
        if kind == "code":
            code.append(source)
        elif kind == "markdown":
            markdown.append(source)
            meta = cell.get("metadata", {}).get("nbgrader", {}) if isinstance(cell.get("metadata"), dict) else {}
            grade_id = meta.get("grade_id") if isinstance(meta, dict) else None
            if answers is not None and grade_id in registry.answers and grade_id not in answers:
                answers[grade_id] = source[:MAX_ANSWER]
    return code, markdown


def exercises_in(markdown, registry=LAB):
    """Graded exercises whose section heading ('## Exercise N') the markdown has."""
    if hasattr(markdown, "cells"):  # an nbformat notebook
        markdown = [cell.source for cell in markdown.cells if cell.cell_type == "markdown"]
    found = {n for text in markdown for n in sections(text)}
    return sorted(found & set(registry.exercises))


def submission_notebooks(path):
    """A submission's notebooks: one .ipynb file, or the folder's (a bounded walk; links refused or left out)."""
    path = Path(path)
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        raise InputError(f"{path} does not exist.") from None
    if stat.S_ISLNK(info.st_mode):
        raise InputError(
            f"{path} is a symbolic link; links are never followed (grade the folder it points to "
            "by its own name if it is really a submission)."
        )
    if stat.S_ISREG(info.st_mode):
        if path.suffix != ".ipynb":
            raise InputError(f"{path} is not a notebook: give .ipynb files or folders of them.")
        return [path]
    if not stat.S_ISDIR(info.st_mode):
        raise InputError(f"{path} is neither a notebook nor a folder.")
    found, todo, seen = [], [(path, 0)], 0
    while todo:
        folder, depth = todo.pop()
        try:
            entries = sorted(os.scandir(folder), key=lambda e: e.name)
        except OSError:
            continue
        for entry in entries:
            seen += 1
            if seen > MAX_FILES:
                raise InputError(f"{path} holds more than {MAX_FILES} files; a submission is a few notebooks.")
            if entry.is_symlink() or entry.name == ".ipynb_checkpoints":
                continue
            if entry.is_dir(follow_symlinks=False) and depth < MAX_DEPTH:
                todo.append((Path(entry.path), depth + 1))
            elif entry.is_file(follow_symlinks=False) and entry.name.endswith(".ipynb"):
                found.append(Path(entry.path))
    if not found:
        raise InputError(f"{path} contains no notebooks (*.ipynb).")
    return sorted(found)[:MAX_NOTEBOOKS]


def _failed_part(part, step, detail, hint, kind=None):
    """The part's check, failed at one step (and no other)."""
    base = {"name": part.name, "passed": False, "hint": hint, "weight": part.weight}
    return _with_step(base, step, detail, hint, kind)


def _with_step(check, step, detail, hint, kind=None, **more):
    """`check` (updated with `more`) with `hint` and one more `step`, failed with `detail` (of `kind`,
    :data:`labkit.exercises.result.KINDS`, unless a slip)."""
    failed = {"step": step, "passed": False, "detail": detail, **({"kind": kind} if kind else {})}
    return {**check, **more, "steps": [*check.get("steps", []), failed], "hint": hint}


def _voided(part, tampered):
    """The check of a part of a notebook that tampered with the grader's watch: none of its answers count."""
    step, hint = "the notebook's answers can be trusted", "remove what the message names and hand it in again."
    return _failed_part(part, step, tampered, hint, TAMPERED)


def _own_code(check, findings):
    """The part's check, failed: the graded function reaches for refused references (its other steps kept)."""
    details = "; ".join(
        f"{function} (line {line} of its definition) reaches for {name}" for function, line, name in findings[:8]
    )
    hint = "the exercise asks you to write this yourself; labkit.bracket and the helpers the lab names stay available."
    return _with_step(check, "calls no reference implementation", details, hint, REFUSED, passed=False)


def _held(check, found):
    """The part's check, held for a person: it passed, but its code is mostly a known source's."""
    detail = (
        f"{found.share:.0%} of the code of {found.definition} (names aside) is the same as {found.source}'s; "
        "held for your instructor to look at"
    )
    hint = (
        "this part's points wait until your instructor has compared your code with the one it resembles (shown "
        "below); write the exercise in your own way to be paid without waiting."
    )
    return _with_step(check, HELD_STEP, detail, hint, held=asdict(found))


def _rescore(verdict, registry):
    exercise = registry.exercises[verdict["exercise"]]
    points = sum(check.get("weight", 0) for check in verdict["checks"] if check["passed"] and not check.get("held"))
    fraction = points / exercise.points if exercise.points else 1.0
    verdict.update(points=points, passed=points == exercise.points, fraction=fraction)
    return verdict


def _student_frames(traceback):
    """The lines of a traceback about the student's code (not its header, nor IPython's or libraries' frames)."""
    kept, skipping = [], False
    for line in traceback.splitlines():
        if line.startswith("Traceback (most recent call last)"):
            continue
        if line.startswith("  File "):
            skipping = "site-packages" in line or "/lib/python" in line
        elif not line.startswith("    "):
            skipping = False  # the exception's own line
        if not skipping:
            kept.append(line)
    return kept


@functools.cache
def _release_code():
    """The code cells of the packaged student release."""
    from ...student_notebooks import paths

    return [cell for path in paths() for cell in read_cells(Path(str(path)))[0]]


@functools.cache
def _released_cells():
    """The release's code cells, whitespace collapsed: a submission's cell among them was never changed."""
    return {" ".join(cell.split()) for cell in _release_code()}


def _untouched(error, code):
    """Whether a cell that raised is work not done: a stub's NotImplementedError, or a release cell left as is."""
    if error.get("kind") == "NotImplementedError":
        return True
    cell = error.get("cell")
    return isinstance(cell, int) and 0 <= cell < len(code) and " ".join(code[cell].split()) in _released_cells()


def _run_problems(name, ran, code=()):
    problems, numbers = [], prompt_numbers(code)  # a cell named as Jupyter numbers it: [n] after Run All
    errors = ran.get("errors") if isinstance(ran.get("errors"), list) else []
    if errors:
        shown, kinds = [], []
        for error in errors[:SHOWN_ERRORS]:
            error = error if isinstance(error, dict) else {}
            index = int(error.get("cell", -1))
            cell = numbers.get(index, index + 1)
            text = f"cell {cell} raised {one_line(error.get('kind'), 100)}: {one_line(error.get('message', ''), 300)}"
            # the worker marks a cell it stopped at its own time limit; an exception named Timeout is the student's
            if error.get("timeout") is True:
                kinds.append((TIMEOUT, f"{name}: cell {cell} ran past its time limit"))
            elif _untouched(error, code):  # a stub, or a cell as released: work not done, not an error of theirs
                kinds.append((NOT_DONE, f"{name}: cell {cell} raised {one_line(error.get('kind'), 100)}"))
            else:
                kinds.append((RAISED, f"{name}: {text}"))
            tail = _student_frames(str(error.get("traceback", ""))[-4000:])
            if tail:
                text += "\n" + "\n".join(f"      | {line}" for line in tail[-6:])
            shown.append(text)
        more = f"\n    and {len(errors) - SHOWN_ERRORS} more" if len(errors) > SHOWN_ERRORS else ""
        text = f"{name}: {len(errors)} cell(s) raised an error (graded as far as it got):\n    "
        problems.append(ProblemText(text + "\n    ".join(shown) + more, kinds))
    if int(ran.get("output_chars", 0) or 0) > OUTPUT_LIMIT:
        text = f"{name}: printed {int(ran['output_chars']):,} characters of output (none of it is kept)."
        problems.append(ProblemText.one(text, OTHER))
    return problems


@functools.lru_cache(maxsize=1)
def _profiles(registry):
    """The refusals of every exercise, computed once per grading process."""
    return refusals.wire(registry.refusals)


def known_sources(registry, folder=None):
    """The known code a part's is compared with: labkit's, the refused modules' and the instructor notebooks in
    `folder`, if given (an InputError when it holds none)."""
    if folder is None:
        return known.corpus(tuple(registry.refusals), ())
    folder = Path(folder)
    notebooks = sorted(folder.glob("*.ipynb")) if folder.is_dir() else []
    if not notebooks:
        raise InputError(
            f"{folder} holds no instructor notebooks (*.ipynb): give --solutions the folder of the course's "
            "instructor notebooks (the course repository's notebooks/)."
        )
    stamps = tuple((str(p), p.stat().st_mtime_ns, p.stat().st_size) for p in notebooks)
    return known.corpus(tuple(registry.refusals), _solutions(stamps))


def warm(registry, solutions=None):
    """Compute what grading every submission reads alike, the known code's fingerprints and the reader of a
    text's own code, so that a process forked afterwards (:mod:`labkit.grading.run.launcher`) finds them made."""
    _own_reader()
    known_sources(registry, solutions)  # last: an InputError here (no notebooks in `solutions`) leaves the rest made


@functools.lru_cache(maxsize=4)
def _solutions(stamps):
    """The notebooks named in `stamps`, ((name, code cells), ...), read once while none of them changes (their
    paths, times and sizes)."""
    return tuple((Path(path).name, tuple(read_cells(Path(path))[0])) for path, _, _ in stamps)


def judge_known(check, part, code, registry, options):
    """A part's check, held for a person when it passed and the code it judges (`code`: the cells) is mostly known
    code: a refused part's graded functions and what they reach; any other part's (a plot, a table) the code that
    draws it, graded functions aside, each judged in its own part."""
    if not check["passed"]:
        return check
    # a graded function another part judges (the driver's interpolant) is judged there, once
    own = part.scanned if part.refused is not None else ()
    try:
        names = own if part.refused is not None else sorted(scan.drawn_with(code, part.names()))
        reached = scan.reached_sources(code, names)
    except scan.Unreadable:
        return check  # nothing held for cells that cannot be read (a refused part failed for them first)
    graded = registry_graded(registry)
    reached = [(n, t) for n, t in reached if n in own or n not in graded]
    found = known.match(known_sources(registry, options.solutions), reached, _own_reader())
    return check if found is None else _held(check, found)


def hold_dependents(results, registry, code):
    """Hold, in `results` ({exercise: verdict}), every passed part whose code reaches a held definition, and
    fail those reaching a graded name a string run as code may have defined: copied code earns nothing through
    what it draws."""
    held = {}  # name: its held match, for the held parts' graded names and the copies
    for number, verdict in results.items():
        for part, check in zip(registry.exercises[number].parts, verdict["checks"]):
            if check.get("held") and check.get("passed"):
                for name in (*part.scanned, check["held"].get("definition", "")):
                    held.setdefault(name, check["held"])
    strung = {}
    with contextlib.suppress(scan.Unreadable):
        strung = {name: why for name, _, why in scan.run_strings(code, sorted(registry_graded(registry)))}
    if not held and not strung:
        return results
    for number, verdict in results.items():
        for index, (part, check) in enumerate(zip(registry.exercises[number].parts, verdict["checks"])):
            if not check.get("passed") or check.get("held"):
                continue
            names = set(part.uses)
            with contextlib.suppress(scan.Unreadable):
                names |= scan.drawn_with(code, [*part.names(), *part.scanned])
            names -= set(part.scanned)
            on_held, on_string = [n for n in held if n in names], sorted(names & strung.keys())  # graded names first
            if on_held:
                verdict["checks"][index] = _held_with(check, on_held[0], held[on_held[0]])
            elif on_string:
                verdict["checks"][index] = _refused_with(check, on_string[0], strung[on_string[0]])
        _rescore(verdict, registry)
    return results


def _held_with(check, name, held):
    detail = (
        f"it is built on {name}, held for your instructor to look at: its code is mostly {held.get('source', '?')}'s"
    )
    hint = (
        f"this part waits with {name}, which it is built on; write {name} in your own way to be paid without waiting."
    )
    return _with_step(check, HELD_STEP, detail, hint, held={**held, "through": name})


def _refused_with(check, name, why, step="is built on the student's own code"):
    """The part's check, failed: it is built on `name`, which a string run as code may have defined (`why`)."""
    hint = (
        f"define {name} with def in a code cell, after any exec, eval or compile of a string, so that the grader "
        "can read it; code run from a string is never graded."
    )
    return _with_step(check, step, why, hint, REFUSED, passed=False)


@functools.lru_cache(maxsize=1)
def registry_graded(registry):
    """Every name a part of the registry scans: the functions judged for copied code each in their own part."""
    return {n for e in registry.exercises.values() for p in e.parts for n in p.scanned}


@functools.cache
def _own_reader():
    return known.own_reader(_release_code())


def _for_sandbox(profiles):
    return {name: {key: profile[key] for key in ("names", "modules", "c_names")} for name, profile in profiles.items()}


def graded_functions(exercise):
    """The names whose ``def`` source the grade keeps: the exercise's and those its parts scan, in order."""
    names = list(exercise.names) + [name for part in exercise.parts for name in part.scanned]
    return [name for name in dict.fromkeys(names) if name.isidentifier()]


def grade_notebook(
    path, options=None, *, deadline=None, skip=(), profiles=None, answers=None, sources=None, variant=None
):
    """Run one notebook in the sandbox and check it: ({exercise: grade dict}, [problems]). `deadline` (monotonic)
    is the submission's; exercises in `skip` are not checked. Answers in words go into `answers` and the source of
    each graded function not yet there into `sources`, when given; `variant` is the student's own data."""
    options = _options(options)
    deadline = deadline if deadline is not None else time.monotonic() + options.total_timeout
    registry = load_registry(options.exercises)
    profiles = profiles or _profiles(registry)
    name = one_line(Path(path).name, 120)
    try:
        code, markdown = read_cells(path, answers, registry)
    except (ValueError, OSError) as exc:
        return {}, [ProblemText.one(f"{name}: {exc}" if name not in str(exc) else str(exc), OTHER)]
    numbers = [n for n in exercises_in(markdown, registry) if n not in skip]
    if not numbers:
        return {}, []
    size = scan.code_bytes(code)
    if size > scan.MAX_CODE_BYTES:
        text = (
            f"{name}: its code cells hold {size:,} bytes, more than the {scan.MAX_CODE_BYTES:,} a lab "
            "notebook needs; it was not graded."
        )
        return {}, [ProblemText.one(text, OTHER)]
    if sources is not None:
        wanted = [n for number in numbers for n in graded_functions(registry.exercises[number]) if n not in sources]
        for function, text in scan.reached_function_sources(code, wanted, registry_graded(registry)).items():
            sources[function] = printable(text)[: scan.MAX_SOURCE_CHARS]
    if deadline - time.monotonic() <= 1:
        text = (
            f"{name}: not run: the submission's time limit of {options.total_timeout} s was used up "
            "by the notebooks before it."
        )
        return {}, [ProblemText.one(text, TIMEOUT)]
    try:
        with timings.phase("sandbox start"):
            notebook = remote.NotebookHandle(options, deadline, _for_sandbox(profiles), registry.passable)
    except remote.NotebookTimeout:  # its sandbox was still starting when the submission's time ran out
        return {}, [_stopped(name, options)]
    except remote.WorkerError as exc:
        return {}, [ProblemText.one(f"{name}: the sandbox could not start ({exc}).", OTHER)]
    with notebook:
        graded = _Graded(name, notebook, code, registry, profiles, options)
        return _grade_in(graded, numbers, variant)


def _stopped(name, options):
    return ProblemText.one(f"{name}: stopped after the submission's time limit of {options.total_timeout} s.", TIMEOUT)


@dataclass(frozen=True)
class _Graded:
    """One notebook being graded: its name as problems give it, its sandbox, its code cells and how it is judged."""

    name: str
    notebook: remote.NotebookHandle
    code: list
    registry: Registry
    profiles: dict
    options: GradeOptions


def _grade_in(graded, numbers, variant):
    """Run the notebook's cells in its sandbox, then check exercises `numbers`: (results, problems)."""
    name, notebook, code, options = graded.name, graded.notebook, graded.code, graded.options
    run = {"op": "run", "cells": code, "cell_timeout": options.cell_timeout}
    try:
        with timings.phase("cells"):
            ran = notebook.request(run, options.total_timeout)
    except remote.NotebookTimeout:
        return {}, [_stopped(name, options)]
    except remote.CellTimeout as exc:
        return {}, [ProblemText.one(f"{name}: {exc}.", TIMEOUT)]
    except remote.WorkerError as exc:
        return {}, [ProblemText.one(f"{name}: {exc} while running its cells.", exc.grader_kind)]
    if "error" in ran and not notebook.tampered:  # the notebook's process died while its cells ran
        error = ran["error"] if isinstance(ran["error"], dict) else {}
        text = f"{name}: {str(error.get('message', 'it stopped'))[:300]} while running its cells."
        return {}, [ProblemText.one(text, CRASH)]
    problems, results = _run_problems(name, ran, code), {}
    if notebook.tampered:
        problems.append(ProblemText.one(f"{name}: {notebook.tampered}; none of its answers count.", TAMPERED))
    for number in numbers:
        mine = None if variant is None else variant.get(str(number), {})
        results[number] = _check_exercise(graded, number, mine, problems)
    hold_dependents(results, graded.registry, code)
    if notebook.stopped:
        text = f"{name}: {notebook.stopped} while its functions were being checked."
        problems.append(ProblemText.one(text, notebook.stopped_kind))
    return results, problems


def _check_exercise(graded, number, variant, problems):
    """Exercise `number`'s grade dict; holding data other than `variant` (the student's) is named in `problems`."""
    notebook, registry, exercise = graded.notebook, graded.registry, graded.registry.exercises[number]
    if notebook.tampered:
        checks = [_voided(part, notebook.tampered) for part in exercise.parts]
        return _rescore({"exercise": number, "defined": True, "checks": checks}, registry)
    verdict = registry.check(number, remote.Namespace(notebook), seed=graded.options.seed, variant=variant)
    if notebook.stopped:  # what it held can no longer be read: no one is named for it
        verdict.pop("other_variant", None)
    other = verdict.get("other_variant")  # kept in the result: the class run names whose data they are
    if other:
        shown = "; ".join(
            f"{param} = {_number(found)} where yours is {_number(value)}"
            for param, (found, value) in sorted(other.items())
        )
        text = (
            f"{graded.name}: exercise {number}: this notebook holds the data of another variant ({shown}); "
            "its parts that depend on the data earn nothing until they are worked on your own."
        )
        problems.append(ProblemText.one(text, VARIANT))
    with timings.phase("recognition"):
        verdict["checks"] = [_judged(check, part, graded) for part, check in zip(exercise.parts, verdict["checks"])]
    return _rescore(verdict, registry)


def _judged(check, part, graded):
    """A part's check, failed for a refused reference or a string run as code, held for known code."""
    code, registry, options = graded.code, graded.registry, graded.options
    if part.refused is None:
        return judge_known(check, part, code, registry, options)
    try:
        findings = scan.scan(code, part.scanned, graded.profiles[part.refused.name])
        strung = scan.run_strings(code, part.scanned)
    except scan.Unreadable as exc:
        why = "keep the notebook's code to what the lab asks for."
        return _failed_part(part, "its source can be read", str(exc), why)
    if findings:
        return _own_code(check, findings)
    if strung:
        name, _, why = strung[0]
        return _refused_with(check, name, why, step="its code can be read")
    return judge_known(check, part, code, registry, options)


def _number(value):
    """A notebook's value for the feedback: a number as printed, anything else by its kind, on one short line."""
    return f"{value:g}" if isinstance(value, (int, float)) else one_line(str(value), 40)


def _options(options):
    """`options`, or the defaults when None; ValueError for anything else."""
    if options is None:
        return GradeOptions()
    if not isinstance(options, GradeOptions):
        raise InputError(f"options must be a GradeOptions (labkit.grading.options); got {options!r}.")
    return options


def submission_name(path):
    """A submission's name: its folder's or notebook's, bytes that are not UTF-8 spelled out as escapes."""
    path = Path(path)
    name = path.stem if path.suffix == ".ipynb" else path.name
    return name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def grade_submission(path, options=None, *, profiles=None, name=None):
    """Grade one submission (a notebook or a folder of them) with the options' rubric (else the lab's) within one
    time limit; `name` (its folder's by default) picks its variant's data."""
    options = _options(options)
    rubric = rubrics.load(options.rubric) if options.rubric is not None else None
    deadline = time.monotonic() + options.total_timeout
    grade = SubmissionGrade(submission_name(path) if name is None else str(name), seed=options.seed)
    variant = options.variants.get(grade.name) if options.variants is not None else None
    if options.variants is not None and variant is None:
        grade.failure = "no variant in this run's roster: add the submission to the roster and grade again."
        return grade
    if rubric is not None:
        grade.rubric = rubric
    try:
        notebooks = submission_notebooks(path)
    except ValueError as exc:
        grade.problems.append(ProblemText.one(str(exc), OTHER))
        return grade
    shared = {"deadline": deadline, "profiles": profiles, "answers": grade.answers, "sources": grade.sources}
    for notebook in notebooks:
        claimed = {n for n, verdict in grade.results.items() if verdict.defined}
        with timings.phase("notebooks"):
            results, problems = grade_notebook(notebook, options, skip=claimed, variant=variant, **shared)
        grade.problems.extend(problems)
        for number, verdict in results.items():
            # an exercise counts from the first notebook that defines its names (or else the first to mention it)
            current = grade.results.get(number)
            if current is None or (verdict["defined"] and not current.defined):
                grade.results[number] = ExerciseResult.from_dict(verdict, number, grade.name)
    return grade


def main(argv=None):
    """Grade the submission a spec file describes and write its result file (:mod:`labkit.grading.run.processes`)."""
    argv = sys.argv[1:] if argv is None else argv
    spec = json.loads(Path(argv[0]).read_text(encoding="utf-8"))
    profiles = json.loads(Path(spec["profiles"]).read_text(encoding="utf-8"))
    if spec.get("backend_origin"):  # a backend registered outside labkit: its module registers it here too
        backends.import_origin(*spec["backend_origin"])
    options = GradeOptions.from_dict(spec["options"])  # the run's options, read once at this process's edge
    timings.reset()
    grade = grade_submission(spec["submission"], options=options, profiles=profiles, name=spec["name"])
    replace_text(Path(spec["result"]), json.dumps(grade.as_dict()))
    timings.write_beside(spec["result"])  # where the time went, for the run's folder (never the student's feedback)
    return 0


if __name__ == "__main__":
    sys.exit(main())
