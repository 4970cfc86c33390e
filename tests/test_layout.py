"""labkit's layout as CONTRIBUTING states it: no two modules import each other, not even inside a function."""

import ast
from pathlib import Path

import labkit

ROOT = Path(labkit.__file__).parent


def modules(root):
    """{dotted module name: (path, whether it is a package's __init__)} of every .py file under `root`."""
    found = {}
    for path in root.rglob("*.py"):
        parts = list(path.relative_to(root.parent).with_suffix("").parts)
        package = parts[-1] == "__init__"
        found[".".join(parts[:-1] if package else parts)] = (path, package)
    return found


def imports(root):
    """{module: the modules it imports anywhere in its source}; `from package import name` counts as importing
    the submodule when `name` is one, else the package."""
    known = modules(root)
    edges = {}
    for name, (path, package) in known.items():
        here = name.split(".") if package else name.split(".")[:-1]
        targets = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets.update(alias.name for alias in node.names if alias.name in known)
            elif isinstance(node, ast.ImportFrom):
                base = here[: len(here) - node.level + 1] if node.level else []
                target = ".".join(base + (node.module.split(".") if node.module else []))
                if target in known:
                    for alias in node.names:
                        sub = f"{target}.{alias.name}"
                        targets.add(sub if sub in known else target)
        targets.discard(name)
        edges[name] = targets
    return edges


def mutual(root):
    edges = imports(root)
    return sorted((a, b) for a, targets in edges.items() for b in targets if a < b and a in edges.get(b, ()))


def test_no_two_modules_of_labkit_import_each_other():
    assert mutual(ROOT) == []


def test_the_search_finds_a_pair_that_imports_each_other_even_inside_a_function(tmp_path):
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "sub" / "__init__.py").write_text("")
    (package / "sub" / "late.py").write_text("def f():\n    from .rubric import g\n    return g\n")
    (package / "sub" / "rubric.py").write_text("from . import late\nfrom ..other import h\n")
    (package / "other.py").write_text("import pkg.sub.late\n")
    assert mutual(package) == [("pkg.sub.late", "pkg.sub.rubric")]
    edges = imports(package)
    assert edges["pkg.sub.rubric"] == {"pkg.sub.late", "pkg.other"}
    assert edges["pkg.other"] == {"pkg.sub.late"}


SUBPACKAGES = ("authoring", "lms", "reports", "sandbox", "store", "submission")


def reaching_out(edges, inside, allowed_prefix="labkit.grading."):
    """{module under `inside`: the labkit.grading modules outside `inside` it imports}."""
    found = {}
    for name, targets in edges.items():
        if name == inside or name.startswith(inside + "."):
            out = {
                t for t in targets if t.startswith(allowed_prefix) and not (t == inside or t.startswith(inside + "."))
            }
            if out:
                found[name] = out
    return found


def test_the_sandbox_imports_nothing_else_of_the_grader():
    assert reaching_out(imports(ROOT), "labkit.grading.sandbox") == {}


def test_the_check_for_the_sandbox_finds_a_module_that_reaches_out(tmp_path):
    package = tmp_path / "labkit"
    (package / "grading" / "sandbox").mkdir(parents=True)
    (package / "grading" / "store").mkdir()
    for init in ("", "grading", "grading/sandbox", "grading/store"):
        (package / init / "__init__.py").write_text("")
    (package / "grading" / "store" / "rubric.py").write_text("")
    (package / "grading" / "sandbox" / "remote.py").write_text("def f():\n    from ..store import rubric\n")
    assert reaching_out(imports(package), "labkit.grading.sandbox") == {
        "labkit.grading.sandbox.remote": {"labkit.grading.store.rubric"}
    }


