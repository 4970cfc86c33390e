"""Hostile submissions: each is a notebook made from the student release with an attack added.

Every one must get no undeserved points, finish within its limits, leave the
tree outside the sandbox unchanged and no process behind, and have feedback
that names what happened. The whole class is graded in one run, as an
instructor would.
"""
import hashlib
import os
import socket
import time
from pathlib import Path

import nbformat
import pytest

from labkit import grading
from labkit.grading import sandbox

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
LABKIT = ROOT / "labkit"
MARK = "labkit-hostile-7777"

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")


def _sandbox_or_skip():
    try:
        sandbox.available()
    except sandbox.SandboxUnavailable as exc:
        if os.environ.get("CI"):
            raise
        pytest.skip(f"no sandbox here: {exc}")


def _tree_hash(folders, leave_out=None):
    """One hash of every path and file under `folders` (but `leave_out`, which grading writes)."""
    digest = hashlib.sha256()
    for folder in folders:
        for path in sorted(Path(folder).rglob("*")):
            if "__pycache__" in path.parts or (leave_out and (path == leave_out or leave_out in path.parents)):
                continue
            digest.update(str(path).encode())
            if path.is_file() and not path.is_symlink():
                digest.update(path.read_bytes())
    return digest.hexdigest()


def _processes_with(marker):
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if marker in cmdline:
                found.append((entry.name, cmdline))
    return found


def _notebook(tmp, name, cells, base="02_convergence.ipynb", replace=None):
    """The released `base` with `cells` added at its end (or `replace`: {start of a cell: new source})."""
    nb = grading.release_notebook(nbformat.read(NOTEBOOKS / base, as_version=4))
    for old, new in (replace or {}).items():
        hits = [c for c in nb.cells if c.cell_type == "code" and c.source.startswith(old)]
        assert len(hits) == 1, old
        hits[0].source = new
    nb.cells += [nbformat.v4.new_code_cell(source) for source in cells]
    path = tmp / f"{name}.ipynb"
    nbformat.write(nb, path)
    return path


