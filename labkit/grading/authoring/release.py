"""The student version of the instructor notebooks, from nbgrader's markers (:func:`release_notebook`); with a
roster and a variants file, one folder per student whose notebooks hold their own data (:func:`with_values`).
The instructor notebooks' nbgrader cell metadata comes from the same markers (:func:`mark`)."""

import ast
import re
from copy import deepcopy
from pathlib import Path

from ...errors import InputError
from ...execute import RAISES, notebook_paths, raising_cells, read_notebook, set_tag
from ...exercises import variants as variant_data
from ...exercises.model import sections
from ...exercises.registry import LAB
from ..store import rubric as rubrics

BEGIN_SOLUTION, END_SOLUTION = "### BEGIN SOLUTION", "### END SOLUTION"
BEGIN_HIDDEN, END_HIDDEN = "### BEGIN HIDDEN TESTS", "### END HIDDEN TESTS"
STUB = ["# YOUR CODE HERE", "raise NotImplementedError()"]
TEXT_STUB = ["YOUR ANSWER HERE"]
SCHEMA_VERSION = 3  # of nbgrader's cell metadata (nbgrader/nbgraderformat/v3.json)
EXERCISE_OF_TESTS = re.compile(r"^# tests for exercise (\d+)\s*$", re.MULTILINE)
# a self-check call, labkit.check.<name>(...) or a course's check_<name>(...); a quoted first argument is an experiment
CHECK_CALL = re.compile(r"(?:\blabkit\.check\.|\bcheck_)(\w+)\(\s*(?:\"(\w+)\")?")


def strip_solutions(source, where="cell", stub=STUB):
    """Replace solution regions by stubs and drop hidden-test regions in one cell's source."""
    lines, out, region = source.split("\n"), [], None
    for number, line in enumerate(lines, start=1):
        marker = line.strip()
        if marker in (BEGIN_SOLUTION, BEGIN_HIDDEN):
            if region:
                raise InputError(f"{where}, line {number}: {marker!r} inside an open {region!r} region.")
            region = marker
            if marker == BEGIN_SOLUTION:  # the stub, indented as the marker
                out.extend(line[: len(line) - len(line.lstrip())] + stub_line for stub_line in stub)
        elif marker in (END_SOLUTION, END_HIDDEN):
            expected = BEGIN_SOLUTION if marker == END_SOLUTION else BEGIN_HIDDEN
            if region != expected:
                raise InputError(f"{where}, line {number}: {marker!r} without a matching {expected!r}.")
            region = None
        elif region is None:
            out.append(line)
    if region:
        raise InputError(f"{where}: the {region!r} region is never closed.")
    return "\n".join(out)


def release_notebook(nb, name="notebook"):
    """The student version of an instructor notebook (a new object): each solution region a stub (:data:`STUB` in
    code, :data:`TEXT_STUB` in markdown), hidden-test regions gone (their cell read-only and not deletable, as
    nbgrader leaves it), outputs cleared."""
    student = deepcopy(nb)
    student.metadata.pop("widgets", None)
    for index, cell in enumerate(student.cells):
        if cell.cell_type == "code":
            if BEGIN_HIDDEN in cell.source:  # JupyterLab and Notebook 7 keep it read-only
                cell.metadata.update(editable=False, deletable=False)
            cell.source = strip_solutions(cell.source, f"{name}, cell {index}")
            cell.outputs = []
            cell.execution_count = None
        elif cell.cell_type == "markdown" and BEGIN_SOLUTION in cell.source:
            cell.source = strip_solutions(cell.source, f"{name}, cell {index}", TEXT_STUB)
    return student


def tag_raising(nb, folder, name="notebook", timeout=300):
    """Tag ``raises-exception`` (in place) the cells of instructor notebook `nb` that raise in its release, run in
    `folder` (for its data files), so that Run All of an unwritten notebook goes on to its end; untag the others.
    Returns the indices of the tagged cells."""
    raising = set(raising_cells(release_notebook(nb, name), folder, timeout))
    for index, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            set_tag(cell, RAISES, index in raising)
    return sorted(raising)


