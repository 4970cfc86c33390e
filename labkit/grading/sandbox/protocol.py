"""What crosses between the grader and a sandboxed notebook: plain numbers in tagged JSON, one object per line.

Tags: ``["f", x]``, ``["i", n]``, ``["none"]``, ``["s", text]``; ``["a", shape, base64 of <f8]`` (integers and
booleans as floats; complex and object arrays are not numbers); ``["t", [...]]`` and ``["l", [...]]``; a course
type of :data:`labkit.wire.TYPES` as its tag and its array fields (e.g. ``["mesh", points, quads]``, validated
by the table's ``rebuild``); a plot as the data of its lines, ``["lines", [[x, y, marker, linestyle], ...]]``,
so plots are judged from data on the grader's side. Towards the notebook only, a labkit function the exercises
declare passable, by name (``["fn", "labkit.piecewise:eval_pherm"]``, optionally with at most
:data:`MAX_KEYWORDS` finite float keywords bound): the notebook gets the watch's trusted copy. From the notebook
only, ``["obj", description]`` for anything else.

:func:`decode` trusts nothing: sizes, depth and shapes are checked, every number becomes a float64 array or a
float, anything else a :class:`NotNumbers` that fails every comparison. Nothing is unpickled or evaluated.
"""

import base64
import functools
import importlib
import json
import math
import os
import select
import signal
import sys
import time
import types

import numpy as np

from ... import wire

MAX_DEPTH = 12
# where a sandbox shows the course modules a rubric names (read-only); the worker puts it on the notebook's path
COURSE_FOLDER = "/opt/labkit-course"
COURSE_PATH = "LABKIT_COURSE_PATH"  # without a sandbox (the none backend): the folders of the course modules
MAX_ELEMENTS = 4_000_000  # numbers in one message (the lab's largest answer has a few thousand)
MAX_TEXT = 2_000
MAX_LINE = 48 * 1024 * 1024  # bytes in one message: enforced while reading, before any parsing
MAX_CONTAINERS = 250_000  # JSON lists and objects in one message: bounds what parsing it allocates
MAX_LINES = 1_000  # Line2D objects of one plot
MAX_KEYWORDS = 8  # float keywords bound to a function handed to student code


class ProtocolError(ValueError):
    """A message that is not in the format (sizes, tags, shapes)."""


class NotNumbers:
    """Stands for a value from the notebook that is not numbers; every check step on it fails."""

    not_numbers = True

    def __init__(self, description):
        self.description = str(description)[:MAX_TEXT]

    def __str__(self):
        return f"got {self.description}, not numbers"

    __repr__ = __str__


def _array_tag(value):
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf":
        kind = "complex numbers" if arr.dtype.kind == "c" else f"an array of {arr.dtype}"
        return ["obj", kind]
    if arr.size > MAX_ELEMENTS:
        return ["obj", f"an array of {arr.size} numbers (too large)"]
    data = np.ascontiguousarray(arr, dtype="<f8").tobytes()
    return ["a", list(arr.shape), base64.b64encode(data).decode("ascii")]


def encode(value, passable=frozenset(), depth=0):
    """Tagged plain form of a value (both sides); a function whose ``module:qualname`` is in `passable` by name."""
    if depth > MAX_DEPTH:
        return ["obj", "a value nested too deeply"]
    if value is None:
        return ["none"]
    if isinstance(value, (bool, np.bool_, float, np.floating)):  # booleans before int, their base class
        return ["f", float(value)]
    if isinstance(value, (int, np.integer)):
        number = int(value)
        return ["i", number] if abs(number) < 2**53 else ["f", float(number)]
    if isinstance(value, str):
        return ["s", value[:MAX_TEXT]]
    if isinstance(value, np.ndarray):
        return _array_tag(value)
    for row in wire.TYPES:
        if isinstance(value, row.kind()):
            return [row.tag] + [_array_tag(getattr(value, name)) for name in row.fields]
    if _is_plot(value):
        return _lines_tag(value)
    if callable(value) and f"{getattr(value, '__module__', '')}:{getattr(value, '__qualname__', '')}" in passable:
        return ["fn", f"{value.__module__}:{value.__qualname__}"]
    if type(value) is functools.partial and not value.args:
        bound = _bound(value.keywords)
        function = encode(value.func, passable, depth + 1)
        if bound is not None and function[0] == "fn" and len(function) == 2:
            return ["fn", function[1], bound]
    if type(value) in (tuple, list):
        return ["t" if type(value) is tuple else "l", [encode(item, passable, depth + 1) for item in value[:100_000]]]
    return ["obj", f"a {type(value).__name__} object"]


