"""The submissions `labkit grade`'s arguments name: one class folder or zip as the LMS gives it
(labkit.grading.lms.intake), or the submissions one by one; ``--student`` picks some of a class."""

from ..errors import InputError


class Chosen:
    """The submissions to grade: their paths and names, students with nothing to grade ({name: why}), notes for
    the instructor, the names the LMS marked late, and the intake they came from (for ``labkit feedback``)."""

    def __init__(self, paths, names=None, ungradable=None, notes=(), marked_late=()):
        self.paths, self.names, self.ungradable = paths, names, dict(ungradable or {})
        self.notes, self.marked_late = list(notes), set(marked_late)
        self.intake = None


def chosen(args, workspace):
    """The :class:`Chosen` submissions of `args`, a class unpacked into `workspace` when it is a zip."""
    found = _found(args, workspace)
    if args.student:
        found.students = _picked(found.students, args.student, args.submissions[0])
    gradable = [student for student in found.students if student.path is not None]
    result = Chosen(
        [student.path for student in gradable],
        [student.name for student in gradable],
        {student.name: student.failure for student in found.students if student.path is None},
        (
            [f"{found.layout} layout in {args.submissions[0]}: {len(found.students)} student(s)"]
            if found.layout != "listed"
            else []
        )
        + found.notes,
        {student.name for student in found.students if student.marked_late},
    )  # (a listed submission's name is its folder's or notebook's, as before)
    result.intake = found  # the layout and the LMS's names, for handing the feedback back (labkit feedback)
    return result


def _found(args, workspace):
    """intake's students of the class folder (or zip), or of the submissions given one by one."""
    from ..grading.lms import intake

    paths = args.submissions
    if len(paths) != 1 or not intake.is_class(paths[0]):
        for flag, value in (("--assignment", args.assignment), ("--student", args.student)):
            if value:
                raise InputError(f"{flag} picks from a class folder (or zip) as the LMS gives it; give that folder.")
        return intake.find_students(paths, workspace)
    from ..grading.lms.roster import read_roster

    roster = read_roster(args.roster) if args.roster is not None else None  # its ids decide whose a file is
    return intake.find_class(paths[0], workspace, assignment=args.assignment, roster=roster)


def _picked(students, wanted, folder):
    """The `students` named in `wanted` (``--student``); a name the class does not have is refused."""
    names = {student.name for student in students}
    unknown = [name for name in wanted if name not in names]
    if unknown:
        from ..grading.store.report import one_line

        shown = ", ".join(repr(one_line(name, 64)) for name in sorted(names)[:10])
        raise InputError(
            f"--student {one_line(unknown[0], 60)!r} is not in {folder}; its students are named {shown}"
            f"{' ...' if len(names) > 10 else ''} (as in grades.csv)."
        )
    return [student for student in students if student.name in wanted]
