"""What a graded function may not reach (a part's :class:`labkit.exercises.model.Refusal`), as the grader sees it.

For the sandbox's watch (:mod:`labkit.grading.sandbox.guard`): the digest of every Python function of the refused
modules, compiled here from the library's files so nothing a notebook does to the live modules changes it, the
module prefixes and the single compiled functions. For the source scan (:mod:`.scan`): every dotted spelling of a
refused or an allowed object in labkit, scipy and numpy. :func:`wire` computes it all once per grading run.
"""

import __future__

import ast
import codeop
import contextlib
import functools
import importlib
import importlib.util
import sys
import types
from pathlib import Path

from ..sandbox.guard import _within, code_key, codes_in


def _module_files(prefix):
    """(module name, file) of every Python source file of a module or package (tests left out)."""
    spec = None
    with contextlib.suppress(ImportError, ValueError):
        spec = importlib.util.find_spec(prefix)
    if spec is not None and spec.submodule_search_locations:
        found = []
        for location in spec.submodule_search_locations:
            for path in sorted(Path(location).rglob("*.py")):
                parts = path.relative_to(location).with_suffix("").parts
                if "tests" not in parts:
                    module = parts[:-1] if parts[-1] == "__init__" else parts
                    found.append((".".join((prefix,) + module), path))
        return found
    if spec is not None and spec.origin and spec.origin.endswith(".py"):
        return [(prefix, Path(spec.origin))]
    return []  # a compiled module: its routines are refused by the module's name


# the flags IPython compiles a cell's statements with (codeop's, which its CachingCompiler keeps), and the
# __future__ features a notebook's earlier cells may have added to them
CELL_FLAGS = codeop.PyCF_DONT_IMPLY_DEDENT | getattr(codeop, "PyCF_ALLOW_INCOMPLETE_INPUT", 0)  # type: ignore[attr-defined]


@functools.cache
def _compiled_codes(path):
    """Every code object of a source file compiled whole (as imported) and statement by statement as IPython
    compiles a cell (its flags, with and without the file's futures), whose bytecode differs (``np.diff(x)``)."""
    source = Path(path).read_bytes()
    found = list(codes_in(compile(source, str(path), "exec", dont_inherit=True)))
    tree = ast.parse(source, str(path))  # it compiled: it parses
    futures = 0
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.module == "__future__":
            for alias in node.names:
                futures |= getattr(__future__, alias.name).compiler_flag  # it compiled: each is a feature
    for flags in sorted({CELL_FLAGS, CELL_FLAGS | futures}):
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.If, ast.Try, ast.With)):
                module = ast.Module([node], type_ignores=[])
                found += codes_in(compile(module, str(path), "exec", flags=flags, dont_inherit=True))
    return tuple(found)


@functools.cache
def recognised(refusal):
    """``(names, modules, c_names)`` for the sandbox: {digest: readable name}, module prefixes, compiled functions."""
    allowed = {}
    for dotted in refusal.allowed:
        module, _, qualname = dotted.rpartition(".")
        allowed.setdefault(module, []).append(qualname)
    names, c_names = {}, set()
    for prefix in refusal.modules:
        for module, path in _module_files(prefix):
            for code in _compiled_codes(path):
                if code.co_name == "<module>" or _within(code.co_qualname, allowed.get(module, ())):
                    continue
                names.setdefault(code_key(code), f"{module}.{code.co_qualname}")
    for dotted in refusal.functions:
        module, _, qualname = dotted.rpartition(".")
        files = _module_files(module)
        if files and files[0][0] == module:
            for code in _compiled_codes(files[0][1]):
                if _within(code.co_qualname, (qualname,)):
                    names.setdefault(code_key(code), dotted)
        else:
            c_names.add((module, qualname))
    return names, tuple(refusal.modules), frozenset(c_names)


LIBRARIES = ("labkit", "scipy", "numpy")  # the packages whose names the scan resolves


def _resolve(dotted):
    """The object a dotted name of labkit, scipy or numpy is (importing their modules only), or None."""
    parts = dotted.split(".")
    if parts[0] not in LIBRARIES:
        return None
    for split in range(len(parts), 0, -1):
        try:
            value = importlib.import_module(".".join(parts[:split]))
        except (ImportError, ValueError, TypeError):
            continue
        try:
            return functools.reduce(getattr, parts[split:], value)
        except AttributeError:
            return None
    return None


@functools.cache
def spellings(refusal):
    """({spelling: the refused object's own name}, [spellings of allowed objects]) in labkit, scipy and numpy."""
    for prefix in refusal.modules:
        if _within(prefix, LIBRARIES):
            with contextlib.suppress(ImportError):
                importlib.import_module(prefix)
    loaded = [(name, module) for name, module in list(sys.modules.items()) if module is not None]
    libraries = [(name, module) for name, module in loaded if _within(name, LIBRARIES)]
    allowed = {id(value): value for value in map(_resolve, refusal.allowed) if value is not None}
    refused = {}
    for name, module in libraries:
        if not _within(name, refusal.modules):
            continue
        for attribute, value in list(vars(module).items()):
            if isinstance(value, types.ModuleType) or id(value) in allowed:
                continue
            home = getattr(value, "__module__", None)
            if isinstance(home, str) and _within(home, refusal.modules) and (id(value) not in refused or home == name):
                refused[id(value)] = (value, f"{name}.{attribute}")
    for dotted in refusal.functions:
        value = _resolve(dotted)
        if value is not None:
            refused.setdefault(id(value), (value, dotted))
    spelled, allowed_spellings = {}, set(refusal.allowed)
    for name, module in libraries:
        for attribute, value in list(vars(module).items()):
            found = refused.get(id(value))
            if found is not None and found[0] is value:
                spelled[f"{name}.{attribute}"] = found[1]
            elif id(value) in allowed and allowed[id(value)] is value:
                allowed_spellings.add(f"{name}.{attribute}")
    return spelled, sorted(allowed_spellings)


def wire(refusals):
    """The profiles of these refusals as JSON-ready data for the sandbox and the scan: {name: {...}}."""
    profiles = {}
    for refusal in refusals:
        names, modules, c_names = recognised(refusal)
        spelled, allowed = spellings(refusal)  # imports the refused modules
        loaded = [name for name, module in list(sys.modules.items()) if module is not None]
        profiles[refusal.name] = {
            "names": {key.hex(): name for key, name in names.items()},
            "modules": list(modules),
            "c_names": sorted(map(list, c_names)),
            "spellings": spelled,
            "allowed": allowed,
            # the refused modules themselves: the scan judges their uses, not their import
            "submodules": sorted(name for name in loaded if _within(name, refusal.modules)),
        }
    return profiles
