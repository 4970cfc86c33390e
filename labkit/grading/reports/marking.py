"""What only a person can mark: answers in words, held parts and excused exercises (``labkit mark``).

A mark is one row of ``marks.csv``, ``submission,item,points,comment``:

* ``exercise12-answer-1`` (an answer's nbgrader grade id, as in grades.csv's "to read" columns) with
  points between 0 and what the rubric's ``[answers]`` table gives it;
* ``exercise2/eval_pherm`` (a part held for a person, :mod:`labkit.grading.submission.known`) with ``release``
  (its points are paid) or ``keep`` (they are not);
* ``exercise12`` with ``excused`` (out of the student's total and full credit) or ``counted`` (back in).

:func:`import_marks` checks every row against the run (its recorded rubric, its submissions, what each
item is worth) before it changes anything; then each marked submission's result (which holds its marks,
each with the time it was first imported), feedback and the run's record and grades.csv are written
again. A row equal to the mark already held changes nothing, so importing twice is importing once; a
later mark of the same item replaces the earlier one.
"""

import csv
import io
import json
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from ...errors import InputError
from ..store import record as records
from ..store.feedback import blank
from ..store.names import name_cell, name_from_cell, shown_name
from ..store.report import csv_cell, one_line, printable, read_results, write_csv, write_result
from ..store.text import points_text

HEADER = ["submission", "item", "points", "comment"]
MAX_MARKS_BYTES = 16 * 1024 * 1024  # a marks.csv larger than this is not read
MAX_COMMENT = 2000  # characters of a comment kept
HELD_WORDS = ("release", "keep")
EXCUSE_WORDS = ("excused", "counted")


@dataclass(frozen=True)
class Mark:
    """One validated row of marks.csv."""

    submission: str
    item: str
    points: object  # a number, or one of HELD_WORDS / EXCUSE_WORDS
    comment: str


def items(grade):
    """What can be marked for `grade`: item -> ("answer", points it is worth) | ("held", None) |
    ("exercise", None)."""
    rubric = grade.rubric
    found = {}
    for grade_id, (number, _) in rubric.registry.answers.items():
        if number in rubric.points:
            found[grade_id] = ("answer", rubric.answers.get(grade_id, 0.0))
    for number, part, _, _ in grade.held():
        found[f"exercise{number}/{part}"] = ("held", None)
    for number in rubric.graded:
        found[f"exercise{number}"] = ("exercise", None)
    return found


def read_marks(text, grades):
    """The rows of marks.csv `text`, each checked against `grades` (by name); ValueError listing every bad
    row (line number and why) when any is bad."""
    by_name = {grade.name: grade for grade in grades}
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    if header is None or [cell.strip().lower() for cell in header] != HEADER:
        shown = "nothing" if header is None else one_line(",".join(header), 120)
        raise InputError(f"marks.csv must start with the header {','.join(HEADER)}; it starts with {shown}.")
    marks, problems = [], []
    for line, row in enumerate(reader, start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) not in (3, 4):
            problems.append(f"line {line}: {len(row)} cells, not 4 ({','.join(HEADER)})")
            continue
        cell, item, points, comment = [*row, ""][:4]
        item, points = item.strip(), points.strip()
        name = name_from_cell(cell, by_name) or cell.strip()  # the whole name, as the page wrote it
        grade = by_name.get(name)
        if grade is None:
            problems.append(f"line {line}: no submission {one_line(name, 80)!r} in this run")
            continue
        if not grade.graded:
            problems.append(f"line {line}: {one_line(name, 80)} could not be graded, so it cannot be marked")
            continue
        known = items(grade)
        if item not in known:
            problems.append(
                f"line {line}: {one_line(item, 80)!r} is nothing to mark for {one_line(name, 80)} (an answer's "
                "grade id such as exercise12-answer-1, exerciseN/part of a held part, or exerciseN to excuse)"
            )
            continue
        kind, worth = known[item]
        value, why = _points(kind, worth, points)
        if not why and kind == "answer" and value and blank(grade.answers.get(item)):
            why = "the student wrote no answer (blank, or YOUR ANSWER HERE): it is marked 0, no answer"
        if why:
            problems.append(f"line {line}: {item} of {one_line(name, 80)}: {why}")
            continue
        marks.append(Mark(name, item, value, printable(comment).strip()[:MAX_COMMENT]))
    if problems:
        shown = problems[:20] + ([f"... and {len(problems) - 20} more"] if len(problems) > 20 else [])
        raise InputError("marks.csv was not imported, nothing changed:\n  " + "\n  ".join(shown))
    return marks


