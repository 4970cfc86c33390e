"""The documentation: every relative link reaches a file (and a heading), the README stays short."""

import re

import pytest
from docs_markdown import (
    DOCS,
    EXERCISE_TABLE_MARKER,
    ROOT,
    anchors,
    broken_links,
    exercise_table,
    links,
    markdown_files,
    slug,
)

# Linked on purpose before they exist, with who writes them. Once such a file exists its links are
# checked like any other; then remove it from here.
PENDING = {"CONTRIBUTING.md": "written after the code restructuring (issue 'One exercise, one place')"}

FILES = markdown_files()


def test_the_expected_documents_exist():
    names = {p.relative_to(ROOT).as_posix() for p in FILES}
    assert {
        "README.md",
        "CHANGELOG.md",
        "docs/students.md",
        "docs/instructors.md",
        "docs/library.md",
        "docs/performance.md",
        "docs/errata.md",
        "docs/grading-security.md",
    } <= names


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_relative_link_reaches_a_file_and_its_heading(path):
    assert broken_links(path, pending=PENDING) == []


@pytest.mark.parametrize("name", sorted(PENDING))
def test_pending_documents_are_linked_and_reported(name):
    linked = any(
        (p.parent / target.partition("#")[0]).resolve() == (ROOT / name).resolve()
        for p in FILES
        for _, target in links(p.read_text())
        if target and "://" not in target
    )
    assert linked, f"{name} is in PENDING but nothing links to it: remove it from PENDING"
    if not (ROOT / name).exists():
        pytest.skip(f"{name} is linked but not written yet: {PENDING[name]}")


def test_every_document_in_docs_is_reachable_from_the_readme():
    readme_targets = {(ROOT / t.partition("#")[0]).resolve() for _, t in links((ROOT / "README.md").read_text())}
    for path in DOCS.glob("*.md"):
        assert path.resolve() in readme_targets, f"the README's 'Where next' does not link {path.name}"


def test_the_readme_fits_in_a_screen_or_two():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 100, f"README.md has {len(lines)} lines: move details into docs/"


def test_the_readme_keeps_the_two_commands():
    readme = (ROOT / "README.md").read_text()
    assert "make lab             # set up .venv and open JupyterLab on your copies of the student notebooks" in readme
    assert "make lab-instructor  # the same on notebooks/" in readme
    assert "make test            # set up .venv and run every test" in readme
    assert "make test" in (ROOT / ".ci" / "run").read_text()


def test_the_errata_are_linked_not_named():
    # "see ERRATA" once pointed to a file outside the project: the errata are docs/errata.md, linked
    for path in FILES:
        assert not re.search(r"\bERRATA\b", path.read_text()), f"{path.name}: link docs/errata.md instead"


def test_the_exercise_table_lists_each_exercise_once_with_its_notebook_and_points():
    holders = [p for p in FILES if EXERCISE_TABLE_MARKER in p.read_text()]
    assert [p.name for p in holders] == ["students.md"]
    rows = exercise_table()
    assert {"exercise", "notebook", "points"} <= set(rows[0])
    from labkit.exercises.registry import LAB

    # exercise 1 (copying code) is in the lab but not graded; the rest are the declared exercises
    assert [int(r["exercise"]) for r in rows] == [1, *sorted(LAB.exercises)]
    for row in rows:
        assert (ROOT / "notebooks" / row["notebook"]).exists(), row
        assert int(row["points"]) >= 0, row


# The checker itself: it must catch what it is there to catch.


def test_slugs_are_githubs():
    assert slug("The notebooks and the lab's 16 exercises") == "the-notebooks-and-the-labs-16-exercises"
    assert slug("Changing a notebook, and what `make test` checks") == "changing-a-notebook-and-what-make-test-checks"
    assert slug("Why an `ipywidgets.Image`") == "why-an-ipywidgetsimage"
    assert slug("2-D") == "2-d"
    assert anchors("# A\n## A\n```\n# not a heading\n```\n") == {"a", "a-1"}


def test_the_checker_finds_a_missing_file_and_a_missing_anchor(tmp_path):
    (tmp_path / "other.md").write_text("# Present heading\n")
    page = tmp_path / "page.md"
    page.write_text(
        "[ok](other.md#present-heading) [self](#top)\n\n# Top\n"
        "[gone](missing.md) [bad anchor](other.md#absent) [bad self](#nowhere)\n"
        "`[in code](missing-too.md)`\n```\n[fenced](missing-as-well.md)\n```\n"
        "[web](https://example.org/x.md) [ref]: ./also-missing.md\n"
        "[def]: ./missing-by-reference.md\n"
    )
    problems = broken_links(page)
    assert len(problems) == 4, problems
    assert any("missing.md" in p and "no such file" in p for p in problems)
    assert any("#absent" in p for p in problems)
    assert any("#nowhere" in p for p in problems)
    assert any("missing-by-reference.md" in p for p in problems)
