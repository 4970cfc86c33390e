"""Following docs/instructors.md from the clone's root leaves `git status` clean: every file and folder its
commands write or read (the variants file, rosters, releases, submissions, grades, marks) is ignored by git."""

import re
import shlex
import shutil
import subprocess

import pytest
from docs_markdown import ROOT

DOC = ROOT / "docs" / "instructors.md"
COMMAND = re.compile(
    r"^\s*(?:\.\./labkit/)?(?:\.venv/bin/)?labkit (?:grade|release|variants|merge|export|report|mark)\b.*"
)
INLINE = re.compile(r"`((?:\.venv/bin/)?labkit (?:grade|release|variants|merge|export|report|mark)\b[^`]*)`")
SUFFIXES = (".csv", ".toml", ".zip", ".txt", ".json", ".html")
PLACEHOLDER = re.compile(r"[A-Z]{2,}\b")
OWN = ("tests/", "notebooks/", "labkit/", "..")  # the repository's own files (--catalog, --solutions), or outside it


def _commands(text):
    lines = [m.group(0) for line in text.splitlines() for m in [COMMAND.match(line)] if m]
    return lines + INLINE.findall(text)


def _paths(command):
    """The files and folders a command of the docs names (an option's value, an argument), as written."""
    words = shlex.split(command.split("#", 1)[0].replace("[--feedback]", ""))
    found = []
    for before, word in zip(["", *words], words):
        if word.startswith(("-", "$")) or PLACEHOLDER.match(word):
            continue  # an option, a shell expansion, a placeholder (CLASS, OUT, TIMES.csv)
        if before == "--out" or word.endswith("/") or word.endswith(SUFFIXES):
            found.append(word.rstrip("/*") + ("/" if word.endswith(("/", "/*")) or before == "--out" else ""))
    return found


def _written():
    paths = {p for command in _commands(DOC.read_text(encoding="utf-8")) for p in _paths(command)}
    return sorted(p for p in paths if not p.startswith(OWN))


def test_the_docs_name_the_instructors_files():
    written = _written()
    for name in ("course-variants.toml", "roster.csv", "release/", "grades/", "marks.csv", "submissions/"):
        assert name in written
    assert _paths('labkit export g/ --canvas book.csv --column "Lab 8"  # note') == ["g/", "book.csv"]


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_following_the_docs_from_the_clone_root_leaves_git_status_clean(tmp_path):
    clone = tmp_path / "clone"
    clone.mkdir()
    shutil.copy(ROOT / ".gitignore", clone / ".gitignore")
    subprocess.run(["git", "init", "-q", str(clone)], check=True)
    subprocess.run(["git", "-C", str(clone), "add", ".gitignore"], check=True)
    for path in _written():
        target = clone / path.rstrip("/")
        target = target / "ada" / "feedback.txt" if path.endswith("/") else target
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text("a student's data\n", encoding="utf-8")
    status = subprocess.run(["git", "-C", str(clone), "status", "--porcelain"], capture_output=True, text=True)
    assert status.stdout.splitlines() == ["A  .gitignore"], "not ignored: " + status.stdout
    (clone / "new_module.py").write_text("x = 1\n", encoding="utf-8")  # the ignore list is not "everything"
    status = subprocess.run(["git", "-C", str(clone), "status", "--porcelain"], capture_output=True, text=True)
    assert "?? new_module.py" in status.stdout.splitlines()
