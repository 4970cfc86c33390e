"""Time `labkit report` on a class of 300: reading the results back, counting, drawing, writing the page,
and the pairwise similarity search (timed apart) when this labkit has one.

Run: ``.venv/bin/python benchmarks/bench_report.py [--count 300] [--repeat 3]``.

The class is made up (tests/class_results.py): the lab's exercises and rubric, students of varying skill
with a branch each, stubs, slips named with the catalog's hints, errors, time limits, refused references,
a few crashes and submissions that could not be graded; its results are written as `labkit grade` writes
them. Each student also has a source of each of a few graded functions (``grade.sources``): independent
variants of the styles students write, plus a few planted copies, for the similarity search. Figures are
printed, never asserted.
"""

import argparse
import contextlib
import io
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from bench_similarity import synthetic_class as similarity_class
from class_results import pair_of, synthetic_class

from labkit.cli import main as cli
from labkit.grading.reports import class_report, similarity
from labkit.grading.store.report import write_report


def timed(function, repeat):
    """(median seconds, last value) of `repeat` calls."""
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), value


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=300, help="submissions in the class (default 300)")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each step; the median is printed")
    parser.add_argument("--copies", type=int, default=4, help="planted copies per graded function (default 4)")
    args = parser.parse_args()
    if args.count < 2 or args.repeat < 1 or args.copies < 0:
        parser.error("--count must be at least 2, --repeat at least 1 and --copies at least 0")

    grades = synthetic_class(args.count, seed=1)
    graded = [g for g in grades if g.graded]
    # the sources of bench_similarity.py: independent variants of 15 functions, and planted copies
    with_sources, planted_by_index = similarity_class(len(graded), 15, 2 * args.copies, 21)
    rename = {own.name: grade.name for own, grade in zip(with_sources, graded)}
    sources = {}
    for own, grade in zip(with_sources, graded):
        grade.sources = dict(own.sources)
        for function, text in own.sources.items():
            sources.setdefault(function, {})[grade.name] = text
    copied = [(f, rename[a], rename[b]) for f, a, b in planted_by_index]
    lines = statistics.mean(len(text.splitlines()) for texts in sources.values() for text in texts.values())
    print(
        f"a class of {len(grades)} submissions ({len(graded)} graded), {len(sources)} graded functions with a "
        f"source each ({lines:.0f} lines on average), {len(copied)} planted copies"
    )

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        write_report(out, grades)
        size = sum(p.stat().st_size for p in (out / "results").glob("*.json"))
        print(f"results/: {len(grades)} files, {size / 1024**2:.1f} MiB")

        read_s, read_back = timed(lambda: class_report.read(out), args.repeat)
        summary_s, summary = timed(lambda: class_report.summarise(read_back), args.repeat)
        pairs = [pair_of(f, a, b, sources[f][a], sources[f][b]) for f, a, b in copied]
        render_s, page = timed(lambda: class_report.render(summary, pairs), args.repeat)
        write_s, path = timed(lambda: class_report.write(out, read_back, pairs), args.repeat)
        print(f"read results/            {read_s * 1000:7.0f} ms")
        print(f"count (summarise)        {summary_s * 1000:7.0f} ms")
        print(f"draw and render the page {render_s * 1000:7.0f} ms  ({len(pairs)} pairs shown)")
        print(f"summarise+render+write   {write_s * 1000:7.0f} ms")
        print(
            f"report.html: {path.stat().st_size / 1024:.0f} KiB, {len(summary.slips)} slips, "
            f"{sum(len(rows) for rows in summary.problems.values())} problem rows, {len(page):,} characters"
        )

        search = getattr(similarity, "similar_pairs", None)
        if search is None:
            print("similarity: not available (labkit.grading.reports.similarity has no similar_pairs yet)")
        else:
            search_s, found = timed(lambda: search(graded, similarity.DEFAULT_THRESHOLD), args.repeat)
            planted = {(f, *sorted((a, b))) for f, a, b in copied}
            hits = {(p.function, *sorted((p.first, p.second))) for p in found}
            comparisons = len(sources) * len(graded) * (len(graded) - 1) // 2
            print(
                f"similarity search        {search_s * 1000:7.0f} ms  ({comparisons:,} pairs compared, {len(found)} "
                f"above {similarity.DEFAULT_THRESHOLD}, {len(planted & hits)} of {len(planted)} planted copies found)"
            )

        def whole():
            with contextlib.redirect_stdout(io.StringIO()):
                return cli(["report", str(out), "--quiet"])

        whole_s, code = timed(whole, args.repeat)
        print(f"labkit report (in-process, similarity included if any) {whole_s:5.2f} s, exit {code}")
        start = time.perf_counter()
        run = subprocess.run(
            [sys.executable, "-m", "labkit.cli", "report", str(out), "--quiet"], capture_output=True, text=True
        )
        print(
            f"labkit report (a fresh process: imports, matplotlib) {time.perf_counter() - start:5.2f} s, "
            f"exit {run.returncode}"
        )


if __name__ == "__main__":
    main()
