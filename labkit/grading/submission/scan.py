"""Reading a notebook's source, on the grader's side (``ast``; nothing is run): what a graded name reaches, the
refused references and unreadable ways of reaching code in it (:func:`scan`), and the graded functions' text
(:func:`function_sources`). Cell magics that run Python (``%%time``) are read as Python; other cells are skipped.
"""

import ast
import importlib.util
import re
import sys
import time

from ..sandbox.guard import _within
from ..store.text import MAX_SOURCE_CHARS

MAX_CODE_BYTES = 512 * 1024  # a lab notebook's code is a few tens of kilobytes
TIME_BUDGET = 20.0  # seconds to read one notebook's code

PYTHON_CELL_MAGICS = {"time", "timeit", "capture", "prun", "debug"}
# modules a graded function may reach without the scan asking what they are
KNOWN = {"numpy", "scipy", "math", "cmath", "labkit", "matplotlib", "functools", "itertools", "operator", "abc"}
KNOWN |= {"collections", "numbers", "fractions", "decimal", "statistics", "typing", "dataclasses", "warnings", "enum"}
KNOWN |= {"bisect", "heapq", "copy"}
DYNAMIC_NAMES = {name: name for name in ("__import__", "eval", "exec", "compile", "setattr", "delattr", "breakpoint")}
DYNAMIC_NAMES |= {"globals": "globals()", "vars": "vars()", "locals": "locals()"}
DYNAMIC_NAMES["get_ipython"] = "get_ipython() (the shell's own namespace)"
STRING_RUNNERS = {"exec", "eval", "compile"}
DYNAMIC_ATTRIBUTES = {"__code__", "__closure__", "__globals__", "__builtins__", "__dict__", "__subclasses__"}
DYNAMIC_ATTRIBUTES |= {"__func__", "__wrapped__", "f_back", "f_locals", "f_globals", "gi_frame", "tb_frame", "cr_frame"}
DYNAMIC_MODULES = {"importlib", "ctypes", "cffi", "gc", "inspect", "marshal", "pickle", "dill", "builtins", "imp"}
DYNAMIC_MODULES |= {"pkgutil", "runpy", "code", "codeop", "threading", "_thread", "multiprocessing", "subprocess"}
DYNAMIC_MODULES.add("signal")
DYNAMIC_DOTTED = {"sys.modules", "sys._getframe", "sys.setprofile", "sys.getprofile", "sys.settrace", "sys.gettrace"}
DYNAMIC_DOTTED |= {"sys._current_frames", "types.FunctionType", "types.CodeType", "os.system", "os.fork"}
DYNAMIC_DOTTED |= {"os.popen", "os.exec", "os.spawn"}


class Unreadable(ValueError):
    """The notebook's code is too large, or too slow, to be read within the scan's budget."""


def python_source(cell):
    """A code cell as Python: IPython's magics and shell escapes become ``pass`` (line numbers kept); None to skip."""
    lines = cell.split("\n")
    first = next((i for i, line in enumerate(lines) if line.strip()), None)
    if first is not None and lines[first].lstrip().startswith("%%"):
        magic = lines[first].lstrip()[2:].split(maxsplit=1)
        if not magic or magic[0] not in PYTHON_CELL_MAGICS:
            return None
        lines[first] = ""
    out = []
    for line in lines:
        stripped = line.lstrip()
        if stripped.startswith(("%", "!")):
            out.append(line[: len(line) - len(stripped)] + "pass")
        else:
            out.append(re.sub(r"=\s*[%!].*$", "= None", line) if re.search(r"=\s*[%!]\w", line) else line)
    return "\n".join(out)


