"""A progress bar with counts and an ETA, for the instructor's long commands (``labkit grade``, ``labkit merge``).

:class:`Progress` draws with `rich <https://rich.readthedocs.io>`_ on standard error, only on a terminal: in a batch
job's log, a pipe or a file it prints nothing at all (``--quiet`` turns it off on a terminal too).

>>> with Progress(3, "grading") as bar:  # not a terminal here: nothing is drawn
...     bar.advance()
>>> bar.shown
False
"""

from collections.abc import Callable
from datetime import timedelta
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console


def _eta_column():
    from rich.progress import ProgressColumn
    from rich.text import Text

    class Eta(ProgressColumn):
        """The time left: the time per finished item so far, times the items left (grading's items take similar
        times but finish in bursts when several run at once, which this average evens out)."""

        def render(self, task):
            if not task.completed or task.total is None or task.elapsed is None:
                return Text("ETA -:--:--", style="progress.remaining")
            left = task.elapsed / task.completed * max(task.total - task.completed, 0)
            return Text(f"ETA {timedelta(seconds=round(left))}", style="progress.remaining")

    return Eta()


class Progress:
    """Counts of `total` items done, a bar, the time taken and an ETA, after what is being done (`what`, "grading");
    drawn on `console` (standard error when None) only when it is a terminal, and never with `enabled` False
    (``--quiet``). `get_time` is the clock in seconds, for tests (rich's own when None).

    >>> import io
    >>> from rich.console import Console
    >>> now = [0.0]
    >>> screen = Console(file=io.StringIO(), force_terminal=True, width=80)
    >>> with Progress(4, "grading", console=screen, get_time=lambda: now[0]) as bar:
    ...     now[0] = 10.0  # one of four done after 10 s: 30 s to go
    ...     bar.advance()
    >>> drawn = screen.file.getvalue()
    >>> "1/4" in drawn and "ETA 0:00:30" in drawn
    True
    """

    def __init__(
        self,
        total: int,
        what: str = "working",
        *,
        enabled: bool = True,
        console: "Console | None" = None,
        get_time: Callable[[], float] | None = None,
    ) -> None:
        self.total, self.done = int(total), 0
        self._bar = None
        if not enabled or self.total <= 0:
            return
        from rich.console import Console

        console = console if console is not None else Console(stderr=True)
        if not console.is_terminal:
            return
        from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeElapsedColumn
        from rich.progress import Progress as Bar

        self._bar = Bar(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            _eta_column(),
            console=console,
            get_time=get_time,
            auto_refresh=False,
        )
        self._task = self._bar.add_task(what, total=self.total)

    @property
    def shown(self) -> bool:
        """Whether the bar is drawn (on a terminal, not turned off)."""
        return self._bar is not None

    def __enter__(self) -> "Progress":
        if self._bar is not None:
            self._bar.start()
            self._bar.refresh()
        return self

    def advance(self, count: int = 1) -> None:
        """Count `count` more items done and redraw."""
        self.done += count
        if self._bar is not None:
            self._bar.update(self._task, completed=self.done)
            self._bar.refresh()

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.stop()
