"""labkit's own code as a copier pastes it into a notebook: rewritten mechanically, or only stripped of its
docstrings. Built from labkit's installed source with ``ast``, so the copies follow the library as it changes."""

import ast
import importlib
import inspect


def _docstring(body):
    first = body[0] if body else None
    return isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str)


class _Renamer(ast.NodeTransformer):
    """Every local name of one function renamed (q0, q1, ...), its docstring gone, a dummy first statement."""

    def __init__(self, dummy):
        self.names, self.dummy = {}, dummy

    def visit_FunctionDef(self, node):
        bound = {a.arg for a in ast.walk(node.args) if isinstance(a, ast.arg)}
        bound |= {n.id for n in ast.walk(node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        saved = dict(self.names)
        for name in sorted(bound):
            self.names.setdefault(name, f"q{len(self.names)}")
        body = node.body[1:] if _docstring(node.body) else node.body
        node.body = ([ast.parse("_ = None").body[0]] if self.dummy else []) + (body or [ast.Pass()])
        self.generic_visit(node)
        self.names = saved
        return node

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_arg(self, node):
        node.arg = self.names.get(node.arg, node.arg)
        return node

    def visit_Name(self, node):
        node.id = self.names.get(node.id, node.id)
        return node


def module_source(name, rename=True, drop=()):
    """The source of labkit module `name` as one cell: its docstrings gone, relative imports made absolute,
    imports from the modules in `drop` left out, and with `rename` every function's locals renamed and a
    dummy first statement in each (a copy by hand: nothing of labkit's left but the code's shape)."""
    module = importlib.import_module(name)
    tree = ast.parse(inspect.getsource(module))
    body = []
    for node in tree.body[1:] if _docstring(tree.body) else tree.body:
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.__package__.split(".")
                node.module = ".".join(base[: len(base) - node.level + 1] + ([node.module] if node.module else []))
                node.level = 0
            if node.module == "__future__" or node.module in drop:
                continue
        body.append(node)
    tree.body = body
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and _docstring(node.body):
            node.body = node.body[1:] or [ast.Pass()]
    for node in tree.body:
        functions = [node] if isinstance(node, ast.FunctionDef) else []
        functions += [
            n for n in getattr(node, "body", []) if isinstance(node, ast.ClassDef) and isinstance(n, ast.FunctionDef)
        ]
        for function in functions:
            if rename:
                _Renamer(dummy=True).visit(function)
    return ast.unparse(tree)


def renamed_cells(cells):
    """Code cells with every function's locals renamed, docstrings gone and a dummy first statement in each
    function (cells that do not parse as Python are kept as they are)."""
    found = []
    for cell in cells:
        try:
            tree = ast.parse(cell)
        except SyntaxError:
            found.append(cell)
            continue
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                _Renamer(dummy=True).visit(node)
        found.append(ast.unparse(tree))
    return found


# -- one further mechanical rewrite of a copy (issue 47): each defeats a comparison of token runs --------------


def _functions(tree):
    return [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]


def dead_stores(cell):
    """A dead assignment after every statement of every function (``z7 = 7``)."""
    tree = ast.parse(cell)
    count = 0
    for function in _functions(tree):
        for node in [function, *ast.walk(function)]:
            for field in ("body", "orelse"):
                block = getattr(node, field, None)
                if not (isinstance(block, list) and block and isinstance(block[0], ast.stmt)):
                    continue
                padded = []
                for statement in block:
                    count += 1
                    filler = ast.parse(f"z{count} = {count}").body[0]
                    padded += [filler, statement] if isinstance(statement, ast.Return) else [statement, filler]
                setattr(node, field, padded)
    return ast.unparse(ast.fix_missing_locations(tree))


class _Getattr(ast.NodeTransformer):
    def visit_Attribute(self, node):
        self.generic_visit(node)
        if not isinstance(node.ctx, ast.Load):
            return node
        call = ast.Call(ast.Name("getattr", ast.Load()), [node.value, ast.Constant(node.attr)], [])
        return ast.copy_location(call, node)


def getattr_reads(cell):
    """Every attribute read spelled ``getattr(obj, "name")``."""
    return ast.unparse(ast.fix_missing_locations(_Getattr().visit(ast.parse(cell))))


def staticmethods(cell, box="Tools"):
    """Every top-level function a staticmethod of one class, called through it; each graded name bound after."""
    tree = ast.parse(cell)
    functions = [n for n in tree.body if isinstance(n, ast.FunctionDef)]
    names = {f.name for f in functions}

    class Through(ast.NodeTransformer):
        def visit_Name(self, node):
            if node.id in names and isinstance(node.ctx, ast.Load):
                return ast.copy_location(ast.Attribute(ast.Name(box, ast.Load()), node.id, ast.Load()), node)
            return node

    for function in functions:
        Through().visit(function)
        function.decorator_list.insert(0, ast.Name("staticmethod", ast.Load()))
    rest = [n for n in tree.body if not isinstance(n, ast.FunctionDef)]
    holder = ast.ClassDef(name=box, bases=[], keywords=[], body=functions, decorator_list=[], type_params=[])
    bound = [ast.parse(f"{name} = {box}.{name}").body[0] for name in sorted(names)]
    tree.body = rest + [holder] + bound
    return ast.unparse(ast.fix_missing_locations(tree))


def exec_compressed(cell):
    """The code compressed into a string and ``exec``'d at the top level of the notebook."""
    import base64
    import zlib

    packed = base64.b64encode(zlib.compress(cell.encode())).decode()
    return f"import base64, zlib\nexec(zlib.decompress(base64.b64decode('{packed}')).decode())"


class _Loops(ast.NodeTransformer):
    """``name = [e for v in it if c]`` written out as ``name = []`` and a loop that appends."""

    def generic_visit(self, node):
        super().generic_visit(node)
        for field in ("body", "orelse"):
            block = getattr(node, field, None)
            if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
                setattr(node, field, [new for statement in block for new in self._written_out(statement)])
        return node

    @staticmethod
    def _written_out(statement):
        value = getattr(statement, "value", None)
        if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1 and isinstance(value, ast.ListComp)):
            return [statement]
        if not isinstance(statement.targets[0], ast.Name) or len(value.generators) != 1:
            return [statement]
        name, generator = statement.targets[0].id, value.generators[0]
        if len(generator.ifs) > 1 or generator.is_async:
            return [statement]
        step = ast.parse(f"{name}.append(ELEMENT)").body[0]
        step.value.args = [value.elt]
        body = [ast.If(test=generator.ifs[0], body=[step], orelse=[])] if generator.ifs else [step]
        loop = ast.For(target=generator.target, iter=generator.iter, body=body, orelse=[])
        return [ast.parse(f"{name} = []").body[0], loop]


def loops(cell):
    """Every list built by a comprehension built by a loop that appends instead."""
    return ast.unparse(ast.fix_missing_locations(_Loops().visit(ast.parse(cell))))


REWRITES = {"dead-stores": dead_stores, "getattr": getattr_reads, "staticmethods": staticmethods, "loops": loops}