class _Reader:
    """The notebook's top-level definitions and import aliases, and the walk from a graded name."""

    def __init__(self, sources, deadline):
        self.deadline, self.texts, self.aliases, self.definitions = deadline, {}, {}, {}
        self.when, self.strings = {}, []  # where each name was last bound; where a string is run as code
        self.statements = []  # the top-level statements that are not definitions (plots are drawn there)
        for cell, source in enumerate(sources):
            text = python_source(source)
            if text is None:
                continue
            self._tick()
            try:
                tree = ast.parse(text)
            except (SyntaxError, ValueError, RecursionError, MemoryError):
                continue  # IPython could not run it either: it defines nothing
            for node in _top_level(tree.body):
                self.texts[node] = text
            for node in tree.body:
                self._record(node, (cell, node.lineno))
                self.strings += [(cell, node.lineno, what) for what in _runs_strings(node, self.definitions)]
                if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                    self.statements.append(node)

    def _tick(self):
        if time.monotonic() > self.deadline:
            raise Unreadable(f"reading the notebook's code took more than {TIME_BUDGET:g} s")

    def _record(self, node, where):
        """Top-level names, bound at `where` (cell, line): the last definition wins, as when the cells run in order."""
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            for local, dotted in _imported(node):
                self.aliases[local] = dotted
                self.definitions.pop(local, None)
        elif isinstance(node, (ast.If, ast.For, ast.While, ast.With, ast.Try)):
            for child in ast.iter_child_nodes(node):
                if isinstance(child, ast.stmt):
                    self._record(child, where)
        else:
            for name in _bound_names(node):
                self.definitions[name], self.when[name] = node, where
                self.aliases.pop(name, None)

    def reached(self, name, stop=frozenset()):
        """(name, node, its local names) of every definition `name`'s reaches (not through those in `stop`)."""
        seen, todo, found = set(), [name], []
        while todo:
            current = todo.pop()
            if current in seen or current not in self.definitions or (current in stop and current != name):
                continue
            seen.add(current)
            node = self.definitions[current]
            local = _locals(node)
            found.append((current, node, local))
            for inner in ast.walk(node):
                self._tick()
                if isinstance(inner, ast.Name) and isinstance(inner.ctx, ast.Load) and inner.id in self.definitions:
                    if inner.id not in seen and inner.id not in local:
                        todo.append(inner.id)
        return found


def _runs_strings(node, definitions=None):
    """How a top-level statement, or a function of the notebook (`definitions`) it calls, runs a string it builds
    as code: ``exec``, ``eval`` or ``compile`` of anything but a literal (``exec(zlib.decompress(...))``)."""
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return []
    found = []
    for inner in ast.walk(node):
        by_name = isinstance(inner, ast.Call) and isinstance(inner.func, ast.Name) and definitions
        called = definitions.get(inner.func.id) if by_name else None
        if isinstance(called, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found += [f"{what} (in {called.name})" for what in _runs_strings(ast.Module(called.body, []))]
    literal = set()  # the runners called on a literal string; ast.walk meets a call before its function's name
    for inner in ast.walk(node):
        if isinstance(inner, ast.Call) and inner.args and isinstance(inner.args[0], ast.Constant):
            if isinstance(inner.args[0].value, str):
                literal.add(id(inner.func))
        elif isinstance(inner, ast.Name) and inner.id in STRING_RUNNERS and id(inner) not in literal:
            found.append(inner.id)
    return found


def run_strings(sources, names):
    """Findings ``(name, line, reason)`` for each graded name that a top-level ``exec`` of a built string may have
    defined (no readable binding after it): code that arrives in a string cannot be read, so it is never graded."""
    reader = _reader(sources)
    findings = []
    for name in names:
        bound = reader.when.get(name, (-1, 0)) if name in reader.definitions else (-1, 0)  # (cell, line)
        late = [(c, line, what) for c, line, what in reader.strings if (c, line) >= bound]
        for cell, line, what in late[:1]:
            reason = (
                f"code cell {cell + 1} (line {line}) runs a string built at run time as code ({what}), after "
                f"the last definition of {name} the grader can read, so it may define {name}: code that "
                "arrives in a string cannot be read, so it is not graded"
            )
            findings.append((name, line, reason))
    return findings


def reached_sources(sources, names, stop=frozenset()):
    """``[(name, source text)]`` of every definition the graded `names` reach (themselves first) as :func:`scan`
    follows them, not through the names in `stop`; :class:`Unreadable` as :func:`scan` raises it.

    Examples
    --------
    >>> cells = ["def h(x):\\n    return x + 1", "def f(x):\\n    return h(x) * 2", "def g(x):\\n    return 0"]
    >>> [name for name, _ in reached_sources(cells, ["f"])]
    ['f', 'h']
    """
    reader = _reader(sources)
    found, seen = [], set()
    for name in names:
        for owner, node, _ in reader.reached(name, frozenset(stop)):
            if node in seen or node not in reader.texts:
                continue
            seen.add(node)
            first = min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])])
            lines = reader.texts[node].split("\n")[first - 1 : node.end_lineno]
            found.append((owner, "\n".join(lines)))  # whole: a long comment must not push the code out
    return found


