"""Sandbox backends behind one interface: the registry, the CLI's switch, a backend that is only a subclass,
and no knowledge of one backend's tool anywhere else."""

import inspect
import io
import json
import os
import re
import subprocess
import sys
import tokenize
from pathlib import Path

import pytest

from labkit import grading
from labkit.cli import build_parser, grade_options
from labkit.grading.options import GradeOptions
from labkit.grading.sandbox import backends
from labkit.grading.sandbox.backends import bwrap, none
from labkit.grading.sandbox.backends.base import Backend, Limits

ROOT = Path(__file__).resolve().parents[3]
LABKIT = ROOT / "labkit"
BACKENDS = LABKIT / "grading" / "sandbox" / "backends"
NOTEBOOKS = ROOT / "notebooks"
RECORD = "LABKIT_TEST_BACKEND_RECORD"  # where the recording backend writes what it was asked, in any process


@backends.register
class Recording(Backend):
    """The none backend's behaviour, and a line in a file for every notebook it boxes: all a test needs."""

    name = "recording"
    summary = "the none backend, recording each notebook it runs (tests only)"

    def available(self):
        self._record({"available": True})

    def warning(self):
        return "recording backend: student code runs unconfined\n"

    def box(self, argv, limits):
        self._record({"argv": list(argv), "memory": limits.memory, "pid": os.getpid()})
        return backends.get_backend("none").box(argv, limits)

    @staticmethod
    def _record(entry):
        path = os.environ.get(RECORD)
        if path:
            with open(path, "a", encoding="utf-8") as handle:
                handle.write(json.dumps(entry) + "\n")


def test_the_registry_lists_bwrap_first_as_the_default_and_none():
    assert backends.names()[:2] == ("bwrap", "none") == backends.BUILTIN
    assert backends.DEFAULT == "bwrap" == GradeOptions().backend
    assert "recording" in backends.names()  # registered by this module, after the built-in ones
    assert isinstance(backends.get_backend("bwrap"), bwrap.Bubblewrap)
    assert isinstance(backends.get_backend("none"), none.Unconfined)
    assert backends.get_backend("none") is not backends.get_backend("none")  # a new instance each time


def test_a_built_in_backend_is_one_module_named_after_it_and_one_registry_entry():
    modules = sorted(p.stem for p in BACKENDS.glob("*.py") if p.stem not in ("__init__", "base"))
    assert modules == sorted(backends.BUILTIN)
    for name in backends.BUILTIN:
        cls = backends.backend_class(name)
        assert cls.__module__ == f"labkit.grading.sandbox.backends.{name}" and cls.name == name
        assert issubclass(cls, Backend) and cls.summary


@pytest.mark.parametrize("name", ["docker", "", "BWRAP", None, 3])
def test_an_unknown_backend_is_a_value_error_that_lists_the_choices(name):
    with pytest.raises(ValueError, match=r"no sandbox backend called .*choose one of: bwrap, none"):
        backends.get_backend(name)
    with pytest.raises(ValueError, match="choose one of: bwrap, none"):
        GradeOptions(backend=name)


def test_registering_checks_what_it_is_given():
    with pytest.raises(ValueError, match="not a subclass of .*Backend"):
        backends.register(object)

    class Nameless(Backend):
        def available(self):
            pass

        def box(self, argv, limits):
            pass

    with pytest.raises(ValueError, match="needs a lower-case name"):
        backends.register(Nameless)

    class Impostor(Nameless):
        name = "none"

    with pytest.raises(ValueError, match="already registered .*none.Unconfined"):
        backends.register(Impostor)
    assert backends.backend_class("none") is none.Unconfined
    with pytest.raises(TypeError):  # the interface is abstract: a backend must say how it boxes a notebook
        type("Half", (Backend,), {"name": "half", "available": lambda self: None})()


def _options(*argv):
    return grade_options(build_parser().parse_args(["grade", "work.ipynb", "--out", "out", *argv]))


@pytest.mark.parametrize("argv", [["--no-sandbox"], ["--sandbox", "none"]])
def test_no_sandbox_is_the_old_name_of_sandbox_none_with_its_warning(argv):
    options = _options(*argv)
    assert options.backend == "none" and options == _options("--sandbox", "none")
    warning = backends.get_backend(options.backend).warning()
    assert "UNCONFINED" in warning and "--sandbox none" in warning
    assert backends.get_backend(_options().backend).warning() is None  # the default warns about nothing


