"""Hostile submissions, graded together with honest classmates in one run, as an instructor would.

Each attack is a submission made from the student release (or files built
for the purpose). For every one: it earns nothing it did not earn, the
honest classmates in the same run get their usual scores, the run finishes
within its limits and leaves nothing behind (no file in the temporary
folder, no process, nothing changed outside the output folder), the
grader's own memory stays under a bound, ``grades.csv`` has every student
once, and the feedback names what happened, as data (no control character
reaches a file or a terminal).
"""

import csv
import hashlib
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import nbformat
import pytest
from conftest import sandbox_or_skip
from copies import module_source
from helpers import processes_with as _processes_with

import labkit.piecewise
from labkit import grading
from labkit.grading.sandbox.backends.base import remove_tree
from labkit.grading.store.report import file_stem, safe_name
from labkit.grading.store.rubric import default

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"
LABKIT = ROOT / "labkit"
MARK = "labkit-hostile-7777"
GRADER_MEMORY_BOUND = 1536 * 1024**2  # the grader's own work on one submission, attacks included
TOTAL_TIMEOUT, CELL_TIMEOUT = 60, 5

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's"),
]  # slow: the hostile class


def _pasted(function):
    """A library function's source as a student pastes it into a cell, its docstring's lines deleted."""
    import ast
    import inspect

    lines = inspect.getsource(function).splitlines()
    doc = ast.parse("\n".join(lines)).body[0].body[0]
    return "\n".join(lines[: doc.lineno - 1] + lines[doc.end_lineno :])


def _tree_hash(folders, leave_out=()):
    """One hash of every path and file under `folders` (but those in `leave_out`, which grading writes)."""
    digest = hashlib.sha256()
    for folder in folders:
        for path in sorted(Path(folder).rglob("*")):
            if "__pycache__" in path.parts or any(path == p or p in path.parents for p in leave_out):
                continue
            digest.update(os.fsencode(path))
            if path.is_file() and not path.is_symlink():
                digest.update(path.read_bytes())
    return digest.hexdigest()


def _grading_processes():
    """(pid, what it grades) of every submission's grading process: forked by the launcher, they all have its
    command line, so they are told apart by their log (stderr), which is named after the submission."""
    found = []
    for pid, _ in _processes_with("labkit.grading.run.launcher") + _processes_with("labkit.grading.submission.scoring"):
        try:
            log = os.readlink(f"/proc/{pid}/fd/2")
        except OSError:
            continue
        if log.endswith(".log"):
            found.append((pid, log))
    return found


def _temporary_leftovers():
    return sorted(p.name for p in Path(tempfile.gettempdir()).iterdir() if p.name.startswith("labkit-"))


def _released(base):
    return grading.release_notebook(nbformat.read(NOTEBOOKS / base, as_version=4))


def _notebook(folder, name, cells, base="02_convergence.ipynb", replace=None):
    """The released `base` with `cells` added at its end (or `replace`: {start of a cell: new source})."""
    nb = _released(base)
    for old, new in (replace or {}).items():
        hits = [c for c in nb.cells if c.cell_type == "code" and c.source.startswith(old)]
        assert len(hits) == 1, old
        hits[0].source = new
    nb.cells += [nbformat.v4.new_code_cell(source) for source in cells]
    path = folder / f"{name}.ipynb"
    nbformat.write(nb, path)
    return path


