"""The ``labkit`` command: execute, release and grade the lab's notebooks.

``labkit notebooks DIR``                   write the student notebooks shipped with labkit into DIR
``labkit handin DIR``                      ready to hand in? run DIR's notebooks and list what is left to do
``labkit execute DIR``                     re-run the instructor notebooks of DIR and save them clean
``labkit release DIR --out DIR``           write the student version of the instructor notebooks
``labkit grade SUBMISSION... --out DIR``   grade submitted notebooks (or folders of them) in a sandbox
``labkit merge DIR... --out DIR``          combine the results of several grading runs
``labkit report OUT``                      write OUT/report.html: the class at a glance, from a grading run
``labkit rubric``                          print the lab's rubric (TOML) to copy and edit for --rubric
``labkit export DIR --canvas FILE ...``    the totals into the course's Canvas gradebook (or --moodle)
``labkit variants --new FILE``             a course's variants file: every student their own data
"""

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

from .errors import InputError

GRADE_EXTRA = ("nbformat", "nbclient", "rich")


def _notebooks(args):
    from .student_notebooks import paths

    out = args.out
    sources = paths()
    existing = [out / p.name for p in sources if (out / p.name).exists()]
    if existing and not args.force:
        raise InputError(
            f"{existing[0]} already exists (your work?); choose another folder, or --force to "
            "overwrite the notebooks there."
        )
    out.mkdir(parents=True, exist_ok=True)
    for source in sources:
        (out / source.name).write_bytes(source.read_bytes())
        print(f"wrote {out / source.name}")
    return 0


def _handin(args):
    from .handin import lab_notebook_of

    folder = args.folder
    if not folder.exists():
        raise InputError(f"there is no {folder}; give the folder that holds your notebooks (or one notebook).")
    if folder.is_file():
        files = [folder] if folder.suffix == ".ipynb" else []
    else:
        files = sorted(p for p in folder.glob("*.ipynb") if not p.name.startswith("."))
    if not files:
        raise InputError(f"{folder} holds no notebooks (*.ipynb); give the folder you work in.")
    if args.timeout < 1:
        raise InputError(f"--timeout must be at least 1 second; got {args.timeout}.")
    lab = [(path, lab_notebook_of(path)) for path in files]
    skipped = [path.name for path, name in lab if name is None]
    lab = [(path, name) for path, name in lab if name is not None]
    if not lab:
        raise InputError(
            f"none of the notebooks in {folder} is one of the lab's ({', '.join(skipped)}); give the folder "
            "that holds 01_limacon.ipynb ... 06_bilinear.ipynb."
        )
    try:
        import nbclient  # noqa: F401 - the student's install may lack it: say so before running anything

        from .handin import run_notebook
    except ModuleNotFoundError as exc:
        raise InputError(
            f"labkit handin runs the notebooks with {exc.name}, which is not installed: pip install nbclient"
        ) from None
    results = []
    for path, _ in lab:
        print(f"running {path.name} ...", file=sys.stderr, flush=True)
        result = run_notebook(path, timeout=args.timeout)
        if path.name != result.notebook:
            result.notebook = f"{path.name} ({result.notebook})"
        results.append(result)
        print(result.text() + "\n", flush=True)
    ready = sum(result.ready for result in results)
    if skipped:
        print(f"Not lab notebooks, not run: {', '.join(skipped)}.")
    from .handin import _wrapped
    from .handin_summary import folder_lines

    for line in folder_lines([name for _, name in lab], ready):
        print(_wrapped(line, ""))
    return 0 if ready == len(results) else 1


def _execute(args):
    from nbclient.exceptions import CellExecutionError

    from .execute import execute, notebook_paths
    from .grading.authoring.nbgrader import mark
    from .grading.authoring.release import tag_raising
    from .grading.store.rubric import load

    rubric = load(args.rubric)  # nbgrader's points are the rubric's in force

    for path in notebook_paths(args.notebooks):

        def marked(nb, name, folder=path.parent):
            tag_raising(nb, folder, name, args.timeout)  # Run All goes on past them in the student's copy
            return mark(nb, name, rubric)

        print(f"executing {path.name} ...", flush=True)
        try:
            execute(path, timeout=args.timeout, before_save=marked)
        except CellExecutionError as exc:
            raise InputError(f"{path.name} failed; it was not saved.\n{str(exc)[:2000]}") from None
    return 0


def _roster_and_variants(args, purpose):
    """(roster, variants file) of ``--roster`` and ``--variants``, both or neither (None, None)."""
    if args.roster is None and args.variants is None:
        return None, None
    if args.roster is None or args.variants is None:
        raise InputError(f"give both --roster and --variants {purpose}, or neither.")
    from .exercises import variants
    from .grading.reports.lms import read_roster

    return read_roster(args.roster), variants.read(args.variants)


def _release(args):
    from .grading.authoring.release import release

    roster, variants = _roster_and_variants(args, "for a release per student")
    registry = _course(args)
    written = release(args.notebooks, args.out, roster, variants, registry)
    if roster is None:
        for path in written:
            print(f"wrote {path}")
        return 0
    print(f"wrote {len(written)} notebooks for {len(roster)} students into {args.out}, one folder each")
    _ties(variants, registry, roster)
    return 0


def _course(args):
    """The exercises of ``--rubric`` (a course's own, named in its rubric), else the lab's."""
    if getattr(args, "rubric", None) is None:
        from .exercises.registry import LAB

        return LAB
    from .grading.store.rubric import load

    return load(args.rubric).registry


