"""The answer key's spellings: what an exercise withholds, written the ways a text could state it.

An exercise's declaration lists what the student is asked to find
(:attr:`labkit.exercises.model.Exercise.withheld`): the order a table shows,
a formula the student derives, a value the student computes. A give-away
rarely quotes it one way only, so the helpers here spell each answer as a
notebook, a hint or a figure would ("order 4", "O(h^4)", "fourth-order",
"rate_pherm = 4"; an error of labkit's table as it prints). Values are
worked out from labkit's references when the key is asked for, never typed
in. :func:`normal` is how both the key and the scanned texts are compared.

>>> normal("O(h**4)") in [normal(text) for text in orders(4)]
True
>>> normal("-2*x / (1 + x**2)**2") == normal("−2x/(1+x^2)^2")
True
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable

from ..errors import InputError

ORDINALS = {1: "first", 2: "second", 3: "third", 4: "fourth", 5: "fifth", 6: "sixth"}
# dropped before comparing: spacing, multiplication signs, grouping, LaTeX's backslashes, numpy's prefixes
_WHOLE = re.compile(r"(\d)\.0+(?![\d])")
_DROPPED = re.compile(r"[\s*(){}\\$]|np\.|numpy\.|math\.")


def normal(text: str) -> str:
    """`text` as the release scan compares it: lower case, one minus sign, ``^`` for powers, no spacing,
    no multiplication signs or brackets, whole numbers without ``.0`` (so ``-2.0*x/(1+x**2)**2`` and
    ``−2x/(1+x^2)^2`` read alike)."""
    text = str(text).lower().replace("\u2212", "-").replace("\u2013", "-").replace("**", "^")
    text = text.replace("\\left", "").replace("\\right", "").replace("\\cdot", "").replace("\\,", "")
    text = _WHOLE.sub(r"\1", text)  # 2.0 * x reads as 2x
    return _DROPPED.sub("", text)


def orders(order: int, rate: str | None = None) -> tuple:
    """The ways a text states the order `order` (and, with the rate's name `rate`, the rate answer)."""
    p = int(order)
    if p < 1:
        raise InputError(f"an order is a whole number of at least 1; got {order!r}.")
    found = [
        f"order {p}",
        f"order-{p}",
        f"order = {p}",
        f"order is {p}",
        f"order of {p}",
        f"O(h^{p})",
        f"h^{p}",
        f"h**{p}",
        f"slope of -{p}",
        f"slope -{p}",
        f"slopes -{p}",
        f"{2**p} = 2^p",
        f"2^p = {2**p}",
        f"2^{p} = {2**p}",
        f"ratios near {2**p}",
        f"ratios approach {2**p}",
        f"close to {2**p}",
        f"rate is {p}",
        f"rate = {p}",
        f"rate of {p}",
    ]
    if p in ORDINALS:
        word = ORDINALS[p]
        found += [f"{word} order", f"{word}-order"]
    if rate:
        found += [f"{rate} = {p}", f"{rate} == {p}"]
    return tuple(found)


def printed(value: float) -> tuple:
    """The ways a worked value prints: 3 to 6 significant digits, with two-digit and short exponents.

    Plain decimals (0.00123) are left out: three digits without an exponent match too much else."""
    value = float(value)
    found = []
    for digits in range(2, 6):
        text = f"{value:.{digits}e}"
        mantissa, exponent = text.split("e")
        found += [text, f"{mantissa}e{int(exponent)}", f"{mantissa}x10^{int(exponent)}"]
    return tuple(found)


def values(compute: Callable[[], Iterable[float]]) -> Callable[[], tuple]:
    """An entry of :attr:`~labkit.exercises.model.Exercise.withheld`: the printed forms of the values
    `compute` returns, worked out when the answer key is asked for."""

    def entry():
        return tuple(text for value in compute() for text in printed(value))

    return entry
