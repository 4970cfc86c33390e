"""Working with very large or very small numbers: a frame scaled by powers of two.

Every interpolant here is covariant under x -> b x and y -> c y: scale the
knots and values, interpolate, scale the answer back (a k-th derivative by
c / b**k). With b and c powers of two the scaling is exact, so the answer is
the same to the last bit wherever no intermediate result overflowed, and
knots anywhere from 1e-300 to 1e308 (or values likewise) are computed
without overflow: differences like ``x[-1] - x[0]``, sums of intervals and
the cubic's powers stay in range. Ordinary magnitudes skip the scaling.

When the answer itself lies beyond the float range (slopes of data that
rise by 1 over an interval of 1e-320, a cubic evaluated far outside its
data), :meth:`Frame.result` and :meth:`Frame.knot_slopes` raise a
ValueError that says so, instead of returning inf or NaN.
"""

import numpy as np

from .errors import InputError

LIMIT = 200  # binary exponents beyond +-LIMIT (about 1e+-60) are scaled


def _exponent(magnitude):
    """e with magnitude in [2**(e-1), 2**e); 0 for zero or non-finite input."""
    magnitude = float(magnitude)
    return int(np.frexp(magnitude)[1]) if 0 < magnitude < np.inf else 0


class Frame:
    """Knots `x` and values `y` (validated, finite) in a frame where both are near 1 in size."""

    def __init__(self, x, y):
        ex = _exponent(max(abs(x[0]), abs(x[-1])))
        ey = _exponent(max(y.max(), -y.min())) if y.size else 0  # two reductions, no temporary
        self.scaled = abs(ex) > LIMIT or abs(ey) > LIMIT
        self.ex, self.ey = (ex, ey) if self.scaled else (0, 0)
        self.knots = np.ldexp(x, -self.ex) if self.scaled else x
        self.values = np.ldexp(y, -self.ey) if self.scaled else y
        self._x = x

    def points(self, xv):
        """Evaluation points in the frame."""
        return np.ldexp(xv, -self.ex) if self.scaled else xv

    def slopes(self, yp):
        """Slopes dy/dx in the frame."""
        return np.ldexp(yp, self.ex - self.ey) if self.scaled else yp

    def result(self, values, der, points):
        """Values (or the der-th derivative) computed in the frame, back in the data's units.

        Raises ValueError if one of them is beyond the float range at a finite point.
        """
        if self.scaled:
            values = np.ldexp(values, self.ey - der * self.ex)
        if values.size and not (np.isfinite(values.min()) and np.isfinite(values.max())):
            bad = ~np.isfinite(values) & np.isfinite(points)
            if np.any(bad):
                where = float(np.ldexp(np.asarray(points)[bad].flat[0], self.ex))
                what = "value" if der == 0 else f"derivative of order {der}"
                raise InputError(
                    f"the interpolant's {what} at xval = {where:g} is beyond the float range; "
                    "evaluate nearer to the data, or rescale xdata and ydata."
                )
        return values

    def knot_slopes(self, slopes, name):
        """Knot slopes computed in the frame, back in the data's units; ValueError if they overflow."""
        with np.errstate(all="ignore"):
            slopes = np.ldexp(slopes, self.ey - self.ex) if self.scaled else slopes
        if not np.all(np.isfinite(slopes)):
            gaps = np.diff(self._x)
            k = int(np.argmin(gaps))
            raise InputError(
                f"the {name} slopes are beyond the float range: the data change too fast for their spacing "
                f"(the smallest interval is xdata[{k + 1}] - xdata[{k}] = {gaps[k]:g}). Rescale ydata, or "
                "merge points that are this close."
            )
        return slopes
