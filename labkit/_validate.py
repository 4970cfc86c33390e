"""Private input checks shared by every public function of labkit.

Each helper returns a float ndarray (never the caller's object when a copy
is needed) and raises ``ValueError`` with a message that names the argument,
says what is wrong and how to fix it.
"""
import numpy as np


def as_float_array(values, name):
    """Convert to a float ndarray, refusing complex, object or string input."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"{name} must be an array of real numbers; could not convert it ({exc})."
        ) from None
    return arr


def as_knots(xdata, name="xdata"):
    """Validate data abscissae: 1-D, at least 2, finite, strictly increasing."""
    x = as_float_array(xdata, name)
    if x.ndim != 1:
        raise ValueError(
            f"{name} must be a 1-D array; got an array of shape {x.shape}. "
            f"Pass a flat sequence such as np.ravel({name})."
        )
    if x.size < 2:
        raise ValueError(
            f"{name} needs at least 2 points to define an interval; got {x.size}."
        )
    # One comparison pass settles the common case: a NaN anywhere fails it,
    # and a strictly increasing array can only hold an infinity at its ends.
    if np.all(x[1:] > x[:-1]) and np.isfinite(x[0]) and np.isfinite(x[-1]):
        return x
    require_finite(x, name)
    k = np.flatnonzero(x[1:] <= x[:-1])[0]
    raise ValueError(
        f"{name} must be strictly increasing, but {name}[{k}] = {x[k]:g} and "
        f"{name}[{k + 1}] = {x[k + 1]:g}. Sort the data (np.argsort) and remove "
        "repeated points."
    )


def as_data(values, n, name, xname="xdata"):
    """Validate values attached to the n knots: 1-D, length n, finite."""
    v = as_float_array(values, name)
    if v.ndim != 1:
        raise ValueError(
            f"{name} must be a 1-D array; got an array of shape {v.shape}."
        )
    if v.size != n:
        raise ValueError(
            f"{name} has {v.size} entries but {xname} has {n}; give one value per "
            f"point of {xname}."
        )
    require_finite(v, name)
    return v


def as_scalar(value, name):
    """Validate a finite real number (an end slope, say)."""
    if value is None:
        raise ValueError(f"{name} is required: give the derivative at that end.")
    v = as_float_array(value, name)
    if v.ndim != 0:
        raise ValueError(f"{name} must be a single number; got shape {v.shape}.")
    require_finite(v, name)
    return float(v)


def require_finite(arr, name):
    if not np.all(np.isfinite(arr)):
        k = np.flatnonzero(~np.isfinite(np.ravel(arr)))[0]
        raise ValueError(
            f"{name} contains a non-finite value (NaN or inf) at flat index {k}; "
            "remove or replace it before interpolating."
        )


def as_points(xval, name="xval"):
    """Evaluation points: any shape, NaN allowed (it gives NaN out)."""
    return as_float_array(xval, name)


def scalar_or_array(result, template):
    """Return a Python-level scalar when the evaluation points were a scalar."""
    return result[()] if np.ndim(template) == 0 else result
