"""Progress of long runs: a tqdm bar in a terminal or Jupyter, plain lines in a log, or yours.

Every long-running entry point (``surface_of_section``, ``time_series``, ``chaos_map``,
``parameter_map``, ``overlap_threshold``, ``relaxed_libration``, ``libration_amplitude``)
takes ``progress``:

* ``None`` (default): **on in a terminal or in Jupyter, for runs longer than** ``DELAY_S``
  **(2 s)**: the bar appears only once the run has lasted that long (the bar is made then), so
  quick calls stay silent. Anywhere else (a log file, CI, a pipe, pytest's capture) nothing
  is written: a library call in a script does not fill its log.
* ``False``: off, nothing written (compile announcements included).
* ``True``: always on: the bar in a terminal or Jupyter; on a stream that is not a terminal,
  one plain line per 10 % (log-friendly), the last at 100 %.
* a callable: ``progress(fraction)`` with the fraction done in [0, 1] after every kernel
  window (every ~1 s, ``ensemble.PROGRESS_SECONDS``). If it also has methods
  ``compiling(text)`` and ``compiled(seconds)`` they receive the compile announcements.

Results are bit-identical whatever ``progress`` is: windows adapt to wall time either way and
window ends never change a step.

Compile time (``ti_spinorbit.engine.compiling``) is announced ("compiling kernels ... (first use
only, about N s)") and left out of the bar's elapsed time, its ETA and rate: the bar's clock
is shifted by the compile time, as tqdm's own ``unpause`` shifts it.

Nesting: an entry point called by another (``relaxed_libration`` runs sections and time
series) with ``progress=None`` draws no bar of its own; its fractions are the outer call's
business (the outer maps its stages onto one 0..1) and its compile announcements go to the
outer bar (:func:`reporting`).

Decisions:
* **tqdm** (``tqdm.auto``, which gives the notebook widget in Jupyter) draws the bar: it is
  the ecosystem's standard, handles terminal width, the delay and rate smoothing. It cannot
  write a log-friendly bar: on a stream that is not a terminal it still redraws with carriage
  returns, which a log file keeps as one ever longer line. So that mode (``progress=True``
  and the command line, in a non-terminal) writes its own plain lines, every ``PLAIN_STEP``,
  with the same elapsed/ETA arithmetic (:func:`eta_seconds`).
* The ETA in plain lines assumes the rate so far continues, elapsed · (1 − f)/f; the bar's
  is tqdm's (smoothed rate of recent updates). Members finish at different times: a guide.
* The bar (``tty``) is made only once the run has lasted ``delay`` (the first update after
  it): a tqdm bar that exists is redrawn by every ``tqdm.write``, its own ``delay=`` or not,
  and one drawn that way is not ended by ``tqdm.close`` (which believes it was never shown),
  so the next line printed ran on after the bar (``ETA 00:001991 VH: ...``). A bar that is
  shown is always closed with a line end (``leave=True``), also when the run fails.
* The clock is injectable (``clock=``) for tests.
"""

import contextlib
import contextvars
import math
import sys
import time

from .._validate import show

#: Seconds a run must last before the default (``progress=None``) bar appears.
DELAY_S = 2.0
#: Fraction between plain lines when the stream is not a terminal.
PLAIN_STEP = 0.1
#: The bar's layout: label, percent, bar, elapsed and ETA (compile time excluded from both).
BAR_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| elapsed {elapsed}, ETA {remaining}"

_ACTIVE = contextvars.ContextVar("ti_spinorbit_progress", default=None)


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


def format_line(fraction, elapsed, label=""):
    """A plain progress line (no line ending): ``label:  40%  elapsed 0:12, ETA 0:18``."""
    head = f"{label}: " if label else ""
    return (f"{head}{100.0 * fraction:3.0f}%  elapsed {format_duration(elapsed)}, "
            f"ETA {format_duration(eta_seconds(fraction, elapsed))}")


def in_jupyter():
    """True inside a Jupyter kernel (notebook, lab, VS Code), where stderr is no terminal
    but a bar still renders."""
    if "ipykernel" not in sys.modules or "IPython" not in sys.modules:
        return False
    try:
        shell = sys.modules["IPython"].get_ipython()
    except Exception:  # noqa: BLE001 - any failure means: not a kernel we can draw in
        return False
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


def _isatty(stream):
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except (ValueError, OSError):        # a closed stream
        return False