def _points(kind, worth, text):
    """(the points of a row, why they are refused or "")."""
    word = text.lower()
    if kind == "held":
        return (word, "") if word in HELD_WORDS else (None, f"points are release or keep, not {one_line(text, 20)!r}")
    if kind == "exercise":
        return (
            (word, "") if word in EXCUSE_WORDS else (None, f"points are excused or counted, not {one_line(text, 20)!r}")
        )
    try:
        value = float(text.replace(",", "."))
    except ValueError:
        return None, f"points {one_line(text, 20)!r} are not a number"
    if not 0.0 <= value <= worth:  # NaN fails this too
        if not worth:
            return None, "the rubric gives this answer no points: add it to the rubric's [answers] table"
        return None, f"points {one_line(text, 20)} are outside 0 to {points_text(worth)}"
    return round(value, 2), ""


def import_marks(out, path, rubric=None, now=None):
    """Put the marks of marks.csv `path` into the run in folder `out`; the number of marks that changed.

    Every row is checked first: an unknown submission or item, points outside the item's range or a
    `rubric` other than the run's (in what it grades) is a ValueError, and nothing is written."""
    out, path = Path(out), Path(path)
    try:
        if path.stat().st_size > MAX_MARKS_BYTES:
            raise InputError(f"{path} is larger than {MAX_MARKS_BYTES} bytes; it is not read.")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the marks {path}: {exc}") from None
    record = records.read(out)
    recorded = record.rubric_object(out)
    if rubric is not None and recorded.digest != rubric.digest:
        raise InputError(
            f"{out} was graded under the rubric {recorded.title!r} ({recorded.digest}), not {rubric.title!r} "
            f"({rubric.digest}): marks are imported under the run's own rubric; leave out --rubric."
        )
    grades = read_results([out], recorded)
    if grades.refused:
        raise InputError(
            f"{out} has result files its record does not vouch for ({one_line(grades.refused[0][0], 200)}); "
            "grade the class again before marking."
        )
    marks = read_marks(text, grades)
    when = (now or datetime.now(UTC)).isoformat(timespec="seconds")
    by_name = {grade.name: grade for grade in grades}
    changed = set()
    for mark in marks:  # a later row replaces an earlier one
        grade = by_name[mark.submission]
        held = grade.marks.get(mark.item)
        if held is not None and held["points"] == mark.points and held["comment"] == mark.comment:
            continue
        grade.marks[mark.item] = {"points": mark.points, "comment": mark.comment, "time": when}
        changed.add((mark.submission, mark.item))
    for name in sorted({name for name, _ in changed}):
        grade = by_name[name]
        content = record.submissions.get(name, {}).get("content")
        records.note(out, record, name, write_result(out, grade), content, save=False)
    if changed:
        records.write(out, record)
        write_csv(out / "grades.csv", list(grades))
    return len(changed)