# the cells of each attack; <OUT>, <LABKIT>, <PORT> and <REPO> are filled in by _fill
ATTACKS = {
    "patched_check": [
        "import labkit.check as c\nreal = c.grade\n"
        "c.grade = lambda n, ns, seed=None: {**real(n, ns), 'passed': True, 'points': c.POINTS[n]}\n"
        "import labkit.exercises.registry as e\ne.LAB.check = c.grade\n"
        "for name in dir(c):\n    obj = getattr(c, name)\n"
        "    if callable(obj) and not isinstance(obj, type): setattr(c, name, lambda *a, **k: True)"
    ],
    "patched_numpy": [
        "import numpy as np, numpy.testing\n"
        "np.allclose = lambda *a, **k: True\nnp.isclose = lambda *a, **k: True\n"
        "np.array_equal = lambda *a, **k: True\nnumpy.testing.assert_allclose = lambda *a, **k: None\n"
        "import builtins\nbuiltins.all = lambda *a: True\nbuiltins.abs = lambda x: 0"
    ],
    "always_equal": [
        "class Liar:\n    def __eq__(self, other): return True\n    __ne__ = lambda s, o: False\n"
        "    __lt__ = __le__ = __gt__ = __ge__ = __eq__\n    def __array__(self, *a, **k): raise TypeError\n"
        "    def __float__(self): return 1.0\n"
        "def eval_pherm(xdata, ydata, ypdata, xval):\n    return Liar()\n"
        "def runge(x):\n    return Liar(), Liar()"
    ],
    "always_equal_array": [
        "import numpy as np\nclass Yes(np.ndarray):\n"
        "    def __eq__(self, other): return np.ones(np.shape(other), bool).view(Yes)\n"
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    return np.zeros(np.shape(xval)).view(Yes)"
    ],
    "fake_result_line": [
        "import json\nfor n in (2, 3, 11, 12):\n"
        "    print('LABKIT-GRADE-0000:' + json.dumps({'exercise': n, 'passed': True, 'points': 10, "
        "'defined': True, 'checks': []}))\n"
        "import os\nline = json.dumps({'id': '0', 'value': ['f', 1.0]}).encode() + b'\\n'\n"
        "for fd in range(1, 40):\n    try: os.write(fd, line)\n    except OSError: pass"
    ],
    "writes_outside": [
        "import os\nseen = []\n"
        "for path in ['/tmp/" + MARK + "', '<OUT>/" + MARK + "', '<LABKIT>/" + MARK + ".py', "
        "'<LABKIT>/__init__.py', '<REPO>/" + MARK + "']:\n"
        "    try:\n        open(path, 'a').write('owned')\n        seen.append(f'wrote {path}')\n"
        "    except OSError as exc:\n        seen.append(f'{path}: {exc.strerror}')\n"
        "raise RuntimeError('; '.join(seen))"
    ],
    "background_process": [
        "import subprocess, os\n"
        "subprocess.Popen(['sleep', '7777'], start_new_session=True)\n"
        "if os.fork() == 0:\n    os.setsid()\n    os.execvp('sleep', ['sleep', '7777'])\n"
        "raise RuntimeError('left sleep 7777 running')"
    ],
    "fork_loop": [
        "import os, time\nchildren = 0\n"
        "for _ in range(400):\n    pid = os.fork()\n"
        "    if pid == 0:\n        time.sleep(120)\n        os._exit(0)\n    children += 1"
    ],
    "memory_grab": ["block = bytearray(6 * 1024**3)"],
    "connects_out": [
        "import socket\ns = socket.create_connection(('127.0.0.1', <PORT>), timeout=5)\ns.sendall(b'" + MARK + "')"
    ],
    "reads_solutions": [
        "source = open('<REPO>/notebooks/02_convergence.ipynb').read()\n"
        "import json\ncells = json.loads(source)['cells']\n"
        "exec(''.join(cells[5]['source']))"
    ],
    "infinite_loop": ["while True:\n    pass"],
    "sys_exit": ["import sys\nsys.exit(1)"],
    "os_exit": ["import os\nos._exit(3)"],
    "prints_100_mb": [
        "import sys\nfor _ in range(100):\n    print('x' * 1_000_000)\n    sys.__stdout__.write('y' * 100)"
    ],
    # the answer-pipe bomb: one 256 MiB line of nested empty lists to every descriptor it can find
    "answer_pipe_bomb": [
        "import os\nbomb = b'[' * (128 * 1024**2) + b']' * (128 * 1024**2) + b'\\n'\n"
        "for fd in range(3, 12):\n    try:\n        os.write(fd, bomb)\n    except OSError:\n"
        "        pass"
    ],
    # a chain of 1,100 folders and a big file in the private folder, and in /tmp
    "deep_folders": [
        "import os\nfull = []\nfor top in (os.path.expanduser('~'), '/tmp'):\n    os.chdir(top)\n"
        "    for _ in range(1100):\n        os.mkdir('d')\n        os.chdir('d')\n"
        "    try:\n        for i in range(6):\n            open(f'big{i}', 'wb').write(b'x' * 60 * 1024**2)\n"
        "    except OSError as exc:\n        full.append(str(exc))\n"
        "os.chdir(os.path.expanduser('~'))\nraise RuntimeError('; '.join(full))"
    ],
    # memory the address-space limit does not count, and a kernel key for the next submission to find
    "memfd": ["import os\nos.memfd_create('hoard')"],
    "keyring": [
        "import ctypes\nlibc = ctypes.CDLL(None, use_errno=True)\n"
        "key = libc.syscall(248, b'user', b'" + MARK + "', b'secret', 6, -4)\n"
        "raise RuntimeError(f'add_key: {key} errno {ctypes.get_errno()}')"
    ],
    # a chain of IPython magics the grader's reader once took minutes over, before a cell that ends it all
    "magic_lines": ["import os\nos._exit(0)"],
    # the watch switched off through the garbage collector's lists, and a reference's code put back
    "gc_switch_off": ["import gc\nfor obj in gc.get_objects():\n    pass"],
    "error_text_forgery": [
        "raise RuntimeError('\\r\\x1b[2K\\x1b[1A\\x1b[2K25 points\\nExercise 2: 10 / 10 - passed\\n"
        "\\x1b]0;owned\\x07\\u2028Total: 118 (full credit is 100)\\u2029')"
    ],
    # the red team's ways into the watch's hooks, each with the reference kept where the scan does not look
    "object_run_inside_the_watch": [
        "import numpy as np, labkit\nfrom labkit.grading.sandbox import guard\n"
        "setattr(np, 'lab_ref', labkit.eval_pherm)\n"
        "class Name:\n    def __init__(self, args):\n        self.args, self.out = args, None\n"
        "    def __format__(self, spec):\n        self.out = np.lab_ref(*self.args)\n"
        "        return 'done'\n"
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    name = Name((xdata, ydata, ypdata, xval))\n"
        "    try:\n        guard._stand_in(name)()\n    except RuntimeError:\n        pass\n"
        "    return name.out"
    ],
    # the second red team: the watch's module, hashlib and the builtins rebound, and the namespace of a
    # stand-in found in a refused module rewritten during the call
    "watch_names_rebound": [
        "import sys, hashlib, numpy as np, labkit\nfrom labkit.grading.sandbox import guard\n"
        "setattr(np, 'ref', labkit.eval_pherm)\nguard.any = guard._within = lambda *a: False\n"
        "guard.TAMPER_EVENTS = frozenset()\nguard.code_key = lambda code: bytes(12)\n"
        "hashlib.sha1 = hashlib.sha256 = lambda *a: hashlib.md5(b'same')\n"
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    for module in list(sys.modules.values()):\n"
        "        for value in list(getattr(module, '__dict__', {}).values()):\n"
        "            if getattr(getattr(value, '__code__', None), 'co_name', '') == 'refused':\n"
        "                value.__globals__['code_key'] = lambda code: bytes(12)\n"
        "                value.__globals__['__builtins__']['len'] = lambda v: 0\n"
        "    return np.ref(xdata, ydata, ypdata, xval)"
    ],
    "fake_compiled_object": [
        "import sys, numpy as np, labkit, labkit.exercises\nclass cython_function_or_method:\n"
        "    @property\n    def __module__(self):\n        f = sys._getframe(1)\n"
        "        while f is not None:\n            if 'state' in f.f_locals:\n"
        "                f.f_locals['state']['profile'] = None\n            f = f.f_back\n"
        "        return 'nothing.to.see'\n"
        "labkit.exercises.zz_fake = cython_function_or_method()\nsetattr(np, 'ref_pherm', labkit.eval_pherm)\n"
        "def eval_pherm(xdata, ydata, ypdata, xval):\n    return np.ref_pherm(xdata, ydata, ypdata, xval)"
    ],
    "profile_hook_fetched_from_c": [
        "import sys, functools, numpy as np, labkit\n"
        "hook = functools.partial(sys.getprofile)()\n"
        "setattr(np, 'ref', labkit.eval_pherm)\n"
        "def eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    found = functools.partial(sys.getprofile)()\n"
        "    if found is not None:\n        for cell in found.__closure__ or ():\n"
        "            if isinstance(cell.cell_contents, dict) and 'profile' in cell.cell_contents:\n"
        "                cell.cell_contents['profile'] = None\n"
        "    return np.ref(xdata, ydata, ypdata, xval)"
    ],
    # labkit's own file run statement by statement, its docstrings stripped: no copy in the notebook
    "exec_statement_by_statement": [
        "import ast, labkit\nsource = open(labkit.piecewise.__file__).read().replace('from ._', 'from labkit._')\n"
        "for node in ast.parse(source).body:\n"
        "    exec(compile(ast.Module([node], []), 'mine.py', 'exec', optimize=2), globals())"
    ],
    "spins_sixty_processes": [
        "import os\nfor _ in range(60):\n    if os.fork() == 0:\n        os.setsid()\n"
        "        while True:\n            pass",
        "import time\ntime.sleep(100)",
        "import time\ntime.sleep(100)",
    ],
}
REPLACED = {  # cells of the release replaced by an attack: {name: (base notebook, {start of a cell: new source})}
    "calls_reference": (
        "02_convergence.ipynb",
        {
            "def eval_pherm(": "import labkit\n\ndef eval_pherm(xdata, ydata, ypdata, xval):\n"
            "    return labkit.eval_pherm(xdata, ydata, ypdata, xval)"
        },
    ),
    "calls_reference_alias": (
        "02_convergence.ipynb",
        {
            "def eval_pherm(": "from scipy.interpolate import CubicHermiteSpline as H\n"
            "from labkit import eval_pherm as reference\n"
            "def helper(*args):\n    return reference(*args)\n\n"
            "def eval_pherm(xdata, ydata, ypdata, xval):\n"
            "    try:\n        return helper(xdata, ydata, ypdata, xval)\n"
            "    except Exception:\n        return H(xdata, ydata, ypdata)(xval)"
        },
    ),
    "exits_in_a_graded_call": (
        "02_convergence.ipynb",
        {"def eval_pherm(": "def eval_pherm(xdata, ydata, ypdata, xval):\n    import os\n    os._exit(5)"},
    ),
    "bpoly_construct_fast": (
        "02_convergence.ipynb",
        {
            "def eval_pherm(": "import numpy as np\nfrom scipy.interpolate import BPoly\n"
            "class H(BPoly):\n    def __new__(cls, x, c):\n"
            "        return BPoly.construct_fast.__func__(cls, c, x)\n"
            "    def __init__(self, *a):\n        pass\n\n"
            "def eval_pherm(xdata, ydata, ypdata, xval):\n"
            "    x, y, yp = (np.asarray(v, float) for v in (xdata, ydata, ypdata))\n"
            "    h = np.diff(x)\n"
            "    c = np.stack([y[:-1], y[:-1] + yp[:-1] * h / 3, y[1:] - yp[1:] * h / 3, y[1:]])\n"
            "    return H(x, c)(np.asarray(xval, float))"
        },
    ),
    "reference_by_assignment": (
        "02_convergence.ipynb",
        {"def eval_pherm(": "import labkit\neval_pherm = labkit.eval_pherm"},
    ),
    "saved_code_object": (
        "02_convergence.ipynb",
        {
            "def eval_pherm(": "import types, labkit\nsaved = labkit.piecewise.eval_pherm.__code__\n"
            "def eval_pherm(xdata, ydata, ypdata, xval):\n"
            "    f = types.FunctionType(saved, labkit.piecewise.__dict__, None, (0,))\n"
            "    return f(xdata, ydata, ypdata, xval)"
        },
    ),
    "graders_reference": (
        "04_splines.ipynb",
        {
            "def complete_system(": "import labkit, labkit.exercises.splines as s\n"
            "def complete_system(xdata, ydata, y1p, ynp):\n"
            "    return s._reference_complete_system(xdata, ydata, y1p, ynp)\n\n"
            "import numpy as np\nfrom labkit import splines\n"
            "def ccspline(xdata, ydata, y1p, ynp):\n"
            "    x, y = np.asarray(xdata, float), np.asarray(ydata, float)\n"
            "    A, D = complete_system(x, y, y1p, ynp)\n"
            "    h = np.diff(x)\n"
            "    return splines._slopes_from_curvatures(h, np.diff(y) / h, np.linalg.solve(A, D))"
        },
    ),
    "private_natural_helpers": (
        "04_splines.ipynb",
        {
            "def ncspline(": "import numpy as np\nimport labkit.splines as s\n"
            "def ncspline(xdata, ydata):\n    x, y = np.asarray(xdata, float), np.asarray(ydata, float)\n"
            "    h = np.diff(x)\n    d = np.diff(y) / h\n"
            "    return s._slopes_from_curvatures(h, d, s.natural_curvatures(h, d))"
        },
    ),
    "ndimage_bilinear": (
        "06_bilinear.ipynb",
        {
            "def runge2d(": "import numpy as np\nimport scipy.ndimage as nd\n"
            "def eval_pbilin(f, xdata, ydata, xval, yval):\n"
            "    xdata, ydata = np.asarray(xdata, float), np.asarray(ydata, float)\n"
            "    z = f(*np.meshgrid(xdata, ydata, indexing='ij'))\n"
            "    i = np.interp(xval, xdata, np.arange(xdata.size))\n"
            "    j = np.interp(yval, ydata, np.arange(ydata.size))\n"
            "    return nd.map_coordinates(z, np.meshgrid(i, j, indexing='ij'), order=1)"
        },
    ),
    # a private helper of labkit's pasted into the notebook, its docstring deleted, under a function of one's own
    "pasted_private_helper": (
        "02_convergence.ipynb",
        {
            "def eval_pherm(": "import numpy as np\nfrom labkit._validate import *\n\n"
            + _pasted(labkit.piecewise._hermite_eval)
            + "\n\ndef eval_pherm(xdata, ydata, ypdata, xval):\n"
            "    x, y, yp, xv = (np.asarray(v, dtype=float) for v in (xdata, ydata, ypdata, xval))\n"
            "    return _hermite_eval(x, y, yp, xv)"
        },
    ),
    # labkit's own modules pasted in, every local renamed and a dummy first statement in each function (the
    # recognition digest never matches, and the scan sees only the notebook's own names)
    "renamed_piecewise": ("02_convergence.ipynb", {"def eval_pherm(": module_source("labkit.piecewise")}),
    "renamed_splines": (
        "04_splines.ipynb",
        {
            "def complete_system(": module_source("labkit.piecewise")
            + "\n\n"
            + module_source("labkit.splines", drop=("labkit.piecewise",)),
            "def ncspline(": "pass",
        },
    ),
    # labkit's module byte for byte but for its docstrings (reformatted): the sandbox's watch knows its code
    "nodoc_bilinear": ("06_bilinear.ipynb", {"def runge2d(": module_source("labkit.bilinear", rename=False)}),
    "renamed_bilinear": ("06_bilinear.ipynb", {"def runge2d(": module_source("labkit.bilinear")}),
    # the copy moved into helpers under a graded function of one's own
    "renamed_helpers": (
        "02_convergence.ipynb",
        {
            "def eval_pherm(": module_source("labkit.piecewise") + "\n\ndef eval_pherm(xdata, ydata, ypdata, xval):\n"
            "    x, y, yp, xv = (np.asarray(v, dtype=float) for v in (xdata, ydata, ypdata, xval))\n"
            "    return _hermite_eval(x, y, yp, xv)"
        },
    ),
    # numpy's compiled interp under another of the names numpy holds it by
    "interp_alias": (
        "06_bilinear.ipynb",
        {
            "def runge2d(": "import numpy as np\nimport numpy._core.multiarray\n"
            "def runge2d(x, y):\n    raise NotImplementedError\n"
            "def eval_pbilin(f, xdata, ydata, xval, yval):\n"
            "    xdata, ydata = np.asarray(xdata, float), np.asarray(ydata, float)\n"
            "    line = getattr(numpy._core.multiarray, 'interp')\n"
            "    X, Y = np.meshgrid(xdata, ydata, indexing='ij')\n    z = f(X, Y)\n"
            "    rows = np.array([line(yval, ydata, row) for row in z])\n"
            "    return np.array([line(xval, xdata, column) for column in rows.T]).T"
        },
    ),
}
EXTRA = {  # attacks added after a release notebook's last cell: {name: (base notebook, cells)}
    "mesh_bomb": (
        "03_meshes.ipynb",
        [
            "import numpy as np, labkit\n"
            "def two_patches(A, B, C, D):\n    heap = labkit.QuadMesh(np.zeros((60_000, 2)), [[0, 1, 2, 3]])\n"
            "    return heap, heap\n"
            "region = labkit.QuadMesh(np.zeros((60_000, 2)), [[0, 1, 2, 3]])"
        ],
    ),
    "exact_limacon_plot": (
        "01_limacon.ipynb",
        [
            "import numpy as np\nt = np.linspace(0, 2 * np.pi, 210)\nr = 1.15 + np.cos(t)\n"
            "ax4.plot(r * np.cos(t), r * np.sin(t))"
        ],
    ),
    # the second red team: a shrinking table typed in, with the rate it shows, and no driver that runs
    "fabricated_table": (
        "02_convergence.ipynb",
        ["errors_pherm = [1 / (n - 1) ** 4 for n in [5, 11, 21, 41, 81, 161, 321, 641]]\nrate_pherm = 4"],
    ),
    "constant_tables": (
        "02_convergence.ipynb",
        [
            "def test_pherm_interpolate(ndata, f=None, interpolate=None):\n    return 1.0\n"
            "errors_pherm = [1.0] * 8\nrate_pherm = 0"
        ],
    ),
}