def with_values(nb, values, name="notebook", registry=LAB):
    """Notebook `nb` (a new object) whose ``variant-data`` cells' one-line assignments of its exercises' parameters
    (a plain number) and derived values hold `values` ({exercise: {parameter: value}}) as the notebook shows them;
    a missing assignment is refused (ValueError), so no student gets the lab's data by mistake."""
    copy = deepcopy(nb)
    wanted, params = _assignments(values, name, registry)
    done = set()
    for index, cell in enumerate(copy.cells):
        if cell.cell_type == "code" and variant_data.DATA_TAG in cell.metadata.get("tags", []):
            done |= _assign(cell, f"{name}, cell {index}", wanted, params)
    missing = sorted(set(wanted) - done)
    if missing:
        raise InputError(
            f"{name} has no data cell assigning {', '.join(missing)}: add a code cell tagged "
            f"{variant_data.DATA_TAG!r} with `{missing[0]} = <the lab's value>`."
        )
    return copy


def _assignments(values, name, registry):
    """({name: the text its assignment gets}, the parameters among them) for the exercises of notebook `name`."""
    wanted, params = {}, set()
    for number, given in values.items():
        exercise = registry.exercises.get(int(number))
        if exercise is None or exercise.notebook != name:
            continue
        for param in exercise.params:
            if param.name in given:
                wanted[param.name] = param.shown(given[param.name])
                params.add(param.name)
        if exercise.derived is not None and all(param.name in given for param in exercise.params):
            wanted.update(exercise.derived(given))
    return wanted, params


def _assign(cell, where, wanted, params):
    """Put the `wanted` texts in one data cell's one-line assignments (in place); the names it assigned."""
    try:
        tree = ast.parse(cell.source)
    except SyntaxError:
        raise InputError(f"{where}: a data cell must be plain Python assignments.") from None
    pieces = re.split(r"(\r\n|\r|\n)", cell.source)  # the line breaks ast counts, kept as they were
    lines, breaks = pieces[0::2], pieces[1::2]
    edits, done = [], set()
    for node in tree.body:
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)):
            continue
        target, value = node.targets[0].id, node.value
        if target not in wanted:
            continue
        if value.lineno != value.end_lineno:
            raise InputError(f"{where}: {target} must be assigned on one line.")
        if target in params and not _number(value):
            raise InputError(f"{where}: {target} must be assigned a number, as `{target} = 1.15`.")
        edits.append((value.lineno - 1, value.col_offset, value.end_col_offset, wanted[target]))
        done.add(target)
    for line, start, end, text in sorted(edits, reverse=True):
        row = lines[line].encode("utf-8")  # ast's offsets count bytes
        lines[line] = (row[:start] + text.encode("utf-8") + row[end:]).decode("utf-8")
    cell.source = "".join(line + brk for line, brk in zip(lines, [*breaks, ""]))
    return done


def _number(node):
    """Whether an expression is a plain number (``1.15``, ``-0.3``), as a data cell assigns a parameter."""
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        node = node.operand
    return isinstance(node, ast.Constant) and type(node.value) in (int, float)


def folder_name(name):
    """A student's release folder: the roster's submission name when it is a plain file name, else a safe one."""
    from ..store.report import safe_name

    name = str(name)
    return name if re.fullmatch(r"[A-Za-z0-9_-][A-Za-z0-9._-]{0,59}", name) else safe_name(name)


def release(notebook_dir, out_dir, roster=None, variants=None, registry=LAB):
    """Write the student version of every notebook of `notebook_dir` into `out_dir`; the paths written.

    With `roster` ({submission name: roster id}) and `variants` (a :class:`~labkit.exercises.variants.VariantsFile`)
    each student gets a folder ``out_dir/<submission name>/`` whose notebooks hold their data."""
    import nbformat

    if (roster is None) != (variants is None):
        raise InputError("give both --roster and --variants for a release per student, or neither.")
    paths = notebook_paths(notebook_dir)
    out = Path(out_dir)
    if out.resolve() == Path(notebook_dir).resolve():
        raise InputError("--out must differ from the notebook folder; the release would overwrite the solutions.")
    students = (
        {None: None} if roster is None else {name: variants.values(registry, key) for name, key in roster.items()}
    )
    folders = [folder_name(name).casefold() for name in students if name is not None]
    if len(set(folders)) != len(folders):  # "Ada" and "ada" are one folder where case is not told apart
        raise InputError("two roster entries would share a release folder; give each submission its own name.")
    released = {path: release_notebook(read_notebook(path), path.name) for path in paths}
    written = []
    for name, values in students.items():
        folder = out if name is None else out / folder_name(name)
        folder.mkdir(parents=True, exist_ok=True)
        for path, student in released.items():
            if values is not None:
                student = with_values(student, values, path.name, registry)
            target = folder / path.name
            nbformat.write(student, target)
            written.append(target)
    return written


