"""Type hints of the public API (``labkit.__all__``): complete, resolvable, and true of what is returned.

The package ships ``py.typed`` (PEP 561), so type checkers and editors read
these annotations. Three kinds of test:

* every parameter and the return of every public function, and of the
  public methods and properties of the public classes, is annotated, and
  every annotation resolves (``typing.get_type_hints`` raises on a string
  annotation that names nothing);
* the values the library actually returns, for scalar and array inputs, are
  of the declared return types;
* the checkers used above catch what they should (a missing annotation, an
  unresolvable one, a value of the wrong type).
"""

import ast
import importlib
import inspect
import sys
import types
import typing
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from numpy.typing import NDArray

import labkit
from labkit.convergence import METHOD_TITLES

matplotlib.use("Agg")

SKIPPED_KINDS = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)


def _type_checking_names(module):
    """What `module` imports under ``if TYPE_CHECKING:`` (matplotlib's Axes, imported only to draw)."""
    names = {}
    for node in ast.walk(ast.parse(inspect.getsource(module))):
        if not (isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"):
            continue
        for statement in node.body:
            if isinstance(statement, ast.ImportFrom) and statement.level == 0:
                source = importlib.import_module(statement.module)
                for alias in statement.names:
                    names[alias.asname or alias.name] = getattr(source, alias.name)
            elif isinstance(statement, ast.Import):
                for alias in statement.names:
                    imported = importlib.import_module(alias.name)
                    names[alias.asname or alias.name.partition(".")[0]] = (
                        imported if alias.asname else sys.modules[alias.name.partition(".")[0]]
                    )
    return names


def hints(function):
    """The resolved annotations of `function`; NameError (or another error) if one does not resolve."""
    module = sys.modules[function.__module__]
    return typing.get_type_hints(function, localns=_type_checking_names(module))


def unannotated(function):
    """Names of the parameters (self/cls, *args and **kwargs aside) and 'return' that carry no annotation."""
    resolved = hints(function)
    missing = []
    for position, (name, parameter) in enumerate(inspect.signature(function).parameters.items()):
        if parameter.kind in SKIPPED_KINDS or (position == 0 and name in ("self", "cls")):
            continue
        if name not in resolved:
            missing.append(name)
    if "return" not in resolved:
        missing.append("return")
    return missing


def public_members(cls):
    """{name: function} of __init__ and the methods, properties and operators written in `cls` itself.

    Private helpers (``_name``) are left out, and so are the methods a
    dataclass generates (``__eq__``, ``__repr__`` ...), which are not in the
    module's source; ``__init__`` is checked even when generated, since its
    parameters are the class's fields.
    """
    source = inspect.getsourcefile(cls)
    members = {}
    for name, value in vars(cls).items():
        if isinstance(value, property):
            function = value.fget
        elif isinstance(value, (staticmethod, classmethod)):
            function = value.__func__
        elif inspect.isfunction(value):
            function = value
        else:
            continue
        if name.startswith("_") and not (name.startswith("__") and name.endswith("__")):
            continue
        if name != "__init__" and function.__code__.co_filename != source:
            continue
        members[name] = function
    return members


def _public_api():
    """{qualified name: function} of every public function and public method of labkit.__all__."""
    api = {}
    for name in labkit.__all__:
        value = getattr(labkit, name)
        if inspect.isclass(value):
            for member, function in public_members(value).items():
                api[f"{name}.{member}"] = function
        elif inspect.isfunction(value):
            api[name] = value
    return api


API = _public_api()


def test_the_public_api_is_what_the_typing_tests_cover():
    # no callable of __all__ escapes the checks (a functools.partial or a compiled function would)
    escaped = [
        n
        for n in labkit.__all__
        if callable(getattr(labkit, n))
        and not (inspect.isclass(getattr(labkit, n)) or inspect.isfunction(getattr(labkit, n)))
    ]
    assert escaped == []
    assert {n for n in API if "." not in n} == {n for n in labkit.__all__ if inspect.isfunction(getattr(labkit, n))}
    assert {
        "Corner.__init__",
        "Corner.dim",
        "QuadMesh.__init__",
        "QuadMesh.plot",
        "QuadMesh.write",
        "QuadMesh.__add__",
        "ConvergenceTable.__init__",
        "ConvergenceTable.order",
    } <= set(API)
    assert "ConvergenceTable.__eq__" not in API and "Corner.__setattr__" not in API  # generated by dataclass


@pytest.mark.parametrize("name", sorted(API))
def test_every_parameter_and_return_is_annotated(name):
    assert unannotated(API[name]) == [], f"{name} lacks annotations"


@pytest.mark.parametrize("name", [n for n in labkit.__all__ if inspect.isclass(getattr(labkit, n))])
def test_the_attributes_of_the_public_classes_are_annotated(name):
    cls = getattr(labkit, name)
    module = sys.modules[cls.__module__]
    attributes = typing.get_type_hints(cls, localns=_type_checking_names(module))
    expected = {
        "Corner": {"point", "ds", "dt", "dsdt"},
        "QuadMesh": {"points", "quads"},
        "ConvergenceTable": {"title", "ndata", "errors"},
    }[name]
    assert set(attributes) == expected


def test_the_method_literal_lists_exactly_the_methods_convergence_table_knows():
    assert typing.get_args(hints(labkit.convergence_table)["method"]) == tuple(METHOD_TITLES)


def test_the_package_is_marked_as_typed():
    marker = Path(labkit.__file__).with_name("py.typed")
    assert marker.is_file()


# --- the declared return types are true ------------------------------------------------------------


def conforms(value, hint):
    """Whether `value` is of the type `hint` (the forms the public API uses: unions, tuples, NDArray, classes)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        return any(conforms(value, arg) for arg in args)
    if origin is tuple:
        return isinstance(value, tuple) and len(value) == len(args) and all(map(conforms, value, args))
    if origin is np.ndarray:  # NDArray[T] is ndarray[shape, dtype[T]]
        (scalar,) = typing.get_args(args[1])
        return isinstance(value, np.ndarray) and np.issubdtype(value.dtype, scalar)
    if hint is None or hint is type(None):
        return value is None
    return isinstance(value, hint)


X, Y, YP = [0.0, 1.0, 2.0, 4.0], [0.0, 1.0, 8.0, 64.0], [0.0, 3.0, 12.0, 48.0]
E1, E2 = [1.0, 0.0], [0.0, 1.0]


def _mesh():
    return labkit.quad_mesh(*np.meshgrid([0.0, 1.0, 2.0], [0.0, 1.0], indexing="ij"))


def _corners():
    return (
        labkit.Corner([0, 0], E1, E2),
        labkit.Corner(E1, E1, E2),
        labkit.Corner([1, 1], E1, E2),
        labkit.Corner(E2, E1, E2, [0.5, 0.5]),
    )


def _init(cls, *args):
    """What cls.__init__ returns, on a fresh instance."""
    return cls.__init__(object.__new__(cls), *args)


def _plot(mesh):
    import matplotlib.pyplot as plt

    try:
        return mesh.plot(color_by_quality=True, title="typed")
    finally:
        plt.close("all")


TABLE = labkit.convergence_table("natural", ndata=(5, 9, 17, 33), ntest=101)

# (what is called, how): a scalar and an array call wherever the return type depends on it
CALLS = [
    ("bracket", lambda tmp: labkit.bracket(X, 1.5)),
    ("bracket", lambda tmp: labkit.bracket(X, [[-1.0, 1.5], [3.0, 9.0]])),
    ("eval_plin", lambda tmp: labkit.eval_plin(X, Y, 1.5)),
    ("eval_plin", lambda tmp: labkit.eval_plin(X, Y, [0.5, 3.0], der=1)),
    ("hermite_basis", lambda tmp: labkit.hermite_basis(0.0, 2.0, 1.0)),
    ("hermite_basis", lambda tmp: labkit.hermite_basis(0.0, 2.0, 1.0, der=3)),
    ("hermite_basis", lambda tmp: labkit.hermite_basis(0.0, 2.0, [0.5, 1.0], der=2)),
    ("eval_pherm", lambda tmp: labkit.eval_pherm(X, Y, YP, 3.0)),
    ("eval_pherm", lambda tmp: labkit.eval_pherm(X, Y, YP, [[3.0]], der=2)),
    ("ccspline", lambda tmp: labkit.ccspline(X, Y, 0.0, 48.0)),
    ("ncspline", lambda tmp: labkit.ncspline(X, Y)),
    ("nakspline", lambda tmp: labkit.nakspline(X, Y)),
    ("spline", lambda tmp: labkit.spline(X, Y, 3.0)),
    ("spline", lambda tmp: labkit.spline(X, [0.0, *Y, 48.0], [3.0, 5.0], der=1)),
    ("pchip_slopes", lambda tmp: labkit.pchip_slopes(X, Y)),
    ("pchip", lambda tmp: labkit.pchip(X, Y, 2.5)),
    ("pchip", lambda tmp: labkit.pchip(X, Y, [2.5], der=3)),
    ("runge", lambda tmp: labkit.runge(1.0)),
    ("runge", lambda tmp: labkit.runge(np.linspace(-1.0, 1.0, 5))),
    ("runge2d", lambda tmp: labkit.runge2d(0.5, 0.5)),
    ("runge2d", lambda tmp: labkit.runge2d([0.5, 1.0], 0.5)),
    ("limacon", lambda tmp: labkit.limacon(0.0)),
    ("limacon", lambda tmp: labkit.limacon(np.linspace(0.0, 6.0, 7), r0=1.0)),
    ("eval_pbilin", lambda tmp: labkit.eval_pbilin(labkit.runge2d, X, X, 1.5, 2.5)),
    ("eval_pbilin", lambda tmp: labkit.eval_pbilin(np.ones((4, 4)), X, X, [1.5, 3.0], [2.5])),
    ("patch", lambda tmp: labkit.patch(*_corners(), np.linspace(0, 1, 3), [0.0, 1.0])),
    ("quad_mesh", lambda tmp: labkit.quad_mesh(*labkit.patch(*_corners(), [0.0, 1.0], [0.0, 1.0]))),
    ("ratio_table", lambda tmp: labkit.ratio_table("halving", [3, 5, 9], [0.4, 0.1, 0.025])),
    ("convergence_table", lambda tmp: labkit.convergence_table("pchip", ndata=(5, 9, 17, 33), ntest=101)),
    ("bilinear_convergence", lambda tmp: labkit.bilinear_convergence(ndata=(3, 5, 9, 17), ntest=21)),
    ("Corner.__init__", lambda tmp: _init(labkit.Corner, [0, 0, 1], [1, 0, 0], [0, 1, 0])),
    ("Corner.dim", lambda tmp: _corners()[0].dim),
    ("QuadMesh.__init__", lambda tmp: _init(labkit.QuadMesh, [[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1, 2, 3]])),
    ("QuadMesh.__repr__", lambda tmp: repr(_mesh())),
    ("QuadMesh.dim", lambda tmp: _mesh().dim),
    ("QuadMesh.edge_lengths", lambda tmp: _mesh().edge_lengths()),
    ("QuadMesh.quality", lambda tmp: _mesh().quality()),
    ("QuadMesh.folded", lambda tmp: _mesh().folded()),
    ("QuadMesh.__add__", lambda tmp: _mesh() + labkit.quad_mesh(*np.meshgrid([2.0, 3.0], [0.0, 1.0], indexing="ij"))),
    ("QuadMesh.write", lambda tmp: _mesh().write(str(tmp / "mesh.vtu"))),
    ("QuadMesh.plot", lambda tmp: _plot(_mesh())),
    ("QuadMesh.describe", lambda tmp: _mesh().describe()),
    ("ConvergenceTable.__init__", lambda tmp: _init(labkit.ConvergenceTable, TABLE.title, TABLE.ndata, TABLE.errors)),
    ("ConvergenceTable.ratios", lambda tmp: TABLE.ratios),
    ("ConvergenceTable.rates", lambda tmp: TABLE.rates),
    ("ConvergenceTable.order", lambda tmp: TABLE.order),
    ("ConvergenceTable.__str__", lambda tmp: str(TABLE)),
    ("ready", lambda tmp: labkit.ready("0.1")),
    ("ready_to_hand_in", lambda tmp: labkit.ready_to_hand_in("02_convergence", namespace={})),
]


def test_every_public_function_and_method_has_a_return_type_check():
    assert {name for name, _ in CALLS} == set(API)


@pytest.mark.parametrize(("name", "call"), CALLS, ids=[f"{name}-{i}" for i, (name, _) in enumerate(CALLS)])
def test_what_is_returned_is_of_the_declared_type(name, call, tmp_path):
    declared = hints(API[name])["return"]
    value = call(tmp_path)
    assert conforms(value, declared), f"{name} returned {type(value).__name__}, declared {declared}"


def test_the_field_types_are_what_the_objects_hold():
    corner, mesh = _corners()[3], _mesh()
    for obj in (corner, mesh, TABLE):
        for attribute, declared in typing.get_type_hints(type(obj)).items():
            assert conforms(getattr(obj, attribute), declared), f"{type(obj).__name__}.{attribute}"


# --- the checkers catch what they should ---------------------------------------------------------


def _no_hints(x, y: int = 0) -> int:
    return x + y


def _no_return(x: int, *args, **kwargs):
    return x


def _dangling(x: "NoSuchType") -> int:  # noqa: F821 -- the point of the test
    return 0


class _Half:
    def __init__(self, value: int) -> None:
        self.value = value

    def twice(self):
        return 2 * self.value

    @property
    def size(self) -> int:
        return 1

    def _helper(self, anything):
        return anything


def test_the_annotation_check_finds_what_is_missing():
    assert unannotated(_no_hints) == ["x"]
    assert unannotated(_no_return) == ["return"]  # *args and **kwargs need none
    with pytest.raises(NameError, match="NoSuchType"):
        unannotated(_dangling)
    members = public_members(_Half)
    assert set(members) == {"__init__", "twice", "size"}
    assert [name for name, fn in members.items() if unannotated(fn)] == ["twice"]


def test_the_return_check_tells_types_apart():
    declared = float | NDArray[np.float64]
    assert conforms(np.float64(1.0), declared) and conforms(np.zeros(2), declared)
    assert not conforms(np.zeros(2, dtype=int), declared)
    assert not conforms([1.0, 2.0], declared)
    assert not conforms(np.int64(1), NDArray[np.intp] | float)
    pair = tuple[float, NDArray[np.float64]]
    assert conforms((1.0, np.ones(1)), pair)
    assert not conforms((1.0,), pair) and not conforms((np.ones(1), 1.0), pair)
    assert conforms(None, int | None) and not conforms(0, str)