def test_the_cli_offers_the_registry_and_refuses_other_names():
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "grade", "x.ipynb", "--out", "o", "--sandbox", "docker"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and "invalid choice: 'docker' (choose from 'bwrap', 'none')" in run.stderr
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "grade", "x.ipynb", "--out", "o", "--sandbox", "bwrap", "--no-sandbox"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and "not allowed with" in run.stderr
    run = subprocess.run(
        [sys.executable, "-m", "labkit.cli", "grade", "--help"], capture_output=True, text=True, timeout=120
    )
    help_text = " ".join(run.stdout.split())
    assert "--sandbox NAME" in help_text and "--no-sandbox" in help_text
    for name in backends.BUILTIN:
        summary = " ".join(backends.backend_class(name).summary.split())
        assert f"{name}{' (the default)' if name == backends.DEFAULT else ''}: {summary}" in help_text


@pytest.mark.slow  # starts a sandbox
def test_the_old_switch_of_the_library_is_gone():
    """``sandboxed=False`` was the ``none`` backend before any release; the options name the backend now."""
    assert GradeOptions(backend="none").backend == "none"
    with pytest.raises(TypeError, match="sandboxed"):
        GradeOptions(sandboxed=False)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="sandboxed"):
        grading.grade([NOTEBOOKS / "06_bilinear.ipynb"], "out", sandboxed=False)  # type: ignore[call-arg]
    assert not hasattr(GradeOptions, "build")


@pytest.mark.slow  # starts a sandbox
def test_a_backend_defined_in_a_test_module_is_all_grading_needs(tmp_path, monkeypatch, capsys):
    """Subclass, register, name it in the options: the grading processes import this module and use it."""
    record = tmp_path / "record.jsonl"
    monkeypatch.setenv(RECORD, str(record))
    options = GradeOptions(backend="recording", limits=Limits(memory=3 * 1024**3), seed=7, jobs=1)
    [grade] = grading.grade([NOTEBOOKS / "06_bilinear.ipynb"], tmp_path / "out", options, progress=False)
    assert grade.graded and grade.total == 8, grade.feedback()
    assert "recording backend: student code runs unconfined" in capsys.readouterr().err
    entries = [json.loads(line) for line in record.read_text().splitlines()]
    assert entries[0] == {"available": True}  # asked once, in this process, before anything was graded
    boxed = entries[1:]
    assert len(boxed) == 1 and boxed[0]["pid"] != os.getpid()  # in the submission's own grading process
    assert boxed[0]["argv"][-3:] == ["-I", "-m", "labkit.grading.sandbox.worker"] and boxed[0]["memory"] == 3 * 1024**3


def test_a_grading_process_cannot_use_a_backend_it_cannot_import(tmp_path):
    with pytest.raises(ValueError, match="cannot import 'no_such_backend_module'"):
        backends.import_origin("no_such_backend_module")
    with pytest.raises(ValueError, match="cannot import the sandbox backend's module"):
        backends.import_origin("no_such_backend_module", str(tmp_path / "missing.txt"))


def test_the_none_backend_gives_a_private_folder_and_removes_it():
    box = backends.get_backend("none").box(["python3", "-c", "pass"], Limits())
    folder = Path(box.cwd)
    assert folder.is_dir() and box.env["HOME"] == str(folder) and box.argv == ["python3", "-c", "pass"]
    (folder / "left.txt").write_text("by the notebook")
    box.close()
    box.close()  # twice is harmless
    assert not folder.exists()


def test_the_bwrap_backend_gives_the_worker_its_uid_and_hands_over_the_seccomp_descriptor():
    worker = [sys.executable, "-I", "-m", "labkit.grading.sandbox.worker"]
    box = backends.get_backend("bwrap").box(worker, Limits())
    try:
        assert box.argv[-len(worker) - 2 :] == ["--", *worker, str(bwrap.sandbox_uid())]
        assert list(inspect.signature(bwrap.command).parameters) == ["argv", "limits", "seccomp_fd", "zygote"]  # no uid
        for fd in box.pass_fds:
            assert f"--seccomp {fd}" in " ".join(box.argv)
            os.fstat(fd)  # open until the worker has it
    finally:
        fds = box.pass_fds
        box.close()
    for fd in fds:
        with pytest.raises(OSError):
            os.fstat(fd)


def _code_and_text(path):
    """Every token of a module but its comments, and the whole text."""
    text = path.read_text(encoding="utf-8")
    tokens = [t.string for t in tokenize.generate_tokens(io.StringIO(text).readline) if t.type != tokenize.COMMENT]
    return " ".join(tokens), text


TOOL_WORDS = re.compile(r"bwrap|bubblewrap|--unshare-|--ro-bind|--die-with-parent", re.IGNORECASE)


