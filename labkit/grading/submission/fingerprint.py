"""The one fingerprinting engine (winnowing, Schleimer, Wilkerson and Aiken 2003; nothing is ever run), for known
code in a graded part (:mod:`.known`) and classmates' similar code (:mod:`labkit.grading.reports.similarity`), each
with its own corpus and threshold. What the student release gives everyone (:func:`release_grams`) is never evidence."""

from __future__ import annotations

import ast
import functools
import textwrap

import numpy as np

NOISE = 25  # normalised characters hashed together: a shorter shared run is never evidence
WINDOW = 6  # winnowing window: a shared run of NOISE + WINDOW - 1 = 30 characters always shares a fingerprint
POWERS = np.uint64(1_000_003) ** np.arange(NOISE - 1, -1, -1, dtype=np.uint64)  # wraps modulo 2**64, as hashes do


def parse(text):
    """The syntax tree of `text` (indentation removed), or None when it is not Python."""
    try:
        return ast.parse(textwrap.dedent(str(text)))
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return None


def canonical(text, namespaces=frozenset()):
    """`text` written back from its normalised syntax tree (itself if it does not parse): no docstrings, dead
    stores or ``staticmethod``; ``getattr(x, "name")`` is ``x.name``, ``x += y`` ``x = x + y``, accumulating
    loops and generators list comprehensions, and ``Name.attr`` of one of the `namespaces` ``attr``.

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
        return ast.unparse(ast.fix_missing_locations(_Canon(frozenset(namespaces)).visit(tree)))
    except (RecursionError, ValueError, TypeError, AttributeError):
        return str(text)


class _Canon(ast.NodeTransformer):
    """The rewrites :func:`canonical` makes, node by node."""

    def __init__(self, namespaces):
        self.namespaces = namespaces | {"self", "cls"}

    def visit_FunctionDef(self, node):
        node.decorator_list = [d for d in node.decorator_list if not _named(d, {"staticmethod", "classmethod"})]
        self.generic_visit(node)
        body = _as_comprehensions(node.body)
        read = {n.id for n in ast.walk(node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
        node.body = _pruned(body, read) or [ast.Pass()]
        return node

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_ClassDef(self, node):  # and a module
        self.generic_visit(node)
        node.body = [s for s in node.body if not _no_effect(s)]
        if isinstance(node, ast.ClassDef) and not node.body:
            node.body = [ast.Pass()]
        return node

    visit_Module = visit_ClassDef

    def visit_Call(self, node):
        self.generic_visit(node)
        if _named(node.func, {"getattr"}) and len(node.args) == 2 and not node.keywords:
            attr = node.args[1].value if isinstance(node.args[1], ast.Constant) else None
            if isinstance(attr, str) and attr.isidentifier():
                return ast.Attribute(value=node.args[0], attr=attr, ctx=ast.Load())
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


def _no_effect(statement):
    """A bare constant (a docstring), a bare name, ``pass``."""
    expression = statement.value if isinstance(statement, ast.Expr) else None
    return isinstance(statement, ast.Pass) or isinstance(expression, (ast.Constant, ast.Name))


def _dead(statement, read):
    """An assignment to plain names that are never read, or a name assigned to itself."""
    if not isinstance(statement, (ast.Assign, ast.AnnAssign)):
        return False
    targets = statement.targets if isinstance(statement, ast.Assign) else [statement.target]
    if not all(isinstance(t, ast.Name) for t in targets):
        return False
    itself = isinstance(statement.value, ast.Name) and all(t.id == statement.value.id for t in targets)
    return itself or all(t.id not in read for t in targets)


def _blocks(statement):
    """(field, block) of each block of statements inside `statement` (a loop's body, an if's else)."""
    for field in ("body", "orelse", "finalbody"):
        block = getattr(statement, field, None)
        if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
            yield field, block


def _pruned(body, read):
    """`body` without statements of no effect and dead stores, nested blocks too."""
    kept = []
    for statement in body:
        if not (_no_effect(statement) or _dead(statement, read)):
            for field, block in _blocks(statement):
                setattr(statement, field, _pruned(block, read) or [ast.Pass()])
            kept.append(statement)
    return kept


def _as_comprehensions(body):
    """`body` with loops folded (:func:`_folded`), nested blocks too, and ``y = e; return y`` as ``return e``."""
    kept: list = []
    for statement in body:
        for field, block in _blocks(statement):
            setattr(statement, field, _as_comprehensions(block))
        folded = _folded(kept[-1], statement) if kept else None
        if folded is not None:
            kept[-1] = ast.copy_location(folded, kept[-1])
        else:
            kept.append(statement)
    if len(kept) >= 2 and isinstance(kept[-1], ast.Return) and isinstance(kept[-1].value, ast.Name):
        last = kept[-2]
        if isinstance(last, ast.Assign) and len(last.targets) == 1 and _named(last.targets[0], {kept[-1].value.id}):
            return kept[:-2] + [ast.copy_location(ast.Return(value=last.value), last)]
    return kept


def _folded(start, loop):
    """``xs = [e for v in it if c]`` for ``xs = []`` and ``for v in it: (if c:) xs.append(e)``, ``s = sum([e for v
    in it])`` for ``s = 0`` and ``for v in it: s = s + e``; else None."""
    match start, loop:
        case ast.Assign(targets=[ast.Name(id=name)], value=first), ast.For(body=[step], orelse=[]):
            conditions = []
        case _:
            return None
    if isinstance(step, ast.If) and not step.orelse and len(step.body) == 1:
        conditions, step = [step.test], step.body[0]
    generator = ast.comprehension(target=loop.target, iter=loop.iter, ifs=conditions, is_async=0)
    match first, step:
        case ast.List(elts=[]), ast.Expr(
            value=ast.Call(func=ast.Attribute(value=ast.Name(id=owner), attr="append"), args=[element], keywords=[])
        ) if owner == name:
            value = ast.ListComp(elt=element, generators=[generator])
        case ast.Constant(value=zero), ast.Assign(
            targets=[ast.Name(id=owner)], value=ast.BinOp(left=ast.Name(id=left), op=ast.Add(), right=element)
        ) if type(zero) in (int, float) and zero == 0 and owner == left == name:
            made = ast.ListComp(elt=element, generators=[generator])
            value = ast.Call(func=ast.Name(id="sum", ctx=ast.Load()), args=[made], keywords=[])
        case _:
            return None
    return ast.Assign(targets=[ast.Name(id=name, ctx=ast.Store())], value=value)


def units(definitions):
    """``[(name, canonical text)]`` of a part's definitions, a class's methods each on its own, trivial wrappers
    left out (the code is where they point).

    >>> box = "class K:\\n    @staticmethod\\n    def g(x):\\n        return x * x + 1"
    >>> found = units([("f", "def f(x):\\n    return K.g(x)"), ("K", box)])
    >>> [name for name, _ in found]
    ['K.g']
    """
    definitions = list(definitions)
    trees = [tree for _, text in definitions if (tree := parse(text)) is not None]
    namespaces = frozenset(n.name for tree in trees for n in tree.body if isinstance(n, ast.ClassDef))
    found = []
    for name, text in definitions:
        tree = parse(canonical(text, namespaces))
        if tree is None:
            found.append((name, str(text)))
            continue
        for node in tree.body:
            if isinstance(node, ast.ClassDef):
                methods = [m for m in node.body if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef))]
                found += [(f"{node.name}.{m.name}", ast.unparse(m)) for m in methods if not _trivial(m)]
            elif not _trivial(node):
                found.append((name, ast.unparse(node)))
    return found


def _trivial(node):
    """A function that only hands its arguments on: at most one conversion, then ``return call(...)``."""
    if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) or len(node.body) > 2:
        return False
    last = node.body[-1]
    if not (isinstance(last, ast.Return) and isinstance(last.value, ast.Call)):
        return False
    arithmetic = [n for n in ast.walk(last.value) if isinstance(n, ast.BinOp)]
    return not arithmetic and (len(node.body) == 1 or isinstance(node.body[0], ast.Assign))


def normalise(text):
    """``(normalised, where)``: `text`'s tokens with a name ``V`` (a function's ``F``, a class's ``O``), a string
    ``S``, no comments, docstrings, white space or round brackets; and the index in `text` of each character.

    >>> normalise("def area(w, h):\\n    '''Doc.'''\\n    return w * h  # cm2")[0]
    'defFV,V:returnV*V'
    >>> normalise("y = np.searchsorted(x, 'a')")[0]
    'V=V.searchsortedV,S'
    """
    out, where, previous = [], [], None
    for start, kind, value in _lexer().get_tokens_unprocessed(str(text)):
        piece = _written(kind)
        # a formatter adds and drops round brackets; adjacent strings are one
        if piece == "" or value in ("(", ")") or (piece == "S" and previous == "S"):
            continue
        piece = value if piece is None or (piece == "V" and previous == ".") else piece
        out.append(piece)
        where.extend(range(start, start + len(piece)) if piece == value else [start])
        previous = piece
    return "".join(out), np.asarray(where, dtype=np.int64)


@functools.cache
def _lexer():
    from pygments import lexers

    return lexers.get_lexer_by_name("python")


@functools.cache
def _written(kind):
    """How :func:`normalise` writes a token of this kind: "" left out, a letter, or None as itself."""
    from pygments import token

    if kind in token.Text or kind in token.Comment or kind in token.String.Doc:
        return ""
    kinds = {"S": token.String, "F": token.Name.Function, "O": token.Name.Class}
    found = next((letter for letter, of in kinds.items() if kind in of), None)
    if found is None and kind in token.Name and not (kind in token.Name.Builtin or kind in token.Name.Exception):
        return "V"
    return found


def kgrams(normalised):
    """The hash of every run of :data:`NOISE` characters of a normalised text (the same in every process)."""
    codes = np.frombuffer(str(normalised).encode("utf-32-le"), dtype=np.uint32).astype(np.uint64)
    if codes.size < NOISE:
        return np.zeros(0, dtype=np.uint64)
    return np.lib.stride_tricks.sliding_window_view(codes, NOISE) @ POWERS


def fingerprints(normalised):
    """``(hashes, positions)``: the winnowed fingerprints of a normalised text, in order of position (a shared
    run of ``NOISE + WINDOW - 1`` characters always shares one).

    >>> hashes, positions = fingerprints("V=V+1" * 20)
    >>> bool(len(hashes)) and bool(np.all(np.diff(positions) > 0))
    True
    >>> fingerprints("V=1")[0].size  # shorter than NOISE: nothing to fingerprint
    0
    """
    grams = kgrams(normalised)
    if grams.size == 0:
        return grams, np.zeros(0, dtype=np.int64)
    width = min(WINDOW, grams.size)
    windows = np.lib.stride_tricks.sliding_window_view(grams, width)
    chosen = np.unique(np.arange(windows.shape[0]) + (width - 1 - np.argmin(windows[:, ::-1], axis=1)))
    return grams[chosen], chosen


def release_grams(cells, rewrite=canonical):
    """Every :data:`NOISE`-character hash of the release `cells`, written by `rewrite` (all: a cut stub leaves none)."""
    found = [kgrams(normalise(rewrite(cell))[0]) for cell in cells]
    return np.unique(np.concatenate(found)) if found else np.zeros(0, dtype=np.uint64)


def own(text, given):
    """``(where, hashes, positions)``: :func:`normalise`'s `where`, and `text`'s fingerprints not `given`."""
    normalised, where = normalise(text)
    hashes, positions = fingerprints(normalised)
    mine = ~np.isin(hashes, given)
    return where, hashes[mine], positions[mine]


def coverage(positions, has):
    """For each row of `has` (which fingerprints at sorted `positions` count), the characters they cover."""
    spots = np.asarray(positions, dtype=float)
    at = np.where(has, spots, np.inf)
    after = np.minimum.accumulate(at[:, ::-1], axis=1)[:, ::-1]  # the first counted position from each on
    following = np.concatenate([after[:, 1:], np.full((len(has), 1), np.inf)], axis=1)
    return np.where(has, np.minimum(NOISE, following - spots), 0.0).sum(axis=1)


def shared_lines(text, where, positions):
    """The 0-based numbers of `text`'s lines that a fingerprint at one of `positions` covers."""
    marks = np.zeros(len(where) + NOISE + 1, dtype=np.int64)
    np.add.at(marks, positions, 1)
    np.add.at(marks, np.asarray(positions) + NOISE, -1)
    covered = where[np.cumsum(marks)[: len(where)] > 0]
    starts = np.cumsum([0] + [len(line) + 1 for line in text.split("\n")[:-1]])
    return sorted(set((np.searchsorted(starts, covered, side="right") - 1).tolist()))