def _auto_import_copy(folder):
    """The instructor notebooks with bracket imported as an editor's auto-import writes it, or through a module
    alias: honest work, every point earned."""
    target = folder / "honest_auto_import"
    target.mkdir()
    for base, old, new in (
        ("02_convergence.ipynb", "labkit.bracket(xdata, xval)", "bracket(xdata, xval)"),
        ("06_bilinear.ipynb", "labkit.bracket(xdata, xval), labkit.bracket(", "pw.bracket(xdata, xval), pw.bracket("),
    ):
        nb = nbformat.read(NOTEBOOKS / base, as_version=4)
        hits = [c for c in nb.cells if c.cell_type == "code" and old in c.source]
        assert len(hits) == 1, (base, old)
        imports = (
            "from labkit.piecewise import bracket\n" if base.startswith("02") else "import labkit.piecewise as pw\n"
        )
        hits[0].source = imports + hits[0].source.replace(old, new)
        nbformat.write(nb, target / base)
    return target


def _fill(source, values):
    for key, value in values.items():
        source = source.replace(key, str(value))
    return source


def _honest_copy(folder, name, notebooks=None):
    target = folder / name
    target.mkdir()
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        if notebooks is None or path.name in notebooks:
            shutil.copy(path, target / path.name)
    return target


