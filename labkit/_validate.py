"""Private input checks shared by every public function of labkit.

Each helper returns a float ndarray (never the caller's object when a copy
is needed) and raises ``ValueError`` with a message that names the argument,
says what is wrong and how to fix it.
"""

import numpy as np

from .errors import InputError

_NOT_NUMBERS = {
    "c": "complex numbers (the imaginary parts would be lost): interpolate the real and imaginary parts "
    "separately, e.g. with {name}.real and {name}.imag",
    "b": "booleans (True/False), not numbers: if you mean 0 and 1, convert on purpose with "
    "np.asarray({name}, dtype=float)",
    "U": "text, not numbers: convert it first, e.g. np.asarray({name}, dtype=float)",
    "S": "text, not numbers: convert it first, e.g. np.asarray({name}, dtype=float)",
    "M": "dates, not numbers: convert them to numbers first (e.g. seconds since a start time)",
    "m": "time spans, not numbers: convert them to numbers first (e.g. / np.timedelta64(1, 's'))",
    "V": "records, not numbers: pass one field as an array of numbers",
}


def _refuse(name, kind):
    raise InputError(f"{name} holds {_NOT_NUMBERS[kind].format(name=name)}.")


def _check_object_item(item, name):
    """An element of an object array: a real number, or a ValueError saying what it is."""
    if item is None:
        raise InputError(f"{name} holds None where a number should be: fill in the value or drop that point.")
    for kind, types in (("c", (complex, np.complexfloating)), ("b", (bool, np.bool_)), ("U", (str, bytes))):
        if isinstance(item, types):
            _refuse(name, kind)
    try:
        float(item)
    except (TypeError, ValueError):
        raise InputError(
            f"{name} holds a {type(item).__name__} object where a number should be; give real numbers only."
        ) from None


def as_float_array(values, name):
    """Convert to a float ndarray, refusing what is not real numbers.

    Complex numbers, booleans, text, dates, None and other objects raise a
    ValueError that names the argument and says how to convert it on
    purpose; nothing is cast silently.
    """
    if values is None:
        raise InputError(f"{name} is None: give an array of real numbers.")
    try:
        arr = np.asarray(values)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be an array of real numbers; could not read it ({exc}).") from None
    kind = arr.dtype.kind
    if kind in _NOT_NUMBERS:
        _refuse(name, kind)
    if kind == "O":
        for item in arr.flat:
            _check_object_item(item, name)
    if arr.dtype == np.float64:
        return arr
    try:
        return arr.astype(float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{name} must be an array of real numbers; could not convert it ({exc}).") from None


def as_order(der, highest):
    """A derivative order: a whole number from 0 to `highest`."""
    if isinstance(der, (bool, np.bool_)) or not isinstance(der, (int, np.integer)) or not 0 <= der <= highest:
        raise InputError(f"der must be a whole number from 0 (the values) to {highest}; got {der!r}.")
    return int(der)


def as_knots(xdata, name="xdata"):
    """Validate data abscissae: 1-D, at least 2, finite, strictly increasing."""
    x = as_float_array(xdata, name)
    if x.ndim != 1:
        raise InputError(
            f"{name} must be a 1-D array; got an array of shape {x.shape}. "
            f"Pass a flat sequence such as np.ravel({name})."
        )
    if x.size < 2:
        raise InputError(f"{name} needs at least 2 points to define an interval; got {x.size}.")
    # One comparison pass settles the common case: a NaN anywhere fails it,
    # and a strictly increasing array can only hold an infinity at its ends.
    if np.all(x[1:] > x[:-1]) and np.isfinite(x[0]) and np.isfinite(x[-1]):
        return x
    require_finite(x, name)
    k = np.flatnonzero(x[1:] <= x[:-1])[0]
    raise InputError(
        f"{name} must be strictly increasing, but {name}[{k}] = {x[k]:g} and "
        f"{name}[{k + 1}] = {x[k + 1]:g}. Sort the data (np.argsort) and remove "
        "repeated points."
    )


def as_data(values, n, name, xname="xdata"):
    """Validate values attached to the n knots: 1-D, length n, finite."""
    v = as_float_array(values, name)
    if v.ndim != 1:
        raise InputError(f"{name} must be a 1-D array; got an array of shape {v.shape}.")
    if v.size != n:
        raise InputError(f"{name} has {v.size} entries but {xname} has {n}; give one value per point of {xname}.")
    require_finite(v, name)
    return v


def as_scalar(value, name):
    """Validate a finite real number (an end slope, say)."""
    if value is None:
        raise InputError(f"{name} is None, but it is required: give a number.")
    v = as_float_array(value, name)
    if v.ndim != 0:
        raise InputError(f"{name} must be a single number; got shape {v.shape}.")
    require_finite(v, name)
    return float(v)


def as_positive_scalar(value, name, what):
    """Validate one positive finite number (a scale); `what` says what it is, for the message."""
    v = as_scalar(value, name)
    if not v > 0:
        raise InputError(f"{name} is {what}; got {v}. Give a number above 0.")
    return v


def require_finite(arr, name):
    if not np.all(np.isfinite(arr)):
        k = np.flatnonzero(~np.isfinite(np.ravel(arr)))[0]
        raise InputError(
            f"{name} contains a non-finite value (NaN or inf) at flat index {k}; "
            "remove or replace it before interpolating."
        )


def as_points(xval, name="xval"):
    """Evaluation points: any shape, NaN allowed (it gives NaN out)."""
    return as_float_array(xval, name)


def scalar_or_array(result, template):
    """Return a Python-level scalar when the evaluation points were a scalar."""
    return result[()] if np.ndim(template) == 0 else result
