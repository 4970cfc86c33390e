"""Time the similarity search (labkit.grading.reports.similarity) on a synthetic class.

Independent variants and a few copies.

Run: ``.venv/bin/python benchmarks/bench_similarity.py [--students 300] [--functions 15] [--copies 8]``.
Each function has four approaches (programs of a dozen statements); each
student takes one and rewrites most of its statements in their own way, under
names of their own, so that independent students share something but not most.
A few students copy one function of a classmate: renamed, re-spaced, with
comments of their own. The search must find exactly those copies. The time
is printed with its parts (fingerprinting, scoring every pair from the
inverted index), and, when copydetect is installed (labkit's test extra), the
pairs of one function it flags, as an outside reference.
"""

import argparse
import io
import itertools
import re
import time

import numpy as np

from labkit.grading.reports import similarity
from labkit.grading.store.report import SubmissionGrade

OPERATORS = ["+", "-", "*", "/", "**"]
CALLS = ["np.sqrt", "np.abs", "np.sum", "np.max", "len", "np.cos", "np.exp", "float", "np.asarray", "np.diff"]
WORDS = ["x", "y", "val", "data", "tmp", "res", "acc", "lo", "hi", "idx", "step", "coef", "pts", "out", "err", "w"]


def _expression(rng, names, depth=0):
    roll = rng.random() if depth else 0.3 + 0.7 * rng.random()  # a statement's expression is never a bare name
    if depth > 2 or roll < 0.3:
        return rng.choice(names) if rng.random() < 0.75 else str(rng.integers(1, 20))
    if roll < 0.5:
        return f"{rng.choice(CALLS)}({_expression(rng, names, depth + 1)})"
    if roll < 0.6:
        return f"{rng.choice(names)}[{rng.choice(names)} + {rng.integers(0, 3)}]"
    op = rng.choice(OPERATORS)
    return f"({_expression(rng, names, depth + 1)} {op} {_expression(rng, names, depth + 1)})"


def _statement(rng, names):
    """One statement of placeholder names (a0, a1, ...), as lines without indentation."""
    roll = rng.random()
    if roll < 0.7:
        return [f"{rng.choice(names)} = {_expression(rng, names)}"]
    if roll < 0.85:
        return [
            f"for {rng.choice(names)} in range(len({rng.choice(names)})):",
            f"    {rng.choice(names)} = {_expression(rng, names)}",
        ]
    return [
        f"if {_expression(rng, names)} > {rng.integers(0, 5)}:",
        f"    {rng.choice(names)} = {_expression(rng, names)}",
    ]


def _mutated(rng, statement):
    """A statement of the approach as one student writes it: often with a number or an operator of their own."""
    if rng.random() < 0.4:
        return statement
    line = rng.integers(len(statement))
    text = statement[line]
    spots = [i for i, c in enumerate(text) if c.isdigit() or c in "+-*/"]
    spots = [i for i in spots if not (text[i].isdigit() and i > 0 and text[i - 1] == "a")]  # not a placeholder
    if spots:
        i = rng.choice(spots)
        new = str(rng.integers(20, 99)) if text[i].isdigit() else rng.choice(["+", "-", "*"])
        text = text[:i] + new + text[i + 1 :]
    return statement[:line] + [text] + statement[line + 1 :]


def _render(function, statements, rename, rng, comments):
    """The source: the placeholders renamed, a comment here and there."""
    lines = [f"def {function}(a0, a1, a2):"]
    for statement in statements:
        if rng.random() < comments:
            lines.append(f"    # step {rng.integers(1, 99)}: {rng.choice(WORDS)} from {rng.choice(WORDS)}")
        for line in statement:
            for placeholder in sorted(rename, key=len, reverse=True):
                line = line.replace(placeholder, rename[placeholder])
            lines.append("    " + line)
    lines.append(f"    return {rename['a3']}")
    return "\n".join(lines) + "\n"


def _names(rng, student):
    words = rng.permutation(WORDS)[:8]
    return {f"a{i}": f"{word}{student % 7 if rng.random() < 0.5 else ''}_{i}" for i, word in enumerate(words)}


