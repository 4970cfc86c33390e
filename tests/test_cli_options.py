"""labkit's command line takes options only as spelled: no abbreviation in any subcommand, and a mistyped
option is refused naming the nearest real one."""

import argparse

import pytest

from labkit.cli import build_parser
from labkit.cli.parser import Parser


def subcommands():
    parser = build_parser()
    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return parser, action.choices


def minimal_argv(name, sub):
    """The subcommand with a value for each required argument, so that only the option under test can fail."""
    argv = [name]
    chosen = [group._group_actions[0] for group in sub._mutually_exclusive_groups if group.required]
    for action in sub._actions:
        if action.option_strings and not action.required and action not in chosen:
            continue
        if action.nargs in ("*", "?") or isinstance(action, argparse._HelpAction):
            continue
        value = [str(next(iter(action.choices))) if action.choices else "1"][: 0 if action.nargs == 0 else 1]
        argv += [action.option_strings[0], *value] if action.option_strings else value
    return argv


def long_options(sub):
    return [o for a in sub._actions for o in a.option_strings if o.startswith("--") and o != "--help"]


def test_every_subcommand_is_a_parser_without_abbreviations():
    parser, subs = subcommands()
    assert isinstance(parser, Parser) and parser.allow_abbrev is False
    assert len(subs) >= 10
    for name, sub in subs.items():
        assert isinstance(sub, Parser), name
        assert sub.allow_abbrev is False, name


def test_every_abbreviated_option_is_refused_naming_the_option(capsys):
    parser, subs = subcommands()
    tried = 0
    for name, sub in subs.items():
        options = long_options(sub)
        parser.parse_args(minimal_argv(name, sub))  # the minimal command line itself is taken
        for option in options:
            cut = option[:-2]
            if len(cut) <= 3 or any(other.startswith(cut) and other != option for other in options):
                continue
            with pytest.raises(SystemExit) as stop:
                parser.parse_args(minimal_argv(name, sub) + [cut])
            assert stop.value.code == 2
            error = capsys.readouterr().err
            assert f"did you mean {option}?" in error, (name, cut, error)
            tried += 1
    assert tried > 40


def test_fre_is_not_fresh(capsys):
    parser, _ = subcommands()
    with pytest.raises(SystemExit):
        parser.parse_args(["grade", "subs", "--out", "g", "--fre"])
    assert "'--fre': did you mean --fresh?" in capsys.readouterr().err
    assert parser.parse_args(["grade", "subs", "--out", "g", "--fresh"]).fresh is True


def test_a_misspelling_names_the_closest_option(capsys):
    parser, _ = subcommands()
    with pytest.raises(SystemExit):
        parser.parse_args(["grade", "subs", "--out", "g", "--rooster", "r.csv"])
    assert "did you mean --roster?" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        parser.parse_args(["grade", "subs", "--out", "g", "--zzzzzz"])
    error = capsys.readouterr().err
    assert "unrecognized option '--zzzzzz'" in error and "did you mean" not in error


def test_negative_numbers_and_dashes_are_values_not_options():
    parser = Parser(prog="t")
    parser.add_argument("--x", type=float)
    parser.add_argument("rest", nargs="*")
    assert parser.parse_args(["--x", "-1", "--", "-a"]).rest == ["-a"]
    assert parser.parse_args(["--x", "-1"]).x == -1
