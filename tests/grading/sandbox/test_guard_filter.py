"""The machine-code filter in front of the watch's profile hook (labkit.grading.sandbox.guard._call_filter): the
hook sees every call of a Python function, exactly as ``sys.setprofile`` reports them, and nothing else, but the
calls of the code objects in the filter's table (those the watch found clean in a request)."""

import json
import platform
import subprocess
import sys

import pytest

# run in a fresh process: a profile function set through the C API would also watch pytest
PROBE = """
import ctypes, json, math, sys
from labkit.grading.sandbox import guard

def work():
    def f(a, b):
        return 1.0 / (1.0 + (a + b) ** 2)
    class Box:
        def value(self):
            return f(1.0, 2.0)
    total = []
    for k in range(50):
        total.append(max(abs(f(k, 0.5)), math.cos(k)))
        try:
            Box().value() + int("x")
        except ValueError:
            pass
    return sum(total), list(map(abs, range(3)))

seen = {}
def hook(obj, frame, what, arg):
    seen[what] = seen.get(what, 0) + 1
    if what == 0:
        seen.setdefault("names", []).append(frame.f_code.co_name)
    return 0

kind = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.py_object, ctypes.c_int, ctypes.c_void_p)
callback = kind(hook)
set_profile = ctypes.pythonapi.PyEval_SetProfile
set_profile.argtypes, set_profile.restype = (ctypes.c_void_p, ctypes.c_void_p), None
plain = ctypes.cast(callback, ctypes.c_void_p).value
address, table, keep = guard._call_filter(plain) if sys.argv[1] != "plain" else (plain, None, None)
if sys.argv[1] == "cached":  # f's code found clean: the filter passes over its calls
    f_code = next(c for c in work.__code__.co_consts if getattr(c, "co_name", "") == "f")
    table[(id(f_code) >> 4) & (guard.SLOTS - 1)] = id(f_code)

reference = []
def python_profile(frame, event, arg):
    if event == "call":
        reference.append(frame.f_code.co_name)
sys.setprofile(python_profile)
expected = work()
sys.setprofile(None)

set_profile(address, None)
got = work()
set_profile(None, None)
names = seen.pop("names", [])
print(json.dumps({"filtered": address != plain, "events": seen, "names": names, "reference": reference,
                  "same": got == expected}))
"""


def _probe(mode):
    out = subprocess.run([sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True, timeout=60)
    return json.loads(out.stdout)


@pytest.mark.skipif(
    platform.machine() != "x86_64" or sys.version_info[:2] != (3, 11), reason="the filter is for x86-64 CPython 3.11"
)
def test_the_filter_passes_every_python_call_and_nothing_else():
    filtered, plain = _probe("filtered"), _probe("plain")
    assert filtered["filtered"] and filtered["same"] and plain["same"]
    # every Python call, in order, as sys.setprofile reports them (functions and methods)
    assert filtered["names"] == filtered["reference"] and filtered["names"].count("f") == 100
    assert set(filtered["events"]) == {"0"}  # (JSON's keys are text) 'call' events only
    # without the filter the hook also gets every return and every call and return of a built-in (max, abs, cos)
    assert plain["names"] == plain["reference"]
    assert sum(plain["events"].values()) > 4 * sum(filtered["events"].values())
    cached = _probe("cached")
    assert cached["same"] and cached["names"] == [n for n in cached["reference"] if n != "f"]