def _ties(variants, registry, roster):
    """Name, on stderr, the roster's students who drew the same data of an exercise."""
    from .exercises.variants import ties
    from .grading.store.report import one_line

    ids = {key: name for name, key in roster.items()}
    for number, tied in ties(variants, registry, roster.values()):
        names = ", ".join(one_line(ids[key], 40) for key in tied)
        print(
            f"labkit: {names} drew the same data of exercise {number}: a copy between them cannot be seen; give "
            f"all but one a fresh draw (labkit variants --redraw ID --exercise {number}) and release again",
            file=sys.stderr,
        )


def _summary(grades, out, start, what):
    from .grading.store.report import one_line
    from .grading.store.text import points_text

    for g in grades:
        lateness = g.lateness
        late = f"  ({points_text(lateness.penalty)} off for late work)" if lateness and lateness.penalty else ""
        print(f"{one_line(g.name, 30):<30} {points_text(g.total) if g.graded else 'not graded':>10}{late}")
    print(
        f"{what} {len(grades)} submission(s) in {time.perf_counter() - start:.1f} s; "
        f"wrote {out / 'grades.csv'}, {out / 'feedback'}/ and {out / 'results'}/"
    )


def _replaced(replaced):
    """Say which results a later folder's replaced in a merge."""
    from .grading.store.report import one_line

    if not replaced:
        return
    print(f"{len(replaced)} result(s) replaced by a later folder's (the later one counts; see merge.json):")
    for r in replaced:
        kept = "; its submission time kept from the earlier result" if r.time_kept else ""
        print(f"  {one_line(r.name, 60)}: {one_line(r.earlier, 200)} -> {one_line(r.later, 200)}{kept}")


def _times_notes(grades, rubric, times):
    """Tell the instructor about the submission times: times that cost nothing or match no submission, and
    each submission a deadline applies to whose time is unknown. The number of times that could not be read."""
    from .grading.store.late import unknown_times
    from .grading.store.report import one_line

    def names(found):
        shown = ", ".join(repr(one_line(name, 40)) for name in sorted(found)[:5])
        return shown + (f" and {len(found) - 5} more" if len(found) > 5 else "")

    graded = {g.name for g in grades}
    if times and rubric.late is None:
        print(
            "labkit grade: the rubric has no [late] table, so the times cost nothing; they are saved with the "
            "results for a `labkit merge` with a rubric that has one.",
            file=sys.stderr,
        )
    stray = set(times or ()) - graded
    if stray:
        print(f"labkit grade: the times file names submission(s) not in this run: {names(stray)}.", file=sys.stderr)
    extended = {name for name, _ in rubric.late.extensions} - graded if rubric.late else set()
    if extended:
        print(
            f"labkit grade: the rubric's [late.extensions] name submission(s) not in this run: {names(extended)}.",
            file=sys.stderr,
        )
    unknown = unknown_times(grades)
    for name, note, error in unknown:
        print(
            f"{'time unreadable' if error else 'no time'} for {one_line(name, 80)}: {one_line(note, 300)}",
            file=sys.stderr,
        )
    if unknown:
        print(
            f"labkit grade: {len(unknown)} submission(s) have no known time, so no late penalty; give their times "
            "in --times TIMES.csv (submission,time) and merge again (labkit merge DIR --times TIMES.csv "
            "--out NEW).",
            file=sys.stderr,
        )
    return sum(error for *_, error in unknown)


