"""Results, saved files and checkpoints bit for bit the same as before, for every method and model.

Two subcommands, and the experiment scripts' self-check:

``run --out FILE.npz``
    Compute a fixed set of small cases with the public API only (names exported by
    ``ti_spinorbit/__init__.py``; the keywords of the 50f824a / 8bb06d8 entry points, which
    :func:`call` moves into ``integrator=Integrator(...)`` / ``run=Run(...)`` in a tree whose
    entry points take those options objects instead), and store every array of every result in ``FILE.npz``: the result's fields (walked
    generically: dataclass fields, nested results, records, systems as their parameter rows,
    perturbations as their fields), the same after ``save()`` + ``load()``, the archive's
    own members and its metadata (flattened to one entry per JSON leaf), and the arrays and
    header of every checkpoint file of the checkpointed cases. Prints the wall time of each
    case.

``compare A.npz B.npz``
    Every stored array of A against B, bit for bit: equal dtype, equal shape, equal bytes
    (float and complex arrays are compared by bit pattern, so NaNs of the same pattern are
    equal and -0.0 differs from 0.0). Prints one row per array (``--only-diff``: the
    differing ones), then the arrays that exist in one file only (skipped, not failed).
    Exit status 1 on any difference or any case that raised, else 0.

``[--quick] [--out DIR]`` (no subcommand: ``experiments/_common.py``'s interface, which
``tests/test_experiments.py`` runs)
    Run the cases (``--quick``: one of each kind) twice in the imported tree and check that
    the two runs agree bit for bit, that every loaded result equals the result saved and that
    the section resumed from its finished checkpoint equals the run that wrote it; writes
    ``DIR/bitwise_compare.png`` (wall time per case) and ``.npz``; exit status 1 on any
    difference.

Run it against a checkout by putting that checkout first on the path, from its root (the
package finds its ``kernels/`` through the checkout's top-level ``kernels`` folder)::

    cd /tmp/wt_old && PYTHONPATH=/tmp/wt_old python /work/main/experiments/bitwise_compare.py run --out /tmp/bw_old.npz
    cd /tmp/wt_head && PYTHONPATH=/tmp/wt_head python /work/main/experiments/bitwise_compare.py run --out /tmp/bw_head.npz
    python /work/main/experiments/bitwise_compare.py compare /tmp/bw_old.npz /tmp/bw_head.npz

``run`` prints the package file it imported; it refuses to run when ``--tree DIR`` is given
and the package was imported from elsewhere. ``--only WORD ...`` runs the cases whose name
contains one of the words (e.g. a smallest reproducer of one difference). The whole set takes
about 20 s on 2 cores, Taichi's kernel cache empty or not.

A checkpoint written as one run in one tree and as launches (``DIR/launch-kkk``) in the other
(chaos_map before and after every stage of a map was checkpointed) is compared with the
other's last launch, the full-length map ("relocated" rows).

What is not compared (volatile by construction, listed in every run's ``__meta__``):

* result fields named ``seconds`` (wall time) and checkpoint headers' ``seconds``;
* the archive's raw bytes: ``save()`` writes ``created_utc`` (the time of writing; also the
  Taichi arch and the package version) into its ``metadata`` member, so two saves of one
  result differ in bytes (the zip members themselves carry no time: NumPy writes them with
  zipfile's fixed 1980-01-01 stamp). Instead the archive's array members are hashed (name,
  dtype, shape, bytes; ``file/arrays_sha256``) and compared one by one (``file/<member>``),
  and the metadata is compared leaf by leaf (``file/metadata/...``, ``metadata_sha256``)
  with ``created_utc`` and the wall time left out; the raw digest is kept in ``__meta__``;
* checkpoint state headers' ``seconds`` (so state.npz's raw bytes differ from run to run;
  its arrays and the rest of its header are compared), the ``lock`` file and, were one
  left, ``lock-owner.json`` (pid, host, time). The records files are deterministic: their
  arrays and the state's ``records_sha256`` (digests of their raw bytes) are compared.
"""

import argparse
import dataclasses
import hashlib
import inspect
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
import zipfile

import numpy as np

#: Field names never stored (wall times).
VOLATILE_FIELDS = ("seconds",)
#: Metadata keys of a saved archive never stored (time of writing).
VOLATILE_METADATA = ("created_utc",)
#: Checkpoint header keys never stored (the run's wall time so far).
VOLATILE_CHECKPOINT = ("seconds",)
#: Checkpoint files whose content is never stored (only their names).
VOLATILE_CHECKPOINT_FILES = ("lock", "lock-owner.json")

#: The Runge-Kutta pairs and the models of every compared tree (the methods of
#: kernels/tableau.py METHODS, the models of surface_of_section's ``model=``).
METHODS = ("cash-karp", "dop853", "vern9")
MODELS = ("planar", "3d", "auto")

SEP = "::"          # case SEP array path


# ---- helpers ----------------------------------------------------------------------------
def accepts(fn, name):
    """Whether callable ``fn`` takes keyword ``name`` by name (not via **kwargs)."""
    p = inspect.signature(fn).parameters.get(name)
    return p is not None and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)


