"""One options object from the command line to the sandbox, its defaults defined once."""

import io
import tokenize
from dataclasses import asdict, fields
from pathlib import Path

import pytest

from labkit import grading
from labkit.cli import build_parser, grade_options
from labkit.grading.options import CPU_GRACE, DEFAULTS, MIB, GradeOptions
from labkit.grading.sandbox import remote
from labkit.grading.sandbox.backends.base import Limits

ROOT = Path(__file__).resolve().parents[2]
LABKIT = ROOT / "labkit"


def _args(*argv):
    return build_parser().parse_args(["grade", "work.ipynb", "--out", "out", *argv])


def test_the_cli_defaults_are_the_dataclass_defaults():
    args = _args()
    assert (args.cell_timeout, args.total_timeout, args.seed, args.sandbox, args.rubric) == (
        DEFAULTS.cell_timeout,
        DEFAULTS.total_timeout,
        DEFAULTS.seed,
        DEFAULTS.backend,
        DEFAULTS.rubric,
    )
    assert args.memory * MIB == DEFAULTS.limits.memory and args.grader_memory * MIB == DEFAULTS.grader_memory
    options = grade_options(args)
    # the one thing the command line sets on purpose: a process's CPU time follows the total time limit
    assert options.limits == Limits(cpu_seconds=DEFAULTS.total_timeout + CPU_GRACE)
    for field in fields(GradeOptions):
        if field.name != "limits":
            assert getattr(options, field.name) == getattr(DEFAULTS, field.name), field.name
    assert GradeOptions() == DEFAULTS and (DEFAULTS.cell_timeout, DEFAULTS.total_timeout) == (60, 600)


def test_every_grade_argument_lands_in_the_options():
    options = grade_options(
        _args(
            "--cell-timeout",
            "7",
            "--total-timeout",
            "50",
            "--memory",
            "100",
            "--grader-memory",
            "200",
            "--seed",
            "3",
            "--sandbox",
            "none",
            "--rubric",
            "my_rubric.toml",
        )
    )
    assert options == GradeOptions(
        cell_timeout=7,
        total_timeout=50,
        seed=3,
        backend="none",
        rubric="my_rubric.toml",
        grader_memory=200 * MIB,
        limits=Limits(memory=100 * MIB, cpu_seconds=50 + CPU_GRACE),
    )
    assert GradeOptions.from_dict(asdict(options)) == options  # as each submission's grading process reads them
    with pytest.raises(ValueError, match="--total-timeout must be at least 1; got 0"):
        grade_options(_args("--total-timeout", "0"))


@pytest.mark.slow  # starts a sandbox
def test_options_refuse_what_they_cannot_use():
    with pytest.raises(ValueError, match="cell-timeout must be at least 1 second"):
        GradeOptions(cell_timeout=0)
    with pytest.raises(ValueError, match="rubric must be the path of a TOML rubric"):
        GradeOptions(rubric=3)
    with pytest.raises(ValueError, match="limits must be a .*Limits"):
        GradeOptions(limits={"memory": 1})
    with pytest.raises(ValueError, match=r"grading option\(s\) timeout; the options are backend, cell_timeout"):
        GradeOptions.from_dict({**asdict(GradeOptions()), "timeout": 5})
    assert GradeOptions(rubric=Path("r.toml")).rubric == "r.toml"
    with pytest.raises(ValueError, match="options must be a GradeOptions"):
        grading.grade([], "out", {"cell_timeout": 5})  # type: ignore[arg-type]


def test_the_lower_layers_take_their_limits_from_the_options():
    class Worker:
        options = GradeOptions(cell_timeout=17)

    assert remote.Namespace(Worker()).timeout == 17
    assert remote.Namespace(Worker(), 3).timeout == 3


def _numbers(path):
    """(line number, number, line) of every number in a module's code."""
    text = path.read_text(encoding="utf-8")
    return [
        (t.start[0], t.string.replace("_", ""), t.line.strip())
        for t in tokenize.generate_tokens(io.StringIO(text).readline)
        if t.type == tokenize.NUMBER
    ]


# numbers equal to a default that mean something else: each is looked at when it changes
NOT_A_DEFAULT = {
    (
        "grading/store/report.py",
        'readable = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._-")[:60] or "submission"',
    ): "characters of a file name",
    ("grading/run/processes.py", "log.seek(max(0, os.path.getsize(self.log) - 4096))"): "bytes of a log's tail",
    ("grading/lms/nbgrader.py", 'there = ", ".join(one_line(a, 60) for a in assignments)'): "characters of a name",
}


def test_the_defaults_are_spelled_out_only_in_the_options():
    defaults = {
        str(DEFAULTS.cell_timeout),
        str(DEFAULTS.total_timeout),
        str(DEFAULTS.limits.memory // MIB),
        str(DEFAULTS.grader_memory // MIB),
    }
    assert defaults == {"60", "600", "4096", "3072"}
    modules = sorted((LABKIT / "grading").rglob("*.py")) + sorted((LABKIT / "cli").glob("*.py"))
    found, seen_in_options = [], set()
    for path in modules:
        name = path.relative_to(LABKIT).as_posix()
        for line_number, number, line in _numbers(path):
            if number not in defaults:
                continue
            if name == "grading/options.py":
                seen_in_options.add(number)
            elif (name, line) not in NOT_A_DEFAULT:
                found.append(f"{name}:{line_number}: {line}")
        text = path.read_text(encoding="utf-8")
        for number in defaults:
            for spelled in (f"(default {number})", f"default={number}", f"+ {number}\n"):
                if spelled in text:
                    found.append(f"{name}: {spelled.strip()}")
    assert found == [], "defaults spelled out outside labkit/grading/options.py:\n" + "\n".join(found)
    assert seen_in_options == {"60", "600"}  # the scan does see them where they are defined
    assert len(modules) > 15


@pytest.mark.slow  # starts a sandbox
def test_exercises_that_disagree_with_the_rubric_are_refused_before_anything_is_graded(tmp_path):
    from labkit import grading

    notebook = Path(__file__).resolve().parents[2] / "notebooks" / "01_limacon.ipynb"
    options = GradeOptions(exercises="some_course:REGISTRY", backend="none")
    with pytest.raises(ValueError, match="name the course's exercises in its rubric"):
        grading.grade([notebook], tmp_path / "out", options=options, progress=False)
    assert not (tmp_path / "out" / "grades.csv").exists()
