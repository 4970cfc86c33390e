"""The ``labkit`` command: ``labkit execute [NOTEBOOK_DIR]``."""
import argparse
import sys
from pathlib import Path

DEFAULT_NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"


def _execute(args):
    from .notebooks import execute, notebook_paths

    for path in notebook_paths(args.notebooks):
        print(f"executing {path.name} ...", flush=True)
        execute(path, timeout=args.timeout)
    return 0


def build_parser():
    parser = argparse.ArgumentParser(prog="labkit", description="Course kit tools for the interpolation lab.")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser(
        "execute",
        help="re-execute every notebook in a fresh kernel and save it clean (the reference outputs)",
    )
    run.add_argument("notebooks", nargs="?", type=Path, default=DEFAULT_NOTEBOOKS,
                     help="folder of notebooks (default: the kit's notebooks/)")
    run.add_argument("--timeout", type=int, default=300, help="seconds allowed per cell")
    run.set_defaults(handler=_execute)
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except ValueError as exc:
        print(f"labkit {args.command}: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