def synthetic_class(students, functions, copies, seed):
    """(grades, the planted copies as {(function, first, second)})."""
    rng = np.random.default_rng(seed)
    placeholders = [f"a{i}" for i in range(8)]
    approaches = {
        f"fn{f:02d}": [[_statement(rng, placeholders) for _ in range(rng.integers(9, 15))] for _ in range(4)]
        for f in range(functions)
    }
    sources = {f"student{s:03d}": {} for s in range(students)}
    for s, name in enumerate(sources):
        for function, options in approaches.items():
            base = options[rng.integers(len(options))]
            own = [_mutated(rng, stmt) if rng.random() < 0.5 else _statement(rng, placeholders) for stmt in base]
            sources[name][function] = _render(function, own, _names(rng, s), rng, 0.2)
    planted, names = set(), list(sources)
    while len(planted) < copies:
        function = f"fn{rng.integers(functions):02d}"
        original, copier = rng.choice(names, 2, replace=False)
        if any(p[0] == function and {original, copier} & set(p[1:]) for p in planted):
            continue
        # the copier's version: the original's statements under the copier's names, comments of their own
        text = sources[original][function]
        lines = [line for line in text.split("\n") if not line.strip().startswith("#")]
        for i, name in enumerate(sorted(set(re.findall(r"\b[a-z]+\d?_\d\b", text)))):
            lines = [re.sub(rf"\b{name}\b", f"q{i}z", line) for line in lines]
        copied = []
        for line in lines:
            if line.strip() and rng.random() < 0.3:
                copied.append(f"    # {rng.choice(WORDS)} again")
            copied.append(line.replace(" = ", "=").replace(" + ", "+"))
        sources[copier][function] = "\n".join(copied)
        planted.add((function, *sorted((str(original), str(copier)))))
    return [SubmissionGrade(name, sources=kept) for name, kept in sources.items()], planted


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=300)
    parser.add_argument("--functions", type=int, default=15)
    parser.add_argument("--copies", type=int, default=8)
    parser.add_argument("--seed", type=int, default=21)
    args = parser.parse_args()
    grades, planted = synthetic_class(args.students, args.functions, args.copies, args.seed)
    size = np.mean([len(text) for g in grades for text in g.sources.values()])
    print(
        f"{args.students} students x {args.functions} functions ({size:.0f} characters each on average), "
        f"{len(planted)} copies planted"
    )

    start = time.perf_counter()
    given = similarity.boilerplate()
    release = time.perf_counter() - start
    start = time.perf_counter()
    pairs = similarity.similar_pairs(grades)
    total = time.perf_counter() - start
    found = {(p.function, p.first, p.second) for p in pairs}
    print(
        f"similar_pairs: {total:.1f} s (the packaged release's boilerplate before it: {release:.2f} s); "
        f"{len(pairs)} flagged at {similarity.DEFAULT_THRESHOLD}"
    )

    def scores_of(copies):
        return ", ".join(f"{p.score:.2f}" for p in pairs if ((p.function, p.first, p.second) in planted) == copies)

    print(
        f"planted copies found: {len(found & planted)} of {len(planted)} (scores {scores_of(True)}); "
        f"flagged pairs that are no copy: {len(found - planted)} (scores {scores_of(False) or '-'})"
    )

    # the parts, on the same class
    by_function = {}
    for grade in grades:
        for function, text in grade.sources.items():
            by_function.setdefault(function, []).append((grade.name, text))
    start = time.perf_counter()
    versions = {f: [similarity._version(n, t, given.hashes) for n, t in texts] for f, texts in by_function.items()}
    fingerprinting = time.perf_counter() - start
    start = time.perf_counter()
    scores = {f: similarity.shares([v for v in kept if v is not None]) for f, kept in versions.items()}
    scoring = time.perf_counter() - start
    print(
        f"parts: fingerprinting {sum(map(len, versions.values()))} sources {fingerprinting:.1f} s, "
        f"scoring all pairs from the inverted index {scoring:.1f} s"
    )
    independent = np.concatenate([np.maximum(s, s.T)[np.triu_indices(len(s), 1)] for s in scores.values()])
    print(
        f"scores of all {len(independent)} pairs: median {np.median(independent):.2f}, "
        f"99th percentile {np.percentile(independent, 99):.2f}, max {independent.max():.2f}"
    )
    reference(by_function, found)


def reference(by_function, found):
    """The pairs that copydetect flags, beside ours, for three functions with a planted copy (an outside reference)."""
    try:
        import copydetect
    except ImportError:
        print("copydetect is not installed: no outside reference")
        return
    for function in sorted({f for f, _, _ in found})[:3]:
        start = time.perf_counter()
        prints = {
            name: copydetect.CodeFingerprint("a.py", 25, 6, fp=io.StringIO(text), language="python")
            for name, text in by_function[function]
        }
        theirs = set()
        for one, other in itertools.combinations(sorted(prints), 2):
            _, both, _ = copydetect.compare_files(prints[one], prints[other])
            if max(both) >= similarity.DEFAULT_THRESHOLD:
                theirs.add((function, one, other))
        ours = {pair for pair in found if pair[0] == function}
        print(
            f"copydetect on all pairs of {function} ({time.perf_counter() - start:.1f} s): flags {len(theirs)}, "
            f"ours {len(ours)}, both {len(ours & theirs)}"
        )


if __name__ == "__main__":
    main()
