"""Progress of a long command on stderr, with the time elapsed and an estimate of the time left.

On a terminal, one line redrawn in place:

    with Progress(len(paths), "validate") as bar:
        for path in paths:
            bar.update(note=path)
            # draws "validate  2/5 [#########---------------]  40 %  elapsed 12 s  ETA 18 s  b.json"
            ...
            bar.clear()  # before printing results on stdout
            print(result)
            bar.advance()

Piped or redirected (a log file, a CI job), a line per completed unit of work, at most one
every ``LOG_INTERVAL`` seconds, and the last one closing a log that has lines: a short command
writes none, a long one leaves a log:

    validate: 2/5 done (40 %), elapsed 12 s, ETA 18 s

The estimate is the mean time per unit done so far times the units left (units of unequal
cost, such as a sweep's stages, make it approximate); it appears once a unit is done.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

# Width of the bar [characters], shortest time between two draws on a terminal [s] and
# between two logged lines elsewhere [s].
WIDTH = 24
REDRAW_INTERVAL = 0.1
LOG_INTERVAL = 10.0


def duration(seconds: float) -> str:
    """A duration as a person reads it: "8 s", "2 min 05 s", "1 h 02 min"."""
    seconds = max(int(round(seconds)), 0)
    if seconds < 60:
        return f"{seconds} s"
    minutes, seconds = divmod(seconds, 60)
    if minutes < 60:
        return f"{minutes} min {seconds:02d} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min"


class Progress:
    """Progress of ``total`` units of work on ``stream``, timed from its creation.

    Args:
        total: units of work (files, optimizations of a sweep).
        label: what is being done, first on the line.
        stream: where to write (default: ``sys.stderr``); on a terminal, one line redrawn in
            place, else a line per completed unit, at most one every ``interval`` seconds.
        interval: shortest time between two logged lines [s] (default ``LOG_INTERVAL``).
    """

    def __init__(
        self,
        total: int,
        label: str = "",
        stream: TextIO | None = None,
        interval: float | None = None,
    ):
        self.total, self.label = max(int(total), 0), label
        self.stream = sys.stderr if stream is None else stream
        isatty = getattr(self.stream, "isatty", None)
        self.terminal = bool(isatty and isatty())
        self.interval = LOG_INTERVAL if interval is None else interval
        self.done = 0
        self.note = ""
        self._start = time.monotonic()
        self._drawn_at = -float("inf")
        self._logged_at = self._start
        self._logged_done = 0
        self._visible = False

    def _fraction(self) -> float:
        return min(self.done / max(self.total, 1), 1.0)

    def timing(self, separator: str = "  ") -> str:
        """The time elapsed and, once a unit is done and until the last, the time left."""
        elapsed = time.monotonic() - self._start
        text = f"elapsed {duration(elapsed)}"
        if 0 < self.done < self.total:
            text += f"{separator}ETA {duration(elapsed / self.done * (self.total - self.done))}"
        return text

    def line(self) -> str:
        """The text of the bar now (on a terminal)."""
        filled = round(WIDTH * self._fraction())
        text = (
            f"{self.label}  {self.done}/{self.total} [{'#' * filled}{'-' * (WIDTH - filled)}] "
            f"{100 * self._fraction():3.0f} %  {self.timing()}"
        )
        return f"{text}  {self.note}" if self.note else text

    def log_line(self) -> str:
        """The text of a logged line now (not on a terminal)."""
        return (
            f"{self.label}: {self.done}/{self.total} done ({100 * self._fraction():.0f} %), "
            f"{self.timing(', ')}"
        )

    def update(self, done: int | None = None, note: str | None = None, force: bool = False):
        """Set the units done and the note (e.g. the file at work), and draw."""
        if done is not None:
            self.done = done
        if note is not None:
            self.note = note
        now = time.monotonic()
        if not self.terminal:
            if self.done < self.total:
                due = now - self._logged_at >= self.interval
            else:  # the last line closes a log, and is none without one
                due = self._logged_done > 0
            if self.done > self._logged_done and due:
                print(self.log_line(), file=self.stream, flush=True)
                self._logged_at, self._logged_done = now, self.done
        elif force or now - self._drawn_at >= REDRAW_INTERVAL:
            self.stream.write("\r" + self.line() + "\x1b[K")
            self.stream.flush()
            self._drawn_at, self._visible = now, True

    def advance(self, units: int = 1, note: str | None = None):
        """Count ``units`` more done, and draw."""
        self.update(self.done + units, note, force=self.done + units >= self.total)

    def clear(self):
        """Erase the bar (before other output on the terminal); the next update redraws it."""
        if self._visible:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self._visible = False
            self._drawn_at = -float("inf")

    def __enter__(self) -> Progress:
        self.update(force=True)
        return self

    def __exit__(self, *exc):
        self.clear()
