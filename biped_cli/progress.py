"""A one-line progress bar on stderr, drawn only when stderr is a terminal.

Piped or redirected (a log file, a test's capture), it writes nothing, so outputs stay clean:

    with Progress(len(paths), "validate") as bar:
        for path in paths:
            bar.update(note=path)  # draws "validate  2/5 [#####-----]  40 %  ETA 8 s  b.json"
            ...
            bar.clear()  # before printing results on stdout
            print(result)
            bar.advance()
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

# Width of the bar [characters] and shortest time between two draws [s].
WIDTH = 24
REDRAW_INTERVAL = 0.1


class Progress:
    """Progress of ``total`` units of work, drawn as one line on ``stream``.

    Args:
        total: units of work (files, points of a sweep).
        label: what is being done, first on the line.
        stream: where to draw (default: ``sys.stderr``).
        enabled: draw or not (default: only if ``stream`` is a terminal).
    """

    def __init__(
        self,
        total: int,
        label: str = "",
        stream: TextIO | None = None,
        enabled: bool | None = None,
    ):
        self.total, self.label = max(int(total), 0), label
        self.stream = sys.stderr if stream is None else stream
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.done = 0
        self.note = ""
        self._start = time.monotonic()
        self._drawn_at = -float("inf")
        self._visible = False

    def line(self) -> str:
        """The text of the bar now."""
        total = max(self.total, 1)
        fraction = min(self.done / total, 1.0)
        filled = round(WIDTH * fraction)
        text = (
            f"{self.label}  {self.done}/{self.total} [{'#' * filled}{'-' * (WIDTH - filled)}] "
            f"{100 * fraction:3.0f} %"
        )
        elapsed = time.monotonic() - self._start
        if 0 < self.done < self.total:
            text += f"  ETA {elapsed / self.done * (self.total - self.done):.0f} s"
        return f"{text}  {self.note}" if self.note else text

    def update(self, done: int | None = None, note: str | None = None, force: bool = False):
        """Set the units done and the note (e.g. the file at work), and draw."""
        if done is not None:
            self.done = done
        if note is not None:
            self.note = note
        now = time.monotonic()
        if self.enabled and (force or now - self._drawn_at >= REDRAW_INTERVAL):
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
