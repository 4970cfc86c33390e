"""labkit's command line tells the user's errors from its own bugs: an InputError (or a path given that cannot be
read, or the instructor's extra missing) is printed as it is and exits 2; anything else is a bug, said so in one
line with how to see the traceback, and exits 1."""

import pytest

from labkit import cli
from labkit.errors import InputError


def _raising(exc):
    def handle(args):
        raise exc

    return handle


def test_an_input_error_is_printed_as_it_is_and_exits_2(tmp_path, capsys):
    assert cli.main(["report", tmp_path, "--similarity-threshold", "2"]) == 2
    error = capsys.readouterr().err
    assert error == "labkit report: --similarity-threshold is a similarity above 0 and at most 1; got 2.0.\n"
    assert cli.main(["rubric", "--check", tmp_path / "missing.toml"]) == 2
    error = capsys.readouterr().err
    assert error.startswith("labkit rubric: ") and "missing.toml" in error and "internal error" not in error


@pytest.mark.parametrize("exc", [ZeroDivisionError("division by zero"), ValueError("operands could not\nbroadcast")])
def test_any_other_exception_is_a_bug_in_one_line_and_exits_1(exc, monkeypatch, capsys):
    monkeypatch.delenv("LABKIT_TRACEBACK", raising=False)
    monkeypatch.setattr(cli.rubric, "handle", _raising(exc))
    assert cli.main(["rubric"]) == 1
    error = capsys.readouterr().err
    assert error.count("\n") == 1, error
    name = type(exc).__name__
    assert error.startswith(f"labkit rubric: internal error, not your input: {name}: ")
    assert " ".join(str(exc).split()) in error and "report it" in error and "LABKIT_TRACEBACK=1" in error


def test_labkit_traceback_lets_a_bug_raise_but_never_an_input_error(monkeypatch, capsys):
    monkeypatch.setenv("LABKIT_TRACEBACK", "1")
    monkeypatch.setattr(cli.rubric, "handle", _raising(ZeroDivisionError("division by zero")))
    with pytest.raises(ZeroDivisionError):
        cli.main(["rubric"])
    monkeypatch.setattr(cli.rubric, "handle", _raising(InputError("give a rubric that exists.")))
    assert cli.main(["rubric"]) == 2
    assert capsys.readouterr().err == "labkit rubric: give a rubric that exists.\n"


def test_a_path_that_cannot_be_read_is_the_users_and_a_pathless_os_error_a_bug(monkeypatch, capsys):
    monkeypatch.delenv("LABKIT_TRACEBACK", raising=False)
    monkeypatch.setattr(cli.rubric, "handle", _raising(PermissionError(13, "Permission denied", "grades/out")))
    assert cli.main(["rubric"]) == 2
    assert capsys.readouterr().err == "labkit rubric: [Errno 13] Permission denied: 'grades/out'\n"
    monkeypatch.setattr(cli.rubric, "handle", _raising(OSError(28, "No space left on device")))
    assert cli.main(["rubric"]) == 1
    assert "internal error, not your input: OSError" in capsys.readouterr().err


def test_a_missing_grade_extra_says_how_to_install_it_and_another_missing_module_is_a_bug(monkeypatch, capsys):
    monkeypatch.delenv("LABKIT_TRACEBACK", raising=False)
    monkeypatch.setattr(cli.rubric, "handle", _raising(ModuleNotFoundError("No module named 'rich'", name="rich")))
    assert cli.main(["rubric"]) == 2
    assert "needs rich, which comes with the instructor's extra: pip install 'labkit[grade]'" in capsys.readouterr().err
    monkeypatch.setattr(cli.rubric, "handle", _raising(ModuleNotFoundError("No module named 'zz'", name="zz")))
    assert cli.main(["rubric"]) == 1
    assert "internal error, not your input: ModuleNotFoundError" in capsys.readouterr().err
