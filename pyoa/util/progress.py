"""The progress bars of pyoa's long jobs: :func:`bar` makes every one of them.

On a terminal, and in a notebook, a bar is tqdm's own, redrawn in place [1]_.
Where standard error is no terminal (a log file, a pipe, a batch job), tqdm's
redraws are carriage returns that fill the log with one endless line; there a
bar writes plain lines instead (:class:`LineBar`): its first state, one at
each tenth of its total, one at least every :data:`LOG_SECONDS` while it
moves, and its last.

References
----------
.. [1] tqdm developers, "tqdm: a fast, extensible progress bar for Python",
   https://tqdm.github.io (``tqdm.auto``, ``tqdm.std.tqdm.display``).
"""

from __future__ import annotations

import sys
import time

from tqdm.std import tqdm

#: Seconds between two lines of a bar on a log, while it moves (a line is also written at each tenth).
LOG_SECONDS = 5.0


class LineBar(tqdm):
    """A tqdm bar that writes whole lines, never a carriage return (see the module docstring)."""

    def __init__(self, *args, **kwargs):
        self._said = None  # (time, tenth, n) of the last line written
        super().__init__(*args, **kwargs)

    def _line(self, last: bool = False) -> None:
        now = time.monotonic()
        tenth = int(10 * self.n / self.total) if self.total else 0
        said = self._said
        if (said is None or tenth > said[1] or (now - said[0] >= LOG_SECONDS or last) and self.n != said[2]):
            self.fp.write(self.__str__() + "\n")
            self.fp.flush()
            self._said = (now, tenth, self.n)

    def display(self, msg=None, pos=None) -> bool:
        if msg is not None:  # tqdm clearing or overwriting its line: nothing to take back on a log
            return False
        self._line()
        return True

    def clear(self, nolock=False) -> None:
        """Nothing to clear: written lines stay (tqdm clears a bar before ``tqdm.write``)."""

    def moveto(self, n) -> None:
        """No cursor to move on a log."""

    def close(self) -> None:
        if not self.disable and self._said is not None:
            self._line(last=True)
        self.leave = False  # its last line is written: tqdm's close then writes nothing more
        super().close()


def bar(**kwargs) -> tqdm:
    """A progress bar: tqdm's (``tqdm.auto``, with ``kwargs``) on a terminal or in a notebook, else
    a :class:`LineBar` with the same arguments. It writes to ``kwargs["file"]``, standard error
    unless given."""
    from tqdm.auto import tqdm as auto
    from tqdm.autonotebook import tqdm as chosen  # tqdm.std's outside a notebook

    stream = kwargs.get("file") or sys.stderr
    if chosen is not tqdm or kwargs.get("disable"):  # a notebook's widget; or no bar at all
        return auto(**kwargs)
    try:
        terminal = stream.isatty()
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        terminal = False
    return tqdm(**kwargs) if terminal else LineBar(**kwargs)
