"""``labkit handin DIR``: ready to hand in? Run DIR's notebooks and list what is left to do."""

import sys
from pathlib import Path

from ..errors import InputError
from . import options


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "handin",
        help="ready to hand in? run your notebooks and list what is left to do",
        description="Run each lab notebook in DIR in a fresh kernel (every cell, even after one raised) and "
        "print, per notebook, the table its last cell shows: each graded part done and passing its "
        "self-check, failing (with the hint) or not done; the cells that raised; the answers in words "
        "left empty. Only the self-checks run, never the grader. Exit status: 0 when every notebook is ready, "
        "1 when something is left to do, 2 for bad input.",
    )
    parser.add_argument("folder", type=Path, metavar="DIR", help="the folder with your notebooks (or one notebook)")
    options.cell_timeout(parser)
    parser.set_defaults(handler=handle)


def _notebooks(folder):
    """The notebooks of `folder` (or `folder` itself, a notebook)."""
    if not folder.exists():
        raise InputError(f"there is no {folder}; give the folder that holds your notebooks (or one notebook).")
    if folder.is_file():
        files = [folder] if folder.suffix == ".ipynb" else []
    else:
        files = sorted(p for p in folder.glob("*.ipynb") if not p.name.startswith("."))
    if not files:
        raise InputError(f"{folder} holds no notebooks (*.ipynb); give the folder you work in.")
    return files


def _runner():
    """handin's run_notebook, refused when nbclient is missing (a student's install may lack it)."""
    try:
        import nbclient  # noqa: F401 - say so before running anything

        from ..handin import run_notebook
    except ModuleNotFoundError as exc:
        raise InputError(
            f"labkit handin runs the notebooks with {exc.name}, which is not installed: pip install nbclient"
        ) from None
    return run_notebook


def handle(args):
    """Run the lab's notebooks of the folder and print what each has left to do; 1 unless all are ready."""
    from ..handin import _wrapped, lab_notebook_of
    from ..handin_summary import folder_lines

    files = _notebooks(args.folder)
    if args.timeout < 1:
        raise InputError(f"--timeout must be at least 1 second; got {args.timeout}.")
    lab = [(path, lab_notebook_of(path)) for path in files]
    skipped = [path.name for path, name in lab if name is None]
    lab = [(path, name) for path, name in lab if name is not None]
    if not lab:
        raise InputError(
            f"none of the notebooks in {args.folder} is one of the lab's ({', '.join(skipped)}); give the folder "
            "that holds 01_limacon.ipynb ... 06_bilinear.ipynb."
        )
    run_notebook = _runner()
    results = []
    for path, _ in lab:
        print(f"running {path.name} ...", file=sys.stderr, flush=True)
        result = run_notebook(path, timeout=args.timeout)
        if path.name != result.notebook:
            result.notebook = f"{path.name} ({result.notebook})"
        results.append(result)
        print(result.text() + "\n", flush=True)
    ready = sum(result.ready for result in results)
    if skipped:
        print(f"Not lab notebooks, not run: {', '.join(skipped)}.")
    for line in folder_lines([name for _, name in lab], ready):
        print(_wrapped(line, ""))
    return 0 if ready == len(results) else 1
