"""What grading writes: a submission's grade, its feedback text, its JSON, grades.csv, and merging.

Layout of an output folder::

    grades.csv               one row per submission: points per exercise, the branch that
                             counted, the extra credit, the total (under the rubric)
    feedback/<name>.txt      what passed, what failed, the hint, what went wrong while running
    results/<name>.json      the same grade as data: merged by ``labkit grade --merge``
    seed.txt                 the seed of the run's random test data

Every file here is written by the grader from its own results; nothing in
it comes from a student's process but plain numbers and short texts, and
those are data: a submission's name becomes a file name through
:func:`safe_name` (a hash keeps two students apart), every text is stripped
of control characters (:func:`printable`) before it reaches a file or a
terminal, and every CSV cell that a spreadsheet would run as a formula is
neutralised (:func:`csv_cell`).
"""

import csv
import hashlib
import json
import re
from dataclasses import dataclass, field
from pathlib import Path

from . import rubric as rubrics
from .rubric import points_text
from .scan import MAX_SOURCE_CHARS

FORMAT = "labkit-grade/2"


@dataclass
class SubmissionGrade:
    """The checks' results for one submission, and its grade under a rubric."""

    name: str
    results: dict = field(default_factory=dict)  # exercise -> grade dict from Registry.check
    problems: list = field(default_factory=list)  # what went wrong while running, per notebook
    seed: int = None
    rubric: rubrics.Rubric = field(default_factory=rubrics.default, repr=False, compare=False)
    failure: str = None  # why the submission could not be graded at all (then it has no points, not zero)
    answers: dict = field(default_factory=dict)  # grade id -> the student's answer in words, for the instructor
    # graded function -> the source of its definition (printable, at most MAX_SOURCE_CHARS), for the similarity
    # search (labkit.grading.similarity); never part of the grade
    sources: dict = field(default_factory=dict)

    @property
    def graded(self):
        return self.failure is None

    @property
    def fractions(self):
        return {n: float(v.get("fraction", 0.0)) for n, v in self.results.items()}

    @property
    def score(self):
        return self.rubric.score(self.fractions)

    @property
    def points(self):
        """Points per graded exercise under the rubric."""
        return self.score.points

    @property
    def total(self):
        return self.score.total

    def feedback(self):
        if not self.graded:
            return printable(
                f"Feedback for {one_line(self.name)}: not graded\n\n! could not be graded: "
                f"{one_line(self.failure, 500)}\n"
                "Your instructor has been told; nothing of this submission was scored.\n"
            )
        score, rubric = self.score, self.rubric
        extra = f" + {points_text(score.extra_total)} extra credit" if score.extra_total else ""
        lines = [
            f"Feedback for {one_line(self.name)}: {points_text(score.total)} points "
            f"({points_text(score.required + score.counted)} / {points_text(score.full_credit)}{extra})",
            "",
        ]
        # a problem's first line is the grader's; what follows (a traceback) is indented, so no line can pose
        # as one of the grader's own
        lines += [line for problem in self.problems for line in _problem_lines(problem)]
        if self.problems:
            lines.append("")
        lines += [rubric.describe(), ""]
        for number in rubric.graded:
            lines += self._exercise_lines(number)
        lines += ["", self._summary()]
        lines += self._answer_lines()
        if self.seed is not None:
            lines += ["", f"(random test data from seed {self.seed})"]
        return printable("\n".join(lines) + "\n")

    def _exercise_lines(self, number):
        points = self.rubric.points[number]
        verdict = self.results.get(number)
        if verdict is None:
            return [
                f"Exercise {number}: 0 / {points_text(points)} - not found: no notebook has its section "
                f"('## Exercise {number}') or it never ran."
            ]
        status = "passed" if verdict["passed"] else "FAILED"
        lines = [f"Exercise {number}: {points_text(self.points[number])} / {points_text(points)} - {status}"]
        total_weight = sum(check.get("weight", 0) for check in verdict["checks"]) or 1
        for check in verdict["checks"]:
            weight = check.get("weight") or 0
            share = points * weight / total_weight
            worth = f" ({points_text(share)} point{'' if share == 1 else 's'})" if weight else ""
            for step in check["steps"]:
                mark = "ok  " if step["passed"] else "FAIL"
                detail = f": {one_line(step['detail'], 1000)}" if step["detail"] else ""
                lines.append(
                    f"    [{mark}] {one_line(check['name'], 100)}{worth}: {one_line(step['step'], 300)}{detail}"
                )
            if check["hint"] and not check["passed"]:
                lines.append(f"    hint: {one_line(check['hint'], 1000)}")
        return lines

    def _answer_lines(self):
        """The answers in words, for the instructor to read (no check scores them)."""
        answers = self.rubric.registry.answers
        if not answers:
            return []
        lines = ["", "For the instructor to read (answers in words, not scored by labkit):"]
        for grade_id, (number, what) in answers.items():
            if number not in self.rubric.points:
                continue
            text = str(self.answers.get(grade_id, "")).strip()
            if not text or text == "YOUR ANSWER HERE":
                text = "(no answer)"
            lines.append(f"  Exercise {number}, {what}:")
            lines += [f"    | {one_line(line, 300)}" for line in text.splitlines()[:20]]
        return lines

    def _summary(self):
        score, rubric = self.score, self.rubric
        lines = [
            f"Exercises {', '.join(map(str, rubric.required))}: {points_text(score.required)} / "
            f"{points_text(sum(rubric.points[n] for n in rubric.required))}"
        ]
        if score.branch == "none":
            lines.append("Branch that counts: none yet (no exercise of either branch earned points)")
        elif score.branch:
            full = sum(rubric.points[n] for n in next(b for b in rubric.branches if b.name == score.branch).exercises)
            lines.append(
                f"Branch that counts: {score.branch}, {points_text(score.counted)} / {points_text(full)} "
                "(the better of the branches)"
            )
        for what, value in score.extra.items():
            lines.append(f"Extra credit, {what}: {points_text(value)}")
        lines.append(f"Total: {points_text(score.total)} (full credit is {points_text(score.full_credit)})")
        return "\n".join(lines)

    def as_dict(self):
        score = self.score
        return {
            "format": FORMAT,
            "name": self.name,
            "seed": self.seed,
            "problems": list(self.problems),
            "failure": self.failure,
            "answers": dict(self.answers),
            "sources": dict(self.sources),
            "results": {str(n): v for n, v in self.results.items()},
            "rubric": self.rubric.title,
            "points": {str(n): v for n, v in score.points.items()},
            "branch": score.branch,
            "extra_credit": score.extra,
            "total": score.total,
        }

    @classmethod
    def from_dict(cls, data, source="a result file", rubric=None):
        """Read back what :meth:`as_dict` wrote (scored again with `rubric`); ValueError names the file."""
        try:
            if data.get("format") != FORMAT:
                raise ValueError(f"format is {data.get('format')!r}, not {FORMAT!r}")
            results = {int(n): v for n, v in data["results"].items()}
            for verdict in results.values():
                float(verdict["fraction"])
            grade = cls(
                str(data["name"]),
                results,
                [str(p) for p in data["problems"]],
                data.get("seed"),
                rubric or rubrics.default(),
                data.get("failure"),
                {str(k): str(v)[:4000] for k, v in dict(data.get("answers") or {}).items()},
                _sources(data.get("sources") or {}),  # results written before the grade kept sources have none
            )
            if grade.failure is not None:
                grade.failure = str(grade.failure)
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{source} is not a labkit grade result ({exc}).") from None
        known = grade.rubric.registry.exercises
        if not set(grade.results) <= set(known):
            raise ValueError(
                f"{source} grades exercises {sorted(grade.results)}, not {sorted(known)}: "
                "it was written by another version of labkit."
            )
        return grade