def _resumed(out):
    """Say how many submissions an earlier run into the same folder had graded, and which part of a shard this is."""
    try:
        record = json.loads((out / "run.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return
    changed = record.get("graded again, changed")
    again = f", {changed} of them graded again because their notebooks changed" if changed else ""
    if record.get("already graded") or changed:
        print(
            f"resumed {out}: {record['already graded']} submission(s) were graded there already and kept, "
            f"{record.get('graded now', 0)} graded now{again} (--fresh grades all again)"
        )
    else:
        print(f"graded {record.get('graded now', 0)} submission(s) now")
    if record.get("shard"):
        print(
            f"shard {record['shard']}: {record.get('submissions')} submission(s); combine the shards with "
            "`labkit merge`"
        )


def grade_options(args):
    """The :class:`~labkit.grading.options.GradeOptions` of `labkit grade`'s arguments; ValueError for a bad one."""
    from .grading.options import CPU_GRACE, MIB, GradeOptions
    from .grading.sandbox.backends.base import Limits

    for name in ("jobs", "cell_timeout", "total_timeout", "memory", "grader_memory"):
        if getattr(args, name) < 1:
            raise InputError(f"--{name.replace('_', '-')} must be at least 1; got {getattr(args, name)}.")
    return GradeOptions(
        cell_timeout=args.cell_timeout,
        total_timeout=args.total_timeout,
        seed=args.seed,
        backend=args.sandbox,
        rubric=args.rubric,
        grader_memory=args.grader_memory * MIB,
        limits=Limits(memory=args.memory * MIB, cpu_seconds=args.total_timeout + CPU_GRACE),
        fork_server=not args.no_fork_server,
        solutions=args.solutions,
        jobs=args.jobs,
        shard=args.shard,
        fresh=args.fresh,
        times_from_submission=args.times_from_submission,
        times_from_mtime=args.times_from_mtime,
    )


def _engine(args):
    """The engine of `labkit grade`'s arguments (labkit.grading.run.engines): ``--dask``'s, else ``--jobs``
    grading processes here."""
    if args.dask is None:
        from .grading.run.engines import LocalEngine

        return LocalEngine(args.jobs)
    from .grading.run.dask import DaskEngine

    return DaskEngine(args.dask, 2 if args.dask_workers is None else args.dask_workers)


def _merge(args):
    from .grading import merge
    from .grading.run.classrun import report_failures
    from .grading.store.late import read_times

    start = time.perf_counter()
    given = [flag for flag, value in (("--shard", args.shard), ("--dask", args.dask), ("--fresh", args.fresh)) if value]
    if given:
        raise InputError(f"{', '.join(given)} grade(s) submissions, which `labkit merge` does not; merge without them.")
    for flag in ("times_from_mtime", "times_from_submission", "times_from_exchange"):
        if getattr(args, flag):
            raise InputError(
                f"--{flag.replace('_', '-')} reads the submissions' files or the exchange, which `labkit merge` does "
                "not: give the times in --times TIMES.csv (the results keep the times they were graded with)."
            )
    times = read_times(args.times) if args.times else None
    grades = merge(args.folders, args.out, args.rubric, times=times, progress=not args.quiet)
    _summary(grades, args.out, start, "merged")
    _replaced(grades.replaced)
    _refused(grades, "the merge")
    unreadable = _times_notes(grades, grades.rubric, times)
    return 1 if report_failures(grades) or unreadable or grades.refused else 0


def _grade(args):
    from .grading import Submissions, grade
    from .grading.run.classrun import report_failures
    from .grading.store.late import read_exchange, read_times

    if args.merge is not None:
        raise InputError(
            "`labkit grade --merge` is now a command of its own: labkit merge DIR... --out DIR [--rubric R] "
            "[--times T]."
        )
    start = time.perf_counter()
    times = read_times(args.times) if args.times else None
    if not args.submissions:
        raise InputError(
            "give the submissions: the class folder (or zip) the LMS gave you, or each submission (notebooks or "
            "folders); `labkit merge DIR...` combines runs."
        )
    if args.dask_workers is not None and args.dask != "local":
        raise InputError("--dask-workers is the size of --dask local; a cluster's workers are started on its machines.")
    options = grade_options(args)
    engine = _engine(args)
    roster, variants = _roster_and_variants(args, "to grade each student against their own data")
    if args.shard is not None:
        from .grading.run.resume import parse_shard

        parse_shard(args.shard)  # a bad one is refused before anything is read
    exchange = None
    if args.times_from_exchange is not None:
        if not args.assignment:
            raise InputError("--times-from-exchange needs --assignment NAME: the assignment's name in nbgrader.")
        exchange = read_exchange(args.times_from_exchange, args.assignment)
    for given in args.submissions:
        if given.is_dir() and args.out.resolve().is_relative_to(given.resolve()):
            raise InputError(
                f"--out {args.out} is inside {given}, where it would read as part of a submission: give an --out "
                "outside it."
            )
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=".labkit-unpacked-", dir=args.out) as workspace:
        found = _class(args, Path(workspace))
        given = Submissions(found.paths, found.names, found.ungradable, times, exchange, roster, variants)
        grades = grade(given, args.out, options, engine=engine, progress=not args.quiet)
    if found.intake is not None:
        from .grading.reports.delivery import remember

        remember(args.out, found.intake)
    rubric = grades.earlier.rubric
    _summary(grades, args.out, start, "listed")
    _resumed(args.out)
    _refused(grades.earlier, "the resumed run")
    print(f"random test data from seed {(args.out / 'seed.txt').read_text().strip()} (repeat the run with --seed)")
    for line in found.notes:
        print(f"labkit grade: {line}", file=sys.stderr)
    if variants is not None:
        others = sum(any(v.get("other_variant") for v in g.results.values()) for g in grades if g.graded)
        print(
            f"each student graded against their own data; {others} submission(s) hold another's: see "
            f"{args.out / 'variants.csv'}"
        )
    _late_marks(grades, found.marked_late)
    unreadable = _times_notes(grades, rubric, times)
    failed = report_failures(grades)
    if unreadable and not failed:
        return 1
    if failed:
        print(
            f"labkit grade: {failed} submission(s) could not be graded (see above and their feedback); "
            "every other submission is in grades.csv.",
            file=sys.stderr,
        )
        return 1
    return 0


class _Class:
    """The submissions of `labkit grade`'s arguments: paths and names to grade, students with nothing to grade
    ({name: why}), notes for the instructor, and the names the LMS marked late."""

    def __init__(self, paths, names=None, ungradable=None, notes=(), marked_late=()):
        self.paths, self.names, self.ungradable = paths, names, dict(ungradable or {})
        self.notes, self.marked_late = list(notes), set(marked_late)
        self.intake = None


def _class(args, workspace):
    """One class folder or zip as the LMS gives it (labkit.grading.run.intake), or the submissions one by one."""
    from .grading.run import intake

    paths = args.submissions
    if len(paths) != 1 or not intake.is_class(paths[0]):
        for flag, value in (("--assignment", args.assignment), ("--student", args.student)):
            if value:
                raise InputError(f"{flag} picks from a class folder (or zip) as the LMS gives it; give that folder.")
        found = intake.find_students(paths, workspace)
    else:
        from .grading.reports.lms import read_roster

        roster = read_roster(args.roster) if args.roster is not None else None  # its ids decide whose a file is
        found = intake.find_class(paths[0], workspace, assignment=args.assignment, roster=roster)
    if args.student:
        names = {student.name for student in found.students}
        unknown = [name for name in args.student if name not in names]
        if unknown:
            from .grading.store.report import one_line

            shown = ", ".join(repr(one_line(name, 64)) for name in sorted(names)[:10])
            raise InputError(
                f"--student {one_line(unknown[0], 60)!r} is not in {paths[0]}; its students are named {shown}"
                f"{' ...' if len(names) > 10 else ''} (as in grades.csv)."
            )
        found.students = [student for student in found.students if student.name in args.student]
    gradable = [student for student in found.students if student.path is not None]
    chosen = _Class(
        [student.path for student in gradable],
        [student.name for student in gradable],
        {student.name: student.failure for student in found.students if student.path is None},
        ([f"{found.layout} layout in {paths[0]}: {len(found.students)} student(s)"] if found.layout != "listed" else [])
        + found.notes,
        {student.name for student in found.students if student.marked_late},
    )  # (a listed submission's name is its folder's or notebook's, as before)
    chosen.intake = found  # the layout and the LMS's names, for handing the feedback back (labkit feedback)
    return chosen


def _refused(found, what):
    """Name each result file that was not read (its run's record does not vouch for it)."""
    from .grading.store.report import one_line

    for path, why in found.refused:
        print(f"labkit: {what}: not read: {one_line(path, 200)}: {one_line(why, 300)}", file=sys.stderr)


def _late_marks(grades, marked):
    """Name the submissions the LMS marked late whose time labkit does not know (so no penalty was applied)."""
    from .grading.store.report import one_line

    unknown = [g.name for g in grades if g.name in marked and g.graded and (g.time is None or g.time.when is None)]
    for name in unknown:
        print(
            f"labkit grade: the LMS marked {one_line(name, 80)} late, but gave no time: give the LMS's submission "
            "times in --times TIMES.csv for the late rule to apply.",
            file=sys.stderr,
        )


def _export(args):
    from .grading.reports import lms
    from .grading.store.record import rubric_for
    from .grading.store.report import read_results

    if args.canvas is not None and args.feedback:
        raise InputError("--feedback is for --moodle; a Canvas gradebook has no feedback column to import.")
    if args.canvas is None and args.new_column:
        raise InputError("--new-column is for --canvas; Moodle's import maps a column to a new grade item itself.")
    # the run's recorded rubric (late rule included): what is exported is grades.csv's total
    grades = read_results([args.results], rubric_for([args.results], args.rubric, "labkit export"))
    _refused(grades, "labkit export")
    if args.canvas is not None:
        export = lms.to_canvas(
            grades,
            args.canvas,
            args.roster,
            args.out or lms.default_file(args.results, "canvas"),
            column=args.column,
            key=args.key or "ID",
            new_column=args.new_column,
            force=args.force,
        )
    else:
        export = lms.to_moodle(
            grades,
            args.roster,
            args.out or lms.default_file(args.results, "moodle"),
            key=args.key or "idnumber",
            column=args.column,
            feedback=args.feedback,
            force=args.force,
        )
    for line in export.problems():
        print(f"labkit export: {line}", file=sys.stderr)
    print(export.summary())
    return 1 if export.listed or grades.refused else 0


def _feedback(args):
    from .grading.reports import delivery

    path, members, notes = delivery.write_upload(args.out, args.layout)
    for line in notes:
        print(f"labkit feedback: {line}", file=sys.stderr)
    print(f"wrote {path}: {len(members)} file(s); {delivery.STEPS[delivery.layout_of(args.out, args.layout)]}")
    return 1 if notes else 0


def _report(args):
    from .grading.progress import Progress
    from .grading.reports import class_report, similarity

    start = time.perf_counter()
    threshold = args.similarity_threshold
    if not 0.0 < threshold <= 1.0:
        raise InputError(f"--similarity-threshold is a similarity above 0 and at most 1; got {threshold}.")
    grades = class_report.read(args.out, args.rubric)  # the run's recorded rubric; a different one is refused
    _refused(grades, "labkit report")
    functions = {function for grade in grades for function in grade.sources}
    with Progress(len(functions), "comparing code", enabled=not args.quiet) as bar:
        pairs, note = similarity.similar_pairs(grades, threshold, progress=bar), None
    path = class_report.write(args.out, grades, pairs, threshold=threshold, similarity_note=note)
    if not args.quiet:
        similar = "similar code not computed" if pairs is None else f"{len(pairs)} similar pair(s)"
        print(
            f"wrote {path}: {len(grades)} submission(s), {similar}, in {time.perf_counter() - start:.1f} s "
            "(open it in a browser; it needs no network)"
        )
    return 1 if grades.refused else 0


def _mark(args):
    from .grading.reports import marking
    from .grading.store.rubric import load

    rubric = None if args.rubric is None else load(args.rubric)
    if args.import_ is None:
        path = marking.write_page(args.out, args.marker, rubric)
        if not args.quiet:
            print(f"wrote {path} (open it in a browser; it needs no network; marks stay in that browser until "
                  "you download marks.csv and import it with --import)")  # fmt: skip
        return 0
    changed = marking.import_marks(args.out, args.import_, rubric)
    if not args.quiet:
        print(f"{changed} mark(s) changed in {args.out} (grades.csv, feedback/, results/ and record.json)")
    return 0


def build_parser():
    from ._cli_parser import Parser
    from .grading.options import DEFAULTS, MIB
    from .grading.reports import similarity
    from .grading.sandbox import backends

    parser = Parser(
        prog="labkit",
        description="Course kit tools for the higher-order interpolation lab.",
        epilog="Grading runs every notebook in a sandbox (`labkit grade --help` lists them: the default has no "
        "network, a read-only system, a private folder and resource limits) and checks it from outside; "
        "see docs/instructors.md.",
    )
    commands = parser.add_subparsers(dest="command", required=True)

    nbs = commands.add_parser(
        "notebooks",
        help="write the student notebooks shipped with labkit into a folder",
        description="Write the lab's six student notebooks (exercises to do, with their "
        "self-checks) into DIR, e.g. for Colab, a JupyterHub or VS Code.",
    )
    nbs.add_argument("out", type=Path, metavar="DIR", help="folder for the notebooks (created if needed)")
    nbs.add_argument("--force", action="store_true", help="overwrite notebooks of the same name in DIR")
    nbs.set_defaults(handler=_notebooks)

    hand = commands.add_parser(
        "handin",
        help="ready to hand in? run your notebooks and list what is left to do",
        description="Run each lab notebook in DIR in a fresh kernel (every cell, even after one raised) and "
        "print, per notebook, the table its last cell shows: each graded part done and passing its "
        "self-check, failing (with the hint) or not done; the cells that raised; the answers in words "
        "left empty. Only the self-checks run, never the grader. Exit status: 0 when every notebook is ready, "
        "1 when something is left to do, 2 for bad input.",
    )
    hand.add_argument("folder", type=Path, metavar="DIR", help="the folder with your notebooks (or one notebook)")
    hand.add_argument("--timeout", type=int, default=300, help="seconds allowed per cell (default %(default)s)")
    hand.set_defaults(handler=_handin)

    run = commands.add_parser(
        "execute",
        help="re-execute every notebook in a fresh kernel and save it clean",
        description="Re-execute the notebooks top to bottom in a fresh python3 kernel and save "
        "them without widget state: the reference outputs nbval compares against. Each notebook's "
        "student release is run too, and the cells that raise there are tagged raises-exception, "
        "so that Run All in a fresh copy goes on to the explorers.",
    )
    run.add_argument("notebooks", type=Path, help="folder of instructor notebooks (the course repository's notebooks/)")
    run.add_argument("--timeout", type=int, default=300, help="seconds allowed per cell (default 300)")
    run.add_argument(
        "--rubric", type=Path, help="TOML rubric whose points nbgrader's test cells get (default: the lab's)"
    )
    run.set_defaults(handler=_execute)

    rel = commands.add_parser(
        "release",
        help="write the student version of the notebooks",
        description="Replace every '### BEGIN SOLUTION' ... '### END SOLUTION' region by a stub "
        "that raises NotImplementedError, remove hidden tests, clear outputs.",
    )
    rel.add_argument("notebooks", type=Path, help="folder of instructor notebooks (the course repository's notebooks/)")
    rel.add_argument("--out", type=Path, required=True, help="folder for the student notebooks")
    rel.add_argument(
        "--roster",
        type=Path,
        help="CSV with the columns submission and id (as for labkit export): one folder per student, with --variants",
    )
    rel.add_argument(
        "--variants",
        type=Path,
        metavar="SECRET_FILE",
        help="the course's variants file (labkit variants --new): each student's notebooks hold their own data",
    )
    rel.add_argument("--rubric", type=Path, help="a course's rubric: its exercises' variants (default: the lab's)")
    rel.set_defaults(handler=_release)

    grd = commands.add_parser(
        "grade",
        help="grade submitted notebooks",
        description="Run each submission (a notebook, or a folder with a student's notebooks) in a sandbox, "
        "check every exercise from outside it, and write grades.csv, feedback/<submission>.txt, "
        "results/<submission>.json and seed.txt. `labkit merge` combines earlier runs' results.",
        epilog="Each submission's result is written as soon as it is graded. Resuming is automatic: when --out "
        "already holds results of an earlier run (same rubric and labkit version), only the submissions without "
        "one are graded, with that run's seed from seed.txt (a different --seed is refused), and a submission that "
        "could not be graded is graded again; grades.csv then covers them all. --fresh starts over instead.",
    )
    grd.add_argument(
        "submissions",
        nargs="*",
        type=Path,
        help="the class as the LMS gives it (one folder or zip: a folder per student, nbgrader's submitted/, "
        "Canvas's or Moodle's download), or the submissions one by one (notebooks or folders of notebooks); put "
        "`--` before them when a name could start with '-'",
    )
    grd.add_argument("--out", type=Path, required=True, help="folder for grades.csv, feedback/ and results/")
    grd.add_argument("--merge", nargs="*", help=argparse.SUPPRESS)  # now `labkit merge`: refused, saying so
    grd.add_argument(
        "--jobs", type=int, default=2, help="submissions graded at once on this machine (default 2; not with --dask)"
    )
    grd.add_argument(
        "--shard",
        metavar="I/N",
        help="grade only the I-th of N equal parts of the submissions (in name order, I from 1): one task of a "
        "batch array each (give every part the same --seed), then `labkit merge` the parts",
    )
    grd.add_argument(
        "--fresh",
        action="store_true",
        help="delete the results and feedback already in --out and grade every submission (by default a run "
        "into a folder with results resumes it)",
    )
    grd.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="grade on a Dask cluster, one task per submission: the scheduler's address (tcp://host:8786), or "
        "'local' for a LocalCluster here; workers need the submissions at the same path (a shared file system), "
        "labkit of this version and the sandbox (pip install 'labkit[dask]')",
    )
    grd.add_argument(
        "--dask-workers",
        type=int,
        metavar="N",
        help="worker processes of --dask local, one submission each at a time (default 2)",
    )
    grd.add_argument(
        "--cell-timeout",
        type=int,
        default=DEFAULTS.cell_timeout,
        help="seconds per cell, and per call of a graded function (default %(default)s)",
    )
    grd.add_argument(
        "--total-timeout",
        type=int,
        default=DEFAULTS.total_timeout,
        help="seconds per submission in all, every notebook of it together (default %(default)s)",
    )
    grd.add_argument(
        "--memory",
        type=int,
        default=DEFAULTS.limits.memory // MIB,
        help="MiB of memory for a notebook's sandbox, and of address space per process (default %(default)s)",
    )
    grd.add_argument(
        "--grader-memory",
        type=int,
        default=DEFAULTS.grader_memory // MIB,
        help="MiB of memory for the grader's own work on one submission (default %(default)s)",
    )
    grd.add_argument(
        "--seed",
        type=int,
        default=DEFAULTS.seed,
        help="seed of the random test data (default: a fresh one, saved in seed.txt)",
    )
    where = grd.add_mutually_exclusive_group()
    where.add_argument(
        "--sandbox",
        choices=backends.names(),
        default=DEFAULTS.backend,
        metavar="NAME",
        help="where student code runs: "
        + "; ".join(
            f"{name}{' (the default)' if name == DEFAULTS.backend else ''}: {backends.backend_class(name).summary}"
            for name in backends.names()
        ),
    )
    where.add_argument(
        "--no-sandbox",
        dest="sandbox",
        action="store_const",
        const=backends.UNCONFINED,
        help=f"the old name of --sandbox {backends.UNCONFINED}: student code runs UNCONFINED, with "
        "your permissions (only for code you trust, or where each submission is already "
        "isolated)",
    )
    grd.add_argument(
        "--rubric",
        type=Path,
        help="TOML rubric: points, required exercises, branches, extra credit, a deadline ([late]) "
        "(default: the one recorded in --out by an earlier run, else the lab's; `labkit rubric` prints it)",
    )
    grd.add_argument(
        "--student",
        action="append",
        metavar="NAME",
        help="grade only this student of the class folder (its name in grades.csv; repeat for more): a regrade, "
        "merged over the class's run with `labkit merge`",
    )
    grd.add_argument(
        "--assignment",
        metavar="NAME",
        help="the assignment to grade in an nbgrader class folder (submitted/STUDENT/NAME/) holding several, and "
        "in the exchange of --times-from-exchange",
    )
    grd.add_argument(
        "--times",
        type=Path,
        metavar="TIMES.csv",
        help="submission times for the rubric's [late] table, as the LMS exports them: a CSV with the columns "
        "submission and time (ISO 8601 with a UTC offset); trusted, and it comes before every other source",
    )
    grd.add_argument(
        "--times-from-exchange",
        type=Path,
        metavar="COURSE",
        help="read the submission times from nbgrader's exchange itself (COURSE: the course's folder there, which "
        "holds inbound/; with --assignment): each student's newest submission",
    )
    grd.add_argument(
        "--times-from-submission",
        action="store_true",
        help="a submission with no other time gets the time in the timestamp.txt inside it (never without this "
        "option: the student's own process writes that file; marked student-supplied)",
    )
    grd.add_argument(
        "--times-from-mtime",
        action="store_true",
        help="a submission with no other time gets its notebooks' newest modification time (never without "
        "this option: copying or unpacking a file changes it, and the student sets it; marked student-supplied)",
    )
    grd.add_argument(
        "--solutions",
        type=Path,
        metavar="DIR",
        help="the instructor notebooks (the course repository's notebooks/): a graded part whose code is mostly "
        "theirs, names aside, is held for you like one that is labkit's or scipy's own (see "
        "docs/grading-security.md); recorded, and used again when the run resumes",
    )
    grd.add_argument(
        "--roster",
        type=Path,
        help="CSV with the columns submission and id: with --variants, each student is graded against their own data",
    )
    grd.add_argument(
        "--variants",
        type=Path,
        metavar="SECRET_FILE",
        help="the course's variants file (labkit variants --new), as given to labkit release; recorded by its digest",
    )
    grd.add_argument(
        "--no-fork-server",
        action="store_true",
        help="start every notebook's sandbox with a fresh Python that imports everything again (slower; the way "
        "before the fork server, which forks each notebook's isolated worker from one warm process per run)",
    )
    grd.add_argument("--quiet", action="store_true", help="no progress bar")
    grd.set_defaults(handler=_grade)

    mrg = commands.add_parser(
        "merge",
        help="combine the results of several grading runs",
        description="Combine the results/ of earlier `labkit grade` --out folders (the shards of a class, a "
        "regrade after the class's run) into one grades.csv, feedback/ and results/ in --out; a later folder's "
        "result replaces an earlier one's for the same submission (a regrade goes last). Only results each "
        "folder's run record vouches for are read.",
    )
    mrg.add_argument("folders", nargs="+", type=Path, metavar="DIR", help="the --out folders of earlier runs")
    mrg.add_argument("--out", type=Path, required=True, help="folder for the merged grades.csv, feedback/ and results/")
    mrg.add_argument(
        "--rubric",
        type=Path,
        help="TOML rubric to score the results with (default: the one the runs recorded); it may differ from "
        "theirs only in its [late] and [held] tables",
    )
    mrg.add_argument(
        "--times",
        type=Path,
        metavar="TIMES.csv",
        help="submission times for the rubric's [late] table (submission,time; ISO 8601 with a UTC offset), in "
        "place of those the results were graded with",
    )
    mrg.add_argument("--quiet", action="store_true", help="no progress bar")
    for flag in ("--shard", "--dask"):  # grading's, refused with a message saying so
        mrg.add_argument(flag, help=argparse.SUPPRESS)
    for flag in ("--fresh", "--times-from-mtime", "--times-from-submission"):
        mrg.add_argument(flag, action="store_true", help=argparse.SUPPRESS)
    mrg.add_argument("--times-from-exchange", type=Path, help=argparse.SUPPRESS)
    mrg.set_defaults(handler=_merge)

    exp = commands.add_parser(
        "export",
        help="put the grades into the course's Canvas gradebook or a Moodle grade import file",
        description="Write each student's total under the rubric for the LMS to import: into the Canvas gradebook "
        "export GRADEBOOK.csv (one assignment column filled in or added, everything else kept), or a CSV for "
        "Moodle's 'Import grades from CSV'. A roster joins submissions to the LMS's students. Submissions that "
        "could not be graded, and students who do not match, are listed and get nothing (never a zero). Exit "
        "status: 0 when every submission and roster entry matched, 1 when the file was written with students "
        "listed, 2 for bad input (then nothing is written).",
    )
    exp.add_argument(
        "results", type=Path, metavar="OUT", help="the --out folder of `labkit grade` (or of `labkit merge`)"
    )
    lms_choice = exp.add_mutually_exclusive_group(required=True)
    lms_choice.add_argument(
        "--canvas",
        type=Path,
        metavar="GRADEBOOK.csv",
        help="the course's gradebook as Canvas exports it (Grades > Export); it is read, never changed",
    )
    lms_choice.add_argument("--moodle", action="store_true", help="write a CSV for Moodle's 'Import grades from CSV'")
    exp.add_argument(
        "--roster",
        type=Path,
        required=True,
        metavar="ROSTER.csv",
        help="CSV with the columns submission (the names in grades.csv) and id (the student's id in the LMS)",
    )
    exp.add_argument(
        "--key",
        help="what the roster's ids are: for Canvas the gradebook column 'ID' (the default), 'SIS User ID' or "
        "'SIS Login ID'; for Moodle 'idnumber' (the default) or 'email'",
    )
    exp.add_argument(
        "--column",
        default="labkit",
        metavar="NAME",
        help="the assignment: Canvas's column of that title is filled (one the gradebook lacks is refused, "
        "unless --new-column); Moodle's grade item column (default %(default)s)",
    )
    exp.add_argument(
        "--new-column",
        action="store_true",
        help="Canvas: add --column as a new assignment column, worth the rubric's full credit (refused if the "
        "gradebook has that column already); without it a --column the gradebook lacks is refused, so a typo "
        "never creates an assignment",
    )
    exp.add_argument("--feedback", action="store_true", help="Moodle: add a Feedback column (the points in words)")
    exp.add_argument(
        "--out",
        type=Path,
        metavar="FILE",
        help="the file to write (default: OUT-canvas.csv or OUT-moodle.csv next to OUT); a summary CSV "
        "(FILE-summary.csv) goes beside it",
    )
    exp.add_argument(
        "--force", action="store_true", help="replace FILE and its summary if they exist (never an input file)"
    )
    exp.add_argument(
        "--rubric",
        type=Path,
        help="leave it out: the rubric recorded by the run is used (one that grades otherwise is refused)",
    )
    exp.set_defaults(handler=_export)

    fbk = commands.add_parser(
        "feedback",
        help="write OUT/feedback-upload.zip: each student's feedback page, named for the LMS's bulk upload",
        description="Read the results/ of a `labkit grade` run in OUT and write OUT/feedback-upload.zip: each "
        "student's feedback as one HTML page, named as the LMS the class came from needs it (the run recorded "
        "its layout): Canvas's 'Re-upload submissions', Moodle's 'Upload multiple feedback files in a zip', "
        "<submission>/feedback.html for a folder per student, and nbgrader's feedback/ folder.",
    )
    fbk.add_argument("out", type=Path, metavar="OUT", help="the --out folder of a `labkit grade` run")
    fbk.add_argument(
        "--layout",
        choices=["canvas", "moodle", "folders", "nbgrader"],
        help="name the files for this layout instead of the one the run recorded",
    )
    fbk.set_defaults(handler=_feedback)

    rep = commands.add_parser(
        "report",
        help="write OUT/report.html: totals, pass rates, slips, problems and similar code of a grading run",
        description="Read the results/ of a `labkit grade` run (or of `labkit merge`) in OUT and write "
        "OUT/report.html, one self-contained page: the distribution of totals, each exercise's and part's "
        "pass rate, the slips the checks named with who made them, the problems (time limits, crashes, "
        "errors, refused references), the students with the most failed parts, and similar code side by "
        "side. Nothing else in OUT is changed.",
    )
    rep.add_argument("out", type=Path, metavar="OUT", help="the --out folder of a `labkit grade` run")
    rep.add_argument(
        "--rubric",
        type=Path,
        help="leave it out: the rubric recorded by the run is used (one that grades otherwise is refused)",
    )
    rep.add_argument(
        "--similarity-threshold",
        type=float,
        default=similarity.DEFAULT_THRESHOLD,
        metavar="X",
        help="show pairs of similar code from this similarity (0 to 1) up (default %(default)s); "
        "similarity never changes a grade",
    )
    rep.add_argument("--quiet", action="store_true", help="print nothing when all goes well")
    rep.set_defaults(handler=_report)

    mrk = commands.add_parser(
        "mark",
        help="write OUT/marking.html to mark answers in words and held parts by keyboard; --import its marks.csv",
        description="--import marks.csv (submission,item,points,comment) puts the marks into the run in OUT: "
        "grades.csv, the feedback, the results that `labkit report` and `labkit export` read. Every row is "
        "checked first; one bad row and nothing changes. A later mark of an item replaces the earlier one.",
    )
    mrk.add_argument("out", type=Path, metavar="OUT", help="the --out folder of a `labkit grade` run")
    mrk.add_argument("--import", dest="import_", type=Path, metavar="MARKS.csv", help="the marks to import")
    mrk.add_argument(
        "--rubric",
        type=Path,
        help="leave it out: the rubric recorded by the run is used (one that grades otherwise is refused)",
    )
    mrk.add_argument(
        "--marker",
        default="instructor",
        help="whose marking order: each marker's page shuffles the students of each item in its own order",
    )
    mrk.add_argument("--quiet", action="store_true", help="print nothing when all goes well")
    mrk.set_defaults(handler=_mark)

    rub = commands.add_parser(
        "rubric",
        help="print the lab's rubric (TOML) to copy and edit",
        description="Print the lab's own rubric. Save it, edit it and pass it to "
        "`labkit grade --rubric FILE`; `--check FILE` validates an edited one.",
    )
    rub.add_argument("--check", type=Path, metavar="FILE", help="validate this rubric and summarise it instead")
    rub.set_defaults(handler=_rubric)

    var = commands.add_parser(
        "variants",
        help="every student their own data: make the variants file, redraw a student, show or check the draws",
        description="A variants file holds the course's secret; each student's data (the limaçon's r0, ...) is "
        "derived from it and the student's roster id, for `labkit release --roster --variants` and `labkit grade "
        "--roster --variants`. Keep it private.",
    )
    action = var.add_mutually_exclusive_group(required=True)
    action.add_argument("--new", type=Path, metavar="FILE", help="write a new variants file with a random secret")
    action.add_argument(
        "--redraw", metavar="ID", help="give the student with this roster id a fresh draw of --exercise"
    )
    action.add_argument("--show", action="store_true", help="print each roster student's data (needs --roster)")
    action.add_argument(
        "--check",
        type=int,
        metavar="N",
        help="check N made-up students' draws (and the --roster's): the solutions earn full marks, the catalog's "
        "slips are caught and named, a copy is caught; exits 1 naming every draw that is not",
    )
    var.add_argument("--variants", type=Path, metavar="SECRET_FILE", help="the course's variants file")
    var.add_argument("--exercise", type=int, help="the exercise to redraw (with --redraw)")
    var.add_argument("--roster", type=Path, help="CSV with the columns submission and id")
    var.add_argument(
        "--solutions", type=Path, default=Path("notebooks"), help="the instructor notebooks (default %(default)s)"
    )
    var.add_argument("--catalog", type=Path, help="a Python file of CORRECT variations and MISTAKES (slips) to check")
    var.add_argument("--rubric", type=Path, help="a course's rubric: its exercises' variants (default: the lab's)")
    var.set_defaults(handler=_variants)
    return parser