def interactive(stream=None):
    """Whether a bar can be drawn: ``stream`` (default stderr) is a terminal, or Jupyter."""
    return _isatty(sys.stderr if stream is None else stream) or in_jupyter()


class Progress:
    """Callable ``progress(fraction)`` that shows a tqdm bar (terminal, Jupyter) or plain lines.

    Parameters
    ----------
    label : str
        Text in front of the bar (the entry point, or the CLI subcommand).
    stream : file, optional
        Where to write (default ``sys.stderr``).
    enabled : bool
        False writes nothing at all.
    tty : bool, optional
        Force bar (True) or plain-line (False) mode; default: :func:`interactive`.
    delay : float
        Seconds before the bar or the first plain line appears: a run
        shorter than that shows no progress at all.
    bar : bool
        False: no bar and no lines, only the compile announcements (CLI ``--no-progress``).
    clock : callable
        Seconds (default ``time.monotonic``); the clock starts when the object is made.
    step : float
        Fraction between plain lines.
    """

    def __init__(self, label="", *, stream=None, enabled=True, tty=None, delay=0.0, bar=True,
                 clock=time.monotonic, step=PLAIN_STEP):
        self.label = label
        self._stream = stream
        self.enabled = bool(enabled)
        self.show_bar = bool(bar)
        self.tty = interactive(stream) if tty is None else bool(tty)
        self.delay = float(delay)
        self._clock = clock
        self.step = float(step)
        self.start = clock()
        self.fraction = 0.0
        self.compile_seconds = 0.0    # kept out of elapsed, ETA and rates
        self.closed = False
        self._next_plain = 1
        self._plain_finished = False
        self._announced = False
        self._bar = None        # the tqdm bar: made once the run has lasted ``delay``

    @property
    def stream(self):
        return sys.stderr if self._stream is None else self._stream

    def _make_bar(self):
        # tqdm: imported when a bar is first drawn (tens of ms, and which front end it
        # takes is decided here, at run time)
        if self._stream is None and in_jupyter():
            from tqdm.auto import tqdm
        else:
            from tqdm.std import tqdm
        # made only once the run has lasted ``delay`` (tqdm's own delay would not do: a tqdm
        # bar that exists is drawn by every ``tqdm.write``, our compile announcements, and
        # ``close`` then thinks it was never shown and leaves its line unended). A tiny delay
        # keeps tqdm from drawing in its constructor, before it has our clock.
        bar = tqdm(total=1.0, desc=self.label, file=self.stream, delay=1e-9,
                   bar_format=BAR_FORMAT, leave=True, dynamic_ncols=self._stream is None,
                   ncols=None if self._stream is None else 80)
        # tqdm reads its clock from this attribute; elapsed time counts from our start
        bar._time = self._clock
        bar.start_t = bar.last_print_t = self.start
        return bar

    def _update_bar(self):
        """Move the bar to ``self.fraction``; the first time, draw it whatever tqdm's minimum
        interval says, and mark it drawn as tqdm's update does (so ``close`` ends its line)."""
        first = self._bar is None
        if first:
            self._bar = self._make_bar()
        bar = self._bar
        bar.update(self.fraction - bar.n)
        if self.fraction >= 1.0 or (first and bar.last_print_t < bar.start_t + bar.delay):
            bar.refresh()
            bar.last_print_n, bar.last_print_t = bar.n, self._clock()

    def elapsed(self):
        """Seconds since the start, compile time excluded."""
        return self._clock() - self.start

    def __call__(self, fraction):
        """Report ``fraction`` done (clipped to [0, 1]; NaN is ignored)."""
        fraction = float(fraction)
        if not self.enabled or self.closed or math.isnan(fraction):
            return
        self.fraction = min(max(fraction, 0.0), 1.0)
        if not self.show_bar:
            return
        # nothing before ``delay``: a short run stays quiet, bar or plain lines
        if self._bar is None and self.elapsed() < self.delay:
            return
        if self.tty:
            self._update_bar()
            return
        # plain lines: one each time the fraction crosses the next step, one at 100 %
        if self.fraction >= 1.0:
            if self._plain_finished:
                return
            self._plain_finished = True
        elif self.fraction < self._next_plain * self.step - 1e-12:
            return
        while self._next_plain * self.step <= self.fraction + 1e-12:
            self._next_plain += 1
        self._write(format_line(self.fraction, self.elapsed(), self.label))

    def _write(self, line):
        if self._bar is not None:
            self._bar.write(line, file=self.stream)
        else:
            self.stream.write(line + "\n")
            self.stream.flush()

    # ---- compile announcements (ti_spinorbit.engine.compiling) ----------------------------------
    def compiling(self, text):
        """Announce a compile that is about to start (one line)."""
        if self.enabled and not self.closed:
            self._announced = True
            self._write(f"{self.label}: {text}" if self.label else text)

    def compiled(self, seconds):
        """A compile of ``seconds`` ended: shift the clocks so that elapsed time, ETA and rate
        leave it out; confirm it when it was announced."""
        seconds = max(float(seconds), 0.0)
        self.compile_seconds += seconds
        self.start += seconds
        if self._bar is not None:
            self._bar.start_t += seconds
            self._bar.last_print_t += seconds
        if self._announced and self.enabled and not self.closed:
            self._announced = False
            self._write(f"{self.label + ': ' if self.label else ''}kernels ready after "
                        f"{seconds:.1f} s (not counted in elapsed time, ETA or rates)")

    def child(self):
        """The reporter of an entry point called inside this one with ``progress=None``."""
        return _Child(self)

    def close(self):
        """End the bar and its line (further updates are ignored)."""
        if self.closed:
            return
        self.closed = True
        if self._bar is not None:
            self._bar.close()      # leave=True: the bar's last state and a line end

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