def _best_of_four(folder):
    """Four copies of the solved convergence notebook, the rate answered 1, 2, 3 and 4: only the first counts."""
    target = folder / "best_of_four"
    target.mkdir()
    for guess in (1, 2, 3, 4):
        nb = nbformat.read(NOTEBOOKS / "02_convergence.ipynb", as_version=4)
        nb.cells.append(nbformat.v4.new_code_cell(f"rate_pherm = {guess}"))
        nbformat.write(nb, target / f"try{guess}.ipynb")
    return target


def _many_stuck_notebooks(folder):
    """Eight notebooks that each loop until their cells' time runs out."""
    target = folder / "eight_stuck_notebooks"
    target.mkdir()
    for i in range(8):
        nb = nbformat.v4.new_notebook()
        nb.cells = [nbformat.v4.new_markdown_cell("## Exercise 16")]
        nb.cells += [nbformat.v4.new_code_cell("while True:\n    pass") for _ in range(3)]
        nbformat.write(nb, target / f"stuck{i}.ipynb")
    return target


@pytest.fixture(scope="module")
def attacked(tmp_path_factory):
    sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("hostile")
    subs_dir = tmp / "submissions"
    subs_dir.mkdir()
    out = tmp / "grades"
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(5)
    server.setblocking(False)
    fill = {"<OUT>": out, "<LABKIT>": LABKIT, "<PORT>": server.getsockname()[1], "<REPO>": ROOT}
    subs = {}
    for name, cells in ATTACKS.items():
        subs[name] = _notebook(subs_dir, name, [_fill(c, fill) for c in cells])
    for name, (base, replace) in REPLACED.items():
        subs[name] = _notebook(subs_dir, name, [], base=base, replace=replace)
    for name, (base, cells) in EXTRA.items():
        subs[name] = _notebook(subs_dir, name, cells, base=base)
    # the magics go first: the cell after them ends the notebook, so only the grader's reader would pay
    nb = nbformat.read(subs["magic_lines"], as_version=4)
    nb.cells.insert(1, nbformat.v4.new_code_cell("\n".join("%time x" for _ in range(21_000))))
    nbformat.write(nb, subs["magic_lines"])
    many = _released("06_bilinear.ipynb")
    many.cells += [nbformat.v4.new_code_cell(f"x{i} = {i}") for i in range(5000)]
    nbformat.write(many, subs_dir / "five_thousand_cells.ipynb")
    subs["five_thousand_cells"] = subs_dir / "five_thousand_cells.ipynb"
    (subs_dir / "invalid_json.ipynb").write_text('{"cells": [ this is not json')
    subs["invalid_json"] = subs_dir / "invalid_json.ipynb"
    big = _released("02_convergence.ipynb")
    big.cells.append(nbformat.v4.new_markdown_cell("x" * 8_600_000))
    nbformat.write(big, subs_dir / "notebook_of_8_mb.ipynb")
    subs["notebook_of_8_mb"] = subs_dir / "notebook_of_8_mb.ipynb"
    with open(subs_dir / "notebook_of_60_mb.ipynb", "w") as handle:
        handle.write('{"nbformat": 4, "cells": [{"cell_type": "markdown", "source": "')
        handle.write("x" * 60_000_000)
        handle.write('"}]}')
    subs["notebook_of_60_mb"] = subs_dir / "notebook_of_60_mb.ipynb"
    subs["mallory"] = subs_dir / "mallory"
    os.symlink(NOTEBOOKS, subs["mallory"])  # an unzipped upload that is a link to the instructor's notebooks
    linked_inside = subs_dir / "linked_inside"
    linked_inside.mkdir()
    os.symlink(NOTEBOOKS / "02_convergence.ipynb", linked_inside / "02_convergence.ipynb")
    _notebook(linked_inside, "own", [])
    subs["linked_inside"] = linked_inside
    subs["best_of_four"] = _best_of_four(subs_dir)
    subs["eight_stuck_notebooks"] = _many_stuck_notebooks(subs_dir)
    for name in (
        "=2+3*7",
        "=cmd|' -C calc'!A0",
        "esc\x1b[31mred",
        "jane doe",
        "jane_doe",
        "y" * 246,
        "zz\u2028Total: 118 (full credit is 100)",
    ):
        subs[name] = _notebook(subs_dir, name, [])
    # a folder whose name is not UTF-8, as an old zip file unpacks
    undecodable = Path(os.fsdecode(bytes(subs_dir) + b"/bad\xff\xfename"))
    undecodable.mkdir()
    _notebook(undecodable, "work", [])
    subs["bad\\xff\\xfename"] = undecodable
    # the honest classmates, in the same run
    subs["honest_alice"] = _honest_copy(subs_dir, "honest_alice")
    subs["honest_bob"] = _honest_copy(subs_dir, "honest_bob", {"02_convergence.ipynb", "06_bilinear.ipynb"})
    subs["honest_auto_import"] = _auto_import_copy(subs_dir)

    outside = [LABKIT, NOTEBOOKS, tmp]
    before = _tree_hash(outside, leave_out=[out])
    leftovers = _temporary_leftovers()
    start = time.perf_counter()
    options = grading.GradeOptions(cell_timeout=CELL_TIMEOUT, total_timeout=TOTAL_TIMEOUT, jobs=2)
    results = grading.grade(list(subs.values()), out, options, progress=False)
    elapsed = time.perf_counter() - start
    time.sleep(0.5)
    try:
        connection = server.accept()
    except BlockingIOError:
        connection = None
    server.close()
    after = _tree_hash(outside, leave_out=[out])
    yield {
        "results": dict(zip(subs, results)),
        "elapsed": elapsed,
        "connection": connection,
        "unchanged": before == after,
        "out": out,
        "count": len(subs),
        "leftovers": (leftovers, _temporary_leftovers()),
    }