def test_no_module_outside_the_backends_names_the_bwrap_tool():
    """Not in code, messages, docstrings or comments: what bubblewrap is and how it is called is bwrap.py's."""
    checked = 0
    for path in sorted(LABKIT.rglob("*.py")):
        if BACKENDS in path.parents:
            continue
        _, text = _code_and_text(path)
        assert not TOOL_WORDS.search(text), f"{path.relative_to(ROOT)} mentions {TOOL_WORDS.search(text)[0]!r}"
        checked += 1
    assert checked > 30  # the whole package was read, the grading modules, the CLI and the checks among them
    # inside the package: the tool's command line only in bwrap.py; the registry only names the backend
    for path in sorted(BACKENDS.glob("*.py")):
        code, _ = _code_and_text(path)
        words = set(m.lower() for m in TOOL_WORDS.findall(code))
        if path.name == "bwrap.py":
            assert {"bwrap", "--unshare-", "--ro-bind", "--die-with-parent"} <= words
        elif path.name == "__init__.py":
            assert words <= {"bwrap", "bubblewrap"}  # its name in BUILTIN, and the package's description
        else:
            assert not words, f"{path.name} knows bwrap's command line: {words}"


def test_the_grading_modules_reach_a_sandbox_only_through_the_interface():
    """remote.py and the run's modules name no backend module, only the registry and the base interface."""
    run = sorted(path.relative_to(LABKIT / "grading").as_posix() for path in (LABKIT / "grading" / "run").glob("*.py"))
    assert "run/processes.py" in run and "run/engines.py" in run
    cli = sorted(f"../cli/{path.name}" for path in (LABKIT / "cli").glob("*.py"))
    assert "../cli/grade.py" in cli
    for name in ("sandbox/remote.py", *run, "submission/scoring.py", "sandbox/worker.py", "options.py", *cli):
        code, _ = _code_and_text(LABKIT / "grading" / name)
        assert not re.search(r"backends \. (bwrap|none)\b|backends import (bwrap|none)\b", code), name


def test_a_new_backend_is_one_new_module_in_the_package(tmp_path):
    """Dropping backends/<name>.py in is all it takes: the registry, the CLI's choices and grading find it."""
    module = BACKENDS / "zzexample.py"
    module.write_text(
        "from . import register\nfrom .none import Unconfined\n\n\n@register\nclass Example(Unconfined):\n"
        '    name = "zzexample"\n    summary = "a test\'s copy of the none backend"\n',
        encoding="utf-8",
    )
    try:
        code = (
            "from labkit.grading.sandbox import backends\nfrom labkit.cli import build_parser\n"
            "print(backends.BUILTIN)\nprint(type(backends.get_backend('zzexample')).__name__)\n"
            "print(build_parser().parse_args(['grade', '--sandbox', 'zzexample', 'x', '--out', 'o']).sandbox)\n"
        )
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    finally:
        module.unlink()
    assert run.returncode == 0, run.stderr
    builtin, found, chosen = run.stdout.splitlines()
    assert builtin == "('bwrap', 'none', 'zzexample')" and found == "Example" and chosen == "zzexample"


@pytest.mark.slow  # starts a sandbox
def test_a_course_module_is_shown_in_the_sandbox_alone_never_the_folder_around_it(tmp_path, monkeypatch):
    from conftest import sandbox_or_skip  # here, not at the top: grading processes import this module

    from labkit.exercises import registry
    from labkit.grading.sandbox.protocol import COURSE_FOLDER

    sandbox_or_skip()
    (tmp_path / "course_mod.py").write_text("ANSWER = 41 + 1\n")
    (tmp_path / "submissions").mkdir()
    (tmp_path / "submissions" / "ada.ipynb").write_text("{}")
    monkeypatch.setitem(registry.COURSES, "course_mod", tmp_path / "course_mod.py")
    probe = (
        "import os, sys; sys.path.append(" + repr(COURSE_FOLDER) + "); import course_mod; "
        f"print(course_mod.ANSWER, os.listdir({COURSE_FOLDER!r}), os.path.exists({str(tmp_path)!r}))"
    )
    args = bwrap.command([sys.executable, "-I", "-B", "-c", probe])
    ran = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout.split() == ["42", "['course_mod.py']", "False"]
    # a course installed in the environment is there already: nothing more is shown
    monkeypatch.setitem(registry.COURSES, "course_mod", Path(grading.__file__).resolve())
    assert COURSE_FOLDER not in bwrap.command(["true"])
