"""Reading the project's markdown: relative links, heading anchors, the exercise table.

Imported by the tests as ``from docs_markdown import ...`` (like ``helpers``).
"""

import re
from pathlib import Path
from urllib.parse import unquote

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
EXERCISE_TABLE_MARKER = "<!-- exercise table: checked by tests against the exercise declarations -->"

_FENCE = re.compile(r"^\s*(```|~~~)")
_HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
_INLINE_CODE = re.compile(r"(`+)(?:(?!\1).)+?\1")
_INLINE_LINK = re.compile(r"\]\(\s*<?([^()\s<>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
_REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+\"[^\"]*\")?\s*$")
_HTML_ANCHOR = re.compile(r"<a\s[^>]*(?:id|name)=\"([^\"]+)\"", re.IGNORECASE)
_SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def markdown_files():
    """The project's own markdown: README, CHANGELOG (and CONTRIBUTING once written), docs/*.md."""
    top = [ROOT / name for name in ("README.md", "CHANGELOG.md", "CONTRIBUTING.md") if (ROOT / name).exists()]
    return top + sorted(DOCS.glob("*.md"))


def _prose_lines(text):
    """(line number, line) outside fenced code blocks, with inline code spans blanked out."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if _FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, _INLINE_CODE.sub("", line)


def slug(heading):
    """The anchor GitHub gives a heading: its text, lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link counts by its text
    text = re.sub(r"<[^>]+>", "", text).strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(text):
    """Every anchor a markdown text defines: headings (GitHub numbers repeats -1, -2, ...) and <a id=...>."""
    found, seen = set(), {}
    fenced = False
    for line in text.splitlines():
        if _FENCE.match(line):
            fenced = not fenced
            continue
        if fenced:
            continue
        found.update(_HTML_ANCHOR.findall(line))
        heading = _HEADING.match(line)
        if heading:
            base = slug(heading.group(2))
            count = seen.get(base, 0)
            seen[base] = count + 1
            found.add(base if count == 0 else f"{base}-{count}")
    return found


def links(text):
    """(line number, target) of every link and image in the prose: inline and reference definitions."""
    for number, line in _prose_lines(text):
        for target in _INLINE_LINK.findall(line):
            yield number, target
        reference = _REFERENCE.match(line)
        if reference:
            yield number, reference.group(1)


def broken_links(path, pending=()):
    """What is wrong with the relative links of one markdown file, as readable strings.

    A link is relative when it has no scheme (``https:``, ``mailto:``). Its file must exist;
    when it names an anchor in a markdown file, a heading of that file must give that anchor.
    Files named in `pending` may be missing (they are reported by their own test).
    """
    path = Path(path)
    problems = []
    for number, target in links(path.read_text(encoding="utf-8")):
        if not target or _SCHEME.match(target):
            continue
        file_part, _, anchor = target.partition("#")
        destination = (path.parent / unquote(file_part)).resolve() if file_part else path.resolve()
        where = f"{path.name}:{number}: {target}"
        if not destination.exists():
            if destination not in {(ROOT / p).resolve() for p in pending}:
                problems.append(f"{where}: no such file {destination}")
            continue
        if anchor and destination.suffix == ".md":
            if unquote(anchor) not in anchors(destination.read_text(encoding="utf-8")):
                problems.append(f"{where}: no heading in {destination.name} gives the anchor #{anchor}")
    return problems


def _cells(row):
    return [cell.strip().strip("`").strip() for cell in row.strip().strip("|").split("|")]


def exercise_table(path=DOCS / "students.md"):
    """The rows of the exercise table (the one right under the marker) as dicts keyed by its header."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    assert lines.count(EXERCISE_TABLE_MARKER) == 1, f"{path} must hold the exercise table's marker once"
    start = lines.index(EXERCISE_TABLE_MARKER) + 1
    header, separator = _cells(lines[start]), _cells(lines[start + 1])
    assert all(re.fullmatch(r":?-{3,}:?", cell) for cell in separator), "a markdown table must follow the marker"
    rows = []
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        cells = _cells(line)
        assert len(cells) == len(header), line
        rows.append(dict(zip(header, cells)))
    return rows
