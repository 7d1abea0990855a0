"""Short, readable summaries of systems, bodies and results: ``repr`` and notebook HTML.

One place for the formatting every class uses: :func:`text` gives a ``__repr__`` of at most a
few lines (no arrays, however many members), :func:`html` a small ``<table>`` for Jupyter's
``_repr_html_``. Both are built from :func:`summary`, a title and lines of (label, value)
pairs, so the two views always say the same thing.

The same helpers serve the helper results (``classify_section()``'s SectionClassification,
an OverlapDecision, ``ts.conservation()``'s Conservation), ``status_names`` (:class:`Names`,
a list that prints on one line) and the command line's summaries (:func:`counts`,
:func:`fields`), so nothing printed is a Python dict, list or array repr.

Round-off prints as 0 (:func:`negligible`): a value below ``ROUNDOFF`` (1e-12) times the
largest of the values printed beside it, or times its body's size for a length. The data
keep what was computed; only the printing rounds.
"""

import html as _html
import math

import numpy as np


#: Longest user-supplied name shown (longer ones are cut with "…").
MAX_NAME = 40
#: Most distinct systems named in a result's summary.
MAX_SYSTEMS = 3


def number(x, spec=".4g"):
    """A float in ``spec`` format; "—" for None, "nan"/"inf" spelled out."""
    if x is None:
        return "—"
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return format(x, spec)


def name(text):
    """A user-supplied name, quoted and cut to ``MAX_NAME`` characters."""
    text = str(text)
    return repr(text if len(text) <= MAX_NAME else text[:MAX_NAME - 1] + "…")


def length(metres):
    """A length in m, or km above 10 km."""
    metres = float(metres)
    return f"{number(metres / 1e3)} km" if abs(metres) >= 1e4 else f"{number(metres)} m"


def counts(mapping):
    """{"done": 30, "inaccurate": 2} -> "done 30, inaccurate 2" (largest first)."""
    if not mapping:
        return "none"
    items = sorted(mapping.items(), key=lambda kv: -kv[1])
    return ", ".join(f"{k} {v}" for k, v in items)


#: Relative size below which a value printed beside others is round-off and prints as 0.
ROUNDOFF = 1e-12


def negligible(values, scale=None, rel=ROUNDOFF):
    """``values`` (floats) with every one whose magnitude is below ``rel`` times ``scale``
    (default: the largest finite magnitude among them) set to 0.0: numbers printed side by
    side, of which some are round-off (a sphere's spin energy exchange, 1e-37 of the total,
    beside the orbit's 1e-3). Non-finite values are kept; the data are never changed, only
    what is printed."""
    values = [float(v) for v in values]
    finite = [abs(v) for v in values if math.isfinite(v)]
    if scale is None:
        scale = max(finite, default=0.0)
    scale = abs(float(scale))
    return [0.0 if math.isfinite(v) and abs(v) < rel * scale else v for v in values]


def sci(x, digits=3):
    """A float in scientific notation (``2.274e-03``), plain "0" when it is exactly zero
    (as :func:`negligible` makes round-off)."""
    if x is not None and float(x) == 0.0:
        return "0"
    return number(x, f".{digits}e")