def test_points(source, where="a test cell", rubric=None):
    """(exercise, points) of a hidden-test cell: the weights of the parts its ``labkit.check.f(...)`` (or
    ``check_f(...)``) calls check (of the experiment the first argument names), scaled to `rubric`'s points."""
    rubric = rubric or rubrics.default()
    registry, found = rubric.registry, EXERCISE_OF_TESTS.search(source)
    if not found or int(found.group(1)) not in registry.exercises:
        raise InputError(f"{where} has hidden tests but no '# tests for exercise N' line naming a graded exercise.")
    number = int(found.group(1))
    exercise = registry.exercises[number]
    checked = {
        part.name
        for function, key in CHECK_CALL.findall(source.split(BEGIN_HIDDEN, 1)[1].split(END_HIDDEN, 1)[0])
        for part in registry.parts_checked(number, function, key or None)
    }
    weights = sum(part.weight for part in exercise.parts if part.name in checked)
    if not weights:
        parts = ", ".join(p.name for p in exercise.parts)
        raise InputError(f"{where} tests exercise {number} but checks none of its parts ({parts}).")
    points = weights * (rubric.points.get(number, exercise.points) / exercise.points if exercise.points else 0)
    return number, int(points) if points == int(points) else round(points, 2)


def answer_ids(nb):
    """The grade ids of a notebook's answers in words, in order: ``exerciseN-answer-K``."""
    ids, exercise, counters = [], None, {}
    for cell in (cell for cell in nb.cells if cell.cell_type == "markdown"):
        found = sections(cell.source)
        if found:
            exercise = found[-1]
        if BEGIN_SOLUTION in cell.source:
            counters[exercise] = counters.get(exercise, 0) + 1
            ids.append(f"exercise{exercise}-answer-{counters[exercise]}")
    return ids


def mark(nb, name="notebook", rubric=None):
    """Give every cell of an instructor notebook nbgrader's metadata (in place; ``labkit execute`` applies it);
    returns `nb`. A code cell with a solution region is a *solution* cell; a markdown one a *manually graded answer*
    worth 0 points (the instructor reads it), grade id ``exerciseN-answer-K``; a hidden-test cell an *autograded
    test* worth the weights of the parts its asserts check (:func:`test_points`); every other cell is *locked*."""
    counters, answers = {}, iter(answer_ids(nb))
    stem = re.sub(r"[^a-zA-Z0-9_-]+", "-", name.rsplit(".", 1)[0])

    def grade_id(kind):
        counters[kind] = counters.get(kind, 0) + 1
        return f"{kind}-{counters[kind]}"

    for index, cell in enumerate(nb.cells):
        meta = {"schema_version": SCHEMA_VERSION, "grade": False, "solution": False, "locked": True}
        if cell.cell_type == "markdown" and BEGIN_SOLUTION in cell.source:
            meta.update(solution=True, grade=True, locked=False, points=0, grade_id=next(answers))
        elif cell.cell_type == "code" and BEGIN_SOLUTION in cell.source:
            meta.update(solution=True, locked=False, grade_id=grade_id(f"{stem}-solution"))
        elif cell.cell_type == "code" and BEGIN_HIDDEN in cell.source:
            number, points = test_points(cell.source, f"{name}, cell {index}", rubric)
            meta.update(grade=True, points=points, grade_id=grade_id(f"exercise{number}-tests"))
        else:
            meta["grade_id"] = grade_id(f"{stem}-locked")
        cell.metadata["nbgrader"] = meta
    return nb
