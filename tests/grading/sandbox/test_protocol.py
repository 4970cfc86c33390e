"""What crosses from a sandboxed notebook: plain numbers only, everything else refused or marked."""

import json

import numpy as np
import pytest

import labkit
from labkit.exercises.result import close, worst
from labkit.grading.sandbox import protocol


def _roundtrip(value, functions=False):
    line = protocol.dumps({"value": protocol.encode(value)})
    return protocol.decode(protocol.loads(line)["value"], functions=functions)


def test_numbers_arrive_as_float64_arrays_and_floats():
    got = _roundtrip((np.arange(6, dtype=np.int32).reshape(2, 3), [np.float32(1.5), True], 7, None, "text"))
    assert isinstance(got, tuple) and isinstance(got[1], list)
    assert got[0].dtype == np.float64 and got[0].shape == (2, 3) and got[0].tolist() == [[0, 1, 2], [3, 4, 5]]
    assert got[1] == [1.5, 1.0] and got[2] == 7 and got[3] is None and got[4] == "text"
    nan = _roundtrip(np.array([np.nan, np.inf, -0.0]))
    assert np.isnan(nan[0]) and nan[1] == np.inf and np.signbit(nan[2])


def test_corners_and_meshes_are_rebuilt_by_their_constructors():
    corner = labkit.Corner([0, 1], [1, 0], [0, 2], [0.5, 0.5])
    got = _roundtrip([corner])[0]
    assert isinstance(got, labkit.Corner) and got.dt.tolist() == [0.0, 2.0] and got.dsdt.tolist() == [0.5, 0.5]
    x, y = np.meshgrid([0.0, 1.0, 2.0], [0.0, 1.0], indexing="ij")
    mesh = _roundtrip(labkit.quad_mesh(x, y))
    assert isinstance(mesh, labkit.QuadMesh) and mesh.quads.tolist() == labkit.quad_mesh(x, y).quads.tolist()


@pytest.mark.parametrize(
    "value, says",
    [
        (np.array([1 + 2j]), "complex numbers"),
        (np.array(["a"]), "an array of <U1"),
        (object(), "a object object"),
        ({"a": 1}, "a dict object"),
        (lambda x: x, "a function object"),
    ],
)
def test_anything_but_numbers_arrives_as_not_numbers(value, says):
    got = _roundtrip(value)
    assert isinstance(got, protocol.NotNumbers) and says in str(got)
    assert not close(got, [1.0]) and says in worst(got, [1.0])


def test_values_that_compare_equal_to_everything_fail():
    class Liar:
        def __eq__(self, other):
            return True

    assert not close(_roundtrip(Liar()), 1.0)
    assert not close(np.array([np.inf]), [1.0]) and "NaN or infinite" in worst([np.inf], [1.0])
    assert "expected shape (2,)" in worst([1.0, 2.0, 3.0], [1.0, 2.0])


def test_invalid_corners_and_meshes_are_not_numbers():
    assert isinstance(
        protocol.decode(["corner", ["a", [1], "AAAAAAAAAAA="]] * 1 + [["obj", "x"]] * 3), protocol.NotNumbers
    )
    bad_quads = protocol.encode(np.array([[0, 1, 2, 9]]))
    points = protocol.encode(np.zeros((4, 2)))
    assert "invalid QuadMesh" in str(protocol.decode(["mesh", points, bad_quads]))


@pytest.mark.parametrize(
    "tag, message",
    [
        (["a", [3], "AAAA"], "does not match its shape"),
        (["a", [-1], ""], "malformed array shape"),
        (["a", [1], "!!!!!!!!!!!="], "not base64"),
        (["zzz"], "unknown value tag"),
        ("text", "malformed value"),
        (["f", "1.0"], "unknown value tag"),
        (["fn", "labkit.piecewise:eval_pherm"], "unknown value tag"),  # the grader never takes functions
    ],
)
def test_malformed_values_are_protocol_errors(tag, message):
    with pytest.raises(protocol.ProtocolError, match=message):
        protocol.decode(tag)


def test_nesting_and_message_shape_are_bounded():
    deep = ["none"]
    for _ in range(protocol.MAX_DEPTH + 5):
        deep = ["l", [deep]]
    with pytest.raises(protocol.ProtocolError, match="nested too deeply"):
        protocol.decode(deep)
    with pytest.raises(protocol.ProtocolError, match="JSON object"):
        protocol.loads(b"[1, 2]")
    with pytest.raises(protocol.ProtocolError, match="not JSON"):
        protocol.loads(b"{'single': 'quotes'}")


