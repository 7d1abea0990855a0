"""A one-line progress bar for long ensemble runs (command line and scripts).

The library reports progress by calling ``progress(fraction)`` with the fraction of the
requested integration time done (in [0, 1]) after every kernel window
(:meth:`~ti_spinorbit.ensemble.Ensemble.run`). :class:`ProgressBar` is such a callable: it
draws ``label [#####.....]  45%  elapsed 0:12  ETA 0:15`` on stderr.

Decisions:
* On a terminal the line is redrawn in place (carriage return), at most every
  ``min_interval`` seconds so a fast run does not spend its time drawing. Anywhere else (a log
  file, CI, a pipe) a carriage-return bar turns into one very long line, so a plain line is
  written only when the fraction crosses the next ``step`` (default every 10 %).
* The ETA assumes the rate so far continues: elapsed × (1 − f)/f. Ensemble members finish at
  different times, so the rate can change; the estimate is a guide, not a promise.
* ``quiet=True`` draws nothing, so callers can pass a bar unconditionally.
* The clock is injectable (``clock=``) for tests.

Usage::

    with ProgressBar("section") as bar:
        tso.surface_of_section(system, 0.0, starts, orbits=1000, progress=bar)
"""

import math
import sys
import time

#: Characters of the bar between the brackets.
BAR_WIDTH = 30
#: Seconds between redraws on a terminal (the last update is always drawn).
MIN_INTERVAL_S = 0.1
#: Fraction between plain lines when the stream is not a terminal.
PLAIN_STEP = 0.1


def eta_seconds(fraction, elapsed):
    """Seconds left if the rate so far continues: elapsed · (1 − f)/f; None before any
    progress (f <= 0) and 0 when done."""
    if not fraction > 0.0:
        return None
    if fraction >= 1.0:
        return 0.0
    return elapsed * (1.0 - fraction) / fraction


def format_duration(seconds):
    """``M:SS`` below an hour, ``H:MM:SS`` above; ``--:--`` for None or a non-finite value."""
    if seconds is None or not math.isfinite(seconds):
        return "--:--"
    s = int(round(max(seconds, 0.0)))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def format_line(fraction, elapsed, label="", width=BAR_WIDTH):
    """The bar's text (no line ending) for ``fraction`` done after ``elapsed`` seconds."""
    filled = int(fraction * width + 1e-9)
    bar = "#" * filled + "." * (width - filled)
    head = f"{label} " if label else ""
    return (f"{head}[{bar}] {100.0 * fraction:3.0f}%  elapsed {format_duration(elapsed)}  "
            f"ETA {format_duration(eta_seconds(fraction, elapsed))}")


class ProgressBar:
    """Callable ``progress(fraction)`` drawing a one-line bar with percent, elapsed and ETA.

    Parameters
    ----------
    label : str
        Text in front of the bar (e.g. the subcommand).
    stream : file, optional
        Where to draw (default ``sys.stderr``, looked up at each call).
    quiet : bool
        Draw nothing.
    tty : bool, optional
        Force terminal (carriage-return) or plain-line mode; default ``stream.isatty()``.
    clock : callable
        Returns seconds (default ``time.monotonic``); the clock starts when the bar is made.
    width, min_interval, step
        Bar width in characters, least seconds between terminal redraws, fraction between
        plain lines.
    """

    def __init__(self, label="", stream=None, quiet=False, tty=None, clock=time.monotonic,
                 width=BAR_WIDTH, min_interval=MIN_INTERVAL_S, step=PLAIN_STEP):
        self.label = label
        self._stream = stream
        self.quiet = bool(quiet)
        self._tty = tty
        self._clock = clock
        self.width = int(width)
        self.min_interval = float(min_interval)
        self.step = float(step)
        self.start = clock()
        self.fraction = 0.0
        self._last_draw = None      # clock time of the last terminal redraw
        self._next_plain = 1        # plain mode: next line at _next_plain · step
        self._plain_finished = False
        self._drawn = False         # something is on the current terminal line
        self._line_length = 0
        self.closed = False

    @property
    def stream(self):
        return sys.stderr if self._stream is None else self._stream

    @property
    def tty(self):
        if self._tty is None:
            isatty = getattr(self.stream, "isatty", None)
            self._tty = bool(isatty and isatty())
        return self._tty

    def elapsed(self):
        return self._clock() - self.start

    def __call__(self, fraction):
        """Report ``fraction`` done (clipped to [0, 1]; NaN is ignored)."""
        fraction = float(fraction)
        if self.quiet or self.closed or math.isnan(fraction):
            return
        self.fraction = min(max(fraction, 0.0), 1.0)
        now = self._clock()
        if self.tty:
            if (self.fraction < 1.0 and self._last_draw is not None
                    and now - self._last_draw < self.min_interval):
                return
            self._last_draw = now
            line = format_line(self.fraction, now - self.start, self.label, self.width)
            pad = " " * max(self._line_length - len(line), 0)
            self.stream.write("\r" + line + pad)
            self._line_length = len(line)
            self._drawn = True
        else:
            if self.fraction >= 1.0:
                if self._plain_finished:
                    return
                self._plain_finished = True
            elif self.fraction < self._next_plain * self.step - 1e-12:
                return
            while self._next_plain * self.step <= self.fraction + 1e-12:
                self._next_plain += 1
            self.stream.write(format_line(self.fraction, now - self.start, self.label,
                                          self.width) + "\n")
        self.stream.flush()

    def close(self):
        """End the bar's line (terminal mode); further updates are ignored."""
        if self.closed:
            return
        self.closed = True
        if self._drawn and not self.quiet:
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
