"""What a definition does, written one way: the syntax-tree normalisation applied before code is fingerprinted.

Winnowing (:mod:`labkit.grading.submission.known`) compares runs of tokens,
so anything a copier inserts at a finer grain than a run defeats it: a dead
assignment after every statement, attributes read as ``getattr(obj,
"name")``, functions moved into a class as staticmethods. :func:`canonical`
parses a definition with :mod:`ast` (nothing is run) and writes it back
with those differences taken out:

* docstrings, statements with no effect (a bare name or constant, ``pass``)
  and dead stores (a name assigned in a function and never read there, or
  assigned to itself) go;
* ``getattr(x, "name")`` becomes ``x.name``; ``x += y`` becomes ``x = x + y``;
* every comprehension and ``list(generator)`` becomes a list comprehension;
* ``staticmethod``/``classmethod`` decorators go, and an attribute of a class
  the notebook uses as a namespace (``Tools.bracket``, ``cls.bracket``) is
  read as the plain name.

:func:`units` splits what a graded part reaches into the units compared one
by one: a class's methods each alone (so a container never dilutes a match),
and trivial wrappers (one call handed on) left out.
"""

from __future__ import annotations

import ast
import textwrap

UNWRAPPED = {"staticmethod", "classmethod"}
SELF = {"self", "cls"}


def parse(text):
    """The syntax tree of `text` (indentation removed), or None when it is not Python."""
    try:
        return ast.parse(textwrap.dedent(str(text)))
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return None


def canonical(text, namespaces=frozenset()):
    """`text` written back from its normalised syntax tree; `text` itself when it does not parse.

    `namespaces` are names of the notebook's classes: ``Name.attr`` of one of them is read as ``attr``.

    Examples
    --------
    >>> text = "def f(x):\\n    '''Doc.'''\\n    _ = None\\n    y = getattr(x, 'size')\\n    y += 1\\n    return y"
    >>> print(canonical(text))
    def f(x):
        y = x.size
        return y + 1
    >>> print(canonical("def g(v):\\n    return Tools.h(v) + sum(w for w in v)", {"Tools"}))
    def g(v):
        return h(v) + sum([w for w in v])
    """
    tree = parse(text)
    if tree is None:
        return str(text)
    try:
        tree = ast.fix_missing_locations(_Canon(frozenset(namespaces)).visit(tree))
        return ast.unparse(tree)
    except (RecursionError, ValueError, TypeError, AttributeError):
        return str(text)


class _Canon(ast.NodeTransformer):
    """The rewrites :func:`canonical` makes, node by node."""

    def __init__(self, namespaces):
        self.namespaces = namespaces | SELF

    def visit_FunctionDef(self, node):
        node.decorator_list = [d for d in node.decorator_list if not _named(d, UNWRAPPED)]
        self.generic_visit(node)
        node.body = _pruned(_as_comprehensions(node.body), _read_names(node)) or [ast.Pass()]
        return node

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_ClassDef(self, node):
        self.generic_visit(node)
        node.body = [s for s in node.body if not _no_effect(s)] or [ast.Pass()]
        return node

    def visit_Module(self, node):
        self.generic_visit(node)
        node.body = [s for s in node.body if not _no_effect(s)]
        return node

    def visit_Call(self, node):
        self.generic_visit(node)
        if _named(node.func, {"getattr"}) and len(node.args) == 2 and not node.keywords and _identifier(node.args[1]):
            return ast.Attribute(value=node.args[0], attr=node.args[1].value, ctx=ast.Load())
        if _named(node.func, {"list"}) and len(node.args) == 1 and isinstance(node.args[0], ast.ListComp):
            return node.args[0]
        return node

    def visit_Attribute(self, node):
        self.generic_visit(node)
        if isinstance(node.value, ast.Name) and node.value.id in self.namespaces:
            return ast.copy_location(ast.Name(id=node.attr, ctx=node.ctx), node)
        return node

    def visit_AugAssign(self, node):
        self.generic_visit(node)
        if not isinstance(node.target, ast.Name):
            return node
        value = ast.BinOp(left=ast.Name(id=node.target.id, ctx=ast.Load()), op=node.op, right=node.value)
        return ast.copy_location(ast.Assign(targets=[node.target], value=value), node)

    def visit_GeneratorExp(self, node):
        self.generic_visit(node)
        return ast.copy_location(ast.ListComp(elt=node.elt, generators=node.generators), node)

    visit_SetComp = visit_GeneratorExp


def _named(node, names):
    return isinstance(node, ast.Name) and node.id in names


def _identifier(node):
    return isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value.isidentifier()


