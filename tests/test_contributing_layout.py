"""CONTRIBUTING.md's map stays whole: every module of the library and every folder of labkit/ and the grader is
named in "Where things live", and the grader's flow is drawn in the order data moves through its rooms."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def section(text, title):
    """The text of the `## title` section of a markdown text, up to the next `## ` heading."""
    start = text.index(f"## {title}\n")
    end = text.find("\n## ", start + 1)
    return text[start : end if end != -1 else None]


def named(text):
    """Every `code span` of `text` split at its commas: the names the map gives."""
    return {name.strip() for span in re.findall(r"`([^`]+)`", text) for name in span.split(",")}


def unnamed(root, text):
    """The library's modules and labkit's and the grader's folders that the map `text` does not name."""
    names = named(text) | {part.strip("` ") for part in re.findall(r"`[^`]+`", text)}
    modules = [p.name for p in (root / "labkit").glob("*.py") if p.name != "__init__.py"]
    folders = [
        f"{p.relative_to(root).as_posix()}/"
        for base in (root / "labkit", root / "labkit" / "grading")
        for p in base.iterdir()
        if p.is_dir() and p.name != "__pycache__"
    ]
    return sorted(name for name in modules + folders if name not in names and not _in_a_span(name, text))


def _in_a_span(name, text):
    return any(name in span.split(", ") or f"`{name}`" in text for span in re.findall(r"`([^`]+)`", text))


def flow_order(text):
    """The rooms named in the first fenced block of `text`, in the order they first appear."""
    block = re.search(r"^```\n(.*?)^```", text, re.MULTILINE | re.DOTALL).group(1)
    rooms = re.findall(r"\b(lms|run|store|reports)/", block)
    return list(dict.fromkeys(rooms))


def test_every_module_and_folder_is_on_the_map():
    text = section((ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8"), "Where things live")
    assert unnamed(ROOT, text) == []


def test_the_flow_is_drawn_in_order():
    text = section((ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8"), "Where things live")
    assert flow_order(text) == ["lms", "run", "store", "reports"]


def test_the_map_check_sees_a_module_or_folder_left_out(tmp_path):
    (tmp_path / "labkit" / "grading" / "rooms").mkdir(parents=True)
    for name in ("__init__.py", "piecewise.py", "newthing.py"):
        (tmp_path / "labkit" / name).write_text("")
    text = "| `piecewise.py` | ... |\n| `labkit/grading/` | ... |\n"
    assert unnamed(tmp_path, text) == ["labkit/grading/rooms/", "newthing.py"]
    assert unnamed(tmp_path, text + "| `newthing.py`, `labkit/grading/rooms/` | ... |") == []
    assert flow_order("```\n run/ then lms/ then store/ run/\n```\n") == ["run", "lms", "store"]
