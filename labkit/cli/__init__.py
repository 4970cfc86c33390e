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

Each command is a module of this package declaring its options (``add``) and doing its job (``handle``);
the options several commands take are declared once in :mod:`labkit.cli.options`. A command's
:class:`~labkit.errors.InputError` is the user's to fix: :func:`main` prints it and exits 2. Any other
exception is a bug in labkit: :func:`main` says so in one line and exits 1 (``LABKIT_TRACEBACK=1`` shows it).
A handler imports the grader's modules when it runs, so that ``labkit notebooks`` and ``labkit handin`` work
without the ``[grade]`` extra.
"""

import os
import sys

from ..errors import InputError
from . import execute, export, feedback, grade, handin, mark, merge, notebooks, release, report, rubric, variants
from .grade import grade_options
from .parser import Parser

__all__ = ["build_parser", "grade_options", "main", "options_that_are_files"]

COMMANDS = (notebooks, handin, execute, release, grade, merge, export, feedback, report, mark, rubric, variants)
GRADE_EXTRA = ("nbformat", "nbclient", "rich")
TRACEBACK = "LABKIT_TRACEBACK"


def build_parser():
    """The ``labkit`` parser, with a subcommand per module of :data:`COMMANDS`."""
    parser = Parser(
        prog="labkit",
        description="Course kit tools for the higher-order interpolation lab.",
        epilog="Grading runs every notebook in a sandbox (`labkit grade --help` lists them: the default has no "
        "network, a read-only system, a private folder and resource limits) and checks it from outside; "
        "see docs/instructors.md.",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add(commands)
    return parser


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
    """Run ``labkit`` on `argv` (default: the command line); the exit status: 0 done, 1 something to look at
    (or a bug in labkit), 2 bad input."""
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
    except Exception as exc:  # the user's errors are told apart from labkit's bugs below
        if os.environ.get(TRACEBACK, "") not in ("", "0") and not _users(exc):
            raise
        return _failed(args.command, exc)


def _users(exc):
    """Whether `exc` is the user's to fix: bad input, a path given that cannot be read or written, or the
    instructor's extra not installed."""
    if isinstance(exc, ModuleNotFoundError):
        return exc.name in GRADE_EXTRA
    return isinstance(exc, InputError) or (isinstance(exc, OSError) and exc.filename is not None)


def _failed(command, exc):
    """Print what went wrong in `command`; the exit status: 2 for the user's error, 1 for a bug in labkit."""
    if isinstance(exc, ModuleNotFoundError) and _users(exc):
        print(
            f"labkit {command}: needs {exc.name}, which comes with the instructor's extra: pip install 'labkit[grade]'",
            file=sys.stderr,
        )
        return 2
    if _users(exc):
        print(f"labkit {command}: {exc}", file=sys.stderr)
        return 2
    message = " ".join(str(exc).split())
    print(
        f"labkit {command}: internal error, not your input: {type(exc).__name__}: {message}; this is a bug in "
        f"labkit, please report it (set {TRACEBACK}=1 to see the traceback).",
        file=sys.stderr,
    )
    return 1
