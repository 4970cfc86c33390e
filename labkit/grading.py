"""Student release and autograding of the lab's notebooks.

``release`` turns the instructor notebooks into the student version: code
between ``### BEGIN SOLUTION`` / ``### END SOLUTION`` becomes a stub that
raises ``NotImplementedError``, hidden tests between ``### BEGIN HIDDEN
TESTS`` / ``### END HIDDEN TESTS`` disappear, outputs are cleared. The
markers are nbgrader's, so a course using nbgrader can take the instructor
notebooks as its source unchanged.

``grade`` executes every submitted notebook in a fresh kernel in a temporary
directory of its own, with a per-cell and a total time limit and a cap on
printed output, then runs :func:`labkit.check.grade` for every exercise whose
functions the notebook defines. It is not a security sandbox: student code
runs with the grader's permissions.
"""
import csv
import json
import multiprocessing
import re
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

from .check import EXERCISES, POINTS
from .notebooks import KERNEL

BEGIN_SOLUTION, END_SOLUTION = "### BEGIN SOLUTION", "### END SOLUTION"
BEGIN_HIDDEN, END_HIDDEN = "### BEGIN HIDDEN TESTS", "### END HIDDEN TESTS"
STUB = ["# YOUR CODE HERE", "raise NotImplementedError()"]
OUTPUT_LIMIT = 100_000  # characters kept per cell; the rest of a flood of output is dropped


# -- release ------------------------------------------------------------------

def strip_solutions(source, where="cell"):
    """Replace solution regions by stubs and drop hidden-test regions in one cell's source."""
    lines, out, region = source.split("\n"), [], None
    for number, line in enumerate(lines, start=1):
        marker = line.strip()
        if marker in (BEGIN_SOLUTION, BEGIN_HIDDEN):
            if region:
                raise ValueError(f"{where}, line {number}: {marker!r} inside an open {region!r} region.")
            region = marker
            if marker == BEGIN_SOLUTION:
                indent = line[: len(line) - len(line.lstrip())]
                out.extend(indent + stub for stub in STUB)
        elif marker in (END_SOLUTION, END_HIDDEN):
            expected = BEGIN_SOLUTION if marker == END_SOLUTION else BEGIN_HIDDEN
            if region != expected:
                raise ValueError(f"{where}, line {number}: {marker!r} without a matching {expected!r}.")
            region = None
        elif region is None:
            out.append(line)
    if region:
        raise ValueError(f"{where}: the {region!r} region is never closed.")
    return "\n".join(out)


def release_notebook(nb, name="notebook"):
    """The student version of an instructor notebook (a new object)."""
    student = nbformat.from_dict(json.loads(json.dumps(nb)))
    student.metadata.pop("widgets", None)
    for index, cell in enumerate(student.cells):
        if cell.cell_type == "code":
            cell.source = strip_solutions(cell.source, f"{name}, cell {index}")
            cell.outputs = []
            cell.execution_count = None
    return student


def release(notebook_dir, out_dir):
    """Write the student version of every notebook of `notebook_dir` into `out_dir`."""
    from .notebooks import notebook_paths

    paths = notebook_paths(notebook_dir)
    out = Path(out_dir)
    if out.resolve() == Path(notebook_dir).resolve():
        raise ValueError("--out must differ from the notebook folder; the release would overwrite the solutions.")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in paths:
        student = release_notebook(_read_notebook(path), path.name)
        target = out / path.name
        nbformat.write(student, target)
        written.append(target)
    return written


# -- grading ------------------------------------------------------------------

@dataclass
class SubmissionGrade:
    """Points per exercise and the feedback for one submission."""

    name: str
    points: dict = field(default_factory=dict)
    results: dict = field(default_factory=dict)  # exercise -> grade dict from labkit.check.grade
    problems: list = field(default_factory=list)  # what went wrong while running, per notebook

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
        return "\n".join(lines) + "\n"


