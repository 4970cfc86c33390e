"""What only a person can mark, as a page: answers in words, held parts and excused exercises (``labkit mark``).
The page writes ``marks.csv``; :mod:`labkit.grading.store.marks` says what a row holds and reads it into the run
(``labkit mark OUT --import marks.csv``)."""

import base64
import functools
import hashlib
import json
import random
import re
import xml.etree.ElementTree as ET
from pathlib import Path

from markupsafe import Markup

from ...errors import InputError
from ...execute import read_notebook
from .. import pages
from ..authoring.release import BEGIN_SOLUTION, END_SOLUTION, answer_ids
from ..store import record as records
from ..store.feedback import blank
from ..store.names import shown_name
from ..store.report import one_line, printable, read_results

PAGE = "marking.html"
SOLUTIONS = Path(__file__).resolve().parents[3] / "notebooks"  # the instructor notebooks, in a source tree
MAX_SHOWN = 20000  # characters of a student's answer shown
LIST_ITEM = re.compile(r"^\s*[-*] ")
# code and maths are set apart first, in this order (no emphasis inside them), then the emphasis around them
ATOMS = (
    ("code", re.compile(r"`([^`]+)`")),
    ("display", re.compile(r"\$\$(.+?)\$\$")),
    ("math", re.compile(r"\$([^$]+)\$")),
)
EMPHASIS = (("strong", re.compile(r"\*\*([^*]+)\*\*")), ("em", re.compile(r"(?<![*\w])\*([^*]+)\*(?!\w)")))
KEPT = re.compile(r"\x00(\d+)\x00")  # an atom's place in a line: printable() took every control character out


def model_answers(folder=SOLUTIONS):
    """{answer grade id: (the question, the model answer)} from the instructor notebooks in `folder` (empty
    when there are none, as in an installed labkit without its source tree)."""
    found = {}
    for path in sorted(Path(folder).glob("*.ipynb")) if Path(folder).is_dir() else ():
        nb = read_notebook(path)
        ids = iter(answer_ids(nb))
        previous = ""
        for cell in (cell for cell in nb.cells if cell.cell_type == "markdown"):
            if BEGIN_SOLUTION in cell.source:
                inside = cell.source.split(BEGIN_SOLUTION, 1)[1].split(END_SOLUTION, 1)[0].strip()
                found[next(ids)] = (previous, inside)
            previous = cell.source
    return found


def _parts():
    """The macros of ``templates/marking_parts.html``, which turn a student's text into HTML, escaped."""
    return pages.environment().get_template("marking_parts.html").module


def math_html(tex, display=False):
    """TeX a student wrote as MathML the browser typesets (offline, no script), every element and attribute
    from a fixed list and every text escaped; the TeX itself, escaped, when it cannot be converted."""
    try:
        from latex2mathml.converter import convert

        tree = ET.fromstring(convert(tex, display="block" if display else "inline"))
    except Exception:  # noqa: BLE001 - any TeX the converter cannot read is shown as it was written
        tree = None
    return _parts().math(tree, tex, display)


def _spans(line):
    """A line of Markdown as (kind, content) spans: plain text (kind None), code, maths (its MathML), or strong
    and em holding spans of their own."""
    kept = []

    def keep(kind, match):
        inner = match.group(1)
        kept.append(("code", inner) if kind == "code" else ("math", math_html(inner, display=kind == "display")))
        return f"\x00{len(kept) - 1}\x00"

    for kind, pattern in ATOMS:
        line = pattern.sub(functools.partial(keep, kind), line)
    return _emphasis(line, kept, EMPHASIS)


def _emphasis(text, kept, rules):
    if not rules:
        return [kept[int(part)] if i % 2 else (None, part) for i, part in enumerate(KEPT.split(text)) if part]
    (kind, pattern), rest = rules[0], rules[1:]
    spans, at = [], 0
    for match in pattern.finditer(text):
        spans += [*_emphasis(text[at : match.start()], kept, rest), (kind, _emphasis(match.group(1), kept, rest))]
        at = match.end()
    return spans + _emphasis(text[at:], kept, rest)


