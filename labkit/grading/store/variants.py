"""``variants.csv`` of a run with variants (:mod:`labkit.exercises.variants`): who had which data."""

from pathlib import Path

from .record import replace_text
from .report import csv_cell, csv_text

VARIANTS_CSV = "variants.csv"


def write_variants(out, grades, students, roster, registry):
    """``variants.csv``, for the instructor only: each submission's roster id and data, and the classmates
    whose data its notebooks hold instead (``another variant`` when no one in the class has them)."""
    varied = [e for e in registry if e.params]
    rows = [["submission", "id", *(f"exercise {e.number}" for e in varied), "holds the data of"]]
    for grade in grades:
        mine = students.get(grade.name)
        if mine is None:
            continue
        holds = []
        for exercise in varied:
            other = getattr(grade.results.get(exercise.number), "other_variant", None) or {}
            if not other:
                continue
            params = {p.name: p for p in exercise.params}
            whose = [
                name
                for name, data in students.items()
                if name != grade.name
                and all(
                    param in params and params[param].holds(found, data.get(str(exercise.number), {}).get(param))
                    for param, (found, _) in other.items()
                )
            ]
            holds.append(f"exercise {exercise.number}: " + (", ".join(whose) if whose else "another variant"))
        shown = [", ".join(f"{p} = {v}" for p, v in mine.get(str(e.number), {}).items()) for e in varied]
        rows.append([grade.name, roster.get(grade.name, ""), *shown, "; ".join(holds)])
    replace_text(Path(out) / VARIANTS_CSV, csv_text([csv_cell(cell) for cell in row] for row in rows))
