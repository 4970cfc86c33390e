"""What a graded function may not reach: the sandbox's watch at run time, the source scan on the grader's side.

The watch is tested through a real worker (unconfined here, so the tests
run without bubblewrap; the hostile suite repeats the important attacks in
the sandbox): each attack is a notebook's cells, and the grader's proxy
calls the student's function with a part's refusal, as grading does.
"""

import subprocess
import sys
import types

import numpy as np
import pytest

import labkit
from labkit.exercises import hermite
from labkit.exercises.model import EXPERIMENTS, INTERPOLANTS, OWN_FUNCTIONS, OWN_PATCH
from labkit.exercises.registry import LAB

pytestmark = pytest.mark.slow  # a worker process per case

REFUSALS = LAB.refusals
from labkit.grading.options import GradeOptions
from labkit.grading.sandbox import guard, remote
from labkit.grading.submission import refusals, scoring
from labkit.grading.submission.scan import Unreadable, python_source, scan

X, Y, YP = np.array([0.0, 1.0, 3.0]), np.array([1.0, -1.0, 2.0]), np.array([0.0, 2.0, -1.0])
XV = np.linspace(-0.5, 3.5, 9)
HONEST_PHERM = """
import numpy as np, labkit

def eval_pherm(xdata, ydata, ypdata, xval):
    xdata, ydata, ypdata, xval = (np.asarray(v, dtype=float) for v in (xdata, ydata, ypdata, xval))
    k = labkit.bracket(xdata, xval)
    a, b = xdata[k], xdata[k + 1]
    h = b - a
    s = (xval - a) / h
    return (ydata[k] * (1 + 2 * s) * (1 - s) ** 2 + ypdata[k] * h * s * (1 - s) ** 2
            + ydata[k + 1] * s**2 * (3 - 2 * s) + ypdata[k + 1] * h * s**2 * (s - 1))
"""
PROFILES = scoring._for_sandbox(refusals.wire(REFUSALS))
UNCONFINED = GradeOptions(backend="none")


@pytest.fixture(scope="module")
def open_notebooks():
    started = []
    yield started
    for notebook in started:
        notebook.close()


def _notebook(open_notebooks, *cells, clean=True):
    notebook = remote.NotebookHandle(UNCONFINED, profiles=PROFILES, passables=LAB.passable)
    open_notebooks.append(notebook)
    ran = notebook.request({"op": "run", "cells": list(cells), "cell_timeout": 30}, 120)
    if clean:
        assert not ran["errors"], ran["errors"]
    return notebook


def _call(notebook, name, refusal, *args):
    return remote.Function(notebook, name, refusal, 30)(*args)


def test_an_honest_function_built_on_the_allowed_helpers_passes_the_check_under_its_refusal(open_notebooks):
    notebook = _notebook(open_notebooks, HONEST_PHERM)
    assert hermite.check_eval_pherm(lambda *a: _call(notebook, "eval_pherm", INTERPOLANTS, *a), seed=3).passed
    assert np.allclose(_call(notebook, "eval_pherm", INTERPOLANTS, X, Y, YP, XV), labkit.eval_pherm(X, Y, YP, XV))


ATTACKS = {
    "the reference itself": "def eval_pherm(*a):\n    return labkit.eval_pherm(*a)",
    "an alias taken before grading": "from labkit.piecewise import eval_pherm as ref\n"
    "def eval_pherm(*a):\n    return ref(*a)",
    "a private helper": "def eval_pherm(x, y, yp, xv):\n"
    "    return labkit.piecewise._hermite_eval(*map(np.asarray, (x, y, yp, xv)))",
    "BPoly through a subclass and construct_fast": (
        "from scipy.interpolate import BPoly\n"
        "class H(BPoly):\n"
        "    def __new__(cls, x, c):\n        return BPoly.construct_fast.__func__(cls, c, x)\n"
        "    def __init__(self, *a):\n        pass\n"
        "def eval_pherm(x, y, yp, xv):\n"
        "    x, y, yp = map(np.asarray, (x, y, yp))\n"
        "    h = np.diff(x)\n"
        "    c = np.stack([y[:-1], y[:-1] + yp[:-1] * h / 3, y[1:] - yp[1:] * h / 3, y[1:]])\n"
        "    return H(x, c)(xv)"
    ),
    "a saved code object put back under a new function": (
        "import types\nsaved = labkit.piecewise.eval_pherm.__code__\n"
        "def eval_pherm(*a):\n    return types.FunctionType(saved, labkit.piecewise.__dict__, None, (0,))(*a)"
    ),
    "labkit's code pasted into the notebook": (
        "import inspect\nexec(inspect.getsource(labkit.piecewise).replace('from ._', 'from labkit._'), globals())"
    ),
    "labkit's file run statement by statement at the top level": (
        "import ast\nsource = open(labkit.piecewise.__file__).read().replace('from ._', 'from labkit._')\n"
        "for node in ast.parse(source).body:\n"
        "    exec(compile(ast.Module([node], []), 'mine.py', 'exec'), globals())"
    ),
    "labkit's file run statement by statement, docstrings stripped": (
        "import ast\nsource = open(labkit.piecewise.__file__).read().replace('from ._', 'from labkit._')\n"
        "for node in ast.parse(source).body:\n"
        "    exec(compile(ast.Module([node], []), 'mine.py', 'exec', optimize=2), globals())"
    ),
    "scipy's CubicHermiteSpline": "import scipy.interpolate as si\n"
    "def eval_pherm(x, y, yp, xv):\n    return si.CubicHermiteSpline(x, y, yp)(xv)",
    "a compiled routine of scipy.interpolate": (
        "from scipy.interpolate import _ppoly\n"
        "def eval_pherm(x, y, yp, xv):\n"
        "    f = getattr(__import__('scipy.interpolate._ppoly').interpolate._ppoly, 'evaluate')\n"
        "    return f(np.zeros((4, 1, 1)), np.asarray(x, float)[:2], np.asarray(xv, float), 0, True,\n"
        "             np.empty((len(xv), 1)))[:, 0]"
    ),
}


