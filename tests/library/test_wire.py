"""The table of course types on the grader's wire (labkit/wire.py): each row crosses the protocol and comes back
as the same value, and a new row is all a new answer type needs."""

import inspect
from dataclasses import dataclass

import numpy as np
import pytest

from labkit import Corner, QuadMesh, wire
from labkit.grading.sandbox import protocol


def roundtrip(value):
    return protocol.decode(protocol.encode(value))


def test_a_corner_and_a_mesh_come_back_equal():
    corner = Corner(point=[0.5, 1.0], ds=[1.0, 0.0], dt=[0.0, 2.0], dsdt=[0.25, -0.5])
    back = roundtrip(corner)
    assert isinstance(back, Corner)
    for name in ("point", "ds", "dt", "dsdt"):
        np.testing.assert_array_equal(getattr(back, name), getattr(corner, name))
    mesh = QuadMesh(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), np.array([[0, 1, 2, 3]]))
    back = roundtrip(mesh)
    assert isinstance(back, QuadMesh)
    np.testing.assert_array_equal(back.points, mesh.points)
    np.testing.assert_array_equal(back.quads, mesh.quads)


def test_every_row_names_a_class_with_its_fields():
    for row in wire.TYPES:
        kind = row.kind()
        assert isinstance(kind, type) and row.tag in wire.BY_TAG
        assert list(inspect.signature(kind).parameters)[: len(row.fields)] == list(row.fields)


@dataclass(frozen=True)
class Segment:
    start: np.ndarray
    end: np.ndarray


def _segment(start, end):
    if start.shape != end.shape:
        raise ValueError("a Segment whose ends differ in size")
    return Segment(start, end)


def test_a_new_answer_type_is_one_row(monkeypatch):
    row = wire.WireType("segment", f"{__name__}:Segment", ("start", "end"), _segment)
    monkeypatch.setattr(wire, "TYPES", wire.TYPES + (row,))
    monkeypatch.setattr(wire, "BY_TAG", {**wire.BY_TAG, "segment": row})
    back = roundtrip(Segment(np.array([0.0, 1.0]), np.array([2.0, 3.0])))
    assert isinstance(back, Segment)
    np.testing.assert_array_equal(back.end, [2.0, 3.0])
    bad = protocol.decode(["segment", protocol.encode(np.zeros(2)), protocol.encode(np.zeros(3))])
    assert isinstance(bad, protocol.NotNumbers) and "differ in size" in str(bad)


def test_without_its_row_the_type_is_only_described(monkeypatch):
    monkeypatch.setattr(wire, "TYPES", ())
    monkeypatch.setattr(wire, "BY_TAG", {})
    tag = protocol.encode(Corner(point=[0.0, 0.0], ds=[1.0, 0.0], dt=[0.0, 1.0], dsdt=[0.0, 0.0]))
    assert tag[0] == "obj"
    with pytest.raises(protocol.ProtocolError):
        protocol.decode(["corner"] + [protocol.encode(np.zeros(2))] * 4)
