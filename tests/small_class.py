"""A class small enough to grade several times in one test run (each submission is one notebook, graded in
about a second), with what a class holds: a solved notebook, a slip that costs one part, the bare release,
a file that is not a notebook, and a name a spreadsheet would run as a formula. Used by the tests of
resuming, shards and Dask, which compare other ways of grading it with one ``--jobs 2`` run."""

import csv
import subprocess
import sys
from pathlib import Path

import nbformat
from catalog import MISTAKES, NOTEBOOKS, Planted, plant

from labkit import grading

SEED = "20261122"
SLIP = next(entry for entry in MISTAKES if entry.name == "phi_corners_numbered_clockwise")  # costs 1 of 8 points


def plant_small_class(folder):
    """The five submissions in `folder`; their paths, in name order."""
    folder = Path(folder)
    plant(Planted("as handed out", "06_bilinear.ipynb", ()), folder / "alice")
    plant(SLIP, folder / "bob")
    bare = grading.release_notebook(nbformat.read(NOTEBOOKS / "06_bilinear.ipynb", as_version=4))
    (folder / "carol").mkdir()
    nbformat.write(bare, folder / "carol" / "06_bilinear.ipynb")
    (folder / "dave.ipynb").write_text('{"cells": [ this is not json')
    plant(SLIP, folder / "=1+1 eve")
    return sorted(folder.iterdir(), key=lambda path: grading.submission.scoring.submission_name(path))


def cli(*args, env=None, timeout=300, cwd=None):
    """``labkit`` in a process of its own (as an instructor runs it)."""
    return subprocess.run(
        [sys.executable, "-m", "labkit.cli", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        cwd=cwd,
    )


def rows(out):
    """grades.csv of an output folder as {submission: row}."""
    with open(Path(out) / "grades.csv", newline="", encoding="utf-8") as handle:
        header, *lines = list(csv.reader(handle))
    return {line[0]: dict(zip(header, line)) for line in lines}


def files(out, folder):
    """{file name: text} of an output folder's results/ or feedback/."""
    return {path.name: path.read_text() for path in sorted((Path(out) / folder).iterdir())}