def _read_notebook(path):
    try:
        text = Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"{path} is not a text file, so not a notebook.") from None
    try:
        return nbformat.reads(text, as_version=4)
    except Exception as exc:  # nbformat raises several kinds for broken files
        raise ValueError(f"{Path(path).name} is not a valid notebook ({type(exc).__name__}: {str(exc)[:200]}).") from None


def submission_notebooks(path):
    """The notebooks of a submission: one .ipynb file, or every .ipynb in a folder."""
    path = Path(path)
    if path.is_dir():
        notebooks = sorted(p for p in path.rglob("*.ipynb") if ".ipynb_checkpoints" not in p.parts)
        if not notebooks:
            raise ValueError(f"{path} contains no notebooks (*.ipynb).")
        return notebooks
    if not path.exists():
        raise ValueError(f"{path} does not exist.")
    if path.suffix != ".ipynb":
        raise ValueError(f"{path} is not a notebook: give .ipynb files or folders of them.")
    return [path]


HEADING = re.compile(r"^#+\s*Exercise\s+(\d+)", re.MULTILINE)


def exercises_in(nb):
    """Graded exercises whose section heading ('## Exercise N') the notebook has."""
    found = {int(n) for cell in nb.cells if cell.cell_type == "markdown" for n in HEADING.findall(cell.source)}
    return sorted(found & set(EXERCISES))


def _grading_cell(numbers, nonce):
    return nbformat.v4.new_code_cell(
        "import json as _labkit_json, labkit.check as _labkit_check\n"
        f"for _n in {numbers}:\n"
        f"    print({nonce!r} + _labkit_json.dumps(_labkit_check.grade(_n, globals())))\n"
    )


class _TotalTimeout(Exception):
    pass


def _on_alarm(signum, frame):
    raise _TotalTimeout()


def _client(nb, workdir, cell_timeout):
    from nbclient import NotebookClient

    class CappedClient(NotebookClient):
        """Drops output beyond OUTPUT_LIMIT characters per cell, so a print loop cannot eat memory."""

        def output(self, outs, msg, display_id, cell_index):
            used = sum(len(str(o.get("text", ""))) + len(str(o.get("data", ""))) for o in outs)
            if used > OUTPUT_LIMIT:
                return None
            return super().output(outs, msg, display_id, cell_index)

    # figures are not graded: no inline PNG rendering halves the run time of the mesh notebook
    return CappedClient(nb, timeout=cell_timeout, kernel_name=KERNEL, allow_errors=True,
                        interrupt_on_timeout=True, resources={"metadata": {"path": str(workdir)}},
                        extra_arguments=["--InlineBackend.figure_formats=[]"])


def _kill_kernel(client):
    """Stop a kernel whose run was abandoned (the alarm leaves nbclient no chance to)."""
    provisioner = getattr(getattr(client, "km", None), "provisioner", None)
    process = getattr(provisioner, "process", None)
    if process is not None and process.poll() is None:
        process.kill()
        process.wait(timeout=10)