def _variants(args):
    from .exercises import variants
    from .grading.reports.lms import read_roster
    from .grading.store.report import one_line

    course = _course(args)
    if args.new is not None:
        variants.new(args.new)
        print(f"wrote {args.new}: keep it private; give it to `labkit release` and `labkit grade` as --variants")
        return 0
    if args.variants is None:
        raise InputError("give the course's variants file: --variants SECRET_FILE (make one with --new FILE).")
    found = variants.read(args.variants)
    roster = read_roster(args.roster) if args.roster is not None else None
    if args.redraw is not None:
        if args.exercise is None or roster is None:
            raise InputError(
                "--redraw needs --exercise N (the exercise whose data the student gets afresh) and --roster (the "
                "roster the id is in)."
            )
        args.redraw = args.redraw.strip()
        if args.redraw not in roster.values():
            raise InputError(
                f"{one_line(args.redraw, 60)} is no id of the roster {args.roster}: give an id as it has it."
            )
        number = variants.redraw(args.variants, args.redraw, args.exercise, course)
        values = variants.read(args.variants).values(course, args.redraw)[args.exercise]
        print(f"{one_line(args.redraw, 60)} now has draw {number} of exercise {args.exercise}: {values}")
        return 0
    if args.show:
        if roster is None:
            raise InputError("--show needs --roster: the students whose data to print.")
        for name, key in roster.items():
            values = found.values(course, key)
            shown = "; ".join(
                f"exercise {n}: " + ", ".join(f"{p} = {v}" for p, v in given.items()) for n, given in values.items()
            )
            print(f"{one_line(name, 40)} ({one_line(key, 30)}): {shown}")
        return 0
    from .grading.authoring.draws import check

    troubles = check(
        found,
        args.check,
        args.solutions,
        args.catalog,
        roster,
        registry=course,
        progress=lambda line: print(line, flush=True),
    )
    for trouble in troubles:
        print(f"not as it should be: {one_line(str(trouble), 300)}")
    print(f"{len(troubles)} draw(s) not as they should be" if troubles else "every draw is as it should be")
    return 1 if troubles else 0