def test_each_subpackage_of_grading_says_its_job_and_its_process():
    for name in SUBPACKAGES:
        init = ROOT / "grading" / name / "__init__.py"
        tree = ast.parse(init.read_text(encoding="utf-8"))
        doc = ast.get_docstring(tree)
        assert doc, f"{init} has no docstring"
        first = doc.splitlines()[0]
        assert first.endswith(".") and len(first) <= 120, f"{init}: the first line is its job, in one line"
        assert "process" in doc, f"{init} does not say which process its code runs in"


def test_the_tests_mirror_the_packages():
    """tests/<package path>/ holds the tests of labkit/<package path>/ (tests/library/ those of labkit/*.py);
    tests/browser/ drives a real browser, and the files at the top are about the whole repository."""
    tests = Path(__file__).resolve().parent
    folders = sorted(
        p.relative_to(tests).as_posix()
        for p in tests.rglob("*")
        if p.is_dir() and p.name != "__pycache__" and p.relative_to(tests).parts[0] not in ("data", "browser")
    )
    assert {"library", "exercises", "plots", "grading/run", "grading/sandbox"} <= set(folders)
    for folder in folders:
        package = ROOT if folder == "library" else ROOT / folder
        assert (package / "__init__.py").is_file(), f"tests/{folder}/ mirrors no package of labkit"
        assert any((tests / folder).glob("test_*.py")), f"tests/{folder}/ holds no test"


def package_of(module, known):
    """The subpackage a module belongs to: `labkit.grading.<room>` inside the grader, `labkit.<part>` elsewhere;
    a top-level module (labkit/errors.py, labkit/grading/options.py) stands for itself."""
    parts = module.split(".")
    for depth in (3, 2):
        prefix = ".".join(parts[:depth])
        if len(parts) > depth - 1 and prefix in known and known[prefix][1] and prefix != "labkit.grading":
            return prefix
    return module


def package_cycles(root):
    """The cycles of the import graph between subpackages, each as the sorted list of the packages in it
    (strongly connected components of more than one package, by Tarjan's method)."""
    known = modules(root)
    graph = {}
    for name, targets in imports(root).items():
        here = package_of(name, known)
        graph.setdefault(here, set()).update(package_of(t, known) for t in targets if package_of(t, known) != here)
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on.add(node)
        for nxt in graph.get(node, ()):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                top = stack.pop()
                on.discard(top)
                component.append(top)
                if top == node:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(cycles)


def test_no_cycle_between_subpackages():
    assert package_cycles(ROOT) == []


def test_the_cycle_search_finds_a_cycle_of_three_packages_through_single_modules(tmp_path):
    root = tmp_path / "labkit"
    for folder in ("", "grading", "grading/a", "grading/b", "grading/c", "other"):
        (root / folder).mkdir(parents=True, exist_ok=True)
        (root / folder / "__init__.py").write_text("")
    (root / "grading" / "a" / "x.py").write_text("from ..b import y\n")
    (root / "grading" / "b" / "y.py").write_text("def f():\n    from ..c import z\n")
    (root / "grading" / "c" / "z.py").write_text("from ...grading.a import x\n")
    (root / "other" / "w.py").write_text("from ..grading.a import x\n")
    assert package_cycles(root) == [["labkit.grading.a", "labkit.grading.b", "labkit.grading.c"]]
    (root / "grading" / "c" / "z.py").write_text("")
    assert package_cycles(root) == []


# The grader's rooms in the order data flows through them, lowest first: a room imports only rooms below it.
# (the class comes in and is planned and run: run; each submission is scored: submission; the store of a run: store;
# what people read: reports and authoring, at the top.)
FLOW = {
    "labkit.grading.progress": 0,
    "labkit.grading.pages": 0,
    "labkit.grading.sandbox": 1,
    "labkit.grading.store": 2,
    "labkit.grading.options": 2,
    "labkit.grading.submission": 3,
    "labkit.grading.lms": 3,
    "labkit.grading.run": 4,
    "labkit.grading.authoring": 4,
    "labkit.grading.reports": 5,
}