class _Child:
    """A nested call's reporter: its fractions are dropped (the outer call reports its own),
    its compile announcements go to the outer reporter."""

    def __init__(self, outer):
        self.outer = outer

    def __call__(self, fraction):
        return None

    def compiling(self, text):
        self.outer.compiling(text)

    def compiled(self, seconds):
        self.outer.compiled(seconds)

    def child(self):
        return self

    def close(self):
        return None


class _Callback(_Child):
    """A user's callable: fractions to it; announcements to its own ``compiling``/``compiled``
    methods when it has them."""

    def __call__(self, fraction):
        return self.outer(fraction)

    def compiling(self, text):
        hook = getattr(self.outer, "compiling", None)
        if callable(hook):
            hook(text)

    def compiled(self, seconds):
        hook = getattr(self.outer, "compiled", None)
        if callable(hook):
            hook(seconds)

    def child(self):
        return _Child(self)


class _Silent(_Child):
    """``progress=False`` (and the default where no bar can be drawn): nothing at all."""

    def __init__(self):
        super().__init__(None)

    def compiling(self, text):
        return None

    def compiled(self, seconds):
        return None


SILENT = _Silent()


def check(progress, name="progress"):
    """``progress`` must be None, True, False or a callable; TypeError naming it otherwise
    (before any work: a bad value would otherwise fail only after the first window)."""
    if progress is None or isinstance(progress, bool) or callable(progress):
        return progress
    raise TypeError(f"{name} must be True, False, None or a callable progress(fraction) "
                    f"(got {show(progress)})")


def active():
    """The reporter of the innermost entry point running in this thread, or None."""
    return _ACTIVE.get()


@contextlib.contextmanager
def reporting(progress, label):
    """The reporter an entry point passes to its runs as ``progress`` (see the module
    docstring for what each value of ``progress`` means); made active for nested calls and
    compile announcements, closed at the end when it was made here."""
    check(progress)
    outer = _ACTIVE.get()
    own = False
    if isinstance(progress, (Progress, _Child)):
        rep = progress
    elif progress is None:
        if outer is not None:
            rep = outer.child()
        elif interactive():
            rep, own = Progress(label, delay=DELAY_S), True
        else:
            rep = SILENT
    elif progress is False:
        rep = SILENT
    elif progress is True:
        rep, own = Progress(label), True
    else:
        rep = _Callback(progress)
    token = _ACTIVE.set(rep)
    try:
        yield rep
    finally:
        _ACTIVE.reset(token)
        if own:
            rep.close()


def stage(report, start, width):
    """A callable mapping a stage's own fraction f onto ``start + width · f`` of ``report``
    (a run made of several integrations: shorter lengths first, doublings, ...)."""
    def forward(fraction):
        report(start + width * min(max(float(fraction), 0.0), 1.0))
    forward.compiling = getattr(report, "compiling", None)
    forward.compiled = getattr(report, "compiled", None)
    return forward
