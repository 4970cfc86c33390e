"""Reference implementations a graded function may not call: switched off at run time, named in its source.

Each exercise lists its refused references (:attr:`labkit.checks.exercises.Exercise.refused`),
for example ``labkit.eval_pherm`` and scipy's cubic interpolants for
exercise 2. Two things use the list:

* inside the sandbox, :func:`switched_off` replaces each reference while the
  grader calls the exercise's function: a Python function gets the code of
  a stub (so every alias of it, ``from labkit import eval_pherm as ref``
  included, is caught), a class gets a stub ``__init__``; the stub raises
  :class:`RefusedReference` naming the call, and the attempt is logged even
  if the student's code catches the error;
* on the grader's side, :func:`scan` reads the notebook's source (``ast``,
  nothing is run) and names the references a graded function, or a
  function of the notebook it calls, reaches for.
"""
import ast
import functools
import importlib
from contextlib import contextmanager

_MISSING = object()
_attempts = []  # refused names called during the current graded call (the sandbox's side)


class RefusedReference(RuntimeError):
    """A graded function called a reference implementation that its exercise asks the student to write."""

    def __init__(self, name):
        super().__init__(f"{name} is switched off while this exercise is graded: "
                         "the exercise asks you to write it yourself")
        self.refused = name


def refuse(name):
    """What every stub does: log the attempt and raise."""
    _attempts.append(name)
    raise RefusedReference(name)


def _resolve(dotted):
    """(object, module, attribute) for 'package.module.Name', or None if it does not exist here."""
    module_name, _, attribute = dotted.rpartition(".")
    try:
        module = importlib.import_module(module_name)
    except ImportError:
        return None
    obj = getattr(module, attribute, _MISSING)
    return None if obj is _MISSING else (obj, module, attribute)


def _stub_code(name):
    namespace = {}
    exec(f"def stub(*args, **kwargs):\n    import labkit.grading.refusals as _r\n    _r.refuse({name!r})\n",
         namespace)
    return namespace["stub"].__code__


def _stub_init(name):
    def __init__(self, *args, **kwargs):
        refuse(name)
    return __init__


@contextmanager
def switched_off(refused):
    """Within the block every reference in `refused` raises RefusedReference; yields the attempt log."""
    undo = []
    _attempts.clear()
    try:
        for name in refused:
            found = _resolve(name)
            if found is None:
                continue
            obj, module, attribute = found
            if isinstance(obj, type):
                before = obj.__dict__.get("__init__", _MISSING)
                obj.__init__ = _stub_init(name)
                undo.append(lambda cls=obj, before=before: (setattr(cls, "__init__", before) if before is not _MISSING
                                                             else delattr(cls, "__init__")))
            elif hasattr(obj, "__code__") and not obj.__code__.co_freevars:
                code = obj.__code__
                obj.__code__ = _stub_code(name)
                undo.append(lambda fn=obj, code=code: setattr(fn, "__code__", code))
            else:  # a compiled function: only the module attribute can be replaced
                setattr(module, attribute, lambda *args, _name=name, **kwargs: refuse(_name))
                undo.append(lambda module=module, attribute=attribute, obj=obj: setattr(module, attribute, obj))
        yield _attempts
    finally:
        for restore in reversed(undo):
            restore()


# -- the grader's side: reading the source --------------------------------------------

def spellings(refused):
    """Every dotted name under which each refused reference can be written: {spelling: name}."""
    names = {}
    for name in refused:
        names[name] = name
        found = _resolve(name)
        if found is not None:
            defining = getattr(found[0], "__module__", None)
            if defining:
                names[f"{defining}.{found[2]}"] = name
    return names


@functools.lru_cache(maxsize=4096)
def _parse(source):
    """The ast of a notebook cell (IPython magics turned into Python first), or None.

    Cached: the grader scans the same cells once per exercise. The trees are only read."""
    try:
        from IPython.core.inputtransformer2 import TransformerManager

        source = TransformerManager().transform_cell(source)
    except Exception:  # noqa: BLE001 - a cell IPython cannot read is simply not scanned
        pass
    try:
        return ast.parse(source)
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return None


def _dotted(node, aliases):
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name) or node.id not in aliases:
        return None
    return ".".join([aliases[node.id]] + parts[::-1])


def scan(sources, names, refused):
    """Findings ``(function, line, reference)``: where the functions `names` of a notebook,
    or notebook functions they call, name a refused reference."""
    if not refused:
        return []
    spelled = spellings(refused)
    trees = [tree for tree in map(_parse, sources) if tree is not None]
    aliases, functions = {}, {}
    for tree in trees:
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    local = alias.asname or alias.name.split(".")[0]
                    aliases[local] = alias.name if alias.asname else local
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                for alias in node.names:
                    aliases[alias.asname or alias.name] = f"{node.module}.{alias.name}"
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                functions[node.name] = node
    findings, seen, todo = [], set(), [n for n in names if n in functions]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        for node in ast.walk(functions[name]):
            if isinstance(node, ast.Name) and node.id in functions and node.id not in seen:
                todo.append(node.id)
            if isinstance(node, (ast.Name, ast.Attribute)):
                dotted = _dotted(node, {k: v for k, v in aliases.items() if k not in functions})
                while dotted:
                    if dotted in spelled:
                        findings.append((name, node.lineno - functions[name].lineno + 1, spelled[dotted]))
                        break
                    dotted = dotted.rpartition(".")[0]
    return sorted(set(findings))