def _feedback(attacked, name):
    return attacked["results"][name].feedback()


def test_an_allowed_helper_imported_from_its_module_costs_nothing(attacked):
    grade = attacked["results"]["honest_auto_import"]
    assert grade.total == 25 + 8 and grade.points[2] == 10 and grade.points[16] == 8, grade.feedback()
    assert "reaches for" not in grade.feedback()


COPIES = {  # the copies of labkit's code: the part held, and the source its feedback names
    "renamed_piecewise": (2, "eval_pherm", "labkit.piecewise."),
    "renamed_splines": (10, "ccspline", "labkit.splines."),
    "renamed_bilinear": (16, "eval_pbilin", "labkit.bilinear."),
    "renamed_helpers": (2, "eval_pherm", "labkit.piecewise."),
}


@pytest.mark.parametrize("name", sorted(COPIES))
def test_a_copy_of_labkits_code_is_held_for_a_person(attacked, name):
    number, part, source = COPIES[name]
    grade = attacked["results"][name]
    held = {(n, p): what for n, p, what, released in grade.held() if not released}
    assert (number, part) in held, grade.feedback()
    assert held[(number, part)]["source"].startswith(source)
    assert grade.points[number] == 0
    feedback = grade.feedback()
    assert "HELD" in feedback and source in feedback and " | " in feedback  # the shared lines side by side
    with open(attacked["out"] / "grades.csv", newline="") as handle:
        row = next(r for r in csv.DictReader(handle) if r["submission"] == name)
    assert f"exercise {number} {part}" in row["held for a person"]