def items(values, limit=6, spec=None):
    """A sequence as a short text: all of it when it has at most ``limit`` items, else its
    first and last items, "…" and the count, with a count of the distinct values when they
    are few (``['done', 'done', …, 'inaccurate'] (1024 items: done 1020, inaccurate 4)``)."""
    values = list(values)

    def show(v):
        return number(v, spec) if spec and isinstance(v, (int, float, np.number)) else repr(v)

    if len(values) <= limit:
        return "[" + ", ".join(show(v) for v in values) + "]"
    first = max(limit // 2, 1)
    last = max(limit - first - 1, 1)
    text = ("[" + ", ".join(show(v) for v in values[:first]) + ", …, "
            + ", ".join(show(v) for v in values[-last:]) + "]")
    try:
        distinct = {}
        for v in values:
            distinct[v] = distinct.get(v, 0) + 1
    except TypeError:                     # unhashable items: the count only
        distinct = {}
    if 0 < len(distinct) <= MAX_DISTINCT:
        return f"{text} ({len(values)} items: {counts({str(k): n for k, n in distinct.items()})})"
    return f"{text} ({len(values)} items)"


def fields(mapping, width=24, indent="", length_scale=None):
    """Lines of a nested mapping (a ``describe()``) as a two-column table: numbers in
    ``.6g``, None as "—", lists of numbers joined with "×" when they are three (semi-axes)
    or ", ", a nested mapping as an indented block under its key, a long list by
    :func:`items`. No Python dict or list reprs.

    Round-off prints as 0 (:func:`negligible`, ``ROUNDOFF`` = 1e-12 relative): in a block
    with a ``bounding_radius_m`` (a body), lengths (keys ending in ``_m``) below 1e-12 of it
    (a polyhedron's centroid offset of 1e-14 m); in a list of numbers (a rotation matrix),
    entries below 1e-12 of its largest."""
    if isinstance(mapping.get("bounding_radius_m"), (int, float)):
        length_scale = float(mapping["bounding_radius_m"])
    lines = []
    for key, value in mapping.items():
        label = f"{indent}{key}"
        if isinstance(value, dict):
            lines.append(label)
            lines.extend(fields(value, width, indent + "  ", length_scale))
        elif isinstance(value, (list, tuple)) and value and all(isinstance(v, dict) for v in value):
            lines.append(f"{label:{width}s} {len(value)} items")
            for k, v in enumerate(value):
                lines.append(f"{indent}  [{k}]")
                lines.extend(fields(v, width, indent + "    ", length_scale))
        else:
            scale = length_scale if str(key).endswith("_m") else None
            lines.append(f"{label:{width}s} {_field(_rounded(value, scale))}")
    return lines


def _numbers(value):
    """The floats of a number or a nested list of numbers, else None."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float, np.number)):
        return [float(value)]
    if isinstance(value, (list, tuple, np.ndarray)) and len(value):
        parts = [_numbers(v) for v in value]
        return None if any(p is None for p in parts) else [x for p in parts for x in p]
    return None


def _rounded(value, scale=None):
    """``value`` with its round-off set to 0 (:func:`negligible`): against ``scale`` when
    given, else against the largest magnitude of a list (a lone number is kept)."""
    flat = _numbers(value)
    if flat is None or (scale is None and len(flat) < 2):
        return value
    zeroed = iter(negligible(flat, scale))

    def rebuild(v):
        if isinstance(v, (list, tuple, np.ndarray)):
            return [rebuild(x) for x in v]
        x = next(zeroed)
        return 0 if x == 0.0 else (v if isinstance(v, (int, np.integer)) else x)

    return rebuild(value)


def _field(value):
    if value is None:
        return "—"
    if isinstance(value, bool) or isinstance(value, str):
        return str(value)
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return number(value, ".6g")
    if isinstance(value, (list, tuple, np.ndarray)):
        values = list(np.ravel(value)) if isinstance(value, np.ndarray) else list(value)
        if len(values) > MAX_FIELD_ITEMS:
            return items(values, spec=".6g")
        if values and all(isinstance(v, (list, tuple, np.ndarray)) for v in values):
            return ", ".join("(" + ", ".join(_field(x) for x in v) + ")" for v in values)
        joiner = " × " if len(values) == 3 and all(
            isinstance(v, (int, float, np.number)) for v in values) else ", "
        return joiner.join(_field(v) for v in values) if values else "—"
    return str(value)


#: Longest list :func:`fields` shows item by item.
MAX_FIELD_ITEMS = 8
#: Most distinct values a long sequence's summary counts one by one.
MAX_DISTINCT = 8


class Names(list):
    """A list (of status names, labels) whose repr stays one line however long it is: the
    first and last items and the count of each distinct value (``display.items``). It is a
    plain ``list`` in every other way (equality, indexing, ``json``, ``numpy.array``)."""

    def __repr__(self):
        return items(self)

    def _repr_pretty_(self, p, cycle):     # IPython's pretty printer would list every item
        p.text(repr(self))


def span(values, spec=".3g"):
    """Range of an array as "lo–hi" (ignoring NaN), "lo" when constant, "—" when empty/NaN."""
    values = np.asarray(values, dtype=np.float64).ravel()
    values = values[np.isfinite(values)]
    if values.size == 0:
        return "—"
    lo, hi = values.min(), values.max()
    return number(lo, spec) if lo == hi else f"{number(lo, spec)}–{number(hi, spec)}"


# ---- bodies and systems ------------------------------------------------------------------
def semi_axes(body):
    """Semi-axes (m) of a Sphere/Ellipsoid; for a general Body those of the uniform ellipsoid
    with the same second moments (T^200 = M a²/5, ...)."""
    axes = getattr(body, "semi_axes", None)
    if axes is not None:
        return tuple(axes), True
    m = float(body.mass)
    return tuple(math.sqrt(5.0 * body.integral(*k) / m) for k in
                 ((2, 0, 0), (0, 2, 0), (0, 0, 2))), False


def body_size(body):
    """"sphere R 600 m", "ellipsoid 245 × 163 × 190 m" or "body ≈ 1 × 0.7 × 0.5 m" (the
    ellipsoid with the same second moments)."""
    axes, exact = semi_axes(body)
    if exact and axes[0] == axes[1] == axes[2]:
        return f"sphere R {length(axes[0])}"
    metres = max(axes) < 1e4
    unit, scale = ("m", 1.0) if metres else ("km", 1e-3)
    dims = " × ".join(number(x * scale) for x in axes)
    return f"ellipsoid {dims} {unit}" if exact else f"body ≈ {dims} {unit} (equal-moment ellipsoid)"


def elongation(body):
    """a/b of the body (of its equal-moment ellipsoid for a general Body)."""
    axes, _ = semi_axes(body)
    return axes[0] / axes[1] if axes[1] > 0 else math.inf


def _body(b):
    axes, _ = semi_axes(b)
    volume = 4.0 / 3.0 * math.pi * axes[0] * axes[1] * axes[2]
    exact = getattr(b, "semi_axes", None) is not None
    lines = [[("shape", body_size(b)), ("mass", f"{number(b.mass)} kg")],
             ([("density", f"{number(b.mass / volume, '.4g')} kg/m³")] if exact and volume > 0
              else []) + [("bounding radius", length(b.bounding_radius))]]
    if b.has_odd_integrals:
        lines[1].append(("odd integrals", "yes"))
    return f"Body {name(b.name)}", lines


def _circular_period(s):
    """The system's circular period at order 4 (the figures' force), NaN where it cannot be
    had (a body of lower order): a repr never fails."""
    try:
        return s.circular_period()
    except (ValueError, TypeError, ZeroDivisionError):
        return math.nan


def _system(s):
    P = s.primary_spin_period
    lines = [[("a/b", number(elongation(s.secondary), ".4g")), ("e", number(s.e, ".4g")),
              ("M_p/M_s", number(s.mass_ratio, ".4g")), ("ω0", f"{number(s.omega0, '.4g')} n"),
              ("P_orb", f"{number(s.orbital_period / 3600.0, '.4g')} h (circular "
                        f"{number(_circular_period(s) / 3600.0, '.4g')} h)")],
             [("a", length(s.a)), ("primary", body_size(s.primary)),
              ("secondary", body_size(s.secondary))]]
    if P is not None:       # a spherical or non-spinning primary: nothing to say
        lines.append([("primary spin period", f"{number(P / 3600.0, '.4g')} h")])
    scale = getattr(s, "density_scale", 1.0)
    if scale != 1.0:        # BinarySystem(orbital_period=...): say what was changed
        lines.append([("densities", f"scaled × {number(scale, '.6g')} to match P_orb")])
    return f"BinarySystem {name(s.name)}", lines


def _systems(systems):
    """One line naming the distinct systems of a result (by identity, first MAX_SYSTEMS)."""
    seen = {}
    for s in systems or ():
        seen.setdefault(id(s), s)
    unique = list(seen.values())
    if not unique:
        return []
    if len(unique) == 1:
        s = unique[0]
        return [("system", name(s.name)), ("a/b", number(elongation(s.secondary), ".4g")),
                ("e", number(s.e, ".4g")), ("M_p/M_s", number(s.mass_ratio, ".4g")),
                ("P_orb", f"{number(s.orbital_period / 3600.0, '.4g')} h")]
    names = sorted({str(s.name) for s in unique})
    shown = ", ".join(name(n) for n in names[:MAX_SYSTEMS]) + (" …" if len(names) > MAX_SYSTEMS else "")
    return [("systems", f"{len(unique)} ({shown})"),
            ("a/b", span([elongation(s.secondary) for s in unique])),
            ("e", span([s.e for s in unique]))]


# ---- results ------------------------------------------------------------------------------
def _run(r, members, rtol=None):
    """members, orbits, rtol, method/order, coordinates, seconds."""
    rtol = getattr(r, "rtol", rtol)
    row = [("members", str(members)), ("orbits", number(getattr(r, "orbits", None), "g"))]
    if rtol is not None:
        row.append(("rtol", number(rtol, "g")))
    method = getattr(r, "method", None)
    if method is not None:
        row.append(("method", str(method)))
    elif getattr(r, "order", None) is not None:
        row.append(("order", str(r.order)))
    row.append(("coordinates", str(getattr(r, "coordinates", "inertial"))))
    seconds = getattr(r, "seconds", None)
    if seconds:
        row.append(("seconds", number(seconds, ".3g")))
    return row


def _status(r):
    row = [("status", counts(r.status_counts))]
    md = getattr(r, "max_drift", None)
    if md is not None and not math.isnan(float(md)):
        row.append(("max_drift", number(md, ".2g")))
    return row


def _section(r):
    n = int(np.size(r.count))
    points = np.asarray(r.count)
    lines = [_run(r, n), _systems(r.systems) or [("system", "—")],
             [("section points", f"{int(points.sum())} (per member {span(points, 'g')})")]
             + ([("⟨Y⟩", span(r.megno))] if r.megno is not None
                and np.isfinite(np.asarray(r.megno, dtype=float)).any() else []),
             _status(r)]
    return "SectionResult", lines


def _time_series(r):
    t = np.asarray(r.t, dtype=np.float64)
    n = t.shape[0] if t.ndim else 0
    samples = t.shape[1] if t.ndim > 1 else 0
    lines = [_run(r, n), _systems(r.systems) or [("system", "—")],
             [("samples per member", str(samples)), ("θ̇/n", span(r.thetadot))],
             _status(r)]
    return "TimeSeriesResult", lines


def _fraction(r):
    # the members a map counts: "done", and "inaccurate" where it counts them (the status
    # names of the result's own table, so this base module needs no engine)
    counts = r.status_counts
    counted = counts.get("done", 0) + (counts.get("inaccurate", 0)
                                       if getattr(r, "include_inaccurate", False) else 0)
    row = [("chaotic fraction", f"{number(r.chaotic_fraction, '.3g')} of {counted} counted")]
    if getattr(r, "megno_chaotic", None) is not None:
        row.append(("threshold ⟨Y⟩ >", number(r.megno_chaotic, "g")))
    if getattr(r, "include_inaccurate", False):
        row.append(("counts inaccurate", "yes"))
    return row


def _chaos_map(r):
    shape = tuple(np.shape(r.megno))
    lines = [_run(r, int(np.prod(shape))),
             _systems(getattr(r.section, "systems", None)) if r.section is not None else [],
             [("grid θ_p × θ̇_p/n", f"{shape[0]} × {shape[1]}" if len(shape) == 2 else str(shape)),
              ("θ_p", f"{span(r.theta_p)} deg"), ("θ̇_p/n", span(r.thetadot_p))],
             _fraction(r), _status(r)]
    return "ChaosMap", [line for line in lines if line]


def _parameter_map(r):
    shape = tuple(np.shape(r.megno))
    lines = [_run(r, int(np.prod(shape))),
             ([("system", name(r.name))] if r.name else [])
             + [("a/b", span(r.elongations)), ("e", span(r.eccentricities)),
                ("grid", " × ".join(str(k) for k in shape) + " (a/b × e × starts)")],
             [("chaotic fraction", span(r.chaotic_fraction)),
              ("ω0", f"{span(r.omega0)} n")],
             _status(r)]
    return "ParameterMap", lines


def _overlap(r):
    sections = r.sections
    members = int(np.size(sections.count)) if sections is not None else 0
    first = "none in scan" if r.first_overlap is None else number(r.first_overlap, ".4g")
    if r.first_overlap is not None and not r.converged and r.lengths is not None:
        first += " (upper bound)"
    lines = [_run(r, members, getattr(sections, "rtol", None)),
             [("system", name(r.name)), ("e", number(r.eccentricity, ".4g")),
              ("a/b scanned", f"{span(r.elongations)} ({len(r.elongations)})")]
             + ([("lengths", f"{span(r.lengths, 'g')} orbits"),
                 ("converged", "yes" if r.converged else "no")] if r.lengths is not None else []),
             [("first overlap a/b", first), ("analytic a/b at ω0^RO", number(r.elongation_ro, ".4g")),
              ("ω0^RO", f"{number(r.omega0_ro, '.4g')} n")]]
    if sections is not None:
        lines.append([("status (first run)", counts(sections.status_counts)),
                      ("inaccurate", str(r.n_inaccurate))])
    else:
        lines.append([("inaccurate", str(r.n_inaccurate))])
    return "OverlapScan", lines


def _libration(r):
    lines = [_run(r, 1),
             [("system", name(r.system.name) if r.system is not None else "—"),
              ("ω0", f"{number(r.omega0, '.4g')} n"),
              ("centre θ̇_p/n", number(r.centre_thetadot_p, ".6g"))],
             [("amplitude", f"{number(r.amplitude, '.4g')} deg"),
              # an amplitude: the sign of 2e/(ω0² − 1) is only the phase (below ω0 = 1 the
              # forced libration is in antiphase), so it is shown as |ψ_A|
              ("|ψ_A|", f"{number(abs(r.psi_A), '.4g')} deg"),
              ("extent", f"{number(r.extent, '.3g')} deg")],
             [("status", str(r.status)), ("converged", "yes" if r.converged else "no")]]
    return "RelaxedLibration", lines


# ---- helper results (not archived results: summarised by class name) ----------------------
def _classification(c):
    labels = np.asarray(c.classification)
    n = int(labels.size)
    lines = [[("members", str(n)),
              ("classes", counts({k: v for k, v in c.counts().items() if v}))]]
    p = np.asarray(c.resonance_p, dtype=np.float64)
    p = p[np.isfinite(p)]
    if p.size:
        found = {}
        for value in p:
            found[_resonance(value)] = found.get(_resonance(value), 0) + 1
        lines.append([("resonances", ", ".join(f"{k} ({v})" for k, v in
                                               sorted(found.items(), key=lambda kv: -kv[1])))])
    row = [("section points", span(c.count, "g")), ("order ratio", span(c.order_ratio))]
    megno = np.asarray(c.megno, dtype=np.float64)
    if np.isfinite(megno).any():
        row.append(("⟨Y⟩", span(megno)))
    lines.append(row)
    confined = np.asarray(c.libration_half_extent_deg, dtype=np.float64)
    if np.isfinite(confined).any():
        lines.append([("libration half extent", f"{span(confined)} deg"),
                      ("centre θ̇_p/n", span(c.libration_centre_thetadot))])
    return "SectionClassification", lines


def _resonance(p):
    """p of a p:1 resonance as "1:1", "3:2", "2:1", "1:2"."""
    for q in (1, 2, 3, 4):
        if abs(p * q - round(p * q)) < 1e-9:
            return f"{int(round(p * q))}:{q}"
    return f"{number(p, '.3g')}:1"


def _decision(d):
    verdict = "overlap" if d.overlap else "separate"
    if d.megno_overlap is not None and bool(d.megno_overlap) != bool(d.overlap):
        verdict += f" (MEGNO says {'overlap' if d.megno_overlap else 'separate'})"
    lines = [[("a/b", number(d.elongation, ".4g")), ("ω0", f"{number(d.omega0, '.4g')} n"),
              ("verdict", verdict)],
             [("1:1 centre", f"{number(d.centre_1, '.4g')} n"),
              ("3:2 centre", f"{number(d.centre_3_2, '.4g')} n"
               + ("" if d.centre_3_2_found else " (not found)"))]]
    if d.connecting_start is not None:
        lo, hi = d.connecting_range
        lines.append([("connecting start", f"{number(d.connecting_start, '.4g')} n"),
                      ("θ̇_p/n range", f"{number(lo, '.4g')}–{number(hi, '.4g')}"),
                      ("⟨Y⟩", number(d.connecting_megno, ".3g"))])
    row = [("orbits", number(d.orbits, "g")), ("inaccurate", str(d.inaccurate)),
           ("max energy drift", number(d.max_energy_drift, ".2g"))]
    lines.append(row)
    return "OverlapDecision", lines


def _conservation(c):
    exchange = negligible([c.exchange_orbit, c.exchange_primary, c.exchange_secondary])
    t = np.asarray(c.t, dtype=np.float64)
    period = float(c.orbital_period) if c.orbital_period is not None else math.nan
    orbits = math.isfinite(period) and period > 0
    lines = [[("member", str(c.member)), ("samples", str(c.samples)),
              ("t", f"{span(t / period if orbits else t)} {'orbits' if orbits else 's'}")],
             [("max |ΔE|/|E0|", sci(c.energy_drift)), ("max |ΔL|/|L0|", sci(c.angmom_drift))],
             [("largest exchange |ΔE_i|/|E0|",
               f"orbit {sci(exchange[0])}, primary spin {sci(exchange[1])}, "
               f"secondary spin {sci(exchange[2])}")]]
    return "Conservation", lines


#: Summaries of the inputs and helper results, by class name (a class or one of its bases).
_SUMMARIES = {"Body": _body, "BinarySystem": _system, "SectionClassification": _classification,
              "OverlapDecision": _decision, "Conservation": _conservation}
#: Summaries of results, by the kind each result class declares (``Result.kind``).
_RESULT_SUMMARIES = {"section": _section, "time_series": _time_series,
                     "chaos_map": _chaos_map, "parameter_map": _parameter_map,
                     "overlap_scan": _overlap, "relaxed_libration": _libration}


def _summary_of(obj):
    kind = getattr(type(obj), "kind", "")
    if kind in _RESULT_SUMMARIES:
        return _RESULT_SUMMARIES[kind]
    return next((_SUMMARIES[c.__name__] for c in type(obj).__mro__ if c.__name__ in _SUMMARIES),
                None)


def summary(obj):
    """(title, lines): each line a list of (label, value) strings."""
    summarise = _summary_of(obj)
    if summarise is None:
        raise TypeError(f"no summary for {type(obj).__name__}")
    title, lines = summarise(obj)
    if getattr(obj, "perturbations", None):     # tides / YORP / BYORP in the equations
        lines = list(lines) + [[("perturbations", _perturbations(obj.perturbations))]]
    return title, lines


def _perturbations(items):
    """"tides on the secondary ×1e+06, byorp ×1e+06": kind, body, strength."""
    return ", ".join(f"{p.kind}" + ("" if p.kind == "byorp" or p.body == "both"
                                     else f" on the {p.body}")
                     + ("" if p.strength == 1 else f" ×{p.strength:g}") for p in items)


def text(obj, one_line=False):
    """A ``__repr__`` of at most a few short lines; ``one_line``: the same on one line, the
    lines separated by ";" (for objects that come in lists, as a scan's decisions)."""
    title, lines = summary(obj)
    body = [", ".join(f"{k} {v}" for k, v in line) for line in lines if line]
    if one_line:
        return f"<{title} " + "; ".join(body) + ">"
    return "\n".join([f"<{title}>"] + ["  " + line for line in body])


def html(obj):
    """A small HTML table for notebooks (``_repr_html_``)."""
    title, lines = summary(obj)
    esc = _html.escape
    rows = "".join(f"<tr><th style=\"text-align:left\">{esc(k)}</th><td style=\"text-align:left\">"
                   f"{esc(v)}</td></tr>" for line in lines for k, v in line)
    return f"<table><caption>{esc(title)}</caption>{rows}</table>"


class Readable:
    """``__repr__`` (a few lines, never the arrays) and ``_repr_html_`` (a small table) for
    the package's systems, bodies and results. Dataclasses that inherit it are declared with
    ``@dataclass(repr=False)``, which keeps this ``__repr__`` instead of generating one."""

    def __repr__(self):
        return text(self)

    def _repr_html_(self):
        return html(self)


class ReadableLine(Readable):
    """:class:`Readable` with a one-line ``__repr__`` (:func:`text` ``one_line``): for what
    comes in lists, where a list of several-line reprs would be hard to read."""

    def __repr__(self):
        return text(self, one_line=True)