def grade_notebook(path, cell_timeout=60, total_timeout=600):
    """Run one notebook and return ({exercise: grade dict}, [problems])."""
    try:
        nb = _read_notebook(path)
    except ValueError as exc:
        return {}, [str(exc)]
    numbers = exercises_in(nb)
    if not numbers:
        return {}, []
    nonce = f"LABKIT-GRADE-{secrets.token_hex(8)}:"
    nb.cells.append(_grading_cell(numbers, nonce))
    problems = []
    with tempfile.TemporaryDirectory(prefix="labkit-grade-") as workdir:
        shutil.copy(path, Path(workdir) / Path(path).name)
        client = _client(nb, workdir, cell_timeout)
        previous = signal.signal(signal.SIGALRM, _on_alarm)
        signal.alarm(int(total_timeout))
        try:
            # the kernel's own log (not the student's output) would clutter the progress bar
            client.execute(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except _TotalTimeout:
            _kill_kernel(client)
            problems.append(f"{Path(path).name}: stopped after the total time limit of {total_timeout} s.")
        except Exception as exc:  # noqa: BLE001 - a broken kernel must not stop the other submissions
            problems.append(f"{Path(path).name}: the run failed ({type(exc).__name__}: {str(exc)[:300]}).")
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)
    results = {}
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            if output.get("output_type") == "stream" and output.get("name") == "stdout":
                for line in output.get("text", "").splitlines():
                    if line.startswith(nonce):
                        verdict = json.loads(line[len(nonce):])
                        results[verdict["exercise"]] = verdict
    errors = [c for c in nb.cells if any(o.get("output_type") == "error" for o in c.get("outputs", []))]
    if errors:
        problems.append(f"{Path(path).name}: {len(errors)} cell(s) raised an error (graded as far as it got).")
    return results, problems


def grade_submission(path, cell_timeout=60, total_timeout=600):
    """Grade one submission (a notebook or a folder of them)."""
    path = Path(path)
    grade = SubmissionGrade(path.stem if path.is_file() else path.name)
    for notebook in submission_notebooks(path):
        results, problems = grade_notebook(notebook, cell_timeout, total_timeout)
        grade.problems.extend(problems)
        for number, verdict in results.items():
            best = grade.results.get(number)
            # an exercise may be mentioned in several notebooks: keep the one that scores,
            # or else the one that defines its functions
            if best is None or (verdict["points"], verdict["defined"]) > (best["points"], best["defined"]):
                grade.results[number] = verdict
    grade.points = {n: (grade.results[n]["points"] if n in grade.results else 0) for n in sorted(EXERCISES)}
    return grade


def _progress(done, total, width=30):
    filled = int(width * done / total)
    sys.stderr.write(f"\rgrading [{'#' * filled}{'.' * (width - filled)}] {done}/{total}")
    if done == total:
        sys.stderr.write("\n")
    sys.stderr.flush()


def grade(submissions, out_dir, jobs=2, cell_timeout=60, total_timeout=600, progress=True):
    """Grade submissions in parallel; write grades.csv and one feedback file each."""
    submissions = [Path(s) for s in submissions]
    for path in submissions:
        submission_notebooks(path)  # bad paths stop here, before any work
    names = [p.stem if p.is_file() else p.name for p in submissions]
    if len(set(names)) != len(names):
        raise ValueError("two submissions have the same name; their feedback files would collide.")
    out = Path(out_dir)
    (out / "feedback").mkdir(parents=True, exist_ok=True)
    grades = {}
    # spawn, not fork: a forked worker inherits the parent's event loop and zmq state,
    # which made kernel start-up several times slower here
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=max(1, jobs), mp_context=context) as pool:
        futures = {pool.submit(grade_submission, p, cell_timeout, total_timeout): p for p in submissions}
        for done, future in enumerate(as_completed(futures), start=1):
            path = futures[future]
            try:
                result = future.result()
            except Exception as exc:  # noqa: BLE001
                result = SubmissionGrade(path.stem if path.is_file() else path.name,
                                         {n: 0 for n in sorted(EXERCISES)}, {}, [f"grading failed: {exc}"])
            grades[path] = result
            if progress:
                _progress(done, len(submissions))
    ordered = [grades[p] for p in submissions]
    _write_csv(out / "grades.csv", ordered)
    for g in ordered:
        (out / "feedback" / f"{_safe(g.name)}.txt").write_text(g.feedback(), encoding="utf-8")
    return ordered


def _safe(name):
    return re.sub(r"[^\w.-]+", "_", name)


def _write_csv(path, grades):
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["submission"] + [f"exercise {n}" for n in sorted(EXERCISES)] + ["total"])
        for g in grades:
            writer.writerow([g.name] + [g.points[n] for n in sorted(EXERCISES)] + [g.total])