def _is_plot(value):
    """A matplotlib Axes or Figure (matplotlib is only imported if the notebook did)."""
    module = sys.modules.get("matplotlib.artist")
    return (
        module is not None
        and isinstance(value, module.Artist)
        and hasattr(value, "get_children")
        and (hasattr(value, "get_lines") or isinstance(getattr(value, "axes", None), list))
    )


def _lines_tag(plot):
    from ...plotdata import lines_of

    try:
        lines = lines_of(plot)
    except Exception as exc:  # noqa: BLE001 - a hostile artist
        return ["obj", f"a plot whose lines cannot be read ({type(exc).__name__})"]
    return [
        "lines",
        [[_array_tag(line.x), _array_tag(line.y), line.marker[:20], line.linestyle[:20]] for line in lines[:MAX_LINES]],
    ]


def _bound(keywords):
    """A partial's keywords as a dict, or None unless they are at most MAX_KEYWORDS finite floats."""
    if not isinstance(keywords, dict) or not 0 < len(keywords) <= MAX_KEYWORDS:
        return None
    bound = {}
    for key, value in keywords.items():
        if not (type(key) is str and key.isidentifier()) or type(value) not in (int, float):
            return None
        try:
            bound[key] = float(value)
        except OverflowError:  # an integer too large for a float
            return None
    return bound if all(map(math.isfinite, bound.values())) else None


def function_names(tags):
    """The names of every ``["fn", name]`` in encoded values (the functions a request hands over)."""
    found, todo = set(), list(tags)
    while todo:
        tag = todo.pop()
        if isinstance(tag, list) and tag:
            if tag[0] == "fn" and len(tag) in (2, 3) and isinstance(tag[1], str):
                found.add(tag[1])
            elif tag[0] in ("t", "l") and len(tag) == 2 and isinstance(tag[1], list):
                todo.extend(tag[1])
    return found


def dumps(message):
    """One line of JSON (NaN and infinities allowed: they are numbers a student may return)."""
    return (json.dumps(message, allow_nan=True, separators=(",", ":")) + "\n").encode("utf-8")


def passable(name):
    """The pristine labkit function a ``["fn", name]`` stands for (the watch copies it before any cell runs)."""
    module, _, attribute = str(name).partition(":")
    if not module.startswith("labkit.") or module.startswith("labkit.grading") or not attribute.isidentifier():
        raise ProtocolError(f"{name!r} is not a labkit function the checks may pass")
    found = getattr(importlib.import_module(module), attribute, None)
    if type(found) is not types.FunctionType or (found.__module__, found.__qualname__) != (module, attribute):
        raise ProtocolError(f"{name!r} is not a module-level labkit function the checks may pass")
    return found


def loads(line):
    """Parse one line (bytes); anything but a bounded JSON object is a ProtocolError. The bounds are checked before
    parsing: a line of nested empty lists would otherwise cost the parser some thirty times its size."""
    if len(line) > MAX_LINE:
        raise ProtocolError(f"a message of {len(line)} bytes is larger than {MAX_LINE}")
    containers = line.count(b"[") + line.count(b"{")
    if containers > MAX_CONTAINERS:
        raise ProtocolError(f"a message of {containers} lists and objects is more than {MAX_CONTAINERS}")
    try:
        message = json.loads(line)
    except (ValueError, RecursionError) as exc:
        raise ProtocolError(f"not JSON ({str(exc)[:100]})") from None
    if not isinstance(message, dict):
        raise ProtocolError("a message must be a JSON object")
    return message


def _array(tag):
    if len(tag) != 3 or not isinstance(tag[1], list) or not isinstance(tag[2], str):
        raise ProtocolError("malformed array")
    shape = tag[1]
    if len(shape) > 32 or not all(type(n) is int and 0 <= n <= MAX_ELEMENTS for n in shape):
        raise ProtocolError("malformed array shape")
    size = math.prod(shape)
    if size > MAX_ELEMENTS or len(tag[2]) != 4 * math.ceil(8 * size / 3):
        raise ProtocolError("array data does not match its shape")
    try:
        raw = base64.b64decode(tag[2], validate=True)
    except ValueError:
        raise ProtocolError("array data is not base64") from None
    return np.frombuffer(raw, dtype="<f8").astype(float).reshape(shape)


def _line(item):
    from ...plotdata import Line

    if not (
        isinstance(item, list)
        and len(item) == 4
        and all(isinstance(part, list) for part in item[:2])
        and all(isinstance(part, str) for part in item[2:])
    ):
        raise ProtocolError("malformed plotted line")
    x, y = _array(item[0]).ravel(), _array(item[1]).ravel()
    return Line(x, y, item[2][:20], item[3][:20])


