"""The ``labkit`` command's argument parser: options are taken only as spelled.

argparse, by default, reads any unambiguous prefix of an option as the option
(``--fre`` as ``--fresh``, which deletes the earlier results). :class:`Parser`
turns that off in the command and in every subcommand (they are made of the
same class), and refuses a mistyped option naming the nearest real one.
"""

from __future__ import annotations

import argparse
import difflib


class Parser(argparse.ArgumentParser):
    """An ArgumentParser without abbreviations whose subcommands are Parsers too.

    >>> parser = Parser(prog="labkit")
    >>> _ = parser.add_argument("--fresh", action="store_true")
    >>> parser.parse_args(["--fresh"]).fresh
    True
    >>> parser.nearest("--fre")
    '--fresh'
    """

    def __init__(self, *args, **kwargs):
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)

    def parse_known_args(self, args=None, namespace=None):
        namespace, extras = super().parse_known_args(args, namespace)
        for extra in extras:
            if extra.startswith("-") and extra not in ("-", "--") and not _number(extra):
                self.error(self.unknown(extra))
        return namespace, extras

    def options(self) -> list[str]:
        """Every option string this parser takes (``--help`` included)."""
        return [option for action in self._actions for option in action.option_strings]

    def nearest(self, given: str) -> str | None:
        """The real option nearest to `given` (a prefix of it first, else the closest spelling), or None."""
        given = given.split("=", 1)[0]
        options = self.options()
        starting = [option for option in options if option.startswith(given) and option.startswith("--")]
        if len(given) > 2 and starting:
            return min(starting, key=len)
        close = difflib.get_close_matches(given, options, n=1, cutoff=0.6)
        return close[0] if close else None

    def unknown(self, given: str) -> str:
        """The error for an option this parser does not take."""
        shown = given.split("=", 1)[0]
        near = self.nearest(given)
        hint = f"did you mean {near}? " if near else ""
        return (
            f"unrecognized option {shown!r}: {hint}labkit takes options only as spelled in full "
            f"(see {self.prog} --help)"
        )


def _number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True