def _blocks(text):
    """Markdown a student wrote as ("list" or "paragraph", [spans of each item or line]) blocks."""
    blocks = []
    for block in re.split(r"\n\s*\n", printable(text)[:MAX_SHOWN].strip()):
        lines = block.splitlines()
        if lines and all(LIST_ITEM.match(line) for line in lines):
            blocks.append(("list", [_spans(LIST_ITEM.sub("", line, count=1)) for line in lines]))
        elif lines:
            blocks.append(("paragraph", [_spans(line) for line in lines]))
    return blocks


def render_markdown(text):
    """Markdown a student wrote as HTML that can run nothing: paragraphs, lists, ``code``, **strong**,
    *emphasis*; maths ($...$, $$...$$) as MathML (:func:`math_html`); every text escaped."""
    return str(_parts().markdown(_blocks(text)))


def _answer_task(rubric, grades, grade_id, models):
    """The task of marking answer `grade_id`, or None when no student wrote it (a blank one is marked 0, no
    answer, and never queued)."""
    number, what = rubric.registry.answers[grade_id]
    question, model = models.get(grade_id, ("", ""))
    entries = [
        {"submission": g.name, "shown": shown_name(g.name, 200), "html": render_markdown(g.answers.get(grade_id) or "")}
        for g in grades
        if g.graded and not blank(g.answers.get(grade_id))
    ]
    if not entries:
        return None
    return {
        "item": grade_id, "kind": "answer", "max": rubric.answers.get(grade_id, 0.0),
        "title": f"Exercise {number}: {what}", "question": render_markdown(question),
        "model": str(_parts().model(_blocks(model), rubric.answer_lines.get(grade_id, ()))), "answers": entries,
    }  # fmt: skip


def _held_tasks(grades):
    """The tasks of the parts held for a person: release or keep, by item."""
    held = {}
    for g in grades:
        for number, part, data, _ in g.held() if g.graded else ():
            lines = [p for p in data.get("lines", ()) if isinstance(p, (list, tuple)) and len(p) == 2]
            pairs = [(one_line(a, 200), one_line(b, 200)) for a, b in lines]
            side = _parts().held(float(data.get("share", 0)), one_line(data.get("source", "?"), 120), pairs)
            entry = {"submission": g.name, "shown": shown_name(g.name, 200), "html": str(side)}
            held.setdefault(f"exercise{number}/{part}", []).append(entry)
    return [
        {"item": item, "kind": "held", "max": 1, "title": f"Held: {item} (1 release, 0 keep)",
         "question": str(_parts().held_question()), "model": "", "answers": entries}
        for item, entries in sorted(held.items())
    ]  # fmt: skip


def tasks(grades, marker="instructor"):
    """What the page marks, by item: [{"item", "title", "max", "kind", "answers": [...]}], each item's
    submissions in an order shuffled for `marker` (the same marker, the same order)."""
    if not grades:
        return []
    rubric = grades[0].rubric
    models = model_answers()
    worth = [
        i for i, (number, _) in rubric.registry.answers.items() if number in rubric.points and rubric.answers.get(i)
    ]
    found = [task for i in worth if (task := _answer_task(rubric, grades, i, models))] + _held_tasks(grades)
    for task in found:
        random.Random(f"{marker}\n{task['item']}").shuffle(task["answers"])
    return found


def _json_for_script(data):
    """JSON that cannot end a script element or a line of it."""
    text = json.dumps(data, ensure_ascii=True)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def write_page(out, marker="instructor", rubric=None):
    """OUT/marking.html: every item to mark, by keyboard, offline; the path written. Its one script is
    ``templates/marking.js`` with the tasks as data, and the page's policy runs that script alone."""
    out = Path(out)
    recorded = records.read(out).rubric_object(out)
    if rubric is not None and recorded.digest != rubric.digest:
        raise InputError(f"{out} was graded under another rubric ({recorded.digest}); leave out --rubric.")
    grades = read_results([out], recorded)
    data = {"run": f"{recorded.digest}:{out.resolve()}", "title": recorded.title, "tasks": tasks(grades, marker)}
    script = str(pages.script("marking.js")).replace("__DATA__", _json_for_script(data))
    digest = base64.b64encode(hashlib.sha256(script.encode("utf-8")).digest()).decode("ascii")
    page = pages.render(PAGE, title=one_line(recorded.title, 200), digest=digest, code=Markup(script))
    path = out / PAGE
    path.write_text(page, encoding="utf-8")
    return path