def _course_type(row, parts):
    """A course type of :data:`labkit.wire.TYPES` from its tagged fields, or a NotNumbers saying why not."""
    fields = [_array(part) if isinstance(part, list) and part[:1] == ["a"] else None for part in parts]
    if any(f is None for f in fields):
        return NotNumbers(f"a {row.tag} with a field that is not numbers")
    try:
        return row.rebuild(*fields)
    except ValueError as exc:
        return NotNumbers(str(exc))


def decode(tag, depth=0, functions=None):
    """The value of a tagged form; on the notebook's side `functions` maps ``["fn", name]`` to those handed over."""
    if depth > MAX_DEPTH + 1:
        raise ProtocolError("nested too deeply")
    if not isinstance(tag, list) or not tag or not isinstance(tag[0], str):
        raise ProtocolError("malformed value")
    kind = tag[0]
    if kind == "f" and len(tag) == 2 and type(tag[1]) in (int, float):
        return float(tag[1])
    if kind == "i" and len(tag) == 2 and type(tag[1]) is int:
        return tag[1]
    if kind == "none":
        return None
    if kind == "s" and len(tag) == 2 and isinstance(tag[1], str):
        return tag[1][:MAX_TEXT]
    if kind == "a":
        return _array(tag)
    if kind in ("t", "l") and len(tag) == 2 and isinstance(tag[1], list):
        items = [decode(item, depth + 1, functions) for item in tag[1]]
        return tuple(items) if kind == "t" else items
    if kind in wire.BY_TAG and len(tag) == 1 + len(wire.BY_TAG[kind].fields):
        try:
            return _course_type(wire.BY_TAG[kind], tag[1:])
        except ProtocolError as exc:
            return NotNumbers(f"an invalid {kind} ({exc})")
    if kind == "lines" and len(tag) == 2 and isinstance(tag[1], list) and len(tag[1]) <= MAX_LINES:
        return [_line(item) for item in tag[1]]
    if kind == "obj" and len(tag) == 2 and isinstance(tag[1], str):
        return NotNumbers(tag[1])
    if kind == "fn" and functions is not None and len(tag) in (2, 3) and isinstance(tag[1], str):
        if tag[1] not in functions:
            raise ProtocolError(f"{tag[1]!r} was not handed over for this request")
        if len(tag) == 2:
            return functions[tag[1]]
        bound = _bound(tag[2])
        if bound is None:
            raise ProtocolError(f"the keywords bound to {tag[1]!r} are not at most {MAX_KEYWORDS} finite floats")
        return functools.partial(functions[tag[1]], **bound)
    raise ProtocolError(f"unknown value tag {kind!r}")


def write_all(fd, data):
    """Write all of `data` to the pipe `fd` (a write may take only part of it)."""
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def ended(signal_number, status):
    """How a notebook's process ended, in words: killed by `signal_number`, else exited with `status`."""
    if signal_number is not None:
        known = signal_number in signal.Signals._value2member_map_
        name = signal.Signals(signal_number).name if known else str(signal_number)
        return f"the notebook's process was killed by {name} (a resource limit, or os.kill)"
    return f"the notebook's process exited with status {status} (os._exit or a crash)"


class Lines:
    """Lines from a pipe, each at most `limit` bytes (a longer one is a ProtocolError)."""

    def __init__(self, fd, limit=MAX_LINE):
        self.fd, self.limit, self.buffer = fd, limit, b""

    def readline(self, until=None):
        """The next line (without its newline), None at the end, TimeoutError after `until` (monotonic)."""
        while b"\n" not in self.buffer:
            if until is not None:
                remaining = until - time.monotonic()
                if not select.select([self.fd], [], [], max(0.0, remaining))[0]:  # a last look when it has passed
                    raise TimeoutError()
            chunk = os.read(self.fd, 1 << 20)
            if not chunk:
                return None
            self.buffer += chunk
            if len(self.buffer) > self.limit:
                raise ProtocolError(f"a line longer than {self.limit} bytes")
        line, _, self.buffer = self.buffer.partition(b"\n")
        return line

    def available(self):
        """Every whole line that can be read now without waiting; ProtocolError when more piles up than `limit`."""
        while select.select([self.fd], [], [], 0)[0]:
            chunk = os.read(self.fd, 1 << 16)
            self.buffer += chunk
            if len(self.buffer) > self.limit:
                raise ProtocolError(f"more than {self.limit} bytes written to the grader's watch")
            if not chunk:
                break
        *lines, self.buffer = self.buffer.split(b"\n")
        return lines