def _read_names(function):
    """Every name a function reads, in itself and the functions inside it."""
    return {n.id for n in ast.walk(function) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


def _no_effect(statement):
    """A statement that does nothing: a bare constant (a docstring), a bare name, ``pass``."""
    if isinstance(statement, ast.Pass):
        return True
    return isinstance(statement, ast.Expr) and isinstance(statement.value, (ast.Constant, ast.Name))


def _dead(statement, read):
    """An assignment to plain names that are never read, or a name assigned to itself."""
    if not isinstance(statement, (ast.Assign, ast.AnnAssign)):
        return False
    targets = statement.targets if isinstance(statement, ast.Assign) else [statement.target]
    if not all(isinstance(t, ast.Name) for t in targets):
        return False
    if isinstance(statement.value, ast.Name) and all(t.id == statement.value.id for t in targets):
        return True
    return all(t.id not in read for t in targets)


def _pruned(body, read):
    """A function body without its statements of no effect and its dead stores (nested blocks too)."""
    kept = []
    for statement in body:
        if _no_effect(statement) or _dead(statement, read):
            continue
        for field in ("body", "orelse", "finalbody"):
            block = getattr(statement, field, None)
            if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
                setattr(statement, field, _pruned(block, read) or [ast.Pass()])
        kept.append(statement)
    return kept


def _as_comprehensions(body):
    """A block with its accumulating loops written as the comprehensions they equal, nested blocks too:
    ``xs = []`` then ``for v in it: xs.append(e)`` (or ``if c: xs.append(e)``) is ``xs = [e for v in it (if c)]``,
    and ``s = 0`` then ``for v in it: s = s + e`` is ``s = sum([e for v in it])``; a value named only to be
    returned is returned (``y = e`` then ``return y`` is ``return e``)."""
    kept: list = []
    for statement in body:
        for field in ("body", "orelse", "finalbody"):
            block = getattr(statement, field, None)
            if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
                setattr(statement, field, _as_comprehensions(block))
        folded = _folded(kept[-1], statement) if kept else None
        if folded is not None:
            kept[-1] = ast.copy_location(folded, kept[-1])
        else:
            kept.append(statement)
    return _returned(kept)


def _returned(block):
    """`block` with ``name = e`` then ``return name`` at its end written ``return e``."""
    if len(block) >= 2 and isinstance(block[-1], ast.Return) and isinstance(block[-1].value, ast.Name):
        last = block[-2]
        if isinstance(last, ast.Assign) and len(last.targets) == 1 and _named(last.targets[0], {block[-1].value.id}):
            return block[:-2] + [ast.copy_location(ast.Return(value=last.value), last)]
    return block


def _folded(start, loop):
    """``name = <comprehension>`` for a start value and the loop that fills it, or None when they are not one."""
    if not (isinstance(start, ast.Assign) and len(start.targets) == 1 and isinstance(start.targets[0], ast.Name)):
        return None
    if not isinstance(loop, ast.For) or loop.orelse or len(loop.body) != 1:
        return None
    name, step, conditions = start.targets[0].id, loop.body[0], []
    if isinstance(step, ast.If) and not step.orelse and len(step.body) == 1:
        conditions, step = [step.test], step.body[0]
    element = _appended(step, name) if isinstance(start.value, ast.List) and not start.value.elts else None
    total = _added(step, name) if _zero(start.value) and element is None else None
    if element is None and total is None:
        return None
    generator = ast.comprehension(target=loop.target, iter=loop.iter, ifs=conditions, is_async=0)
    made = ast.ListComp(elt=element if element is not None else total, generators=[generator])
    value = made if element is not None else ast.Call(func=ast.Name(id="sum", ctx=ast.Load()), args=[made], keywords=[])
    return ast.Assign(targets=[ast.Name(id=name, ctx=ast.Store())], value=value)


def _appended(step, name):
    """`e` of ``name.append(e)``, else None."""
    call = step.value if isinstance(step, ast.Expr) else None
    if isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute) and call.func.attr == "append":
        if _named(call.func.value, {name}) and len(call.args) == 1 and not call.keywords:
            return call.args[0]
    return None


def _added(step, name):
    """`e` of ``name = name + e`` (``name += e`` is already written so), else None."""
    if isinstance(step, ast.Assign) and len(step.targets) == 1 and _named(step.targets[0], {name}):
        value = step.value
        if isinstance(value, ast.BinOp) and isinstance(value.op, ast.Add) and _named(value.left, {name}):
            return value.right
    return None


def _zero(node):
    return isinstance(node, ast.Constant) and type(node.value) in (int, float) and node.value == 0


# -- the units a part's code is compared in -------------------------------------------------------------------


def units(definitions):
    """``[(name, canonical text)]``: a part's definitions as :func:`canonical` writes them, a class's methods
    each on its own and trivial wrappers left out (they hand a call on, so the code is where they point).

    Examples
    --------
    >>> box = "class K:\\n    @staticmethod\\n    def g(x):\\n        return x * x + 1"
    >>> found = units([("f", "def f(x):\\n    return K.g(x)"), ("K", box)])
    >>> [name for name, _ in found]
    ['K.g']
    """
    definitions = list(definitions)
    namespaces = set()
    for _, text in definitions:
        tree = parse(text)
        if tree is not None:
            namespaces.update(n.name for n in tree.body if isinstance(n, ast.ClassDef))
    namespaces = frozenset(namespaces)
    found = []
    for name, text in definitions:
        found.extend(_split(name, text, namespaces))
    return found


def _split(name, text, namespaces):
    tree = parse(canonical(text, namespaces))
    if tree is None:
        return [(name, str(text))]
    pieces = []
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            methods = [m for m in node.body if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef))]
            pieces += [(f"{node.name}.{m.name}", m) for m in methods if not _trivial(m)]
        elif not _trivial(node):
            pieces.append((name, node))
    return [(label, ast.unparse(node)) for label, node in pieces]


def _trivial(node):
    """A function that only hands its arguments on: at most one conversion, then ``return call(...)``."""
    if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) or len(node.body) > 2:
        return False
    last = node.body[-1]
    if not (isinstance(last, ast.Return) and isinstance(last.value, ast.Call)):
        return False
    arithmetic = [n for n in ast.walk(last.value) if isinstance(n, ast.BinOp)]
    return not arithmetic and (len(node.body) == 1 or isinstance(node.body[0], ast.Assign))
