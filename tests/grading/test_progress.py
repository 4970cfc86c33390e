"""The progress bar of `labkit grade` and `labkit merge`: counts and an ETA on a terminal, nothing anywhere else."""

import io

from rich.console import Console

from labkit.grading.progress import Progress


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def _run(console, total=4, done=2, seconds=20.0, **options):
    clock = Clock()
    with Progress(total, "grading", console=console, get_time=clock, **options) as bar:
        for _ in range(done):
            clock.now += seconds / done
            bar.advance()
    return bar


def test_nothing_is_printed_when_the_output_is_not_a_terminal(capsys):
    screen = io.StringIO()
    bar = _run(Console(file=screen))  # a file: not a terminal
    assert screen.getvalue() == "" and not bar.shown
    with Progress(3, "grading") as bar:  # standard error, captured by pytest: not a terminal
        bar.advance(3)
    assert capsys.readouterr() == ("", "") and bar.done == 3


def test_on_a_terminal_it_shows_the_counts_and_an_eta():
    screen = io.StringIO()
    bar = _run(Console(file=screen, force_terminal=True, width=100), total=4, done=2, seconds=20.0)
    drawn = screen.getvalue()
    # 2 of 4 done in 20 s: 10 s each, so 20 s to go
    assert bar.shown and "grading" in drawn and "2/4" in drawn and "ETA 0:00:20" in drawn
    assert "0/4" in drawn and "ETA -:--:--" in drawn  # before the first one finishes there is no estimate


def test_the_eta_follows_the_time_per_item_so_far():
    screen = io.StringIO()
    _run(Console(file=screen, force_terminal=True, width=100), total=10, done=1, seconds=90.0)
    assert "1/10" in screen.getvalue() and "ETA 0:13:30" in screen.getvalue()  # 9 left at 90 s each


def test_quiet_turns_it_off_on_a_terminal_too():
    screen = io.StringIO()
    bar = _run(Console(file=screen, force_terminal=True), enabled=False)
    assert screen.getvalue() == "" and not bar.shown and bar.done == 2


def test_nothing_to_do_draws_nothing():
    screen = io.StringIO()
    _run(Console(file=screen, force_terminal=True), total=0, done=0)
    assert screen.getvalue() == ""
