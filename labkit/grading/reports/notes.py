"""What a grading run or merge tells the instructor when it ends, as lines of text the command line prints
(``labkit grade``, ``labkit merge``)."""

import json

from ..store.late import unknown_times
from ..store.report import one_line


def _names(found):
    shown = ", ".join(repr(one_line(name, 40)) for name in sorted(found)[:5])
    return shown + (f" and {len(found) - 5} more" if len(found) > 5 else "")


def time_notes(grades, rubric, times):
    """The lines on a run's submission times for the instructor, and how many times could not be read: of
    `grades`, scored under `rubric`, with the `times` given with ``--times`` by submission name (or None)."""
    graded = {g.name for g in grades}
    lines = []
    if times and rubric.late is None:
        lines.append(
            "labkit grade: the rubric has no [late] table, so the times cost nothing; they are saved with the "
            "results for a `labkit merge` with a rubric that has one."
        )
    stray = set(times or ()) - graded
    if stray:
        lines.append(f"labkit grade: the times file names submission(s) not in this run: {_names(stray)}.")
    extended = {name for name, _ in rubric.late.extensions} - graded if rubric.late else set()
    if extended:
        lines.append(
            f"labkit grade: the rubric's [late.extensions] name submission(s) not in this run: {_names(extended)}."
        )
    unknown = unknown_times(grades)
    for name, note, error in unknown:
        lines.append(f"{'time unreadable' if error else 'no time'} for {one_line(name, 80)}: {one_line(note, 300)}")
    if unknown:
        lines.append(
            f"labkit grade: {len(unknown)} submission(s) have no known time, so no late penalty; give their times "
            "in --times TIMES.csv (submission,time) and merge again (labkit merge DIR --times TIMES.csv --out NEW)."
        )
    return lines, sum(error for *_, error in unknown)


def late_mark_notes(grades, marked):
    """A line per graded submission the LMS marked late whose time is unknown (so no penalty was applied)."""
    return [
        f"labkit grade: the LMS marked {one_line(g.name, 80)} late, but gave no time: give the LMS's submission "
        "times in --times TIMES.csv for the late rule to apply."
        for g in grades
        if g.name in marked and g.graded and (g.time is None or g.time.when is None)
    ]


def resumed_notes(out):
    """How many submissions the run into `out` graded now and kept from an earlier run, and which shard it was
    (from its ``run.json``; nothing when that cannot be read)."""
    try:
        record = json.loads((out / "run.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    changed = record.get("graded again, changed")
    again = f", {changed} of them graded again because their notebooks changed" if changed else ""
    if record.get("already graded") or changed:
        lines = [
            f"resumed {out}: {record['already graded']} submission(s) were graded there already and kept, "
            f"{record.get('graded now', 0)} graded now{again} (--fresh grades all again)"
        ]
    else:
        lines = [f"graded {record.get('graded now', 0)} submission(s) now"]
    if record.get("shard"):
        lines.append(
            f"shard {record['shard']}: {record.get('submissions')} submission(s); combine the shards with "
            "`labkit merge`"
        )
    return lines


def holding_another_variant(grades):
    """How many graded submissions hold another student's data in some exercise."""
    return sum(any(v.other_variant for v in g.results.values()) for g in grades if g.graded)
