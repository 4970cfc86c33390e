"""The options several commands take, each declared once here; a command adds them with its own help when the
option means something of its own there."""

import argparse
from pathlib import Path

RUN_FOLDER = "the --out folder of a `labkit grade` run"
RUN_RUBRIC = "leave it out: the rubric recorded by the run is used (one that grades otherwise is refused)"
COURSE_RUBRIC = "a course's rubric: its exercises' variants (default: the lab's)"
ROSTER = "CSV with the columns submission and id"
VARIANTS = "the course's variants file"
TIMES = "submission times for the rubric's [late] table"


def run_folder(parser, text=RUN_FOLDER, dest="out"):
    """The positional OUT: the folder a grading run wrote."""
    parser.add_argument(dest, type=Path, metavar="OUT", help=text)


def out(parser, text, **given):
    """``--out``: where the command writes (required unless `given` says otherwise)."""
    parser.add_argument("--out", type=Path, **{"required": True, **given}, help=text)


def rubric(parser, text=RUN_RUBRIC):
    """``--rubric FILE``: a TOML rubric."""
    parser.add_argument("--rubric", type=Path, help=text)


def roster(parser, text=ROSTER, **given):
    """``--roster``: a CSV joining submissions to the LMS's ids."""
    parser.add_argument("--roster", type=Path, **given, help=text)


def variants(parser, text=VARIANTS):
    """``--variants SECRET_FILE``: the course's variants file."""
    parser.add_argument("--variants", type=Path, metavar="SECRET_FILE", help=text)


def times(parser, text):
    """``--times TIMES.csv``: the submissions' times for the rubric's [late] table."""
    parser.add_argument("--times", type=Path, metavar="TIMES.csv", help=f"{TIMES}{text}")


def quiet(parser, text="no progress bar"):
    """``--quiet``."""
    parser.add_argument("--quiet", action="store_true", help=text)


def force(parser, text):
    """``--force``: replace what is there."""
    parser.add_argument("--force", action="store_true", help=text)


def cell_timeout(parser):
    """``--timeout``: seconds per cell when a notebook is run here."""
    parser.add_argument("--timeout", type=int, default=300, help="seconds allowed per cell (default %(default)s)")


def instructor_notebooks(parser):
    """The positional folder of instructor notebooks."""
    parser.add_argument(
        "notebooks", type=Path, help="folder of instructor notebooks (the course repository's notebooks/)"
    )


def hidden(parser, *flags, **given):
    """Options another command takes, accepted here only to be refused with a message saying so."""
    for flag in flags:
        parser.add_argument(flag, **given, help=argparse.SUPPRESS)
