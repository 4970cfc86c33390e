"""``labkit execute DIR``: re-run the instructor notebooks of DIR and save them clean."""

from ..errors import InputError
from . import options


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "execute",
        help="re-execute every notebook in a fresh kernel and save it clean",
        description="Re-execute the notebooks top to bottom in a fresh python3 kernel and save "
        "them without widget state: the reference outputs nbval compares against. Each notebook's "
        "student release is run too, and the cells that raise there are tagged raises-exception, "
        "so that Run All in a fresh copy goes on to the explorers.",
    )
    options.instructor_notebooks(parser)
    options.cell_timeout(parser)
    options.rubric(parser, "TOML rubric whose points nbgrader's test cells get (default: the lab's)")
    parser.set_defaults(handler=handle)


def handle(args):
    """Execute each notebook, tagging the cells that raise in its student release; a failing one is not saved."""
    from nbclient.exceptions import CellExecutionError

    from ..execute import execute, notebook_paths
    from ..grading.authoring.release import mark, tag_raising
    from ..grading.store.rubric import load

    rubric = load(args.rubric)  # nbgrader's points are the rubric's in force

    for path in notebook_paths(args.notebooks):

        def marked(nb, name, folder=path.parent):
            tag_raising(nb, folder, name, args.timeout)  # Run All goes on past them in the student's copy
            return mark(nb, name, rubric)

        print(f"executing {path.name} ...", flush=True)
        try:
            execute(path, timeout=args.timeout, before_save=marked)
        except CellExecutionError as exc:
            raise InputError(f"{path.name} failed; it was not saved.\n{str(exc)[:2000]}") from None
    return 0