def marks_csv(grades):
    """marks.csv of every mark `grades` hold (the file :func:`import_marks` reads)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(HEADER)
    for grade in grades:
        for item, mark in sorted(grade.marks.items()):
            points = mark["points"]
            writer.writerow([name_cell(grade.name), item, points if isinstance(points, str) else points_text(points),
                             csv_cell(mark["comment"])])  # fmt: skip
    return buffer.getvalue()


# -- the marking page ---------------------------------------------------------------------------------------------

PAGE = "marking.html"
SOLUTIONS = Path(__file__).resolve().parents[3] / "notebooks"  # the instructor notebooks, in a source tree
MAX_SHOWN = 20000  # characters of a student's answer shown


def model_answers(folder=SOLUTIONS):
    """{answer grade id: (the question, the model answer)} from the instructor notebooks in `folder` (empty
    when there are none, as in an installed labkit without its source tree)."""
    import nbformat

    from ..authoring.nbgrader import answer_ids
    from ..authoring.release import BEGIN_SOLUTION, END_SOLUTION

    found = {}
    for path in sorted(Path(folder).glob("*.ipynb")) if Path(folder).is_dir() else ():
        nb = nbformat.read(path, as_version=4)
        ids = iter(answer_ids(nb))
        previous = ""
        for cell in nb.cells:
            if cell.cell_type != "markdown":
                continue
            if BEGIN_SOLUTION in cell.source:
                inside = cell.source.split(BEGIN_SOLUTION, 1)[1].split(END_SOLUTION, 1)[0].strip()
                found[next(ids)] = (previous, inside)
            previous = cell.source
    return found


# the MathML a page may show: elements and attributes of presentation MathML, nothing that links or runs
MATHML_TAGS = {
    "math", "mrow", "mi", "mn", "mo", "ms", "mtext", "mspace", "msup", "msub", "msubsup", "mfrac", "msqrt",
    "mroot", "mover", "munder", "munderover", "mtable", "mtr", "mtd", "mstyle", "mpadded", "mphantom",
    "menclose", "semantics",
}  # fmt: skip
MATHML_ATTRIBUTES = {
    "display", "stretchy", "mathvariant", "fence", "separator", "lspace", "rspace", "accent", "accentunder",
    "columnalign", "rowspacing", "columnspacing", "displaystyle", "scriptlevel", "width", "height", "depth",
    "linethickness", "notation", "minsize", "maxsize", "symmetric", "movablelimits", "largeop",
}  # fmt: skip


def math_html(tex, display=False):
    """TeX a student wrote as MathML the browser typesets (offline, no script), every element and attribute
    from a fixed list and every text escaped; the TeX itself, escaped, when it cannot be converted."""
    import html
    import xml.etree.ElementTree as ET

    fallback = f'<span class="math{" display" if display else ""}">{html.escape(tex, quote=True)}</span>'
    try:
        from latex2mathml.converter import convert

        tree = ET.fromstring(convert(tex, display="block" if display else "inline"))
    except Exception:  # noqa: BLE001 - any TeX the converter cannot read is shown as it was written
        return fallback

    def build(node):
        tag = node.tag.rpartition("}")[2]
        if tag not in MATHML_TAGS:
            return html.escape("".join(node.itertext()))
        attributes = "".join(
            f' {name}="{html.escape(value, quote=True)}"'
            for name, value in node.attrib.items()
            if name in MATHML_ATTRIBUTES
        )
        inner = html.escape(node.text or "") + "".join(build(child) + html.escape(child.tail or "") for child in node)
        return f"<{tag}{attributes}>{inner}</{tag}>"

    return build(tree)


def render_markdown(text):
    """Markdown a student wrote as HTML that can run nothing: every character escaped first, then paragraphs,
    lists, ``code``, **strong**, *emphasis*; maths ($...$, $$...$$) as MathML (:func:`math_html`)."""
    import html
    import re

    escaped = html.escape(printable(text)[:MAX_SHOWN], quote=True)
    out, items = [], []

    def inline(line):
        maths = []  # typeset apart, so the emphasis rules below never reach into the MathML

        def keep(rendered):
            maths.append(rendered)
            return f"\x00{len(maths) - 1}\x00"  # printable() took every control character out of the text

        line = re.sub(r"`([^`]+)`", r"<code>\1</code>", line)
        line = re.sub(r"\$\$(.+?)\$\$", lambda m: keep(math_html(html.unescape(m.group(1)), display=True)), line)
        line = re.sub(r"\$([^$]+)\$", lambda m: keep(math_html(html.unescape(m.group(1)))), line)
        line = re.sub(r"\*\*([^*]+)\*\*", r"<strong>\1</strong>", line)
        line = re.sub(r"(?<![*\w])\*([^*]+)\*(?!\w)", r"<em>\1</em>", line)
        return re.sub(r"\x00(\d+)\x00", lambda m: maths[int(m.group(1))], line)

    def flush():
        if items:
            out.append("<ul>" + "".join(f"<li>{inline(i)}</li>" for i in items) + "</ul>")
            items.clear()

    for block in re.split(r"\n\s*\n", escaped.strip()):
        lines = block.splitlines()
        if all(re.match(r"\s*[-*] ", line) for line in lines):
            items.extend(re.sub(r"^\s*[-*] ", "", line) for line in lines)
            flush()
        elif lines:
            out.append("<p>" + "<br>".join(inline(line) for line in lines) + "</p>")
    return "".join(out) or "<p><em>(no answer)</em></p>"


def _rubric_lines(lines):
    """The rubric's lines for an answer ([answers] rubric), as a list under the model answer."""
    import html

    if not lines:
        return ""
    return '<p>Rubric:</p><ul class="rubric">' + "".join(f"<li>{html.escape(line)}</li>" for line in lines) + "</ul>"