def imports_up_the_flow(root, flow):
    """[(room, room it imports)] for every import from a room to one at its level or above it in `flow`."""
    known = modules(root)
    found = set()
    for name, targets in imports(root).items():
        here = package_of(name, known)
        for target in targets:
            there = package_of(target, known)
            if here in flow and there in flow and here != there and flow[there] >= flow[here]:
                found.add((here, there))
    return sorted(found)


def test_every_room_of_the_grader_is_placed_in_the_flow():
    found = (ROOT / "grading").iterdir()
    rooms = {
        f"labkit.grading.{p.stem if p.is_file() else p.name}"
        for p in found
        if p.suffix == ".py" or (p / "__init__.py").is_file()
    }
    rooms = {r for r in rooms if not r.endswith(("__init__", "__pycache__", ".toml"))}
    assert rooms - set(FLOW) == set()


def test_no_room_imports_up_the_flow():
    assert imports_up_the_flow(ROOT, FLOW) == []


def test_the_flow_check_finds_an_import_upwards(tmp_path):
    root = tmp_path / "labkit"
    for folder in ("", "grading", "grading/low", "grading/high"):
        (root / folder).mkdir(parents=True, exist_ok=True)
        (root / folder / "__init__.py").write_text("")
    (root / "grading" / "high" / "h.py").write_text("from ..low import l\n")
    (root / "grading" / "low" / "l.py").write_text("")
    flow = {"labkit.grading.low": 0, "labkit.grading.high": 1}
    assert imports_up_the_flow(root, flow) == []
    (root / "grading" / "low" / "l.py").write_text("def f():\n    from ..high import h\n")
    assert imports_up_the_flow(root, flow) == [("labkit.grading.low", "labkit.grading.high")]


MAX_LINES, MAX_PARAMETERS = 80, 8


def oversized(root, skip=frozenset()):
    """[(file:line name, lines, parameters)] of every function under `root` (nested ones too) over
    :data:`MAX_LINES` lines (its decorators included) or over :data:`MAX_PARAMETERS` parameters (self and cls
    not counted); files whose path relative to `root`'s parent is in `skip` are left out."""
    found = []
    for path in sorted(root.rglob("*.py")):
        relative = path.relative_to(root.parent).as_posix()
        if relative in skip or "student_notebooks" in path.parts:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            first = node.decorator_list[0].lineno if node.decorator_list else node.lineno
            lines = node.end_lineno - first + 1
            a = node.args
            named = [arg.arg for arg in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
            if named[:1] in (["self"], ["cls"]):
                named = named[1:]
            parameters = len(named) + bool(a.vararg) + bool(a.kwarg)
            if lines > MAX_LINES or parameters > MAX_PARAMETERS:
                found.append((f"{relative}:{node.lineno} {node.name}", lines, parameters))
    return found


def test_no_function_of_labkit_is_too_long_or_takes_too_many_parameters():
    assert oversized(ROOT) == []


def test_the_size_check_finds_a_long_function_a_wide_one_and_a_long_nested_one(tmp_path):
    package = tmp_path / "pkg"
    package.mkdir()
    body = "".join(f"    x{i} = {i}\n" for i in range(MAX_LINES - 2))
    (package / "fits.py").write_text(
        f"@staticmethod\ndef at_the_limit():\n{body}\n"
        "class C:\n    def method(self, a, b, c, d, e, f, g, h):\n        pass\n"
    )
    (package / "over.py").write_text(
        f"@staticmethod\n@staticmethod\ndef long():\n{body}\n"
        "def wide(a, b, c, d, e, f, g, h, *rest):\n    pass\n"
        "def outer():\n    def inner():\n" + "".join(f"        x{i} = {i}\n" for i in range(MAX_LINES - 1))
    )
    found = {where.split(" ")[1]: (lines, parameters) for where, lines, parameters in oversized(package)}
    assert found == {"long": (MAX_LINES + 1, 0), "wide": (2, 9), "outer": (MAX_LINES + 1, 0)}