def test_functions_cross_only_by_name_and_only_the_listed_ones():
    from labkit.exercises.registry import LAB

    tag = protocol.encode(labkit.eval_pherm, LAB.passable)
    assert tag == ["fn", "labkit.piecewise:eval_pherm"]
    assert protocol.encode(labkit.eval_pherm)[0] == "obj"  # only the functions the exercises declare cross
    assert protocol.encode(np.sin, LAB.passable)[0] == "obj"
    with pytest.raises(protocol.ProtocolError, match="not a labkit function the checks may pass"):
        protocol.passable("os:system")
    assert protocol.passable("labkit.functions:runge2d") is labkit.runge2d
    # the notebook's side takes only what this request handed over, by name
    handed = {"labkit.functions:runge2d": labkit.runge2d}
    assert protocol.decode(["fn", "labkit.functions:runge2d"], functions=handed) is labkit.runge2d
    with pytest.raises(protocol.ProtocolError, match="not handed over"):
        protocol.decode(["fn", "labkit.piecewise:eval_pherm"], functions=handed)
    assert protocol.function_names([["t", [["fn", "a:b"], ["l", [["fn", "c:d"]]]]], ["f", 1.0]]) == {"a:b", "c:d"}


def test_a_corner_is_rebuilt_checked_without_running_its_class_code():
    corner = protocol.decode(protocol.encode(labkit.Corner([0, 1], [1, 0], [0, 2])))
    assert isinstance(corner, labkit.Corner) and corner.dsdt.tolist() == [0.0, 0.0] and corner.dim == 2
    mismatched = [
        "corner",
        protocol.encode(np.zeros(2)),
        protocol.encode(np.zeros(3)),
        protocol.encode(np.zeros(2)),
        protocol.encode(np.zeros(2)),
    ]
    assert "same size" in str(protocol.decode(mismatched))
    infinite = ["corner"] + [protocol.encode(np.array([np.inf, 0.0]))] * 4
    assert "NaN or infinite" in str(protocol.decode(infinite))


def test_a_message_is_bounded_before_it_is_parsed():
    # a line of nested empty lists costs the JSON parser some thirty times its size: refused on its bytes
    bomb = b'{"id": "x", "value": ' + b"[" * (protocol.MAX_CONTAINERS + 1) + b"]" * (protocol.MAX_CONTAINERS + 1) + b"}"
    with pytest.raises(protocol.ProtocolError, match="lists and objects"):
        protocol.loads(bomb)
    with pytest.raises(protocol.ProtocolError, match="larger than"):
        protocol.loads(b" " * (protocol.MAX_LINE + 1))
    # the largest honest answer fits: the lab's meshes and a long plotted curve
    line = protocol.dumps({"id": "x", "value": protocol.encode([np.zeros((100_000, 2)), list(range(50_000))])})
    assert protocol.loads(line)["id"] == "x"


def test_dumps_is_one_line_of_json():
    line = protocol.dumps({"value": protocol.encode("two\nlines")})
    assert line.endswith(b"\n") and line.count(b"\n") == 1
    assert json.loads(line)["value"] == ["s", "two\nlines"]


def test_a_passable_function_with_float_keywords_crosses_as_a_partial_and_nothing_else_does():
    """A student's variant of the Runge function is labkit.runge with a bound: it crosses by name with its float
    keywords and is rebuilt around the function handed over; a partial of anything else, or with positional,
    non-float or too many keywords, does not cross."""
    import functools

    from labkit.exercises.registry import LAB

    scaled = functools.partial(labkit.runge, a=1.25)
    tag = protocol.encode(scaled, LAB.passable)
    assert tag == ["fn", "labkit.functions:runge", {"a": 1.25}]
    assert protocol.function_names([["l", [tag]]]) == {"labkit.functions:runge"}
    line = protocol.loads(protocol.dumps({"value": tag}))["value"]
    got = protocol.decode(line, functions={"labkit.functions:runge": labkit.runge})
    x = np.linspace(-2, 2, 9)
    assert np.array_equal(got(x)[0], 1 / (1 + 1.25 * x**2))  # the handed function, with the student's scale
    for other in (
        functools.partial(np.sin),  # not a labkit function
        functools.partial(labkit.runge, 1.0),  # positional
        functools.partial(labkit.runge, a="1.25"),  # not a float
        functools.partial(labkit.runge, a=np.inf),
        functools.partial(labkit.runge, **{f"k{i}": 1.0 for i in range(protocol.MAX_KEYWORDS + 1)}),
    ):
        assert protocol.encode(other, LAB.passable)[0] == "obj"
    with pytest.raises(protocol.ProtocolError, match="finite floats"):
        protocol.decode(
            ["fn", "labkit.functions:runge", {"a": "os"}], functions={"labkit.functions:runge": labkit.runge}
        )
    with pytest.raises(protocol.ProtocolError, match="not handed over"):
        protocol.decode(["fn", "labkit.piecewise:eval_pherm", {"a": 1.0}], functions={})