def tasks(grades, marker="instructor"):
    """What the page marks, by item: [{"item", "title", "max", "kind", "answers": [...]}], each item's
    submissions in an order shuffled for `marker` (the same marker, the same order)."""
    import html
    import random

    if not grades:
        return []
    rubric = grades[0].rubric
    models = model_answers()
    found = []
    for grade_id, (number, what) in rubric.registry.answers.items():
        if number not in rubric.points or not rubric.answers.get(grade_id):  # only what is worth points
            continue
        question, model = models.get(grade_id, ("", ""))
        entries = [  # only answers the student wrote: a blank one is marked 0, no answer, and never queued
            {
                "submission": g.name,
                "shown": shown_name(g.name, 200),
                "html": render_markdown(g.answers.get(grade_id) or ""),
            }
            for g in grades
            if g.graded and not blank(g.answers.get(grade_id))
        ]
        if not entries:
            continue
        random.Random(f"{marker}\n{grade_id}").shuffle(entries)
        found.append({
            "item": grade_id, "kind": "answer", "max": rubric.answers.get(grade_id, 0.0),
            "title": f"Exercise {number}: {what}", "question": render_markdown(question),
            "model": render_markdown(model) + _rubric_lines(rubric.answer_lines.get(grade_id, ())),
            "answers": entries,
        })  # fmt: skip
    held = {}
    for g in grades:
        for number, part, data, _ in g.held() if g.graded else ():
            item = f"exercise{number}/{part}"
            pairs = [p for p in data.get("lines", ()) if isinstance(p, (list, tuple)) and len(p) == 2]
            rows = "".join(
                f"<tr><td><code>{html.escape(one_line(a, 200))}</code></td>"
                f"<td><code>{html.escape(one_line(b, 200))}</code></td></tr>"
                for a, b in pairs
            )
            side = (
                f'<table class="side"><caption>{float(data.get("share", 0)):.0%} the same as '
                f'{html.escape(one_line(data.get("source", "?"), 120))}</caption><thead><tr><th scope="col">'
                f'the student\'s code</th><th scope="col">the known source</th></tr></thead>'
                f"<tbody>{rows}</tbody></table>"
            )
            held.setdefault(item, []).append({"submission": g.name, "shown": shown_name(g.name, 200), "html": side})
    for item, entries in sorted(held.items()):
        random.Random(f"{marker}\n{item}").shuffle(entries)
        found.append({
            "item": item, "kind": "held", "max": 1, "title": f"Held: {item} (1 release, 0 keep)",
            "question": "<p>Its code matched a known source. Release its points (1) or keep them held (0).</p>",
            "model": "", "answers": entries,
        })  # fmt: skip
    return found


def _json_for_script(data):
    """JSON that cannot end a script element or a line of it."""
    text = json.dumps(data, ensure_ascii=True)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def write_page(out, marker="instructor", rubric=None):
    """OUT/marking.html: every item to mark, by keyboard, offline; the path written."""
    import base64
    import hashlib

    out = Path(out)
    record = records.read(out)
    recorded = record.rubric_object(out)
    if rubric is not None and recorded.digest != rubric.digest:
        raise InputError(f"{out} was graded under another rubric ({recorded.digest}); leave out --rubric.")
    grades = read_results([out], recorded)
    data = {"run": f"{recorded.digest}:{out.resolve()}", "title": recorded.title, "tasks": tasks(grades, marker)}
    script = SCRIPT.replace("__DATA__", _json_for_script(data))
    digest = base64.b64encode(hashlib.sha256(script.encode("utf-8")).digest()).decode("ascii")
    policy = f"default-src 'none'; script-src 'sha256-{digest}'; style-src 'unsafe-inline'; img-src data:"
    import html

    page = (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{policy}">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>Marking: {html.escape(one_line(recorded.title, 200))}</title>\n<style>{STYLE}</style>\n</head>\n"
        '<body>\n<header><h1>Marking</h1><p id="progress" role="status" aria-live="polite"></p>\n'
        '<p class="keys">Keys: digits give points, <kbd>j</kbd> or <kbd>&rarr;</kbd> next, <kbd>k</kbd> or '
        "<kbd>&larr;</kbd> previous, <kbd>c</kbd> the comment box (<kbd>Esc</kbd> leaves it).</p>\n"
        '<button type="button" id="download">Download marks.csv</button></header>\n'
        '<main id="main"><h2 id="title"></h2><section aria-labelledby="q-h"><h3 id="q-h">Question</h3>'
        '<div id="question"></div></section><section aria-labelledby="m-h"><h3 id="m-h">Model answer '
        '<span id="worth"></span></h3><div id="model"></div></section>'
        '<section aria-labelledby="a-h"><h3 id="a-h">Answer of <span id="who"></span></h3>'
        '<div id="answer" class="answer"></div></section>'
        '<p id="given" aria-live="polite"></p>'
        '<label for="comment">Comment</label> <input id="comment" list="comments" size="60">'
        '<datalist id="comments"></datalist></main>\n'
        f"<script>{script}</script>\n</body>\n</html>\n"
    )
    path = out / PAGE
    path.write_text(page, encoding="utf-8")
    return path