#: Keywords of the older entry points that newer trees take inside an options object:
#: (name of the entry point's keyword, the options class exported by the package, the
#: field's name in it).
OPTION_FIELDS = {
    "model": ("integrator", "Integrator", "model"),
    "order": ("integrator", "Integrator", "order"),
    "atol": ("integrator", "Integrator", "atol"),
    "escape_distance": ("integrator", "Integrator", "escape_distance"),
    "rtol": ("integrator", "Integrator", "rtol"),
    "method": ("integrator", "Integrator", "method"),
    "progress": ("run", "Run", "progress"),
    "checkpoint": ("run", "Run", "checkpoint"),
    "resume": ("run", "Run", "resume"),
    "overwrite_checkpoint": ("run", "Run", "overwrite"),
    "window_orbits": ("run", "Run", "window_orbits"),
    "client": ("run", "Run", "client"),
    "chunk_size": ("run", "Run", "chunk_size"),
}


def call(fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` in the API of the tree imported, branching on its signature:
    a keyword ``fn`` names is passed as it is; one it does not name goes

    * into an options object when ``fn`` takes one and the package exports its class
      (``model=`` -> ``integrator=Integrator(model=...)``, ``progress=`` / ``checkpoint=`` /
      ``window_orbits=`` -> ``run=Run(...)``, :data:`OPTION_FIELDS`);
    * else through ``**section_kwargs`` when ``fn`` passes those on to surface_of_section
      and surface_of_section names it;

    anything else is a TypeError naming the keyword (adapt the case), never passed on
    silently."""
    import ti_spinorbit as tso

    params = inspect.signature(fn).parameters
    var_kw = any(q.kind == q.VAR_KEYWORD for q in params.values())
    direct, options, missing = {}, {}, []
    for k, v in kwargs.items():
        if accepts(fn, k):
            direct[k] = v
            continue
        target = OPTION_FIELDS.get(k)
        if target is not None and accepts(fn, target[0]) and hasattr(tso, target[1]):
            options.setdefault(target[:2], {})[target[2]] = v
        elif var_kw and accepts(tso.surface_of_section, k):
            direct[k] = v      # **section_kwargs of the studies go to surface_of_section
        else:
            missing.append(k)
    if missing:
        raise TypeError(f"{fn.__name__}{inspect.signature(fn)} has no keyword "
                        f"{', '.join(missing)}: adapt the case to this tree")
    for (keyword, cls), fields in options.items():
        direct[keyword] = getattr(tso, cls)(**fields)
    return fn(*args, **direct)


def _json_leaves(obj, prefix, out):
    """JSON value -> {path: array}: dicts by key, lists of numbers as one array, lists of
    text as one leaf per item (its count), other lists by index, scalars as 0-d arrays
    (None as the text '<None>')."""
    if isinstance(obj, dict):
        for k in sorted(obj):
            _json_leaves(obj[k], f"{prefix}/{k}", out)
    elif isinstance(obj, list):
        if obj and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in obj):
            out[prefix] = np.asarray(obj)
        elif obj and all(isinstance(v, str) for v in obj):
            # a list of names (the arrays of an archive, ...): one leaf per name, so that a
            # name one tree adds is an entry of that tree only (skipped), not a shifted list
            for v in obj:
                out[f"{prefix}/{v}"] = np.asarray(obj.count(v))
        elif not obj:
            out[prefix] = np.asarray("<empty list>")
        else:
            for k, v in enumerate(obj):
                _json_leaves(v, f"{prefix}/{k}", out)
    elif obj is None:
        out[prefix] = np.asarray("<None>")
    else:
        out[prefix] = np.asarray(obj)


def _normalise(a):
    """An array as stored: object arrays of str as unicode, other object arrays as the
    repr of each element (exact for floats: shortest round-trip text)."""
    a = np.asarray(a)
    if a.dtype == object:
        if all(isinstance(v, str) for v in a.flat):
            return a.astype(str) if a.size else np.zeros(a.shape, dtype="<U1")
        return np.array([repr(v) for v in a.flat], dtype=str).reshape(a.shape)
    return a


def flatten(obj, prefix, out, skipped, seen=None):
    """Every number and array reachable from a result -> ``out[path]``; the paths of
    volatile fields go to ``skipped``."""
    import ti_spinorbit as tso

    seen = set() if seen is None else seen
    if obj is None:
        out[prefix] = np.asarray("<None>")
    elif isinstance(obj, tso.BinarySystem):
        out[prefix + "/parameter_row"] = np.asarray(obj.parameter_row())
        out[prefix + "/name"] = np.asarray(obj.name)
    elif isinstance(obj, np.ndarray):
        out[prefix] = _normalise(obj)
    elif isinstance(obj, (bool, int, float, complex, str, np.generic)):
        out[prefix] = np.asarray(obj)
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        if id(obj) in seen:
            return
        seen.add(id(obj))
        for f in dataclasses.fields(obj):
            if f.name in VOLATILE_FIELDS:
                skipped.add(f"{prefix}/{f.name}")
                continue
            flatten(getattr(obj, f.name), f"{prefix}/{f.name}", out, skipped, seen)
    elif isinstance(obj, (list, tuple)):
        if obj and all(isinstance(s, tso.BinarySystem) for s in obj):
            out[prefix + "/parameter_rows"] = np.stack([s.parameter_row() for s in obj])
            out[prefix + "/names"] = np.array([s.name for s in obj], dtype=str)
        elif obj and all(isinstance(v, (bool, int, float, np.generic)) for v in obj):
            out[prefix] = np.asarray(obj)
        elif not obj:
            out[prefix] = np.asarray("<empty>")
        else:
            for k, v in enumerate(obj):
                flatten(v, f"{prefix}/{k}", out, skipped, seen)
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            flatten(obj[k], f"{prefix}/{k}", out, skipped, seen)
    elif hasattr(obj, "__dict__"):
        flatten(dict(vars(obj)), prefix, out, skipped, seen)
    else:
        out[prefix] = np.asarray(f"<{type(obj).__name__}> {obj!r}")


def _array_hash(arrays):
    h = hashlib.sha256()
    for k in sorted(arrays):
        a = np.ascontiguousarray(arrays[k])
        h.update(f"{k}|{a.dtype.str}|{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def saved_file_arrays(result, workdir, name):
    """save() the result, load() it back; the loaded result's arrays (``loaded/...``), the
    archive's members (``file/<member>``), their hash and the metadata's leaves."""
    import ti_spinorbit as tso

    out, skipped = {}, set()
    path = os.path.join(workdir, name.replace("/", "_") + ".npz")
    tso.save(result, path)
    flatten(tso.load(path), "loaded", out, skipped)
    members = {}
    with np.load(path, allow_pickle=False) as z:
        for k in z.files:
            if k == "metadata":
                meta = json.loads(str(z[k]))
            else:
                members[k] = z[k]
    for k, a in members.items():
        out["file/" + k] = a
    out["file/arrays_sha256"] = np.asarray(_array_hash(members))
    for k in VOLATILE_METADATA:
        if meta.pop(k, None) is not None:
            skipped.add("file/metadata/" + k)
    _strip(meta, VOLATILE_FIELDS, "file/metadata", skipped)
    _json_leaves(meta, "file/metadata", out)
    out["file/metadata_sha256"] = np.asarray(
        hashlib.sha256(json.dumps(meta, sort_keys=True).encode()).hexdigest())
    with zipfile.ZipFile(path) as zf:
        stamps = sorted({i.date_time for i in zf.infolist()})
    raw = hashlib.sha256(open(path, "rb").read()).hexdigest()
    return out, skipped, {"raw_sha256": raw, "zip_date_times": [list(s) for s in stamps]}


def _strip(obj, keys, prefix, skipped):
    """Remove ``keys`` whose value is a number (a wall time, not a unit's text) from every
    dict inside a JSON value, noting the paths."""
    if isinstance(obj, dict):
        for k in list(obj):
            if k in keys and isinstance(obj[k], (int, float)):
                del obj[k]
                skipped.add(f"{prefix}/{k}")
            else:
                _strip(obj[k], keys, f"{prefix}/{k}", skipped)
    elif isinstance(obj, list):
        for k, v in enumerate(obj):
            _strip(v, keys, f"{prefix}/{k}", skipped)


def checkpoint_arrays(directory):
    """Every checkpoint file under ``directory`` -> arrays (``ckpt/<relative path>/...``)."""
    out, skipped, names = {}, set(), []
    for root, dirs, files in os.walk(directory):
        dirs.sort()
        for f in sorted(files):
            rel = os.path.relpath(os.path.join(root, f), directory)
            names.append(rel)
            if f in VOLATILE_CHECKPOINT_FILES:
                skipped.add(f"ckpt/{rel}")
                continue
            if not f.endswith(".npz"):
                with open(os.path.join(root, f), "rb") as fh:
                    out[f"ckpt/{rel}/sha256"] = np.asarray(hashlib.sha256(fh.read()).hexdigest())
                continue
            arrays = {}
            with np.load(os.path.join(root, f), allow_pickle=False) as z:
                for k in z.files:
                    arrays[k] = z[k]
            if "header" in arrays:
                header = json.loads(str(arrays.pop("header")))
                _strip(header, VOLATILE_CHECKPOINT, f"ckpt/{rel}/header", skipped)
                _json_leaves(header, f"ckpt/{rel}/header", out)
            for k in VOLATILE_CHECKPOINT:
                if arrays.pop(k, None) is not None:
                    skipped.add(f"ckpt/{rel}/{k}")
            for k, a in arrays.items():
                out[f"ckpt/{rel}/{k}"] = a
            out[f"ckpt/{rel}/arrays_sha256"] = np.asarray(_array_hash(arrays))
    for rel in names:                   # one leaf per file: a file one tree adds is skipped
        out[f"ckpt/files/{rel}"] = np.asarray(True)
    return out, skipped


# ---- the cases --------------------------------------------------------------------------
def grid(thetas, rates):
    """Every (θ_p, θ̇_p) pair of two 1-D lists, as two flat arrays."""
    T, D = np.meshgrid(np.asarray(thetas, float), np.asarray(rates, float), indexing="ij")
    return T.ravel(), D.ravel()


TH, TD = grid([0.0, 45.0, 90.0, 135.0], [0.8, 1.0, 1.3, 1.6])       # 4 x 4 starts
SYSTEM_NAMES = ("1991 VH", "2000 DP107", "1999 KW4", "1996 FG3")    # one per column of 4


def catalogue_members():
    """16 members: four catalogue systems, each with the 4 x 4 starts' θ̇_p of one row."""
    import ti_spinorbit as tso

    systems = [tso.catalog.system(n) for n in SYSTEM_NAMES]
    return [systems[k % 4] for k in range(len(TH))]


def vh():
    import ti_spinorbit as tso
    return tso.catalog.system("1991 VH")


def perturbations(yorp_convention=None):
    """Tides on both bodies (constant Q and constant time lag), YORP on the secondary, BYORP;
    strengths that keep every force a perturbation over 20 orbits. ``yorp_convention``:
    passed to YORP where this tree's YORP has the keyword."""
    import ti_spinorbit as tso

    yorp = dict(body="secondary", coefficient=5e-4, strength=1e3)
    byorp = dict(coefficient=1e-3, strength=1e3)
    if yorp_convention is not None and accepts(tso.YORP, "convention"):
        yorp["convention"] = yorp_convention
    # the mean-distance form, which trees before the heliocentric distance had
    if accepts(tso.YORP, "distance"):
        yorp["distance"] = byorp["distance"] = "mean"
    return [tso.Tides(body="secondary", strength=1e3),
            tso.Tides(body="primary", k2=1e-3, time_lag=60.0, strength=1e2),
            tso.YORP(**yorp),
            tso.BYORP(**byorp)]


def explicit_states(system, planar):
    """Two explicit InitialState starts built from numbers (not from the paper's start):
    planar ones (every axis along the orbit normal, so model="auto" may pick the planar
    model), or out of the plane."""
    import ti_spinorbit as tso

    a, n, e = system.a, system.mean_motion, system.e
    states = []
    for k, (phase, spin) in enumerate(((20.0, 1.1), (70.0, 0.9))):
        c, s = np.cos(np.radians(phase)), np.sin(np.radians(phase))
        Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        r = a * (1.0 - e)
        V = np.array([0.0, a * n * np.sqrt((1.0 + e) / (1.0 - e)) * 0.999, 0.0])
        w1 = 0.0 if system.primary_spin_period is None else 2 * np.pi / system.primary_spin_period
        if planar:
            A1, A2 = np.eye(3), Rz
            w2 = [0.0, 0.0, spin * n]
        else:
            t = np.radians(8.0 + 4.0 * k)
            tilt = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(t), -np.sin(t)],
                             [0.0, np.sin(t), np.cos(t)]])
            A1 = np.array([[np.cos(0.05), 0.0, np.sin(0.05)], [0.0, 1.0, 0.0],
                           [-np.sin(0.05), 0.0, np.cos(0.05)]])
            A2 = Rz @ tilt
            V = V + np.array([0.0, 0.0, 0.02 * V[1]])
            w2 = [0.01 * n, -0.02 * n, spin * n]
        st = tso.InitialState(R=np.array([r, 0.0, 0.0]), V=V,
                              primary_attitude=A1, primary_omega=[0.0, 0.0, w1],
                              secondary_attitude=A2, secondary_omega=w2)
        states.append(st.kicked([0.0, -1e-4 * V[1], 0.0]) if k == 1 else st)
    return states


def build_cases():
    """[(name, function(workdir) -> (result, checkpoint directory or None))]."""
    import ti_spinorbit as tso

    sos, ts = tso.surface_of_section, tso.time_series
    cases = []

    def add(name):
        def deco(fn):
            cases.append((name, fn))
            return fn
        return deco

    # surfaces of section of catalogue systems: every method x every model
    for method in METHODS:
        for model in MODELS:
            def fn(wd, method=method, model=model):
                return call(sos, catalogue_members(), TH, TD, orbits=20, method=method,
                            model=model, progress=False), None
            add(f"section/{method}/{model}")(fn)

    @add("section/apsidal")
    def _(wd):
        return call(sos, vh(), TH, TD, orbits=20, coordinates="apsidal", progress=False), None

    @add("section/order2-rtol1e-9")
    def _(wd):
        return call(sos, vh(), TH, TD, orbits=20, order=2, rtol=1e-9, progress=False), None

    @add("section/order3-3d")
    def _(wd):
        return call(sos, vh(), TH[:8], TD[:8], orbits=20, order=3, model="3d",
                    progress=False), None

    # tilted starts (the 3-D model) and explicit InitialState starts
    @add("section/tilted")
    def _(wd):
        s = vh()
        states = [s.tilted_start(t, d, roll=10.0, pitch=5.0) for t, d in
                  ((0.0, 1.0), (45.0, 1.3), (90.0, 0.8), (30.0, 1.6))]
        return call(sos, s, orbits=20, initial_states=states, progress=False), None

    @add("section/tilted-vern9")
    def _(wd):
        s = vh()
        states = [s.tilted_start(t, d, pitch=3.0, inclination=2.0, spin_x=0.05) for t, d in
                  ((0.0, 1.0), (60.0, 1.2))]
        return call(sos, s, orbits=20, initial_states=states, method="vern9",
                    progress=False), None

    for planar in (True, False):
        label = "planar" if planar else "3d"

        @add(f"section/explicit-{label}")
        def _(wd, planar=planar):
            s = vh()
            return call(sos, s, orbits=20, initial_states=explicit_states(s, planar),
                        progress=False), None

    # perturbed runs (tides on both bodies, YORP, BYORP), each model; YORP's default and,
    # where the tree has the keyword, the convention the old package used
    for model in MODELS:
        @add(f"perturbed/default/{model}")
        def _(wd, model=model):
            return call(sos, vh(), TH[:8], TD[:8], orbits=20, model=model,
                        perturbations=perturbations(), progress=False), None

        @add(f"perturbed/one-turn/{model}")
        def _(wd, model=model):
            return call(sos, vh(), TH[:8], TD[:8], orbits=20, model=model,
                        perturbations=perturbations("one-turn"), progress=False), None

    @add("perturbed/one-turn/planar-vern9")
    def _(wd):
        return call(sos, vh(), TH[:8], TD[:8], orbits=20, method="vern9",
                    perturbations=perturbations("one-turn"), progress=False), None

    @add("perturbed/time_series-3d")
    def _(wd):
        return call(ts, vh(), [0.0, 90.0], [1.0, 1.3], orbits=5, samples_per_orbit=16,
                    model="3d", states=True, perturbations=perturbations("one-turn"),
                    progress=False), None

    # chaos indicators
    @add("indicators/section-planar")
    def _(wd):
        return call(sos, vh(), TH, TD, orbits=10, indicators=True, progress=False), None

    for method in METHODS[1:]:
        @add(f"indicators/section-planar-{method}")
        def _(wd, method=method):
            return call(sos, vh(), TH[:8], TD[:8], orbits=10, indicators=True, method=method,
                        progress=False), None

    @add("indicators/section-full")
    def _(wd):
        return call(sos, vh(), TH[:8], TD[:8], orbits=10, indicators=True,
                    indicator_space="full", progress=False), None

    @add("indicators/classify_section")
    def _(wd):
        r = call(sos, vh(), TH, TD, orbits=10, indicators=True, progress=False)
        return call(tso.classify_section, r), None

    @add("indicators/chaos_map")
    def _(wd):
        return call(tso.chaos_map, vh(), [0.0, 45.0, 90.0, 135.0], [0.8, 1.0, 1.3, 1.6],
                    orbits=10, progress=False), None

    @add("indicators/chaos_map-tilt")
    def _(wd):
        return call(tso.chaos_map, vh(), [0.0, 90.0], [1.0, 1.3], orbits=8, tilt=(5.0, 3.0),
                    fraction_orbits=(), progress=False), None

    @add("indicators/chaos_map-perturbed")
    def _(wd):
        return call(tso.chaos_map, vh(), [0.0, 90.0], [1.0, 1.3], orbits=8,
                    perturbations=perturbations("one-turn"), fraction_orbits=(),
                    progress=False), None

    @add("indicators/parameter_map")
    def _(wd):
        return call(tso.parameter_map, "1991 VH", [1.1, 1.3], [0.05, 0.1], orbits=8,
                    theta_p=[0.0], thetadot_p=[1.0, 1.5], progress=False), None

    # time series
    @add("time_series/planar")
    def _(wd):
        return call(ts, vh(), [0.0, 90.0], [1.0, 1.3], orbits=5, samples_per_orbit=16,
                    progress=False), None

    @add("time_series/3d-states")
    def _(wd):
        return call(ts, vh(), [0.0, 90.0], [1.0, 1.3], orbits=5, samples_per_orbit=16,
                    model="3d", states=True, progress=False), None

    @add("time_series/explicit-3d-dop853")
    def _(wd):
        s = vh()
        return call(ts, s, orbits=5, samples_per_orbit=16,
                    initial_states=explicit_states(s, False), method="dop853",
                    progress=False), None

    @add("time_series/apsidal")
    def _(wd):
        return call(ts, vh(), [0.0], [1.0, 1.3], orbits=5, samples_per_orbit=16,
                    coordinates="apsidal", progress=False), None

    # studies at minimal sizes
    @add("overlap_threshold")
    def _(wd):
        return call(tso.overlap_threshold, "1991 VH", elongations=[1.05], orbits=4,
                    max_orbits=8, centre_starts=2, separatrix_starts=2,
                    progress=False), None

    @add("relaxed_libration")
    def _(wd):
        return call(tso.relaxed_libration, vh(), orbits=5, samples_per_orbit=32,
                    zoom_candidates=5, max_iterations=2, max_orbits=10,
                    progress=False), None

    @add("libration_amplitude")
    def _(wd):
        return call(tso.libration_amplitude, vh(), [0.8, 0.9, 1.6], 2, samples_per_orbit=16,
                    rtol=1e-10, progress=False), None

    @add("libration_amplitude-one")
    def _(wd):
        return call(tso.libration_amplitude, vh(), 0.85, 3, samples_per_orbit=16,
                    progress=False), None

    # early stops at a loose tolerance: e = 0.6, rtol 1e-3 "escapes" (a tolerance artefact)
    @add("section/loose-escape")
    def _(wd):
        s = tso.catalog.system("1991 VH", eccentricity=0.6)
        return call(sos, s, 0.0, [0.3, 0.48, 0.66, 0.84], orbits=200, rtol=1e-3,
                    progress=False), None

    # checkpoints: a single run (state + records per window), a time series (samples), a map
    # (every stage) and a multi-launch study; the section is also resumed from its
    # finished checkpoint
    @add("checkpoint/section")
    def _(wd):
        d = os.path.join(wd, "ckpt-section")
        return call(sos, vh(), TH[:8], TD[:8], orbits=20, window_orbits=4, checkpoint=d,
                    progress=False), d

    @add("checkpoint/section-resumed")
    def _(wd):
        d = os.path.join(wd, "ckpt-section")
        return call(sos, vh(), TH[:8], TD[:8], orbits=20, window_orbits=4, checkpoint=d,
                    resume=True, progress=False), None

    @add("checkpoint/time_series-3d")
    def _(wd):
        d = os.path.join(wd, "ckpt-ts")
        return call(ts, vh(), [0.0, 90.0], [1.0, 1.3], orbits=6, samples_per_orbit=16,
                    window_orbits=2, model="3d", checkpoint=d, progress=False), d

    @add("checkpoint/chaos_map")
    def _(wd):
        d = os.path.join(wd, "ckpt-map")
        return call(tso.chaos_map, vh(), [0.0, 90.0], [1.0, 1.3], orbits=8, window_orbits=4,
                    checkpoint=d, progress=False), d

    @add("checkpoint/overlap_threshold")
    def _(wd):
        d = os.path.join(wd, "ckpt-overlap")
        return call(tso.overlap_threshold, "1991 VH", elongations=[1.05], orbits=4,
                    max_orbits=8, centre_starts=2, separatrix_starts=2, checkpoint=d,
                    progress=False), d

    return cases


# ---- run --------------------------------------------------------------------------------
def _git_commit(path):
    try:
        return subprocess.run(["git", "-C", path, "rev-parse", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def _tree():
    import ti_spinorbit as tso

    tree = os.path.dirname(os.path.dirname(os.path.abspath(tso.__file__)))
    return tree, _git_commit(tree)


def compute(cases, label=""):
    """Run ``cases`` [(name, fn)]; returns (store {case::path: array}, meta dict)."""
    import ti_spinorbit as tso

    tree, commit = _tree()
    store, skipped_all = {}, {}
    meta = {"tree": tree, "commit": commit, "package_file": tso.__file__,
            "version": tso.__version__, "cases": {}}
    t_all = time.perf_counter()
    workdir = tempfile.mkdtemp(prefix="bitwise_compare-")
    try:
        for name, fn in cases:
            t0 = time.perf_counter()
            info = {}
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    result, ckpt_dir = fn(workdir)
                t_case = time.perf_counter() - t0
                out, skipped = {}, set()
                flatten(result, "result", out, skipped)
                if isinstance(result, tso.Result):        # libration_amplitude: an array
                    saved, s_skipped, file_info = saved_file_arrays(result, workdir, name)
                    out.update(saved)
                    skipped |= s_skipped
                    info.update(file_info)
                if ckpt_dir is not None:
                    c_out, c_skipped = checkpoint_arrays(ckpt_dir)
                    out.update(c_out)
                    skipped |= c_skipped
                info["warnings"] = sorted({f"{w.category.__name__}: {str(w.message)[:120]}"
                                           for w in caught})
                info["status_counts"] = getattr(result, "status_counts", None)
            except Exception as exc:      # a case that fails is stored as such, and compared
                t_case = time.perf_counter() - t0
                out, skipped = {"__error__": np.asarray(f"{type(exc).__name__}: {exc}")}, set()
                print(f"  {name}: FAILED {type(exc).__name__}: {exc}", flush=True)
            for k, a in out.items():
                store[f"{name}{SEP}{k}"] = a
            skipped_all[name] = sorted(skipped)
            info["seconds"] = round(t_case, 3)
            info["arrays"] = len(out)
            meta["cases"][name] = info
            counts = info.get("status_counts")
            print(f"{label}{name:42s} {t_case:7.2f} s  {len(out):4d} arrays  {counts or ''}",
                  flush=True)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    meta["seconds_total"] = round(time.perf_counter() - t_all, 3)
    meta["skipped_volatile"] = skipped_all
    return store, meta


def _select(cases, only):
    return [(n, f) for n, f in cases if not only or any(o in n for o in only)]


def cmd_run(args):
    os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
    os.environ.setdefault("MPLBACKEND", "Agg")
    import ti_spinorbit as tso

    tree, commit = _tree()
    print(f"ti_spinorbit {tso.__version__} from {tso.__file__} (commit {commit})", flush=True)
    if args.tree and os.path.realpath(tree) != os.path.realpath(args.tree):
        sys.exit(f"imported ti_spinorbit from {tree}, not {args.tree}: put the tree first on "
                 "PYTHONPATH and run from its root")
    cases = _select(build_cases(), args.only)
    store, meta = compute(cases)
    store["__meta__"] = np.asarray(json.dumps(meta))
    out_path = args.out if args.out.endswith(".npz") else args.out + ".npz"
    np.savez_compressed(out_path, **store)
    print(f"total {meta['seconds_total']:.1f} s, {len(cases)} cases, {len(store) - 1} arrays "
          f"-> {out_path}")


#: The cases of the self-check's --quick mode (one of each kind of run).
QUICK_CASES = ("section/cash-karp/", "section/vern9/planar", "section/tilted",
               "perturbed/one-turn/planar", "indicators/chaos_map", "time_series/3d-states",
               "overlap_threshold", "checkpoint/section")


def self_check():
    """``bitwise_compare.py [--quick] [--out DIR]`` (the experiment scripts' interface,
    ``experiments/_common.py``): the cases run twice in this tree must agree bit for bit
    (results, saved files, checkpoints), every loaded result must equal the result saved,
    and the run resumed from a finished checkpoint the run that wrote it. Writes
    DIR/bitwise_compare.png and .npz; exit status 1 on any difference."""
    import _common          # the experiments folder's shared plumbing (arguments, saving)
    import matplotlib.pyplot as plt

    args, started = _common.parse(__doc__.splitlines()[0])
    cases = _select(build_cases(), QUICK_CASES if args.quick else None)
    first, meta = compute(cases, "run 1  ")
    second, _ = compute(cases, "run 2  ")
    names = [n for n, _ in cases]
    rerun, roundtrip, resumed, failures = {}, {}, 0, []
    for name in names:
        keys = [k for k in first if k.startswith(name + SEP)]
        errors = [k for k in keys if k.endswith("__error__")]
        failures += [f"{k}: {first[k]}" for k in errors]
        bad = [k for k in keys if k not in second or compare_arrays(first[k], second[k])]
        bad += [k for k in second if k.startswith(name + SEP) and k not in first]
        rerun[name] = len(keys) - len(bad)
        failures += [f"rerun differs: {k}" for k in bad]
        loaded = [k for k in keys if SEP + "loaded/" in k]
        same = 0
        for k in loaded:
            r = k.replace(SEP + "loaded/", SEP + "result/")
            if r in first and compare_arrays(first[k], first[r]) is None:
                same += 1
            elif r in first:
                failures.append(f"loaded differs from saved: {k}")
        roundtrip[name] = same
    fresh = "checkpoint/section" + SEP + "result/"
    again = "checkpoint/section-resumed" + SEP + "result/"
    for k in [k for k in first if k.startswith(again)]:
        f = fresh + k[len(again):]
        if f in first and compare_arrays(first[k], first[f]) is None:
            resumed += 1
        elif f in first:
            failures.append(f"resumed differs from the run that wrote it: {k}")
    for f in failures:
        print(f"[bitwise_compare] DIFFERENCE {f}")
    fig, ax = plt.subplots(figsize=(7, 0.25 * len(names) + 1.5))
    y = np.arange(len(names))
    ax.barh(y, [meta["cases"][n]["seconds"] for n in names], color="C0")
    ax.set_yticks(y, [n.replace("_", " ") for n in names], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("wall time of the case (s)")
    ax.set_title(f"{len(names)} cases, {sum(rerun.values())} arrays equal bit for bit on a "
                 f"rerun, {len(failures)} differences", fontsize=9)
    numbers = {"cases": len(names), "arrays": len(first),
               "arrays_equal_on_rerun": int(sum(rerun.values())),
               "loaded_equal_to_saved": int(sum(roundtrip.values())),
               "resumed_equal_to_uninterrupted": int(resumed), "differences": len(failures),
               "seconds_per_run": float(meta["seconds_total"])}
    _common.save(args, "bitwise_compare", fig,
                 {"seconds": np.array([meta["cases"][n]["seconds"] for n in names])},
                 {"cases": names, "commit": meta["commit"]}, numbers, started)
    return 1 if failures else 0


# ---- compare ----------------------------------------------------------------------------
def _bits(a):
    """A float or complex array as unsigned integers of its bit patterns."""
    if a.dtype.kind == "c":
        a = a.view(a.real.dtype)
    return a.view(f"u{a.dtype.itemsize}")


def compare_arrays(a, b):
    """None when bit for bit equal, else a short description of the first difference."""
    if a.dtype != b.dtype:
        return f"dtype {a.dtype} vs {b.dtype}" + (f", shape {a.shape} vs {b.shape}"
                                                  if a.shape != b.shape else "")
    if a.shape != b.shape:
        return f"shape {a.shape} vs {b.shape}"
    if a.dtype.kind in "fc":
        neq = _bits(np.ascontiguousarray(a)) != _bits(np.ascontiguousarray(b))
        if a.dtype.kind == "c":
            neq = neq.reshape(a.shape + (2,)).any(-1)
    else:
        neq = a != b
    neq = np.asarray(neq)
    if not neq.any():
        return None
    idx = tuple(int(i) for i in np.argwhere(neq)[0]) if neq.ndim else ()
    text = f"{int(neq.sum())}/{neq.size} differ, first at {idx}"
    if a.dtype.kind in "fciub":
        x, y = a.astype(np.float64) if a.dtype.kind != "c" else a, \
            b.astype(np.float64) if b.dtype.kind != "c" else b
        with np.errstate(invalid="ignore"):
            d = np.abs(x - y)[neq]
        d = d[np.isfinite(d)]
        text += f": {a[idx]!r} vs {b[idx]!r}"
        if d.size:
            text += f", max |diff| {d.max():.3g}"
        nan_a, nan_b = np.isnan(x[neq]).sum(), np.isnan(y[neq]).sum()
        if nan_a != nan_b:
            text += f" (NaN {nan_a} vs {nan_b})"
    else:
        va, vb = str(a[idx]), str(b[idx])
        text += f": {va[:60]!r} vs {vb[:60]!r}"
    return text


def _hash_over_common(A, B, ka, kb, case, name, d):
    """A hash that differs because its archive or checkpoint file has entries in one tree
    only (a new field, a metadata key one tree writes): the same hash over the entries both
    trees stored (``file/<member>``, ``file/metadata/...``, ``ckpt/<file>/<array>``). Returns
    (difference or None, note)."""
    if name == "file/arrays_sha256":
        prefix, exclude = f"{case}{SEP}file/", ("file/metadata", "file/arrays_sha256")
    elif name == "file/metadata_sha256":
        prefix, exclude = f"{case}{SEP}file/metadata/", ()
    elif name.startswith("ckpt/") and name.endswith("/arrays_sha256"):
        prefix, exclude = f"{case}{SEP}{name[:-len('arrays_sha256')]}", ("/header/", "sha256")
    else:
        return d, ""

    def members(keys):
        return {k for k in keys if k.startswith(prefix)
                and not any(x in k.partition(SEP)[2] for x in exclude if x)}
    ma, mb = members(ka), members(kb)
    common = ma & mb
    if ma == mb or not common:
        return d, ""
    ha = _array_hash({k: A[k] for k in common})
    hb = _array_hash({k: B[k] for k in common})
    note = f"{len(common)} common entries, {len(ma - mb)} only in A, {len(mb - ma)} only in B"
    if ha == hb:
        return None, f"OK over the {note}"
    return f"{d} (and over the {note})", ""


def cmd_compare(args):
    A, B = np.load(args.a, allow_pickle=False), np.load(args.b, allow_pickle=False)
    meta_a = json.loads(str(A["__meta__"])) if "__meta__" in A.files else {}
    meta_b = json.loads(str(B["__meta__"])) if "__meta__" in B.files else {}
    print(f"A: {args.a}  ({meta_a.get('tree')}, {meta_a.get('commit', '')[:10]})")
    print(f"B: {args.b}  ({meta_b.get('tree')}, {meta_b.get('commit', '')[:10]})")
    ka = {k for k in A.files if not k.startswith("__")}
    kb = {k for k in B.files if not k.startswith("__")}
    order = list(dict.fromkeys([k.split(SEP)[0] for k in A.files if SEP in k]
                               + [k.split(SEP)[0] for k in B.files if SEP in k]))
    rank = {c: i for i, c in enumerate(order)}
    differ, same, errors = [], 0, []
    width = max([len(k.split(SEP)[0]) for k in ka | kb] + [4])
    print(f"\n{'case':{width}s}  {'array':48s}  result")
    for k in sorted(ka & kb, key=lambda k: (rank.get(k.split(SEP)[0], 0), k)):
        case, _, name = k.partition(SEP)
        if name == "__error__":
            errors.append(k)
            print(f"{case:{width}s}  {name:48s}  ERROR A: {str(A[k])[:80]} | B: {str(B[k])[:80]}")
            continue
        d = compare_arrays(A[k], B[k])
        note = "OK"
        if d is not None and name.endswith("_sha256"):
            d, note = _hash_over_common(A, B, ka, kb, case, name, d)
        if d is None:
            same += 1
            if not args.only_diff:
                print(f"{case:{width}s}  {name:48s}  {note}")
        else:
            differ.append(k)
            print(f"{case:{width}s}  {name:48s}  DIFF {d}")
    for label, keys, src in (("A", ka - kb, A), ("B", kb - ka, B)):
        for k in sorted(keys, key=lambda k: (rank.get(k.split(SEP)[0], 0), k)):
            if k.endswith(SEP + "__error__"):
                errors.append(k)
                print(f"{k.split(SEP)[0]:{width}s}  {'__error__':48s}  ERROR only in {label}: "
                      f"{str(src[k])[:100]}")
    only_a = {k for k in ka - kb if not k.endswith("__error__")}
    only_b = {k for k in kb - ka if not k.endswith("__error__")}
    # a checkpoint of one run in one tree and of several launches (DIR/launch-kkk) in the
    # other: compare the single run with the last launch (the full-length one)
    for keys_1, keys_2, first_is_a in ((only_a, only_b, True), (only_b, only_a, False)):
        pairs = []
        for case in order:
            launches = sorted({k.split(SEP)[1].split("/")[1] for k in keys_2
                               if k.startswith(f"{case}{SEP}ckpt/launch-")})
            if not launches or any(k.startswith(f"{case}{SEP}ckpt/launch-") for k in keys_1):
                continue
            for k in sorted(keys_1):
                c, _, name = k.partition(SEP)
                if c != case or not name.startswith("ckpt/") or name.startswith("ckpt/files/"):
                    continue
                other = f"{case}{SEP}ckpt/{launches[-1]}/{name[len('ckpt/'):]}"
                if other in keys_2:
                    pairs.append((k, other))
        for k, other in pairs:
            ka_, kb_ = (k, other) if first_is_a else (other, k)
            keys_1.discard(k)
            keys_2.discard(other)
            case, _, name_a = ka_.partition(SEP)
            label = f"{name_a} ~ B {kb_.partition(SEP)[2]}"
            d = compare_arrays(A[ka_], B[kb_])
            if d is None:
                same += 1
                if not args.only_diff:
                    print(f"{case:{width}s}  {label:48s}  OK (relocated)")
            else:
                differ.append(ka_)
                print(f"{case:{width}s}  {label:48s}  DIFF (relocated) {d}")
    only_a, only_b = sorted(only_a), sorted(only_b)
    for label, keys in (("A", only_a), ("B", only_b)):
        print(f"\nonly in {label} (skipped, {len(keys)}):")
        for k in keys:
            print(f"  {k}")
    ca, cb = meta_a.get("cases", {}), meta_b.get("cases", {})
    print(f"\n{'case':{width}s}  {'A s':>8s}  {'B s':>8s}")
    for c in order:
        sa, sb = ca.get(c, {}).get("seconds"), cb.get(c, {}).get("seconds")
        print(f"{c:{width}s}  {sa if sa is not None else '-':>8}  {sb if sb is not None else '-':>8}")
    print(f"{'total':{width}s}  {meta_a.get('seconds_total', '-'):>8}  "
          f"{meta_b.get('seconds_total', '-'):>8}")
    cases_diff = sorted({k.split(SEP)[0] for k in differ}, key=lambda c: rank.get(c, 0))
    print(f"\n{same} arrays identical, {len(differ)} differ in {len(cases_diff)} cases"
          f"{': ' + ', '.join(cases_diff) if cases_diff else ''}; {len(errors)} errors; "
          f"{len(only_a)} only in A, {len(only_b)} only in B (skipped)")
    return 1 if differ or errors else 0


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] not in ("run", "compare", "-h", "--help"):
        return self_check()         # --quick / --out DIR: the experiment scripts' interface
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="compute the cases and store their arrays")
    r.add_argument("--out", required=True, help="output .npz")
    r.add_argument("--tree", help="refuse to run unless ti_spinorbit is imported from this checkout")
    r.add_argument("--only", nargs="+", help="run only the cases whose name contains one of these")
    c = sub.add_parser("compare", help="compare two files written by run, bit for bit")
    c.add_argument("a")
    c.add_argument("b")
    c.add_argument("--only-diff", action="store_true", help="print only differing arrays")
    args = p.parse_args(argv)
    if args.cmd == "run":
        cmd_run(args)
        return 0
    return cmd_compare(args)


if __name__ == "__main__":
    sys.exit(main())