def code_bytes(sources):
    """The bytes of a notebook's code cells (as UTF-8)."""
    return sum(len(str(s).encode("utf-8", "surrogatepass")) for s in sources)


def drawn_with(sources, names):
    """The definitions `names` reach, and those the statements mentioning them reach (``ax.plot(my_eval(t))``).

    Examples
    --------
    >>> cells = ["def h(x):\\n    return x", "fig, ax = 1, 2", "ax.plot(h(3))", "def g(x):\\n    return 0"]
    >>> sorted(drawn_with(cells, ["ax"]) & {"ax", "g", "h"})
    ['ax', 'h']
    """
    reader = _reader(sources)
    wanted, found, starts = set(names), set(), list(names)
    for node in reader.statements:
        loaded = {n.id for n in ast.walk(node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
        if loaded & wanted:
            starts += sorted(loaded & set(reader.definitions))
            found.update(loaded)  # a name bound where the reader cannot see (exec) counts too
    for name in starts:
        found.update(owner for owner, _, _ in reader.reached(name))
    return found


def _locals(node):
    """The names a function definition (and the functions inside it) binds for itself: not the notebook's."""
    if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
        return set()
    bound, declared = set(), set()
    for inner in ast.walk(node):
        if isinstance(inner, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            arguments = inner.args
            every = arguments.posonlyargs + arguments.args + arguments.kwonlyargs + [arguments.vararg, arguments.kwarg]
            bound.update(arg.arg for arg in every if arg is not None)
            if inner is not node and not isinstance(inner, ast.Lambda):
                bound.add(inner.name)
        elif isinstance(inner, ast.Name) and isinstance(inner.ctx, (ast.Store, ast.Del)):
            bound.add(inner.id)
        elif isinstance(inner, (ast.Global, ast.Nonlocal)):
            declared.update(inner.names)
        elif isinstance(inner, (ast.Import, ast.ImportFrom)):
            bound.update(local for local, _ in _imported(inner))
    return bound - declared


def _imported(node):
    """(local name, dotted name) of each name an import binds."""
    for alias in node.names:
        if isinstance(node, ast.Import):
            top = alias.name.split(".")[0]
            yield (alias.asname or top), (alias.name if alias.asname else top)
        elif node.module and not node.level:
            yield (alias.asname or alias.name), f"{node.module}.{alias.name}"
        else:  # a relative import: a module the notebook wrote itself
            yield (alias.asname or alias.name), f".{node.module or ''}.{alias.name}"


def _dotted(node, aliases):
    """The dotted name an attribute chain spells, aliases resolved (``getattr(m, "name")`` is ``m.name``)."""
    parts = []
    while isinstance(node, ast.Attribute) or _constant_getattr(node):
        part, node = (node.attr, node.value) if isinstance(node, ast.Attribute) else (node.args[1].value, node.args[0])
        parts.append(part)
    if not isinstance(node, ast.Name) or node.id not in aliases:
        return None
    return ".".join([aliases[node.id]] + parts[::-1])


def _constant_getattr(node):
    """Whether `node` is ``getattr(value, "name")`` (or with a default): an attribute written as a string."""
    name = node.args[1] if _getattr_call(node) and len(node.args) <= 3 and not node.keywords else None
    return isinstance(name, ast.Constant) and isinstance(name.value, str) and name.value.isidentifier()


def _getattr_call(node):
    """Whether `node` calls ``getattr`` with an object and a name."""
    function = node.func if isinstance(node, ast.Call) else None
    return isinstance(function, ast.Name) and function.id == "getattr" and len(node.args) >= 2


class _Refused:
    """What one refusal refuses, as the scan asks it: a module prefix, or a known spelling of a refused object."""

    def __init__(self, profile):
        self.modules = tuple(profile["modules"])
        self.spellings = dict(profile["spellings"])  # dotted spelling -> the refused object's own name
        self.allowed = set(profile["allowed"])
        self.submodules = set(profile.get("submodules", ()))  # the refused modules themselves, as loaded

    def chain(self, dotted):
        """Why a whole attribute chain is refused (its longest refused prefix), or None: also when a longer prefix
        is an allowed helper (``labkit.piecewise.bracket``, however ``labkit.piecewise`` is reached)."""
        while dotted:
            if dotted in self.allowed:
                return None
            if dotted in self.spellings:
                own = self.spellings[dotted]
                return dotted if own == dotted else f"{own} (as {dotted})"
            if _within(dotted, self.modules):
                return dotted
            dotted = dotted.rpartition(".")[0]
        return None


def _dynamic(node, aliases):
    """A way of reaching code that the scan cannot follow, written at `node`, or None."""
    if isinstance(node, ast.Name) and node.id in DYNAMIC_NAMES and node.id not in aliases:
        return DYNAMIC_NAMES[node.id]
    if isinstance(node, ast.Attribute) and node.attr in DYNAMIC_ATTRIBUTES:
        return node.attr
    if _getattr_call(node) and not isinstance(node.args[1], ast.Constant):
        return "getattr with a computed name"
    if isinstance(node, (ast.Name, ast.Attribute)):
        dotted = _dotted(node, aliases)
        if dotted:
            top = dotted.split(".")[0]
            if dotted.startswith("."):
                return f"a module of the notebook's own ({dotted.lstrip('.')})"
            if top in DYNAMIC_MODULES or dotted.startswith(tuple(DYNAMIC_DOTTED)):
                return dotted
            if top not in KNOWN and not _installed(top):
                return f"{dotted} (a module the notebook wrote itself?)"
    return None


def _installed(top):
    """Whether a top-level module is the standard library's or installed here (found, never imported)."""
    if top in sys.stdlib_module_names:
        return True
    try:
        return importlib.util.find_spec(top) is not None
    except (ImportError, ValueError):
        return False


def scan(sources, names, profile):
    """Findings ``(function, line, reference)``: where the graded `names`, or what they reach, name a reference
    that `profile` (one refusal, as :func:`.refusals.wire` gives it) switches off, or reach for code in a way the
    scan cannot follow. Raises :class:`Unreadable` past :data:`MAX_CODE_BYTES` or :data:`TIME_BUDGET`."""
    if profile is None:
        return []
    reader = _reader(sources)
    refused, findings = _Refused(profile), set()
    for name in names:
        for owner, definition, own_names in reader.reached(name):
            local = {k: v for k, v in reader.aliases.items() if k not in own_names}
            start = getattr(definition, "lineno", 1)
            # the inner links of an attribute chain are judged with the whole chain (``pw`` in ``pw.bracket``)
            inner = set()
            for node in ast.walk(definition):
                reader._tick()
                if isinstance(node, ast.Attribute):
                    inner.add(id(node.value))
                elif _constant_getattr(node):
                    inner.add(id(node.args[0]))
                elif isinstance(node, (ast.Import, ast.ImportFrom)):
                    for alias_name, dotted in _imported(node):
                        local[alias_name] = dotted
                        # a refused module imported is judged by its uses (``pw.bracket`` is allowed)
                        why = (None if dotted in refused.submodules else refused.chain(dotted)) or (
                            dotted.split(".")[0] if dotted.split(".")[0] in DYNAMIC_MODULES else None
                        )
                        if why:
                            findings.add((owner, node.lineno - start + 1, why))
            outside = {k: v for k, v in local.items() if k not in reader.definitions}
            for node in ast.walk(definition):
                reader._tick()
                what = None
                if isinstance(node, (ast.Name, ast.Attribute, ast.Call)) and id(node) not in inner:
                    dotted = _dotted(node, outside)
                    what = refused.chain(dotted) if dotted else None
                what = what or _dynamic(node, outside)
                if what:
                    findings.add((owner, getattr(node, "lineno", start) - start + 1, what))
    # an attribute chain reports itself and its prefixes: keep the longest on each line
    prefixes = {f for f in findings for g in findings if g[:2] == f[:2] and g[2] != f[2] and g[2].startswith(f[2])}
    return sorted(findings - prefixes)


_READERS: dict = {}


def _reader(sources):
    """The notebook's :class:`_Reader` (the last one kept), reading for :data:`TIME_BUDGET` from now;
    :class:`Unreadable` past :data:`MAX_CODE_BYTES`."""
    sources, deadline = tuple(sources), time.monotonic() + TIME_BUDGET
    size = code_bytes(sources)
    if size > MAX_CODE_BYTES:
        raise Unreadable(
            f"the notebook's code cells hold {size:,} bytes, more than the {MAX_CODE_BYTES:,} a lab notebook needs"
        )
    found = _READERS.get(sources)
    if found is None:
        _READERS.clear()
        found = _READERS[sources] = _Reader(sources, deadline)
    found.deadline = deadline
    return found


def function_sources(sources, names):
    """``{name: source}``, from its first decorator to its last line (at most :data:`MAX_SOURCE_CHARS`, whole lines),
    of the last top-level ``def`` of each of `names` in a notebook's code cells (parsed, never run).

    A definition counts where the cells, run in order, leave it bound (a later assignment or import drops it; a
    cell that does not parse defines nothing). Nothing at all past :data:`MAX_CODE_BYTES`.

    Examples
    --------
    >>> cells = ["import numpy as np", "def f(x):\\n    return 2 * x\\n\\nf(1)", "def g(:"]
    >>> function_sources(cells, ["f", "g", "h"])
    {'f': 'def f(x):\\n    return 2 * x'}
    """
    wanted = set(names)
    if not wanted or code_bytes(sources) > MAX_CODE_BYTES:
        return {}
    found = {}
    for cell in sources:
        lines = str(cell).replace("\r\n", "\n").replace("\r", "\n").split("\n")
        text = python_source("\n".join(lines))
        if text is None:
            continue
        try:
            nodes = list(_top_level(ast.parse(text).body))
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            continue
        for node in nodes:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if node.name in wanted:
                    first = min([node.lineno] + [d.lineno for d in node.decorator_list])
                    found[node.name] = _clip("\n".join(lines[first - 1 : node.end_lineno]))
            else:
                for bound in _bound_names(node):
                    found.pop(bound, None)
    return found


def reached_function_sources(sources, names, graded=()):
    """:func:`function_sources` of `names`, each followed by the helpers it reaches (other `graded` names aside), so
    code moved into a helper is compared where the graded function uses it.

    Examples
    --------
    >>> cells = ["def h(x):\\n    return x + 1", "def f(x):\\n    return h(x) * 2"]
    >>> print(reached_function_sources(cells, ["f"])["f"])
    def f(x):
        return h(x) * 2
    <BLANKLINE>
    def h(x):
        return x + 1
    """
    found = function_sources(sources, names)
    for name, text in found.items():
        try:
            helpers = [t for n, t in reached_sources(sources, [name], stop=set(graded))[1:] if n != name]
        except Unreadable:
            continue
        found[name] = _clip("\n\n".join([text, *helpers]))
    return found


def _top_level(body):
    """The statements a cell runs at its top level, those inside top-level compound statements included."""
    for node in body:
        yield node
        if isinstance(node, (ast.If, ast.For, ast.AsyncFor, ast.While, ast.With, ast.AsyncWith, ast.Try)):
            inner = [node.body, getattr(node, "orelse", []), getattr(node, "finalbody", [])]
            inner += [handler.body for handler in getattr(node, "handlers", [])]
            for block in inner:
                yield from _top_level(block)


def _bound_names(node):
    """The names a top-level statement binds."""
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        return [local for local, _ in _imported(node)]
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return [node.name]
    if isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        return [n.id for target in targets for n in ast.walk(target) if isinstance(n, ast.Name)]
    return []


def _clip(text):
    """At most :data:`MAX_SOURCE_CHARS` characters of `text`: whole lines while they fit."""
    if len(text) <= MAX_SOURCE_CHARS:
        return text
    cut = text[:MAX_SOURCE_CHARS]
    return cut[: cut.rindex("\n")] if "\n" in cut else cut