STYLE = """
body{font-family:system-ui,sans-serif;margin:0 auto;max-width:60rem;padding:1rem;color:#111;background:#fff}
.answer{border:2px solid #245;padding:.5rem 1rem;background:#f4f7fb}
.math{font-family:serif;font-style:italic;background:#eef}
table.side{border-collapse:collapse;width:100%}table.side td,table.side th{border:1px solid #999;padding:2px 6px;
vertical-align:top;text-align:left}kbd{border:1px solid #777;border-radius:3px;padding:0 3px}
#given{font-weight:bold}button{font-size:1rem}
"""

SCRIPT = r"""
(function(){
"use strict";
var DATA = __DATA__;
var KEY = "labkit-marks:" + DATA.run;
var order = [];
DATA.tasks.forEach(function(t, i){ t.answers.forEach(function(a, j){ order.push([i, j]); }); });
var state = {pos: 0, marks: {}};
try { var saved = JSON.parse(localStorage.getItem(KEY) || "null"); if (saved) state = saved; } catch (e) {}
function save(){ try { localStorage.setItem(KEY, JSON.stringify(state)); } catch (e) {} }
function id(t, a){ return JSON.stringify([a.submission, t.item]); }
function $(x){ return document.getElementById(x); }
function current(){ var p = order[state.pos]; return p ? [DATA.tasks[p[0]], DATA.tasks[p[0]].answers[p[1]]] : null; }
function text(points, kind){ if (kind === "held") return points === 1 ? "release" : "keep"; return String(points); }
function show(){
  var left = order.filter(function(p){ var t = DATA.tasks[p[0]]; return !state.marks[id(t, t.answers[p[1]])]; }).length;
  $("progress").textContent = left + " of " + order.length + " left to mark";
  var c = current(); if (!c) { $("title").textContent = "Nothing to mark"; return; }
  var t = c[0], a = c[1], m = state.marks[id(t, a)];
  $("title").textContent = t.title + " (" + (state.pos + 1) + " of " + order.length + ")";
  $("question").innerHTML = t.question; $("model").innerHTML = t.model || "<p>(none)</p>";
  $("worth").textContent = t.kind === "held" ? "" : "(worth " + t.max + ")";
  $("who").textContent = a.shown; $("answer").innerHTML = a.html;
  $("given").textContent = m ? "Marked: " + text(m.points, t.kind) : "Not marked yet";
  $("comment").value = m ? m.comment : "";
  var seen = {}, list = $("comments"); list.textContent = "";
  Object.keys(state.marks).forEach(function(k){ var s = state.marks[k].comment;
    if (s && !seen[s]) { seen[s] = 1; var o = document.createElement("option"); o.value = s; list.appendChild(o); } });
}
function give(points){
  var c = current(); if (!c) return; var t = c[0], a = c[1];
  if (points > t.max) return;
  state.marks[id(t, a)] = {points: points, comment: $("comment").value, submission: a.submission,
    item: t.item, kind: t.kind};
  save(); show();
}
function move(by){ state.pos = Math.max(0, Math.min(order.length - 1, state.pos + by)); save(); show(); }
$("comment").addEventListener("input", function(){
  var c = current(); if (!c) return; var m = state.marks[id(c[0], c[1])]; if (m) { m.comment = this.value; save(); } });
$("comment").addEventListener("keydown", function(e){
  if (e.key === "Escape" || e.key === "Enter") { this.blur(); e.preventDefault(); } });
document.addEventListener("keydown", function(e){
  if (e.target === $("comment") || e.ctrlKey || e.metaKey || e.altKey) return;
  if (/^[0-9]$/.test(e.key)) { give(Number(e.key)); e.preventDefault(); }
  else if (e.key === "j" || e.key === "ArrowRight") { move(1); e.preventDefault(); }
  else if (e.key === "k" || e.key === "ArrowLeft") { move(-1); e.preventDefault(); }
  else if (e.key === "c") { $("comment").focus(); e.preventDefault(); }
});
function cell(s){ s = String(s); if (/^[=+\-@\t\r]/.test(s)) s = "'" + s;
  return /[",\n\r]/.test(s) ? '"' + s.replace(/"/g, '""') + '"' : s; }
$("download").addEventListener("click", function(){
  var rows = ["submission,item,points,comment"];
  Object.keys(state.marks).forEach(function(k){ var m = state.marks[k];
    rows.push([cell(m.submission), cell(m.item), text(m.points, m.kind), cell(m.comment || "")].join(",")); });
  var blob = new Blob([rows.join("\r\n") + "\r\n"], {type: "text/csv"});
  var link = document.createElement("a"); link.href = URL.createObjectURL(blob); link.download = "marks.csv";
  document.body.appendChild(link); link.click(); link.remove();
});
show();
})();
"""