def _rubric(args):
    from .grading.store.rubric import DEFAULT, load
    from .grading.store.text import points_text

    if args.check:
        rubric = load(args.check)
        print(rubric.describe())
        print("  points: " + ", ".join(f"exercise {n} {points_text(p)}" for n, p in rubric.points.items()))
        if rubric.late is not None and rubric.late.extensions:
            print(f"  extensions: {len(rubric.late.extensions)} student(s) have a deadline of their own")
        print(f"  digest: {rubric.digest} (results of runs with the same digest can be merged)")
    else:
        print(DEFAULT.read_text(encoding="utf-8"), end="")
    return 0


def options_that_are_files(argv):
    """The arguments before ``--`` that read as options but name a file or folder here: a submission folder
    named ``--sandbox=none`` that a shell's ``*`` put among the options.

    >>> options_that_are_files(["grade", "--out", "g", "--", "-odd"])
    []
    """
    found = []
    for argument in argv:
        if argument == "--":
            break
        if argument.startswith("-") and len(argument) > 1 and os.path.lexists(argument):
            found.append(argument)
    return found


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(map(str, argv))
    clash = options_that_are_files(argv)
    if clash:
        print(
            f"labkit: {clash[0]!r} is an option, and also a file or folder here (a submission named so?); nothing "
            "was run. A name that starts with '-' reads as an option: give the class folder instead (labkit grade "
            "CLASS --out OUT), or put `--` before the submissions (labkit grade --out OUT -- *).",
            file=sys.stderr,
        )
        return 2
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except ValueError as exc:
        print(f"labkit {args.command}: {exc}", file=sys.stderr)
        return 2
    except ModuleNotFoundError as exc:
        if exc.name not in GRADE_EXTRA:
            raise
        print(
            f"labkit {args.command}: needs {exc.name}, which comes with the instructor's extra: "
            "pip install 'labkit[grade]'",
            file=sys.stderr,
        )
        return 2


if __name__ == "__main__":
    sys.exit(main())