def _sources(value):
    """A result file's sources, bounded and printable; TypeError when they are not names and texts."""
    sources = dict(value)
    if not all(isinstance(k, str) and isinstance(v, str) for k, v in sources.items()):
        raise TypeError("its sources are not function names and source texts")
    return {printable(k)[:200]: printable(v)[:MAX_SOURCE_CHARS] for k, v in sources.items()}


def _problem_lines(problem):
    first, *rest = str(problem).split("\n") or [""]
    return [f"! {one_line(first, 1000)}"] + [
        "    " + printable(line).replace("\t", " ")[:1000] if line.startswith(" ") else "    | " + one_line(line, 1000)
        for line in rest[:40]
    ]


# control characters, and the invisible ones that break or reorder lines (line and paragraph separators, bidi marks)
CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff\ufff9-\ufffb]")
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def printable(text):
    """`text` without control characters but newline and tab (no escape sequence reaches a terminal), and
    with bytes that were not UTF-8 (a file name from an old zip) spelled out as escapes."""
    text = str(text).encode("utf-8", "backslashreplace").decode("utf-8")
    return CONTROL.sub("\ufffd", text)


def one_line(text, limit=200):
    """A submission's text as one printable line (a name in a table or a terminal)."""
    line = printable(str(text)).replace("\n", " ").replace("\t", " ")
    return line if len(line) <= limit else line[: limit - 1] + "\u2026"