def test_no_honest_classmate_is_held(attacked):
    for name, grade in attacked["results"].items():
        if name.startswith("honest_"):
            assert grade.held() == [], grade.feedback()


def test_the_honest_classmates_get_their_usual_scores(attacked):
    rubric = default()
    alice, bob = attacked["results"]["honest_alice"], attacked["results"]["honest_bob"]
    assert alice.total == rubric.maximum, alice.feedback()
    assert alice.problems == []
    assert bob.total == 25 + 8 and bob.points[2] == 10 and bob.points[3] == 15 and bob.points[16] == 8, bob.feedback()


UNDESERVED = {  # what an attacker keeps: exercises whose points it may have, and nothing else
    "best_of_four": {2, 3},  # the first notebook is an honest solution but for its rate answer
    "mallory": set(),
    "linked_inside": set(),
}


def test_no_hostile_submission_gets_a_point_it_did_not_earn(attacked):
    for name, grade in attacked["results"].items():
        if name.startswith("honest_"):
            continue
        allowed = UNDESERVED.get(name, set())
        assert grade.graded, f"{name}: {grade.failure}"
        earned = {n for n, points in grade.points.items() if points}
        assert earned <= allowed, f"{name}: {earned}\n{grade.feedback()}"


def test_only_the_first_notebook_that_defines_an_exercise_counts(attacked):
    grade = attacked["results"]["best_of_four"]
    rate = next(c for c in grade.results[3].parts if c.name == "rate_pherm")
    assert not rate.passed and "got 1" in json.dumps(rate.as_dict())
    assert grade.points[3] == 15 * (12 / 15)  # the driver and the table are right, the rate is not


def test_the_class_is_graded_within_its_limits(attacked):
    # every submission is bounded by its total limit plus the grader's grace; most end far sooner.
    # Generous: a busy machine must not fail this (the run of about 40 submissions takes ~3 minutes here)
    assert attacked["elapsed"] < 900, attacked["elapsed"]
    stuck = attacked["results"]["eight_stuck_notebooks"]
    assert any("time limit" in p for p in stuck.problems), stuck.problems
    assert any("not run: the submission's time limit" in p for p in stuck.problems), stuck.problems


def test_nothing_outside_the_sandbox_changed_and_nothing_is_left_behind(attacked):
    assert attacked["unchanged"]
    assert not Path(f"/tmp/{MARK}").exists()
    assert not (LABKIT / f"{MARK}.py").exists() and not (ROOT / MARK).exists()
    assert sorted(p.name for p in attacked["out"].iterdir()) == [
        "feedback",
        "grades.csv",
        "record.json",
        "results",
        "rubric.toml",
        "run.json",
        "seed.txt",
        "timings.json",  # where each submission's grading time went (labkit.grading.sandbox.timings)
    ]
    before, after = attacked["leftovers"]
    assert after == before, f"left in {tempfile.gettempdir()}: {sorted(set(after) - set(before))}"


def test_no_process_outlives_grading(attacked):
    deadline = time.monotonic() + 10
    while (_processes_with("sleep 7777") or _processes_with("labkit.grading")) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _processes_with("sleep 7777") == []
    assert (
        _processes_with("labkit.grading.sandbox.worker") == []
        and _processes_with("labkit.grading.submission.scoring") == []
    )
    assert (
        _processes_with("labkit.grading.sandbox.zygote") == [] and _processes_with("labkit.grading.run.launcher") == []
    )
    assert _processes_with("bwrap") == []


def test_the_listening_socket_saw_no_connection(attacked):
    assert attacked["connection"] is None


RUN = {}  # the hostile class's run.json, shown in the test run's summary (tests/conftest.py)


def test_the_graders_own_memory_stays_under_its_bound(attacked):
    run = json.loads((attacked["out"] / "run.json").read_text())
    RUN.update(run)
    if run["grader peak bytes"] is None:
        pytest.skip("no memory cgroup here to measure the grader's peak")
    assert run["grader peak bytes"] < GRADER_MEMORY_BOUND, run


def test_the_class_was_graded_through_the_fork_server(attacked):
    """Every attack here ran in workers forked from the run's fork server (labkit.grading.sandbox.forkserver)."""
    if os.geteuid() != 0:
        pytest.skip("the fork server is offered only to a grader running as root")
    run = json.loads((attacked["out"] / "run.json").read_text())
    assert run["fork server"] is True and run["forked grading processes"] is True, run


