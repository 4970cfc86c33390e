"""Reference implementations a graded function may not call: switched off at run time, found in source."""
import numpy as np
import pytest
import scipy.interpolate

import labkit
from labkit.checks import exercises, hermite
from labkit.grading.refusals import RefusedReference, scan, switched_off

X, Y, YP = np.array([0.0, 1.0, 3.0]), np.array([1.0, -1.0, 2.0]), np.array([0.0, 2.0, -1.0])
XV = np.linspace(-0.5, 3.5, 9)


def test_every_alias_of_a_refused_function_raises_and_is_restored_after():
    captured = labkit.eval_pherm  # taken before grading, as a student's `from labkit import ...` would
    from labkit.piecewise import eval_pherm as deep
    expected = scipy.interpolate.CubicHermiteSpline(X, Y, YP)(XV)
    with switched_off(["labkit.eval_pherm"]) as attempts:
        for alias in (captured, deep, labkit.eval_pherm):
            with pytest.raises(RefusedReference, match="labkit.eval_pherm is switched off"):
                alias(X, Y, YP, XV)
        assert attempts == ["labkit.eval_pherm"] * 3
    assert np.allclose(captured(X, Y, YP, XV), expected)


def test_a_refused_class_raises_through_aliases_and_classmethods():
    Hermite = scipy.interpolate.CubicHermiteSpline
    with switched_off(exercises.EXERCISES[2].refused) as attempts:
        with pytest.raises(RefusedReference, match="CubicHermiteSpline"):
            Hermite(X, Y, YP)
        with pytest.raises(RefusedReference, match="BPoly"):
            scipy.interpolate.BPoly.from_derivatives(X, np.c_[Y, YP])
        try:  # caught by the student's code: still logged
            scipy.interpolate.CubicSpline(X, Y)
        except RefusedReference:
            pass
        assert attempts[-1] == "scipy.interpolate.CubicSpline"
        assert labkit.bracket(X, XV).tolist() == np.clip(np.searchsorted(X, XV, "right") - 1, 0, 1).tolist()
    assert np.allclose(Hermite(X, Y, YP)(XV), labkit.eval_pherm(X, Y, YP, XV))
    assert "__init__" not in scipy.interpolate.CubicHermiteSpline.__dict__ or \
        scipy.interpolate.CubicHermiteSpline.__init__.__name__ == "__init__"


def test_a_student_eval_pherm_built_on_the_allowed_helpers_is_graded_as_usual():
    def eval_pherm(xdata, ydata, ypdata, xval):
        k = labkit.bracket(xdata, xval)
        xdata, ydata, ypdata, xval = map(np.asarray, (xdata, ydata, ypdata, xval))
        a, b, t = xdata[k], xdata[k + 1], np.asarray(xval, float)
        h = b - a
        s = (t - a) / h
        return (ydata[k] * (1 + 2 * s) * (1 - s) ** 2 + ypdata[k] * h * s * (1 - s) ** 2
                + ydata[k + 1] * s**2 * (3 - 2 * s) + ypdata[k + 1] * h * s**2 * (s - 1))

    def in_the_sandbox(*args):  # as the worker calls it: references off during the call only
        with switched_off(exercises.EXERCISES[2].refused) as attempts:
            value = eval_pherm(*args)
        assert attempts == []
        return value

    assert hermite.eval_pherm(in_the_sandbox, seed=3).passed


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
    found = scan(sources, ["eval_pherm"], exercises.EXERCISES[2].refused)
    assert ("eval_pherm", 4, "scipy.interpolate.CubicHermiteSpline") in found
    assert ("helper", 2, "labkit.eval_pherm") in found
    assert all(name != "labkit.bracket" for *_, name in found)
    assert scan(sources, ["runge"], exercises.EXERCISES[3].refused) == [("runge", 2, "labkit.runge")]


def test_scan_leaves_a_students_own_function_of_the_same_name_alone():
    sources = ["from labkit import eval_pherm\n", "def eval_pherm(xdata, ydata, ypdata, xval):\n"
               "    return 0 * xval if len(xdata) > 2 else eval_pherm(xdata[:2], ydata, ypdata, xval)"]
    assert scan(sources, ["eval_pherm"], exercises.EXERCISES[2].refused) == []
    assert scan(sources, ["eval_pherm"], ()) == []