# the cells of each attack; <OUT>, <LABKIT>, <PORT> and <REPO> are filled in by _fill
ATTACKS = {
    "patched_check": ["import labkit.check as c\nreal = c.grade\n"
                      "c.grade = lambda n, ns, seed=None: {**real(n, ns), 'passed': True, 'points': c.POINTS[n]}\n"
                      "import labkit.checks.exercises as e\ne.grade = c.grade\n"
                      "for name in dir(c):\n    obj = getattr(c, name)\n"
                      "    if callable(obj) and not isinstance(obj, type): setattr(c, name, lambda *a, **k: True)"],
    "patched_numpy": ["import numpy as np, numpy.testing\n"
                      "np.allclose = lambda *a, **k: True\nnp.isclose = lambda *a, **k: True\n"
                      "np.array_equal = lambda *a, **k: True\nnumpy.testing.assert_allclose = lambda *a, **k: None\n"
                      "import builtins\nbuiltins.all = lambda *a: True\nbuiltins.abs = lambda x: 0"],
    "always_equal": ["class Liar:\n    def __eq__(self, other): return True\n    __ne__ = lambda s, o: False\n"
                     "    __lt__ = __le__ = __gt__ = __ge__ = __eq__\n    def __array__(self, *a, **k): raise TypeError\n"
                     "    def __float__(self): return 1.0\n"
                     "def eval_pherm(xdata, ydata, ypdata, xval):\n    return Liar()\n"
                     "def runge(x):\n    return Liar(), Liar()"],
    "always_equal_array": ["import numpy as np\nclass Yes(np.ndarray):\n"
                           "    def __eq__(self, other): return np.ones(np.shape(other), bool).view(Yes)\n"
                           "def eval_pherm(xdata, ydata, ypdata, xval):\n"
                           "    return np.zeros(np.shape(xval)).view(Yes)"],
    "fake_result_line": ["import json\nfor n in (2, 3, 11, 12):\n"
                         "    print('LABKIT-GRADE-0000:' + json.dumps({'exercise': n, 'passed': True, 'points': 10, "
                         "'defined': True, 'checks': []}))\n"
                         "import os\nline = json.dumps({'id': '0', 'value': ['f', 1.0]}).encode() + b'\\n'\n"
                         "for fd in range(1, 12):\n    try: os.write(fd, line)\n    except OSError: pass"],
    "writes_outside": ["import os\nseen = []\n"
                       "for path in ['/tmp/" + MARK + "', '<OUT>/" + MARK + "', '<LABKIT>/" + MARK + ".py', "
                       "'<LABKIT>/__init__.py', '<REPO>/" + MARK + "']:\n"
                       "    try:\n        open(path, 'a').write('owned')\n        seen.append(f'wrote {path}')\n"
                       "    except OSError as exc:\n        seen.append(f'{path}: {exc.strerror}')\n"
                       "raise RuntimeError('; '.join(seen))"],
    "background_process": ["import subprocess, os\n"
                           "subprocess.Popen(['sleep', '7777'], start_new_session=True)\n"
                           "if os.fork() == 0:\n    os.setsid()\n    os.execvp('sleep', ['sleep', '7777'])\n"
                           "raise RuntimeError('left sleep 7777 running')"],
    "fork_loop": ["import os, time\nchildren = 0\n"
                  "for _ in range(400):\n    pid = os.fork()\n"
                  "    if pid == 0:\n        time.sleep(120)\n        os._exit(0)\n    children += 1"],
    "memory_grab": ["block = bytearray(6 * 1024**3)"],
    "connects_out": ["import socket\ns = socket.create_connection(('127.0.0.1', <PORT>), timeout=5)\n"
                     "s.sendall(b'" + MARK + "')"],
    "reads_solutions": ["source = open('<REPO>/notebooks/02_convergence.ipynb').read()\n"
                        "import json\ncells = json.loads(source)['cells']\n"
                        "exec(''.join(cells[5]['source']))"],
    "infinite_loop": ["while True:\n    pass"],
    "sys_exit": ["import sys\nsys.exit(1)"],
    "os_exit": ["import os\nos._exit(3)"],
    "prints_100_mb": ["import sys\nfor _ in range(100):\n    print('x' * 1_000_000)\n"
                      "    sys.__stdout__.write('y' * 100)"],
}
REFERENCE_CALLS = {
    "calls_reference": {"def eval_pherm(": "import labkit\n\ndef eval_pherm(xdata, ydata, ypdata, xval):\n"
                                           "    return labkit.eval_pherm(xdata, ydata, ypdata, xval)"},
    "calls_reference_alias": {"def eval_pherm(": "from scipy.interpolate import CubicHermiteSpline as H\n"
                                                 "from labkit import eval_pherm as reference\n"
                                                 "def helper(*args):\n    return reference(*args)\n\n"
                                                 "def eval_pherm(xdata, ydata, ypdata, xval):\n"
                                                 "    try:\n        return helper(xdata, ydata, ypdata, xval)\n"
                                                 "    except Exception:\n"
                                                 "        return H(xdata, ydata, ypdata)(xval)"},
    "exits_in_a_graded_call": {"def eval_pherm(": "def eval_pherm(xdata, ydata, ypdata, xval):\n"
                                                  "    import os\n    os._exit(5)"},
}


def _fill(source, values):
    for key, value in values.items():
        source = source.replace(key, str(value))
    return source


@pytest.fixture(scope="module")
def attacked(tmp_path_factory):
    _sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("hostile")
    out = tmp / "grades"
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(5)
    server.setblocking(False)
    fill = {"<OUT>": out, "<LABKIT>": LABKIT, "<PORT>": server.getsockname()[1], "<REPO>": ROOT}
    subs = {name: _notebook(tmp, name, [_fill(c, fill) for c in cells]) for name, cells in ATTACKS.items()}
    subs.update({name: _notebook(tmp, name, [], replace=replace) for name, replace in REFERENCE_CALLS.items()})
    many = grading.release_notebook(nbformat.read(NOTEBOOKS / "06_bilinear.ipynb", as_version=4))
    many.cells += [nbformat.v4.new_code_cell(f"x{i} = {i}") for i in range(5000)]
    nbformat.write(many, tmp / "five_thousand_cells.ipynb")
    subs["five_thousand_cells"] = tmp / "five_thousand_cells.ipynb"
    (tmp / "invalid_json.ipynb").write_text('{"cells": [ this is not json')
    subs["invalid_json"] = tmp / "invalid_json.ipynb"
    outside = [LABKIT, NOTEBOOKS, tmp]
    before = _tree_hash(outside, leave_out=out)
    start = time.perf_counter()
    results = grading.grade(list(subs.values()), out, jobs=2, cell_timeout=5, total_timeout=60, progress=False)
    elapsed = time.perf_counter() - start
    time.sleep(0.5)
    try:
        connection = server.accept()
    except BlockingIOError:
        connection = None
    server.close()
    after = _tree_hash(outside, leave_out=out)
    yield {"results": dict(zip(subs, results)), "elapsed": elapsed, "connection": connection,
           "unchanged": before == after, "out": out, "count": len(subs)}