def test_grades_csv_has_every_student_once_and_no_formula(attacked):
    with open(attacked["out"] / "grades.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    names = [row[0] for row in rows[1:]]
    assert len(names) == len(set(names)) == attacked["count"]
    assert "'=2+3*7" in names and "'=cmd|' -C calc'!A0" in names
    assert not any(cell.startswith(("=", "+", "-", "@", "\t", "\r")) for row in rows for cell in row)
    assert not any("\x1b" in cell for row in rows for cell in row)


def test_every_student_has_a_file_of_their_own_with_a_short_safe_name(attacked):
    feedback = sorted((attacked["out"] / "feedback").iterdir())
    assert len(feedback) == 2 * attacked["count"]  # the text and the page of each
    assert len(list((attacked["out"] / "feedback").glob("*.txt"))) == attacked["count"]
    assert all(len(p.name) < 90 and p.name.isascii() and "\x1b" not in p.name for p in feedback)
    assert safe_name("jane doe") != safe_name("jane_doe")
    for name in ("jane doe", "jane_doe"):
        text = (attacked["out"] / "feedback" / f"{file_stem(name)}.txt").read_text()
        assert text.startswith("Total: ") and text.splitlines()[1] == f"Feedback for {name}"


def test_no_control_character_reaches_a_feedback_file(attacked):
    for path in (attacked["out"] / "feedback").iterdir():
        text = path.read_text(encoding="utf-8")
        assert not [ch for ch in "\x1b\r\x07\x00" if ch in text], (
            path.name,
            [ch for ch in "\x1b\r\x07\x00" if ch in text],
        )
    forged = (attacked["out"] / "feedback" / f"{file_stem('error_text_forgery')}.txt").read_text()
    assert "25 points" in forged  # the student's text is there, as data:
    for text in (
        forged,
        (
            attacked["out"] / "feedback" / f"{file_stem('zz' + chr(0x2028) + 'Total: 118 (full credit is 100)')}.txt"
        ).read_text(),
    ):
        assert not any(
            line.startswith(("Exercise 2: 10 / 10", "25 points", "Total: 118")) for line in text.splitlines()
        )


def test_names_reach_the_terminal_without_escape_sequences(attacked, tmp_path):
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "labkit.cli",
            "merge",
            str(attacked["out"]),
            "--out",
            str(tmp_path / "merged"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    assert "\x1b" not in run.stdout and "esc" in run.stdout
    with open(tmp_path / "merged" / "grades.csv", newline="", encoding="utf-8") as handle:
        assert len(list(csv.reader(handle))) == attacked["count"] + 1  # jane doe and jane_doe both kept


@pytest.mark.parametrize(
    "name, named",
    [
        ("patched_check", "not done"),
        ("patched_numpy", "not done"),
        ("always_equal", "got a Liar object, not numbers"),
        ("always_equal_array", "wrong for x^[0, 1, 2, 3]"),
        ("fake_result_line", "not done"),
        ("writes_outside", "Read-only file system"),
        ("background_process", "subprocess.Popen"),
        ("fork_loop", "os.fork"),
        ("memory_grab", "MemoryError"),
        # a forked worker's network namespace has no loopback up (the plain way's bwrap sandbox has one)
        ("connects_out", ("ConnectionRefusedError", "Network is unreachable")),
        ("reads_solutions", "No such file or directory"),
        ("infinite_loop", ("Timeout: interrupted", "ran past its time limit")),
        ("sys_exit", "SystemExit"),
        ("os_exit", "exited with status 3"),
        ("exits_in_a_graded_call", "exited with status 5"),
        ("prints_100_mb", "printed 100,00"),
        ("invalid_json", "is not a valid notebook"),
        ("calls_reference", "called labkit.piecewise.eval_pherm, which is switched off"),
        ("calls_reference_alias", "reaches for labkit.piecewise.eval_pherm"),
        ("five_thousand_cells", "not done"),
        ("answer_pipe_bomb", "out of protocol"),
        ("deep_folders", "No space left on device"),
        ("memfd", "PermissionError: [Errno 1] Operation not permitted"),
        ("keyring", "ctypes.dlsym"),
        ("magic_lines", "exited with status 0"),
        ("gc_switch_off", "gc.get_objects"),
        ("mesh_bomb", "meshes of 60,000 and 60,000 nodes"),
        ("mesh_bomb", "60,000 nodes and 1 elements"),
        ("exact_limacon_plot", "exact limaçon, not its Hermite interpolant"),
        ("constant_tables", "this table shows no experiment"),
        ("constant_tables", "no rate to read"),
        ("fabricated_table", "this part is checked against what test_pherm_interpolate returns"),
        ("bpoly_construct_fast", "construct_fast, which is switched off"),
        ("reference_by_assignment", "reaches for labkit.piecewise.eval_pherm"),
        ("saved_code_object", "function.__new__"),
        ("graders_reference", "labkit.exercises.splines._reference_complete_system"),
        ("graders_reference", "labkit.splines._slopes_from_curvatures"),
        ("private_natural_helpers", "labkit.splines.natural_curvatures"),
        ("ndimage_bilinear", "scipy.ndimage"),
        ("notebook_of_60_mb", "more than the 10 MB a lab notebook needs"),
        ("notebook_of_8_mb", "not done"),
        ("mallory", "is a symbolic link; links are never followed"),
        ("object_run_inside_the_watch", "which is switched off"),
        ("watch_names_rebound", "which is switched off"),
        ("fake_compiled_object", "which is switched off"),
        ("profile_hook_fetched_from_c", "which is switched off"),
        ("spins_sixty_processes", "os.fork"),
        ("exec_statement_by_statement", "labkit.piecewise.eval_pherm, which is switched off"),
        ("pasted_private_helper", "labkit.piecewise._hermite_eval, which is switched off"),
        ("interp_alias", "interp, which is switched off"),
        ("bad\\xff\\xfename", "not done"),
        ("linked_inside", "not done"),
    ],
)
def test_feedback_names_what_happened(attacked, name, named):
    feedback = _feedback(attacked, name)
    assert any(words in feedback for words in ((named,) if isinstance(named, str) else named)), feedback


def test_a_link_inside_a_submission_is_not_graded_as_its_work(attacked):
    grade = attacked["results"]["linked_inside"]
    assert grade.total == 0 and "02_convergence.ipynb" not in " ".join(grade.problems)


def test_calls_through_aliases_and_helpers_are_refused_and_named(attacked):
    feedback = _feedback(attacked, "calls_reference_alias")
    section = feedback.split("Exercise 2:")[1].split("\nExercise ")[0]
    assert "switched off" in section  # the runtime refusal, though the code caught the error
    assert "helper" in section and "CubicHermiteSpline" in section


def test_an_uninterruptible_loop_is_stopped_by_the_total_limit(tmp_path):
    sandbox_or_skip()
    path = _notebook(
        tmp_path,
        "stubborn",
        ["import time\nwhile True:\n    try:\n        time.sleep(100)\n    except BaseException:\n        pass"],
    )
    start = time.perf_counter()
    results, problems = grading.grade_notebook(path, grading.GradeOptions(cell_timeout=1, total_timeout=6))
    # the limit is 6 s; unstopped, only the grader's grace would end it (126 s): the rest is slack for a busy machine
    assert time.perf_counter() - start < 100
    assert results == {} and "the submission's time limit of 6 s" in problems[0]
    assert _processes_with("labkit.grading.sandbox.worker") == []


def test_deep_folders_are_removed_without_recursion(tmp_path):
    top = tmp_path / "private"
    top.mkdir()
    os.chdir(top)
    try:
        for _ in range(1100):
            os.mkdir("d")
            os.chdir("d")
        Path("file").write_text("x")
        os.chmod(".", 0o500)  # a folder the student made unwritable
    finally:
        os.chdir(ROOT)
    remove_tree(top)
    assert not top.exists()


def test_a_memory_cgroup_counts_what_the_address_space_limit_does_not(tmp_path):
    from labkit.grading.sandbox import cgroup

    group = cgroup.create(96 * 1024**2, label="labkit-test")
    if group is None:
        if os.environ.get("CI") and os.geteuid() == 0:
            raise AssertionError("no memory cgroup could be made as root")
        pytest.skip("no memory cgroup can be made here")
    try:
        # 300 MiB in files of /dev/shm-like tmpfs and anonymous memory, from a process without rlimits
        child = subprocess.Popen(
            [
                sys.executable,
                "-c",
                "import os\nblocks = []\nfor _ in range(300):\n"
                "    blocks.append(bytearray(1024**2))\nprint('held it all')",
            ],
            preexec_fn=group.join,
            stdout=subprocess.PIPE,
            text=True,
        )
        output, _ = child.communicate(timeout=120)
        assert child.returncode != 0 and "held it all" not in output
        assert group.out_of_memory()
    finally:
        group.remove()
    assert not group.path.exists()


def test_the_notebooks_filter_refuses_memfd_keyrings_ptrace_threads_and_signal_handlers():
    from labkit.grading.sandbox import seccomp

    if seccomp.program() is None:
        pytest.skip("no seccomp filter for this architecture")
    code = (
        "import ctypes, os, signal, threading\nfrom labkit.grading.sandbox import seccomp, guard\n"
        "numbers = seccomp.SYSCALLS[__import__('platform').machine()]\n"
        "assert seccomp.install_for_notebook()\nlibc = ctypes.CDLL(None, use_errno=True)\nseen = {}\n"
        "for name, args in (('add_key', (b'user', b'k', b'v', 1, -4)), ('keyctl', (0, -4)),\n"
        "                   ('ptrace', (16, os.getppid(), 0, 0)), ('memfd_create', (b'x', 0))):\n"
        "    ctypes.set_errno(0)\n    result = libc.syscall(numbers[name], *args)\n"
        "    seen[name] = (result, ctypes.get_errno())\n"
        "try:\n    threading.Thread(target=print).start()\n    seen['thread'] = 'started'\n"
        "except RuntimeError:\n    seen['thread'] = 'refused'\n"
        "try:\n    signal.signal(signal.SIGUSR1, print)\n    seen['sigaction'] = 'set'\n"
        "except OSError:\n    seen['sigaction'] = 'refused'\n"
        "pid = os.fork()\nif pid == 0:\n    os._exit(0)\nos.waitpid(pid, 0)\nprint(seen)"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    seen = eval(run.stdout)
    assert all(seen[name] == (-1, 1) for name in ("add_key", "keyctl", "ptrace", "memfd_create")), seen
    assert seen["thread"] == "refused" and seen["sigaction"] == "refused"  # and fork still works (above)
    assert seccomp.program("sparc") is None


def test_a_grading_process_that_dies_costs_only_its_own_submission(tmp_path):
    """A killed grading process is started once more; killed twice, that student is 'could not be graded'."""
    sandbox_or_skip()
    import threading

    honest = _honest_copy(tmp_path, "steady", {"06_bilinear.ipynb"})
    once = _honest_copy(tmp_path, "killed_once", {"06_bilinear.ipynb"})
    twice = _honest_copy(tmp_path, "killed_twice", {"06_bilinear.ipynb"})
    kills = {"killed_once": 1, "killed_twice": 2}
    stop = threading.Event()

    def killer():
        done = {name: set() for name in kills}
        while not stop.is_set():
            for pid, cmdline in _grading_processes():
                for name, times in kills.items():
                    if safe_name(name) in cmdline and pid not in done[name] and len(done[name]) < times:
                        done[name].add(pid)
                        try:
                            os.kill(int(pid), 9)
                        except ProcessLookupError:
                            pass
            time.sleep(0.05)

    thread = threading.Thread(target=killer, daemon=True)
    thread.start()
    try:
        grades = grading.grade([honest, once, twice], tmp_path / "out", grading.GradeOptions(jobs=3), progress=False)
    finally:
        stop.set()
        thread.join()
    steady, killed_once, killed_twice = grades
    assert steady.graded and steady.total == 8
    assert killed_once.graded and killed_once.total == 8
    assert not killed_twice.graded and "tried 2 times" in killed_twice.failure
    with open(tmp_path / "out" / "grades.csv", newline="") as handle:
        rows = {row[0]: row for row in csv.reader(handle)}
    status, total = rows["submission"].index("status"), rows["submission"].index("total")
    assert rows["killed_twice"][status].startswith("not graded: ") and rows["killed_twice"][total] == ""
    assert rows["steady"][status] == "graded"
    assert "could not be graded" in (tmp_path / "out" / "feedback" / f"{file_stem('killed_twice')}.txt").read_text()