@pytest.mark.parametrize("name", ATTACKS)
def test_every_path_to_a_library_interpolant_is_refused(open_notebooks, name):
    notebook = _notebook(open_notebooks, "import numpy as np, labkit", ATTACKS[name])
    with pytest.raises(remote.StudentError) as refused:
        _call(notebook, "eval_pherm", INTERPOLANTS, X, Y, YP, XV)
    # refused by the watch, or the way round it reported as tampering: either way the answer is void
    assert refused.value.kind in ("RefusedReference", "Tampered"), (refused.value.kind, str(refused.value))
    assert "switched off" in str(refused.value) or "cannot vouch" in str(refused.value)


def test_private_spline_helpers_and_ndimage_are_refused_like_the_public_functions(open_notebooks):
    notebook = _notebook(
        open_notebooks,
        "import numpy as np, labkit\nfrom labkit import splines\nimport scipy.ndimage",
        "def ncspline(x, y):\n    x, y = np.asarray(x, float), np.asarray(y, float)\n    h = np.diff(x)\n"
        "    s = np.diff(y) / h\n    return splines._slopes_from_curvatures(h, s, splines.natural_curvatures(h, s))",
        "def eval_pbilin(f, xd, yd, xv, yv):\n    z = f(*np.meshgrid(xd, yd, indexing='ij'))\n"
        "    i = np.interp(xv, xd, np.arange(len(xd)))\n    j = np.interp(yv, yd, np.arange(len(yd)))\n"
        "    I, J = np.meshgrid(i, j, indexing='ij')\n"
        "    return scipy.ndimage.map_coordinates(z, [I, J], order=1)",
    )
    for name, args, reference in (
        ("ncspline", (X, Y), "labkit.splines"),
        ("eval_pbilin", (labkit.runge2d, X, X, XV, XV), "interp"),
    ):
        with pytest.raises(remote.StudentError, match="switched off") as refused:
            _call(notebook, name, INTERPOLANTS, *args)
        assert reference in str(refused.value)


def test_a_handed_over_function_is_trusted_only_in_the_call_it_was_handed_to(open_notebooks):
    notebook = _notebook(
        open_notebooks,
        "import numpy as np\nkept = []",
        "def driver(n, f):\n    kept.append(f)\n    return float(np.max(f(np.linspace(0, 5, n))[0]))",
        "def runge(x):\n    return kept[0](x)",
    )
    # the driver may use the labkit runge the check hands it (labkit.functions is refused in its part too)
    assert _call(notebook, "driver", OWN_FUNCTIONS, 11, labkit.runge) == pytest.approx(1.0)
    # but a student who kept it cannot use it for the part that asks for their own runge
    with pytest.raises(remote.StudentError, match="labkit.functions.runge"):
        _call(notebook, "runge", OWN_FUNCTIONS, XV)


def test_a_handed_over_function_gets_plain_numbers_whatever_it_is_given(open_notebooks):
    notebook = _notebook(
        open_notebooks,
        "import numpy as np, labkit",
        "class Sly:\n    def __array__(self, *a, **k):\n"
        "        return labkit.convergence_table('pherm').errors[:1]\n"
        "def driver(n, f):\n    return float(f(Sly())[0][0])",
    )
    # the student's hook runs before the trusted copy does, so its refused call is seen
    with pytest.raises(remote.StudentError, match="labkit.convergence"):
        _call(notebook, "driver", EXPERIMENTS, 11, labkit.runge)