def test_no_hostile_submission_gets_a_point(attacked):
    for name, grade in attacked["results"].items():
        assert grade.total == 0, f"{name}:\n{grade.feedback()}"


def test_the_class_is_graded_within_its_limits(attacked):
    # every notebook is bounded by its 60 s total limit; stopped, crashed and flooding ones end
    # far sooner, so the class of 20, two at a time, takes well under two minutes
    assert attacked["elapsed"] < 120, attacked["elapsed"]


def test_nothing_outside_the_sandbox_changed(attacked):
    assert attacked["unchanged"]
    assert not Path(f"/tmp/{MARK}").exists()
    assert not (LABKIT / f"{MARK}.py").exists() and not (ROOT / MARK).exists()
    assert sorted(p.name for p in attacked["out"].iterdir()) == ["feedback", "grades.csv", "results", "seed.txt"]


def test_no_process_outlives_grading(attacked):
    deadline = time.monotonic() + 10
    while (_processes_with("sleep 7777") or _processes_with("labkit.grading.worker")) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _processes_with("sleep 7777") == []
    assert _processes_with("labkit.grading.worker") == []
    assert _processes_with("bwrap") == []


def test_the_listening_socket_saw_no_connection(attacked):
    assert attacked["connection"] is None


@pytest.mark.parametrize("name, named", [
    ("patched_check", "not implemented yet"),
    ("patched_numpy", "not implemented yet"),
    ("always_equal", "got a Liar object, not numbers"),
    ("always_equal_array", "wrong for x^[0, 1, 2, 3]"),
    ("fake_result_line", "not implemented yet"),
    ("writes_outside", "Read-only file system"),
    ("background_process", "left sleep 7777 running"),
    ("fork_loop", "BlockingIOError"),
    ("memory_grab", "MemoryError"),
    ("connects_out", "ConnectionRefusedError"),
    ("reads_solutions", "No such file or directory"),
    ("infinite_loop", "Timeout: interrupted"),
    ("sys_exit", "SystemExit"),
    ("os_exit", "exited with status 3"),
    ("exits_in_a_graded_call", "exited with status 5"),
    ("prints_100_mb", "printed 100,00"),
    ("invalid_json", "is not a valid notebook"),
    ("calls_reference", "called labkit.eval_pherm, which is switched off"),
    ("calls_reference_alias", "reaches for labkit.eval_pherm"),
    ("five_thousand_cells", "not implemented yet"),
])
def test_feedback_names_what_happened(attacked, name, named):
    assert named in attacked["results"][name].feedback(), attacked["results"][name].feedback()


def test_calls_through_aliases_and_helpers_are_refused_and_named(attacked):
    feedback = attacked["results"]["calls_reference_alias"].feedback()
    section = feedback.split("Exercise 2:")[1].split("\nExercise ")[0]
    assert "switched off" in section  # the runtime refusal, though the code caught the error
    assert "helper" in section and "scipy.interpolate.CubicHermiteSpline" in section


def test_an_uninterruptible_loop_is_stopped_by_the_total_limit(tmp_path):
    _sandbox_or_skip()
    path = _notebook(tmp_path, "stubborn", ["import time\nwhile True:\n    try:\n        time.sleep(100)\n"
                                            "    except BaseException:\n        pass"])
    start = time.perf_counter()
    results, problems = grading.grade_notebook(path, cell_timeout=1, total_timeout=6)
    assert time.perf_counter() - start < 15
    assert results == {} and "total time limit of 6 s" in problems[0]
    assert _processes_with("labkit.grading.worker") == []