def safe_name(name):
    """A submission's name as a file name: safe characters, at most 60 of them, and a hash of the whole name,
    so two students never share a file ("jane doe" and "jane_doe" differ)."""
    readable = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._-")[:60] or "submission"
    return f"{readable}-{hashlib.sha256(str(name).encode('utf-8', 'surrogatepass')).hexdigest()[:10]}"


def csv_cell(value):
    """A cell a spreadsheet shows as text: one starting like a formula gets a leading apostrophe (OWASP)."""
    text = one_line(value, 500) if isinstance(value, str) else value
    if isinstance(text, str) and text.startswith(FORMULA_START):
        return "'" + text
    return text


CSV_TAIL = ["required", "branch", "branch points", "extra credit", "total", "full credit", "status"]


def read_columns(graded, registry):
    """One empty column per answer in words of the graded exercises, for the instructor to fill in."""
    return [f"to read: exercise {number}, {what}" for number, what in registry.answers.values() if number in graded]


def write_csv(path, grades):
    """One row per submission: points per exercise, the branch that counted, extra credit, total, status.

    A submission that could not be graded has empty points and says why in its status."""
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        graded = grades[0].rubric.graded if grades else []
        to_read = read_columns(graded, grades[0].rubric.registry if grades else None) if grades else []
        writer.writerow(["submission"] + [f"exercise {n}" for n in graded] + CSV_TAIL + to_read)
        for g in grades:
            if not g.graded:
                writer.writerow(
                    [csv_cell(g.name)]
                    + [""] * (len(graded) + len(CSV_TAIL) - 1)
                    + [csv_cell(f"not graded: {g.failure}")]
                    + [""] * len(to_read)
                )
                continue
            s = g.score
            writer.writerow(
                [csv_cell(g.name)]
                + [points_text(s.points[n]) for n in graded]
                + [
                    points_text(s.required),
                    csv_cell(s.branch),
                    points_text(s.counted),
                    points_text(s.extra_total),
                    points_text(s.total),
                    points_text(s.full_credit),
                    "graded",
                ]
                + [""] * len(to_read)
            )


def write_result(out_dir, grade):
    """results/<name>.json and feedback/<name>.txt of one submission."""
    out = Path(out_dir)
    for folder in ("results", "feedback"):
        (out / folder).mkdir(parents=True, exist_ok=True)
    (out / "results" / f"{safe_name(grade.name)}.json").write_text(
        json.dumps(grade.as_dict(), indent=1), encoding="utf-8"
    )
    (out / "feedback" / f"{safe_name(grade.name)}.txt").write_text(grade.feedback(), encoding="utf-8")


def write_report(out_dir, grades):
    """grades.csv plus each submission's result and feedback files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for grade in grades:
        write_result(out, grade)
    write_csv(out / "grades.csv", grades)


def read_results(folders, rubric=None):
    """Every results/*.json of the given output folders, in name order; ValueError on a clash."""
    grades = {}
    for folder in map(Path, folders):
        files = sorted((folder / "results").glob("*.json"))
        if not files:
            raise ValueError(
                f"{folder} holds no results/*.json: give the --out folders of earlier `labkit grade` runs."
            )
        for path in files:
            try:
                data = json.loads(path.read_text(encoding="utf-8"))
            except (UnicodeDecodeError, ValueError) as exc:
                raise ValueError(f"{path} is not JSON ({exc}).") from None
            grade = SubmissionGrade.from_dict(data, str(path), rubric)
            if grade.name in grades:
                raise ValueError(f"submission {grade.name!r} is graded twice ({path}); keep one of the two results.")
            grades[grade.name] = grade
    return [grades[name] for name in sorted(grades)]


def merge(folders, out_dir, rubric=None):
    """Combine the results of several grading runs (e.g. one per batch job) into one grades.csv,
    scored with `rubric` (the lab's when None)."""
    grades = read_results(folders, rubric)
    write_report(out_dir, grades)
    seeds = sorted({g.seed for g in grades if g.seed is not None})
    (Path(out_dir) / "seed.txt").write_text("".join(f"{s}\n" for s in seeds), encoding="utf-8")
    return grades
