"""``labkit feedback OUT``: each student's feedback page in a zip named for the LMS's bulk upload."""

import sys

from . import options


def add(commands):
    """Declare the command and its options."""
    parser = commands.add_parser(
        "feedback",
        help="write OUT/feedback-upload.zip: each student's feedback page, named for the LMS's bulk upload",
        description="Read the results/ of a `labkit grade` run in OUT and write OUT/feedback-upload.zip: each "
        "student's feedback as one HTML page, named as the LMS the class came from needs it (the run recorded "
        "its layout): Canvas's 'Re-upload submissions', Moodle's 'Upload multiple feedback files in a zip', "
        "<submission>/feedback.html for a folder per student, and nbgrader's feedback/ folder.",
    )
    options.run_folder(parser)
    parser.add_argument(
        "--layout",
        metavar="LMS",
        help="name the files for this LMS instead of the one the run recorded: canvas, moodle, folders, nbgrader, "
        "or the name of an LMS module added to labkit/grading/lms/",
    )
    parser.set_defaults(handler=handle)


def handle(args):
    """Write the upload zip and say how to hand it to the LMS; 1 when something is noted about it."""
    from ..grading.lms import delivery, named

    path, members, notes = delivery.write_upload(args.out, args.layout)
    for line in notes:
        print(f"labkit feedback: {line}", file=sys.stderr)
    print(f"wrote {path}: {len(members)} file(s); {named(delivery.layout_of(args.out, args.layout)).steps}")
    return 1 if notes else 0
