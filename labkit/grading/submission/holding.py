"""Parts built on code that is not the student's (:func:`labkit.grading.submission.scoring.grade_notebook`):
parts without a refusal judged for known code on what draws them, and parts reaching held or string-run
definitions holding or failing with them."""

from __future__ import annotations

from ...exercises.result import REFUSED
from ..store.report import HELD_STEP
from . import scan


def judge_plain(check, part, code, graded, judge):
    """A passed part without a refusal, `judge`d (check, [(name, source)]) on what draws it but `graded` names."""
    if not check["passed"]:
        return check
    readable = [n for n in part.names() if n.isidentifier()]
    try:
        reached = scan.reached_sources(code, sorted(scan.drawn_with(code, readable)))
    except scan.Unreadable:
        return check
    return judge(check, [(n, t) for n, t in reached if n not in graded])


def hold_dependents(results, registry, code, graded, rescore):
    """Hold, in `results` ({exercise: verdict}), every passed part whose code reaches a held definition, and
    fail those reaching a `graded` name a string run as code may have defined; `rescore` (verdict, registry)."""
    held = {}  # name: its held match, for the held parts' graded names and the copies
    for number, verdict in results.items():
        for part, check in zip(registry.exercises[number].parts, verdict["checks"]):
            if check.get("held") and check.get("passed"):
                for name in (*part.scanned, check["held"].get("definition", "")):
                    held.setdefault(name, check["held"])
    try:
        strung = {name: why for name, _, why in scan.run_strings(code, sorted(graded))}
    except scan.Unreadable:
        strung = {}
    if not held and not strung:
        return results
    for number, verdict in results.items():
        parts = registry.exercises[number].parts
        for index, (part, check) in enumerate(zip(parts, verdict["checks"])):
            if not check.get("passed") or check.get("held"):
                continue
            readable = [n for n in (*part.names(), *part.scanned) if n.isidentifier()]
            try:
                names = set(part.uses) | scan.drawn_with(code, readable)
            except scan.Unreadable:
                names = set(part.uses)
            names -= set(part.scanned)
            on_held, on_string = [n for n in held if n in names], sorted(names & strung.keys())  # graded names first
            if on_held:
                verdict["checks"][index] = _held_with(check, on_held[0], held[on_held[0]])
            elif on_string:
                verdict["checks"][index] = _refused_with(check, on_string[0], strung[on_string[0]])
        rescore(verdict, registry)
    return results


def _held_with(check, name, held):
    detail = (
        f"it is built on {name}, held for your instructor to look at: its code is mostly {held.get('source', '?')}'s"
    )
    hint = (
        f"this part waits with {name}, which it is built on; write {name} in your own way to be paid without waiting."
    )
    steps = list(check.get("steps", [])) + [{"step": HELD_STEP, "passed": False, "detail": detail}]
    return {**check, "held": {**held, "through": name}, "steps": steps, "hint": hint}


def run_from_a_string(check, findings):
    """The part's check, failed: a graded name may have been defined by code run from a string (`findings`)."""
    name, _, why = findings[0]
    return _refused_with(check, name, why, step="its code can be read")


def _refused_with(check, name, why, step="is built on the student's own code"):
    step = {"step": step, "passed": False, "detail": why, "kind": REFUSED}
    hint = (
        f"define {name} with def in a code cell, after any exec, eval or compile of a string, so that the grader "
        "can read it; code run from a string is never graded."
    )
    return {**check, "passed": False, "steps": list(check.get("steps", [])) + [step], "hint": hint}
