"""What grading writes: a submission's grade, its feedback text, its JSON, grades.csv, and merging.

Layout of an output folder::

    grades.csv               one row per submission, one column per exercise, and the total
    feedback/<name>.txt      what passed, what failed, the hint, what went wrong while running
    results/<name>.json      the same grade as data: merged by ``labkit grade --merge``
    seed.txt                 the seed of the run's random test data

Every file here is written by the grader from its own results; nothing in
it comes from a student's process but plain numbers and short texts.
"""
import csv
import json
import re
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..checks.exercises import EXERCISES, POINTS

FORMAT = "labkit-grade/1"


@dataclass
class SubmissionGrade:
    """Points per exercise and the feedback for one submission."""

    name: str
    points: dict = field(default_factory=dict)
    results: dict = field(default_factory=dict)  # exercise -> grade dict from labkit.check.grade
    problems: list = field(default_factory=list)  # what went wrong while running, per notebook
    seed: int = None

    @property
    def total(self):
        return sum(self.points.values())

    def feedback(self):
        lines = [f"Feedback for {self.name}: {self.total} / {sum(POINTS.values())} points", ""]
        lines += [f"! {problem}" for problem in self.problems]
        if self.problems:
            lines.append("")
        for number in sorted(EXERCISES):
            verdict = self.results.get(number)
            if verdict is None:
                lines.append(f"Exercise {number}: 0 / {POINTS[number]} - not found: no notebook has its section "
                             f"('## Exercise {number}') or it never ran.")
                continue
            status = "passed" if verdict["passed"] else "FAILED"
            lines.append(f"Exercise {number}: {verdict['points']} / {POINTS[number]} - {status}")
            for check in verdict["checks"]:
                for step in check["steps"]:
                    mark = "ok  " if step["passed"] else "FAIL"
                    detail = f": {step['detail']}" if step["detail"] else ""
                    lines.append(f"    [{mark}] {check['name']}: {step['step']}{detail}")
                if check["hint"] and not check["passed"]:
                    lines.append(f"    hint: {check['hint']}")
        if self.seed is not None:
            lines += ["", f"(random test data from seed {self.seed})"]
        return "\n".join(lines) + "\n"

    def as_dict(self):
        data = asdict(self)
        data["format"] = FORMAT
        data["total"] = self.total
        data["results"] = {str(n): v for n, v in self.results.items()}
        data["points"] = {str(n): v for n, v in self.points.items()}
        return data

    @classmethod
    def from_dict(cls, data, source="a result file"):
        """Read back what :meth:`as_dict` wrote; ValueError names the file if it is not one."""
        try:
            if data.get("format") != FORMAT:
                raise ValueError(f"format is {data.get('format')!r}, not {FORMAT!r}")
            grade = cls(str(data["name"]), {int(n): int(v) for n, v in data["points"].items()},
                        {int(n): v for n, v in data["results"].items()}, list(data["problems"]), data.get("seed"))
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{source} is not a labkit grade result ({exc}).") from None
        if set(grade.points) != set(EXERCISES):
            raise ValueError(f"{source} grades exercises {sorted(grade.points)}, not {sorted(EXERCISES)}: "
                             "it was written by another version of labkit.")
        return grade


def safe_name(name):
    """A submission's name as a file name."""
    return re.sub(r"[^\w.-]+", "_", name)


def write_csv(path, grades):
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["submission"] + [f"exercise {n}" for n in sorted(EXERCISES)] + ["total"])
        for g in grades:
            writer.writerow([g.name] + [g.points[n] for n in sorted(EXERCISES)] + [g.total])


def write_result(out_dir, grade):
    """results/<name>.json and feedback/<name>.txt of one submission."""
    out = Path(out_dir)
    for folder in ("results", "feedback"):
        (out / folder).mkdir(parents=True, exist_ok=True)
    (out / "results" / f"{safe_name(grade.name)}.json").write_text(json.dumps(grade.as_dict(), indent=1),
                                                                     encoding="utf-8")
    (out / "feedback" / f"{safe_name(grade.name)}.txt").write_text(grade.feedback(), encoding="utf-8")


def write_report(out_dir, grades):
    """grades.csv plus each submission's result and feedback files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for grade in grades:
        write_result(out, grade)
    write_csv(out / "grades.csv", grades)


def read_results(folders):
    """Every results/*.json of the given output folders, in name order; ValueError on a clash."""
    grades = {}
    for folder in map(Path, folders):
        files = sorted((folder / "results").glob("*.json"))
        if not files:
            raise ValueError(f"{folder} holds no results/*.json: give the --out folders of earlier `labkit grade` runs.")
        for path in files:
            try:
                data = json.loads(path.read_text(encoding="utf-8"))
            except (UnicodeDecodeError, ValueError) as exc:
                raise ValueError(f"{path} is not JSON ({exc}).") from None
            grade = SubmissionGrade.from_dict(data, str(path))
            if grade.name in grades:
                raise ValueError(f"submission {grade.name!r} is graded twice ({path}); keep one of the two results.")
            grades[grade.name] = grade
    return [grades[name] for name in sorted(grades)]


def merge(folders, out_dir):
    """Combine the results of several grading runs (e.g. one per batch job) into one grades.csv."""
    grades = read_results(folders)
    write_report(out_dir, grades)
    seeds = sorted({g.seed for g in grades if g.seed is not None})
    (Path(out_dir) / "seed.txt").write_text("".join(f"{s}\n" for s in seeds), encoding="utf-8")
    return grades