def test_coons_may_use_eval_pherm_and_the_corners_it_is_given(open_notebooks):
    notebook = _notebook(
        open_notebooks,
        "import numpy as np, labkit",
        "def coons(A, B, C, D, s, t):\n    assert A.dim == 2\n"
        "    x = labkit.eval_pherm([0, 1], [A.point[0], B.point[0]], [A.ds[0], B.ds[0]], s)\n"
        "    return np.add.outer(x, 0 * np.asarray(t)), np.add.outer(0 * x, np.asarray(t))",
        "def cheat(A, B, C, D, s, t):\n    return labkit.patch(A, B, C, D, s, t)",
    )
    corners = [labkit.Corner(p, [1.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
    x, y = _call(notebook, "coons", OWN_PATCH, *corners, np.linspace(0, 1, 4), np.linspace(0, 1, 5))
    assert x.shape == (4, 5)
    with pytest.raises(remote.StudentError, match="labkit.patches"):
        _call(notebook, "cheat", OWN_PATCH, *corners, np.linspace(0, 1, 4), np.linspace(0, 1, 5))


@pytest.mark.parametrize(
    "cells, says",
    [
        (["import gc\ndef eval_pherm(*a):\n    gc.get_objects()\n    return 0.0"], "gc.get_objects"),
        (["import gc, functools\nfunctools.partial(gc.get_referrers, labkit)()"], "gc.get_referrers"),  # from C code
        (
            ["import sys\ndef eval_pherm(*a):\n    sys.setprofile(None)\n    return labkit.eval_pherm(*a)"],
            "sys.setprofile",
        ),
        (["import ctypes\nctypes.c_char.from_address(id(labkit))"], "ctypes.cdata"),
        (["import types\nf = types.FunctionType(labkit.piecewise.eval_pherm.__code__, {})"], "function.__new__"),
        # the red team's ways into the watch's own hooks (now nothing of the student's runs inside them):
        # a stand-in made with a name of the student's own, whose formatting calls the reference
        (
            [
                "import numpy as np\nfrom labkit.grading.sandbox import guard\nnp.lab_ref = labkit.eval_pherm\n"
                "class Name:\n    def __init__(self, args):\n        self.args, self.out = args, None\n"
                "    def __format__(self, spec):\n        self.out = np.lab_ref(*self.args)\n        return 'x'\n"
                "def eval_pherm(x, y, yp, xv):\n    name = Name((x, y, yp, xv))\n    try:\n        guard._stand_in(name)()\n"
                "    except RuntimeError:\n        pass\n    return name.out"
            ],
            "switched off",
        ),
        # the second red team: every name the watch's module, hashlib and the builtins hold, rebound
        (
            [
                "import builtins, hashlib, numpy as np\nfrom labkit.grading.sandbox import guard\nnp.ref = labkit.eval_pherm\n"
                "guard.any = guard._within = lambda *a: False\nguard.TAMPER_EVENTS = frozenset()\n"
                "guard.code_key = lambda code: bytes(12)\nguard._sha1 = guard._sha256 = lambda *a: hashlib.md5(b'same')\n"
                "hashlib.sha1 = hashlib.sha256 = guard._sha1\nguard.sign = lambda *a: ''\n"
                "guard.attestation_text = lambda r, p, pa, s, d: (r, p or '', ','.join(sorted(pa)), 'clean', d)\n"
                "def eval_pherm(*a):\n    return np.ref(*a)"
            ],
            "switched off",
        ),
        # ... and the watch's names reached through the globals of a stand-in found in a refused module
        (
            [
                "import sys, numpy as np\nnp.ref = labkit.eval_pherm\n"
                "def eval_pherm(*a):\n    found = 0\n    for module in list(sys.modules.values()):\n"
                "        for value in list(getattr(module, '__dict__', {}).values()):\n"
                "            code = getattr(value, '__code__', None)\n"
                "            if getattr(code, 'co_name', '') == 'refused':\n                g = value.__globals__\n"
                "                g['code_key'] = lambda code: bytes(12)\n                g['TAMPER_EVENTS'] = frozenset()\n"
                "                g['__builtins__']['len'] = lambda v: 0\n                found += 1\n"
                "    assert found, 'no stand-in found'\n    return np.ref(*a)"
            ],
            "switched off",
        ),
        (
            [
                "import sys, numpy as np, labkit.exercises.splines\nclass cython_function_or_method:\n"
                "    @property\n    def __module__(self):\n        raise SystemExit('inside the watch')\n"
                "labkit.exercises.zz_fake = cython_function_or_method()\nnp.ref_pherm = labkit.eval_pherm\n"
                "def eval_pherm(*a):\n    return np.ref_pherm(*a)"
            ],
            "switched off",
        ),
        (
            [
                "import sys, functools, numpy as np\nhook = functools.partial(sys.getprofile)()\nassert hook is None\n"
                "np.ref = labkit.eval_pherm\ndef eval_pherm(*a):\n    assert functools.partial(sys.getprofile)() is None\n"
                "    return np.ref(*a)"
            ],
            "switched off",
        ),
        (
            [
                "from labkit.grading.sandbox import protocol\nseen, decode, encode = [], protocol.decode, protocol.encode\n"
                "def peek(tag, *a, **k):\n    value = decode(tag, *a, **k)\n    seen.append(value)\n    return value\n"
                "def answer(value, *a):\n    return encode(labkit.eval_pherm(*seen[-4:]) if len(seen) >= 4 else value, *a)\n"
                "protocol.decode, protocol.encode = peek, answer"
            ],  # the worker's own helpers, rewritten
            "switched off",
        ),
        (
            [
                "import labkit.grading.sandbox.protocol as p, json\nreal = p.loads\nstash = {}\n"
                "def peek(line):\n    request = real(line)\n    if request.get('op') == 'call':\n"
                "        stash['answer'] = labkit.eval_pherm(X, Y, YP, XV)\n    return request\np.loads = peek"
            ],
            "switched off",
        ),
        (
            ["import sys\ndef eval_pherm(*a):\n    sys.audit('labkit.end', b'{}')\n    return labkit.eval_pherm(*a)"],
            "labkit.end raised by the notebook",
        ),
    ],
)
def test_switching_the_watch_off_or_going_round_it_voids_the_answer(open_notebooks, cells, says):
    notebook = _notebook(
        open_notebooks,
        "import numpy as np, labkit\nX, Y, YP, XV = "
        "np.array([0., 1, 3]), np.array([1., -1, 2]), np.array([0., 2, -1]), np.linspace(-.5, 3.5, 9)",
        HONEST_PHERM,
        *cells,
        clean=False,
    )
    with pytest.raises(remote.StudentError) as voided:
        _call(notebook, "eval_pherm", INTERPOLANTS, X, Y, YP, XV)
    assert says in str(voided.value), str(voided.value)


@pytest.mark.parametrize(
    "cell, error",
    [
        ("import threading\nthreading.Thread(target=print).start()", "can't start new thread"),
        ("import signal\nsignal.signal(signal.SIGALRM, lambda *a: None)", "Operation not permitted"),
        ("import os\nos.memfd_create('hoard')", "Operation not permitted"),
    ],
)
def test_threads_signal_handlers_and_anonymous_memory_are_refused_even_without_the_sandbox(open_notebooks, cell, error):
    notebook = remote.NotebookHandle(UNCONFINED, profiles=PROFILES, passables=LAB.passable)
    open_notebooks.append(notebook)
    ran = notebook.request({"op": "run", "cells": [cell], "cell_timeout": 30}, 120)
    assert ran["errors"] and error in ran["errors"][0]["message"], ran


def test_a_forged_answer_line_never_reaches_the_grader(open_notebooks):
    notebook = _notebook(
        open_notebooks,
        HONEST_PHERM,
        "import os, json\nfor fd in range(3, 40):\n    try:\n"
        "        os.write(fd, (json.dumps({'id': 'x', 'value': ['f', 1.0]}) + '\\n').encode())\n"
        "    except OSError:\n        pass",
    )
    assert np.allclose(_call(notebook, "eval_pherm", INTERPOLANTS, X, Y, YP, XV), labkit.eval_pherm(X, Y, YP, XV))


def test_an_attestation_the_notebook_writes_for_its_own_request_voids_the_answer(open_notebooks):
    # the request's id is found on the worker's frames, and a line for it written to every descriptor
    notebook = _notebook(
        open_notebooks,
        "import sys, os, numpy as np, labkit\nnp.ref = labkit.eval_pherm",
        "def eval_pherm(*a):\n    frame, rid = sys._getframe(), None\n"
        "    while frame is not None and rid is None:\n"
        "        request = frame.f_locals.get('request')\n"
        "        rid = request.get('id') if isinstance(request, dict) else None\n"
        "        frame = frame.f_back\n    assert rid, 'no request id found'\n"
        "    line = '\\t'.join([str(rid), 'interpolants', '', 'clean', '0' * 64, '0' * 64]) + '\\n'\n"
        "    for fd in range(3, 40):\n        try:\n            os.write(fd, line.encode())\n"
        "        except OSError:\n            pass\n    return np.ref(*a)",
    )
    with pytest.raises(remote.StudentError, match="wrote to the grader's watch"):
        _call(notebook, "eval_pherm", INTERPOLANTS, X, Y, YP, XV)


def test_the_hooks_look_up_nothing_a_notebook_can_rebind():
    """The watch's hooks find their names in a private namespace; none of them is a module read at call time."""
    import builtins
    import dis

    hooks = {"audit", "profile_hook", "_begin", "_choose", "_end", "_stub", "_unstub", "_key", "_note_tampering"}
    hooks |= {"_genuine", "_note_busy", "_holds_target", "_stub_module", "_remember", "_forget", "_as_a_worker_sends"}
    functions = [f for f in vars(guard).values() if isinstance(f, type(guard.install))]
    codes = [c for f in functions for c in guard.codes_in(f.__code__) if c.co_name in hooks]
    codes += [f.__code__ for f in (guard.code_key, guard.sign, guard.attestation_text, guard._within)]
    assert {c.co_name for c in codes} >= hooks
    for code in codes:
        for instruction in dis.get_instructions(code):
            if instruction.opname == "LOAD_GLOBAL":
                name = instruction.argval
                value = vars(guard).get(name, vars(builtins).get(name))
                assert value is not None, (code.co_name, name)
                assert not isinstance(value, type(guard)), f"{code.co_name} reads the module {name} when it runs"
            if instruction.opname == "LOAD_DEREF":
                assert instruction.argval not in {"ctypes", "sys", "os", "gc", "hashlib", "hmac", "builtins"}
    assert not guard.EXPOSED & {"code_key", "sign", "attestation_text", "_within", "_install", "install"}


def test_a_call_that_ends_the_process_costs_only_that_call(open_notebooks):
    notebook = _notebook(open_notebooks, HONEST_PHERM, "import os\ndef quits(*a):\n    os._exit(7)")
    with pytest.raises(remote.StudentError, match="exited with status 7"):
        _call(notebook, "quits", None, 1.0)
    # the next request starts a fresh notebook process, which runs the cells again
    assert np.allclose(_call(notebook, "eval_pherm", INTERPOLANTS, X, Y, YP, XV), labkit.eval_pherm(X, Y, YP, XV))


def test_the_grader_computes_the_digests_from_the_library_files():
    names, modules, c_names = refusals.recognised(INTERPOLANTS)
    recognised = set(names.values())
    assert {
        "labkit.piecewise.eval_pherm",
        "labkit.piecewise._hermite_eval",
        "labkit.splines._slopes_from_curvatures",
        "scipy.interpolate._interpolate._PPolyBase.construct_fast",
        "labkit.exercises.splines._reference_complete_system",
        "numpy.lib._function_base_impl.interp",
    } <= recognised
    assert "labkit.piecewise.bracket" not in recognised  # the lab lets students use it
    # what the sandbox recognises is the live code's digest
    assert names[guard.code_key(labkit.eval_pherm.__code__)] == "labkit.piecewise.eval_pherm"
    assert ("numpy._core._multiarray_umath", "interp") in c_names and "scipy.ndimage" in modules
    # a student's function of the same name and size is not mistaken for labkit's
    student = compile(HONEST_PHERM, "<cell>", "exec").co_consts
    assert not any(guard.code_key(code) in names for code in student if hasattr(code, "co_code"))


def test_labkit_check_exports_no_reference_of_the_grader():
    assert not [name for name in dir(labkit.check) if name.startswith("_reference")]


# -- the source scan ---------------------------------------------------------

WIRED = refusals.wire(REFUSALS)


def _scan(sources, names, refusal):
    return scan(sources, names, WIRED[refusal.name])


def test_scan_names_references_through_aliases_helpers_and_magics():
    sources = [
        "%matplotlib inline\nimport labkit as lk\nimport scipy.interpolate as si\n"
        "from labkit.piecewise import eval_pherm as ref",
        "def helper(*a):\n    return ref(*a)\n\ndef eval_pherm(xdata, ydata, ypdata, xval):\n"
        "    k = lk.bracket(xdata, xval)\n    if k is None:\n        return si.CubicHermiteSpline(xdata, ydata, ypdata)(xval)\n"
        "    return helper(xdata, ydata, ypdata, xval)",
        "def runge(x):\n    return lk.runge(x)",
        "def broken(:\n",
    ]
    found = _scan(sources, ["eval_pherm"], INTERPOLANTS)
    assert any(f[:2] == ("eval_pherm", 4) and "as scipy.interpolate.CubicHermiteSpline" in f[2] for f in found), found
    assert ("helper", 2, "labkit.piecewise.eval_pherm") in found
    assert all("bracket" not in what for *_, what in found)
    assert _scan(sources, ["runge"], OWN_FUNCTIONS) == [("runge", 2, "labkit.functions.runge (as labkit.runge)")]


@pytest.mark.parametrize(
    "sources, what",
    [
        (["import labkit\nref = labkit.eval_pherm", "def eval_pherm(*a):\n    return ref(*a)"], "labkit.eval_pherm"),
        (["import labkit\neval_pherm = labkit.eval_pherm"], "labkit.eval_pherm"),
        (
            [
                "from scipy.interpolate import CubicHermiteSpline\nclass H(CubicHermiteSpline):\n    pass",
                "def eval_pherm(x, y, yp, xv):\n    return H(x, y, yp)(xv)",
            ],
            "CubicHermiteSpline",
        ),
        (["import numpy as np\ndef eval_pherm(x, y, yp, xv):\n    return np.interp(xv, x, y)"], "interp"),
        (["def eval_pherm(*a):\n    m = __import__('lab' + 'kit')\n    return m.eval_pherm(*a)"], "__import__"),
        (
            [
                "import importlib\nm = importlib.import_module('labkit')",
                "def eval_pherm(*a):\n    return m.eval_pherm(*a)",
            ],
            "importlib",
        ),
        (["def eval_pherm(*a):\n    return getattr(__builtins__, 'ev' + 'al')('1')"], "getattr with a computed name"),
        (["import types, labkit\nc = labkit.eval_pherm.__code__\ndef eval_pherm(*a):\n    return 0"], None),
    ],
)
def test_scan_follows_module_level_names_classes_and_dynamic_access(sources, what):
    found = _scan(sources, ["eval_pherm"], INTERPOLANTS)
    if what is None:  # a name the graded function never reaches is none of its business
        assert found == []
    else:
        assert any(what in reference for *_, reference in found), found


def test_scan_leaves_honest_code_alone():
    sources = [
        "from labkit import eval_pherm\nimport numpy as np\nM = 3\nydata = np.zeros(3)",
        "def eval_pherm(xdata, ydata, ypdata, xval):\n    M = len(xdata)\n"
        "    return 0 * xval if M > 2 else eval_pherm(xdata[:2], ydata, ypdata, xval)",
    ]
    assert _scan(sources, ["eval_pherm"], INTERPOLANTS) == []
    assert scan(sources, ["eval_pherm"], None) == []


def test_scan_is_bounded_and_reads_magics_as_ipython_runs_them():
    assert python_source("%%bash\nls") is None
    assert python_source("%%time\nx = 1").strip() == "x = 1"
    assert python_source("  !ls\nx = %time f()") == "  pass\nx = None"
    with pytest.raises(Unreadable, match="more than"):
        _scan(["x = 1\n" * 100_000], ["eval_pherm"], INTERPOLANTS)
    many_magics = "\n".join("%time x" for _ in range(20_000))  # IPython's own reader took minutes on this
    assert _scan([many_magics, HONEST_PHERM], ["eval_pherm"], INTERPOLANTS) == []


def test_every_refusal_of_every_part_is_wired():
    parts = [part for exercise in LAB.exercises.values() for part in exercise.parts if part.refused]
    assert {part.refused for part in parts} == set(REFUSALS)
    for refusal in REFUSALS:
        assert refusals.recognised(refusal)[0], refusal.name


def test_the_scan_names_the_self_checks_in_a_grading_process_that_never_imported_them():
    """The grader's process loads labkit.check only because the refusals name it: the scan must not depend on
    what happened to be imported (``import labkit`` no longer loads the checks)."""
    code = (
        "import sys\nfrom labkit.exercises.registry import LAB\nfrom labkit.grading.submission import refusals, scan\n"
        "assert 'labkit.check' not in sys.modules\n"
        "wired = refusals.wire(LAB.refusals)\n"
        "sources = ['import labkit.check\\nfrom labkit.check import runge as r\\n"
        "def runge(x):\\n    return labkit.check.driver, r\\n"
        "def runge2(x):\\n    return labkit.exercises.hermite.check_runge\\n']\n"
        "for names in (('runge',), ('runge2',)):\n"
        '    print(sorted({found[2] for found in scan.scan(sources, names, wired["the lab\'s functions"])}))\n'
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    first, second = run.stdout.splitlines()
    assert "labkit.check.driver" in first and "labkit.check.runge" in first, first
    assert "labkit.exercises.hermite.check_runge" in second, second


# -- the allowed helpers, however they are spelled --------------------------

# how a graded function calls each helper a refusal allows (a new allowed helper fails the tests below until it
# has one here); the helpers themselves come from the registry
EXAMPLE_CALLS = {
    "labkit.piecewise.bracket": "({}([0.0, 1.0, 3.0], [0.5, 2.0]), 1.0)[1]",
    "labkit.patches.Corner": "({}([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1.0)[1]",
    "labkit.patches._vector": "({}([1.0, 2.0], 'point'), 1.0)[1]",
}


def _spellings_of(spelling, tag=""):
    """(import cell, expression of the object) for every way a notebook may name the object at `spelling`."""
    module, _, name = spelling.rpartition(".")
    parent, _, last = module.rpartition(".")
    forms = [
        (f"import {module}", spelling),
        (f"from {module} import {name}", name),
        (f"from {module} import {name} as helper_alias{tag}", f"helper_alias{tag}"),
        (f"import {module} as mod_alias{tag}", f"mod_alias{tag}.{name}"),
        (f"import {module} as mod_alias{tag}", f"getattr(mod_alias{tag}, {name!r})"),
    ]
    if parent:
        forms.append((f"from {parent} import {last} as sub_alias{tag}", f"sub_alias{tag}.{name}"))
    return forms


def _allowed_helpers():
    """(refusal, helper's own dotted name, a spelling of it) of every helper every refusal of the lab allows."""
    found = []
    for refusal in REFUSALS:
        for helper in refusal.allowed:
            spelled = [s for s in WIRED[refusal.name]["allowed"] if refusals._resolve(s) is refusals._resolve(helper)]
            assert helper in spelled, (helper, spelled)
            found += [(refusal, helper, spelling) for spelling in spelled]
    return found


def _refused_neighbour(refusal, spelling):
    """A refused function exported by the same module as the allowed `spelling` (the same spellings must fail),
    or None when that module holds none (``labkit.plots.editor.Corner``: a module that only uses the helper)."""
    module = spelling.rpartition(".")[0]
    own = {refusals._resolve(s) for s in WIRED[refusal.name]["allowed"]}
    return next(
        (
            s
            for s in sorted(WIRED[refusal.name]["spellings"])
            if s.rpartition(".")[0] == module
            and isinstance(refusals._resolve(s), types.FunctionType)
            and refusals._resolve(s) not in own
            and not s.rpartition(".")[2].startswith("__")
        ),
        None,
    )


def _graded_cells(spelling, call, inside, tag=""):
    """The cells of a notebook whose `graded` uses the object at `spelling`, imported at the top or inside."""
    cells = []
    for i, (imports, expression) in enumerate(_spellings_of(spelling, tag)):
        body = f"    return {call.format(expression)}"
        if inside:
            cells.append(f"def graded_{i}(*a):\n    {imports}\n{body}")
        else:
            cells.append(f"{imports}\ndef graded_{i}(*a):\n{body}")
    return cells


def test_every_allowed_helper_passes_the_scan_however_it_is_spelled_and_its_neighbours_do_not():
    helpers = _allowed_helpers()
    assert {helper for _, helper, _ in helpers} == {h for r in REFUSALS for h in r.allowed} == set(EXAMPLE_CALLS)
    wrongly_refused, missed = [], []
    for refusal, helper, spelling in helpers:
        neighbour = _refused_neighbour(refusal, spelling)
        for inside in (False, True):
            cells = _graded_cells(spelling, EXAMPLE_CALLS[helper], inside)
            for i in range(len(cells)):
                if _scan(cells, [f"graded_{i}"], refusal):
                    wrongly_refused.append(cells[i])
            if neighbour is None:
                continue
            refused_cells = _graded_cells(neighbour, "{}()", inside)
            for i in range(len(refused_cells)):
                if not _scan(refused_cells, [f"graded_{i}"], refusal):
                    missed.append(refused_cells[i])
    assert wrongly_refused == [] and missed == [], (wrongly_refused, missed)
    # a refused module handed on whole is still refused: what it is used for is out of the scan's sight
    assert _scan(["import labkit.piecewise as pw\ndef graded(*a):\n    return vars(pw)"], ["graded"], INTERPOLANTS)
    assert _scan(["from labkit import piecewise\ndef graded(f):\n    return f(piecewise)"], ["graded"], INTERPOLANTS)


def test_every_allowed_helper_passes_the_watch_however_it_is_spelled(open_notebooks):
    allowed, refused = [], []  # (refusal, function name, cell): one notebook for each kind
    for n, (refusal, helper, spelling) in enumerate(_allowed_helpers()):
        for inside in (False, True):
            for i, cell in enumerate(_graded_cells(spelling, EXAMPLE_CALLS[helper], inside, n)):
                allowed.append(
                    (refusal, f"allowed_{n}_{inside:d}_{i}", cell.replace(f"graded_{i}", f"allowed_{n}_{inside:d}_{i}"))
                )
        # called with as many numbers as it takes positional arguments: the call starts, whatever it then raises
        neighbour = _refused_neighbour(refusal, spelling)
        if neighbour is None:
            continue
        for i, cell in enumerate(_graded_cells(neighbour, "{0}(*[0.5] * {0}.__code__.co_argcount)", False, n)):
            refused.append((refusal, f"refused_{n}_{i}", cell.replace(f"graded_{i}", f"refused_{n}_{i}")))
    notebook = _notebook(open_notebooks, *[cell for *_, cell in allowed])
    for refusal, name, cell in allowed:
        assert _call(notebook, name, refusal) == 1.0, cell
    notebook = _notebook(open_notebooks, *[cell for *_, cell in refused])
    for refusal, name, cell in refused:
        with pytest.raises(remote.StudentError, match="switched off"):
            _call(notebook, name, refusal)
            pytest.fail(cell)


# -- labkit's code pasted into a notebook ------------------------------------

PASTED = (  # library functions a student might paste, private helpers among them
    labkit.piecewise._hermite_eval,
    labkit.piecewise.eval_pherm,
    labkit.splines._slopes_from_curvatures,
    labkit.splines.natural_curvatures,
    labkit.monotone._interior_slopes,
    labkit.bilinear._cell_and_weight,
)
PASTE_IMPORTS = (
    "import numpy as np\nfrom numpy.typing import ArrayLike, NDArray\n"
    "from labkit._validate import *\nfrom labkit._locate import *\nfrom labkit._frame import Frame"
)


def pasted(function, docstring=True):
    """`function`'s source as a student pastes it into a cell: verbatim, or with its docstring's lines deleted."""
    import ast
    import inspect
    import textwrap

    lines = textwrap.dedent(inspect.getsource(function)).splitlines()
    node = ast.parse("\n".join(lines)).body[0]
    if not docstring and ast.get_docstring(node) is not None:
        doc = node.body[0]
        del lines[doc.lineno - 1 : doc.end_lineno]
    return "\n".join(lines)


def test_the_digest_is_the_same_with_or_without_the_docstring():
    def key(source, name, optimize=-1):
        namespace = {}
        exec(compile(PASTE_IMPORTS + "\n" + source, "<cell>", "exec", optimize=optimize), namespace)
        return guard.code_key(namespace[name].__code__)

    for function in PASTED:
        kept = key(pasted(function), function.__name__)
        assert kept == key(pasted(function, False), function.__name__)  # the docstring's lines deleted
        assert kept == key(pasted(function), function.__name__, optimize=2)  # stripped by the compiler
    names = refusals.recognised(INTERPOLANTS)[0]
    assert names[guard.code_key(labkit.piecewise._hermite_eval.__code__)] == "labkit.piecewise._hermite_eval"


@pytest.mark.parametrize("docstring", [True, False], ids=["docstrings kept", "docstrings deleted"])
def test_labkit_functions_pasted_into_cells_are_recognised(open_notebooks, docstring):
    """Each copy is pasted in a cell of its own (IPython compiles it apart from the imports), with a function of
    the student's own that calls it."""
    cells = [PASTE_IMPORTS] + [pasted(function, docstring) for function in PASTED]
    for i, function in enumerate(PASTED):
        arguments = function.__code__.co_argcount - len(function.__defaults__ or ())
        cells.append(f"def uses_{i}(*a):\n    return {function.__name__}(*[np.linspace(1.0, 2.0, 5)] * {arguments})")
    notebook = _notebook(open_notebooks, *cells)
    for i, function in enumerate(PASTED):
        with pytest.raises(remote.StudentError, match="switched off") as refused:
            _call(notebook, f"uses_{i}", INTERPOLANTS)
        assert f"{function.__module__}.{function.__qualname__}" in str(refused.value)


def test_every_alias_of_numpys_compiled_interp_is_switched_off(open_notebooks):
    import importlib
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        importlib.import_module("numpy.core.multiarray")  # numpy 2's shim of the old names, which the notebook loads
    compiled = {
        id(importlib.import_module(module).__dict__[name]): name
        for module, name in (f.rsplit(".", 1) for f in INTERPOLANTS.functions)
        if not hasattr(importlib.import_module(module).__dict__[name], "__code__")
    }
    aliases = sorted(
        (module, attribute)
        for module, value in list(sys.modules.items())
        if module.split(".")[0] == "numpy" and value is not None
        for attribute, held in list(vars(value).items())
        if id(held) in compiled
    )
    assert len({module for module, _ in aliases}) >= 4, aliases
    cells = [
        "import sys, warnings, numpy as np\nwith warnings.catch_warnings():\n    warnings.simplefilter('ignore')\n"
        "    import numpy.core.multiarray"
    ]
    for i, (module, attribute) in enumerate(aliases):
        cells.append(f"def via_{i}(x, xp, fp):\n    return getattr(sys.modules[{module!r}], {attribute!r})(x, xp, fp)")
    notebook = _notebook(open_notebooks, *cells)
    for i, alias in enumerate(aliases):
        with pytest.raises(remote.StudentError, match="switched off"):
            _call(notebook, f"via_{i}", INTERPOLANTS, XV, X, Y)
            pytest.fail(str(alias))
