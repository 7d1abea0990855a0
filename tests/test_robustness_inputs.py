"""Degenerate and mistyped input is refused before any integration, and the
library bounds spin rates and the primary's spin as the command line does (part 3).

Every case asserts the exception type and that the one-line message names the parameter (and
the allowed range where there is one); the command-line cases run ``python -m ti_spinorbit``
and assert exit status 2, one line on stderr naming the flag, and no traceback. Nothing here
integrates: each refusal comes before any Taichi work, so the file runs in seconds."""

import os
import re
import subprocess
import sys
import time

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import _validate
from ti_spinorbit.studies.overlap import overlap_vs_eccentricity

from conftest import run_cli

P = tso.Sphere(600, 1581)
S = tso.Ellipsoid(245, 163, 150, 2000)
GOOD_SECOND = {(2, 0, 0): 0.3, (0, 2, 0): 0.2, (0, 0, 2): 0.1}


def line_body():
    """Two point masses on a line: a body with a zero principal moment (integrated to "done"
    with NaN diagnostics before it was refused)."""
    return tso.Body.from_point_masses([[100, 0, 0], [-100, 0, 0]], [1e9, 1e9])[0]


# ---- 1. degenerate bodies and systems: ValueError naming the parameter and its range -----

DEGENERATE = [
    ("line-secondary", lambda vh: tso.BinarySystem(P, line_body(), 3000, 0.1),
     r"^secondary: each principal moment must be at least 1e-06 of the largest \(got A, B, C = 0, "),
    ("line-primary", lambda vh: tso.BinarySystem(line_body(), S, 3000, 0.1),
     r"^primary: each principal moment must be at least 1e-06 of the largest"),
    ("sphere-1e300", lambda vh: tso.Sphere(1e300, 1000),
     r"^radius must lie in \[0\.001, 1e\+10\] m \(got 1e\+300\)"),
    ("sphere-1e300-mass", lambda vh: tso.Sphere(1e300, mass=1e12),
     r"^radius must lie in \[0\.001, 1e\+10\] m"),
    ("ellipsoid-1e200", lambda vh: tso.Ellipsoid(1e200, 100, 100, 1000),
     r"^a must lie in \[0\.001, 1e\+10\] m \(got 1e\+200\)"),
    ("ellipsoid-tiny-c", lambda vh: tso.Ellipsoid(3, 2, 1e-9, 1000),
     r"^c must lie in \[0\.001, 1e\+10\] m \(got 1e-09\)"),
    ("ellipsoid-needle", lambda vh: tso.Ellipsoid(1e4, 1e-3, 1e-3, 1000),
     r"^semi-axes a=10000, b=0\.001, c=0\.001 make a needle: \(b² \+ c²\)/\(a² \+ b²\) must be "
     r">= 1e-06"),
    ("system-a-1e200", lambda vh: tso.BinarySystem(P, S, 1e200, 0.1),
     r"^a must lie in \[0\.001, 1e\+13\] m \(got 1e\+200\)"),
    ("sphere-density-1e-300", lambda vh: tso.Sphere(100, 1e-300),
     r"^density must lie in \[1, 100000\] kg/m\^3 \(got 1e-300\)"),
    ("ellipsoid-density-1e6", lambda vh: tso.Ellipsoid(3, 2, 1, 1e6),
     r"^density must lie in \[1, 100000\] kg/m\^3 \(got 1000000\.0\)"),
    ("catalog-density-1e-300", lambda vh: tso.catalog.system("1991 VH", secondary_density=1e-300),
     r"^secondary_density must lie in \[1, 100000\] kg/m\^3 \(got 1e-300\)"),
    ("body-mass-1e40", lambda vh: tso.Body(1e40, GOOD_SECOND, 1.0),
     r"^mass must lie in \[1e-09, 1e\+35\] kg \(got 1e\+40\)"),
    ("ellipsoid-mass-from-density-too-large", lambda vh: tso.Sphere(1e10, 1e5),
     r"^mass \(density × volume\) must lie in \[1e-09, 1e\+35\] kg"),
    ("body-negative-second-moment",
     lambda vh: tso.Body(1.0, {(2, 0, 0): 0.5, (0, 2, 0): -0.1, (0, 0, 2): 0.1}, 1.0),
     r"^integrals\[\(0, 2, 0\)\] must be >= 0: a second moment .* \(got -0\.1\)"),
    ("body-bounding-radius-inside", lambda vh: tso.Body(1.0, GOOD_SECOND, 0.5),
     r"^bounding_radius must be >= 0\.774597 m, the smallest sphere the integrals allow \(RMS "
     r"radius sqrt\(\(T\^200 \+ T\^020 \+ T\^002\)/mass\) = 0\.774597 m, .*\(got 0\.5\)"),
    ("body-fourth-moment-outside",
     lambda vh: tso.Body(1.0, {**GOOD_SECOND, (4, 0, 0): 16.0}, 1.0),
     r"^bounding_radius must be >= 2 m, the smallest sphere the integrals allow .*\(got 1\)"),
    ("point-cloud-too-large",
     lambda vh: tso.Body.from_point_masses([[1e300, 0, 0], [0, 1, 0], [0, 0, 1]], [1, 1, 1]),
     r"^points must lie within 1e\+10 m of the origin \(got a coordinate of 1e\+300 m\)"),
    ("point-cloud-bounding-radius-inside",
     lambda vh: tso.Body.from_point_masses([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]],
                                           [1, 1, 1, 1], bounding_radius=0.9),
     r"^bounding_radius must be >= 1 m, the smallest sphere"),
    ("mass-ratio-1e26",
     lambda vh: tso.BinarySystem(tso.Sphere(1e4, 1e5), tso.Sphere(1e-3, 1.0), 1e5, 0.0),
     r"^mass ratio m1/m2 must lie in \[1e-12, 1e\+12\] \(got 1e\+26: primary 4\.18879e\+17 kg"),
    ("primary-spin-too-fast", lambda vh: tso.BinarySystem(P, S, 3000, 0.1, primary_spin_period=1e-3),
     r"^primary_spin_period must satisfy \|P\| >= orbital period / 100000 = [\d.]+ s \(a spin of "
     r"at most 100000 n; got 0\.001\)"),
    ("primary-spin-too-fast-retrograde",
     lambda vh: tso.BinarySystem(P, S, 3000, 0.1, primary_spin_period=-1e-3),
     r"^primary_spin_period must satisfy \|P\| >= orbital period / 100000"),
    ("potential-reflection",
     lambda vh: tso.mutual_potential(P, S, [3000, 0, 0], np.diag([1.0, 1.0, -1.0])),
     r"^S must be a proper rotation matrix, det S = \+1 \(got det S = -1: a reflection\)"),
    ("potential-reflection-in-batch",
     lambda vh: tso.mutual_potential(P, S, [[3000, 0, 0]] * 2, np.stack([np.eye(3), -np.eye(3)])),
     r"^S must be a proper rotation matrix, det S = \+1"),
    ("potential-not-orthonormal",
     lambda vh: tso.mutual_potential(P, S, [3000, 0, 0], [[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]),
     r"^S must be a rotation matrix \(S\^T S = 1\)"),
    # the ordering and shape rules keep holding
    ("ellipsoid-unordered", lambda vh: tso.Ellipsoid(1, 2, 0.5, 1000), r"a >= b >= c"),
    ("system-e-one", lambda vh: tso.BinarySystem(P, S, 3000, 1.0), r"^e must lie in \[0.0, 1.0\)"),
    ("system-overlap", lambda vh: tso.BinarySystem(P, S, 500, 0.1), r"^bodies overlap at pericentre"),
    ("catalog-eccentricity-overlap", lambda vh: tso.catalog.system("1991 VH", eccentricity=0.99),
     r"^eccentricity must lie in \[0, 0\.7291\) for 1991 VH: at 0\.99 the bodies overlap at "
     r"pericentre"),
]


@pytest.mark.parametrize("name, call, message", DEGENERATE, ids=[c[0] for c in DEGENERATE])
def test_degenerate_input_is_refused(vh, name, call, message):
    with pytest.raises(ValueError, match=message) as err:
        call(vh)
    assert "\n" not in str(err.value)


def test_a_line_of_point_masses_is_still_a_body_for_the_potential():
    """The potential of a rod is well defined (only its spin equations divide by the zero
    moment), so Body accepts it and BinarySystem refuses it."""
    rod = line_body()
    assert rod.moments[0] == 0.0 and rod.moments[1] > 0


# ---- 2. wrong types: a message naming the parameter, in every entry point ----------------

def _pm(vh, **kw):
    return tso.parameter_map("1991 VH", [1.05], [0.05], **{"orbits": 1, **kw})


def _ov(vh, **kw):
    return tso.overlap_threshold("1991 VH", **{"elongations": [1.02], "orbits": 1, **kw})


TYPES = [
    # surface_of_section / time_series
    ("section-orbits-list", lambda vh: tso.surface_of_section(vh, 0, 1.0, [1, 2]), TypeError,
     r"^orbits must be a single number, not a list \(got \[1, 2\]\)"),
    ("section-orbits-text", lambda vh: tso.surface_of_section(vh, 0, 1.0, "1"), TypeError,
     r"^orbits must be a number \(got '1'\)"),
    ("section-orbits-bool", lambda vh: tso.surface_of_section(vh, 0, 1.0, True), TypeError,
     r"^orbits must be a number, not a bool"),
    ("section-rtol-list", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1, rtol=[1e-10]),
     TypeError, r"^rtol must be a single number, not a list"),
    ("section-atol-text", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                                            integrator=tso.Integrator(atol="1e-12")),
     TypeError, r"^atol must be a number \(got '1e-12'\)"),
    ("section-theta-complex", lambda vh: tso.surface_of_section(vh, 1j, 1.0, 1), TypeError,
     r"^theta_p must be a real number, not complex \(got 1j\)"),
    ("section-theta-complex-array",
     lambda vh: tso.surface_of_section(vh, np.array([0.0, 1j]), 1.0, 1), TypeError,
     r"^theta_p must be a real number, not complex"),
    ("section-theta-empty", lambda vh: tso.surface_of_section(vh, [], 1.0, 1), ValueError,
     r"^theta_p and thetadot_p must hold at least one start each \(got shapes \(0,\) and \(\)\)"),
    ("section-theta-none", lambda vh: tso.surface_of_section(vh, None, 1.0, 1), TypeError,
     r"^theta_p must be a number \(got None\)"),
    ("section-thetadot-text", lambda vh: tso.surface_of_section(vh, 0, "fast", 1), TypeError,
     r"^thetadot_p must be a number \(got 'fast'\)"),
    ("section-order-bool", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                                             integrator=tso.Integrator(order=True)),
     TypeError, r"^order must be an integer, 0 or in \[2, 16\] \(got True\)"),
    ("section-progress-not-callable",
     lambda vh: tso.surface_of_section(vh, 0, 1.0, 1, run=tso.Run(progress=5)), TypeError,
     r"^progress must be True, False, None or a callable progress\(fraction\) \(got 5\)"),
    ("section-system-number", lambda vh: tso.surface_of_section(5, 0, 1.0, 1), TypeError,
     r"^system must be a BinarySystem, a catalogue name or a non-empty list of them \(got 5\)"),
    ("section-window-text", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                                              run=tso.Run(window_orbits="16")),
     TypeError, r"^window_orbits must be a number \(got '16'\)"),
    ("time-series-orbits-none", lambda vh: tso.time_series(vh, 0, 1.0, None), TypeError,
     r"^orbits must be a number \(got None\)"),
    ("time-series-samples-bool",
     lambda vh: tso.time_series(vh, 0, 1.0, 1, samples_per_orbit=True), ValueError,
     r"^samples_per_orbit must be an integer in \[1, 100000\] \(got True\)"),
    ("time-series-samples-text",
     lambda vh: tso.time_series(vh, 0, 1.0, 1, samples_per_orbit="64"), TypeError,
     r"^samples_per_orbit must be a number \(got '64'\)"),
    # chaos_map / parameter_map
    ("map-orbits-list", lambda vh: tso.chaos_map(vh, [0.0], [1.0], [1]), TypeError,
     r"^orbits must be a single number, not a list"),
    ("map-rtol-text", lambda vh: tso.chaos_map(vh, [0.0], [1.0], 1, rtol="1e-10"), TypeError,
     r"^rtol must be a number \(got '1e-10'\)"),
    ("map-theta-complex", lambda vh: tso.chaos_map(vh, [1j], [1.0], 1), TypeError,
     r"^theta_p must be a real number, not complex"),
    ("map-thetadot-text", lambda vh: tso.chaos_map(vh, [0.0], ["a"], 1), TypeError,
     r"^thetadot_p must be a number \(got \['a'\]\)"),
    ("map-megno-list", lambda vh: tso.chaos_map(vh, [0.0], [1.0], 1, megno_chaotic=[4]),
     TypeError, r"^megno_chaotic must be a single number, not a list"),
    ("parameter-map-orbits-text", lambda vh: _pm(vh, orbits="5"), TypeError,
     r"^orbits must be a number \(got '5'\)"),
    ("parameter-map-megno-none", lambda vh: _pm(vh, megno_chaotic=None), TypeError,
     r"^megno_chaotic must be a number \(got None\)"),
    ("parameter-map-eccentricities-text",
     lambda vh: tso.parameter_map("1991 VH", [1.05], ["x"], orbits=1), TypeError,
     r"^eccentricities must be a number"),
    # overlap_threshold
    ("overlap-center-starts-text", lambda vh: _ov(vh, centre_starts="a"), TypeError,
     r"^centre_starts must be a number \(got 'a'\)"),
    ("overlap-center-starts-bool", lambda vh: _ov(vh, centre_starts=True), ValueError,
     r"^centre_starts must be an integer in \[2, 100000\] \(got True\)"),
    ("overlap-separatrix-starts-float", lambda vh: _ov(vh, separatrix_starts=2.5), ValueError,
     r"^separatrix_starts must be an integer in \[2, 100000\] \(got 2\.5\)"),
    ("overlap-orbits-list", lambda vh: _ov(vh, orbits=[5]), TypeError,
     r"^orbits must be a single number, not a list"),
    ("overlap-rtol-text", lambda vh: _ov(vh, rtol="1e-10"), TypeError,   # None: the default
     r"^rtol must be a number \(got '1e-10'\)"),
    ("overlap-eccentricity-list", lambda vh: _ov(vh, eccentricity=[0.1]), TypeError,
     r"^eccentricity must be a single number, not a list"),
    ("overlap-elongations-complex", lambda vh: _ov(vh, elongations=[1.02j]), TypeError,
     r"^elongations must be a real number, not complex"),
    ("overlap-libration-limit-range", lambda vh: _ov(vh, libration_limit=120), ValueError,
     r"^libration_limit must lie in \(0, 90\] deg \(got 120\)"),
    ("overlap-vs-eccentricity-complex",
     lambda vh: overlap_vs_eccentricity("1991 VH", [0.1j], elongations=[1.02], orbits=1),
     TypeError, r"^eccentricities must be a real number, not complex"),
    ("overlap-system-number", lambda vh: tso.overlap_threshold(5, elongations=[1.02], orbits=1),
     TypeError, r"^system must be a catalogue name or a callable"),
    # relaxed_libration / libration_amplitude
    ("libration-orbits-list", lambda vh: tso.relaxed_libration(vh, orbits=[5]), TypeError,
     r"^orbits must be a single number, not a list"),
    ("libration-xtol-text", lambda vh: tso.relaxed_libration(vh, orbits=5, xtol="1e-6"),
     TypeError, r"^xtol must be a number \(got '1e-6'\)"),
    ("libration-progress", lambda vh: tso.relaxed_libration(vh, orbits=5,
                                                            run=tso.Run(progress="bar")),
     TypeError, r"^progress must be True, False, None or a callable progress\(fraction\) \(got 'bar'\)"),
    ("libration-amplitude-orbits-text",
     lambda vh: tso.libration_amplitude(vh, 1.0, orbits="5"), TypeError,
     r"^orbits must be a number \(got '5'\)"),
    ("libration-amplitude-thetadot-complex",
     lambda vh: tso.libration_amplitude(vh, [1.0 + 0.5j], orbits=5), TypeError,
     r"^thetadot_p must be a real number, not complex"),
    # mutual_potential
    ("potential-order-text", lambda vh: tso.mutual_potential(P, S, [3000, 0, 0], np.eye(3), order="4"),
     TypeError, r"^order must be an integer, 0 or in \[2, 16\] \(got '4'\)"),
    ("potential-S-complex",
     lambda vh: tso.mutual_potential(P, S, [3000, 0, 0], np.eye(3) * (1 + 0j)), TypeError,
     r"^S must be a real number, not complex"),
    # bodies
    ("body-integrals-list", lambda vh: tso.Body(1.0, [0.3, 0.2, 0.1], 1.0), TypeError,
     r"^integrals must be a dict \{\(l, m, n\): T\^lmn\} \(got list \[0\.3, 0\.2, 0\.1\]\)"),
    ("body-mass-list", lambda vh: tso.Body([1.0], GOOD_SECOND, 1.0), TypeError,
     r"^mass must be a single number, not a list"),
    ("body-radius-text", lambda vh: tso.Body(1.0, GOOD_SECOND, "1"), TypeError,
     r"^bounding_radius must be a number \(got '1'\)"),
    ("body-integral-value-list", lambda vh: tso.Body(1.0, {**GOOD_SECOND, (4, 0, 0): [1, 2]}, 1.0),
     TypeError, r"^integrals\[\(4, 0, 0\)\] must be a single number, not a list"),
    ("body-name-number", lambda vh: tso.Body(1.0, GOOD_SECOND, 1.0, 5), TypeError,
     r"^name must be a string \(got 5\)"),
    ("sphere-radius-none", lambda vh: tso.Sphere(None, 1000), TypeError,
     r"^radius must be a number \(got None\)"),
    ("sphere-density-complex", lambda vh: tso.Sphere(100, 1000j), TypeError,
     r"^density must be a real number, not complex"),
    ("sphere-density-array", lambda vh: tso.Sphere(100, np.array([1000.0, 2000.0])), TypeError,
     r"^density must be a single number, not a ndarray \(got \[1000\.0, 2000\.0\]\)"),
    ("ellipsoid-b-list", lambda vh: tso.Ellipsoid(3, [1, 2], 1, 1000), TypeError,
     r"^b must be a single number, not a list"),
    ("ellipsoid-mass-bool", lambda vh: tso.Ellipsoid(3, 2, 1, mass=True), TypeError,
     r"^mass must be a number, not a bool"),
    # binary systems and the catalogue
    ("system-a-list", lambda vh: tso.BinarySystem(P, S, [3000, 4000], 0.1), TypeError,
     r"^a must be a single number, not a list"),
    ("system-e-text", lambda vh: tso.BinarySystem(P, S, 3000, "0.1"), TypeError,
     r"^e must be a number \(got '0\.1'\)"),
    ("system-period-text", lambda vh: tso.BinarySystem(P, S, 3000, 0.1, primary_spin_period="3h"),
     TypeError, r"^primary_spin_period must be a number \(got '3h'\)"),
    ("system-a-none", lambda vh: tso.BinarySystem(P, S, None, 0.1), TypeError,
     r"^a must be a number \(got None\)"),
    ("catalog-elongation-list", lambda vh: tso.catalog.system("1991 VH", elongation=[1.1]),
     TypeError, r"^elongation must be a single number, not a list"),
    ("catalog-density-text", lambda vh: tso.catalog.system("1991 VH", secondary_density="2000"),
     TypeError, r"^secondary_density must be a number \(got '2000'\)"),
    ("catalog-eccentricity-complex", lambda vh: tso.catalog.system("1991 VH", eccentricity=0.1j),
     TypeError, r"^eccentricity must be a real number, not complex"),
]


@pytest.mark.parametrize("name, call, error, message", TYPES, ids=[c[0] for c in TYPES])
def test_wrong_types_name_the_parameter(vh, name, call, error, message):
    with pytest.raises(error, match=message) as err:
        call(vh)
    assert type(err.value) is error and "\n" not in str(err.value)


def test_long_arrays_are_shown_by_shape_not_printed():
    with pytest.raises(ValueError) as err:
        tso.surface_of_section(tso.catalog.system("1991 VH"), np.full((40, 40), np.nan), 1.0, 1)
    assert str(err.value) == "theta_p must be finite (got array of shape (40, 40))"


def test_refusals_come_before_taichi_starts(tmp_path):
    """In a fresh interpreter, a run of refused calls leaves Taichi uninitialised: the checks
    come before any kernel work."""
    script = tmp_path / "refuse.py"
    script.write_text(
        "import ti_spinorbit as tso\n"
        "from ti_spinorbit import runtime\n"
        "vh = tso.catalog.system('1991 VH')\n"
        "calls = [lambda: tso.surface_of_section(vh, 0, 1e6, 1),\n"
        "         lambda: tso.surface_of_section(vh, 0, 1.0, 1, rtol='x'),\n"
        "         lambda: tso.surface_of_section(vh, 0, 1.0, 1, window_orbits='x'),\n"
        "         lambda: tso.time_series(vh, 1j, 1.0, 1),\n"
        "         lambda: tso.chaos_map(vh, [0.0], [1e9], 1),\n"
        "         lambda: tso.relaxed_libration(vh, orbits=[5]),\n"
        "         lambda: tso.overlap_threshold('1991 VH', elongations=[1.02], orbits=1, rtol=[1]),\n"
        "         lambda: tso.mutual_potential(vh.primary, vh.secondary, [3000, 0, 0],\n"
        "                                      [[1, 0, 0], [0, 1, 0], [0, 0, -1]])]\n"
        "for call in calls:\n"
        "    try:\n"
        "        call()\n"
        "    except (TypeError, ValueError):\n"
        "        pass\n"
        "    else:\n"
        "        raise SystemExit('not refused')\n"
        "print('arch', runtime.current_arch())\n")
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=120, env=_env())
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip().splitlines()[-1] == "arch None"


def _env():
    """The environment with this checkout first on PYTHONPATH (for subprocesses)."""
    return dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.dirname(os.path.dirname(os.path.abspath(tso.__file__)))]
        + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))


# ---- 3 (part). spin rates and the primary's spin are bounded as on the command line -------

SPIN = [
    ("section-1e6", lambda vh: tso.surface_of_section(vh, 0, 1e6, orbits=1), "thetadot_p", "1e+06"),
    ("section-1e9-in-array",
     lambda vh: tso.surface_of_section(vh, 0, [1.0, -1e9], orbits=1), "thetadot_p", "-1e+09"),
    ("time-series-101", lambda vh: tso.time_series(vh, 0, 101.0, orbits=1), "thetadot_p", "101"),
    ("map-1e6", lambda vh: tso.chaos_map(vh, [0.0], [1.0, 1e6], orbits=1), "thetadot_p", "1e+06"),
    ("parameter-map-1e6", lambda vh: _pm(vh, thetadot_p=[1e6]), "thetadot_p", "1e+06"),
    ("libration-candidates",
     lambda vh: tso.relaxed_libration(vh, orbits=5, candidates=np.linspace(1, 1e3, 9)),
     "candidates", "1000"),
    ("libration-amplitude", lambda vh: tso.libration_amplitude(vh, 1e6, orbits=1),
     "thetadot_p", "1e+06"),
]


@pytest.mark.parametrize("name, call, parameter, got", SPIN, ids=[c[0] for c in SPIN])
def test_spin_rates_are_bounded_within_a_second(vh, name, call, parameter, got):
    started = time.perf_counter()
    with pytest.raises(ValueError) as err:
        call(vh)
    assert time.perf_counter() - started < 1.0
    assert str(err.value) == (f"{parameter} must lie in [-100, 100] (units of the mean motion n; "
                              f"got {got})")


def test_the_spin_bound_is_the_command_lines():
    from ti_spinorbit import cli
    from ti_spinorbit.cli import options

    assert cli.MAX_SPIN is _validate.MAX_SPIN
    assert (options.SPIN.low, options.SPIN.high) == (-_validate.MAX_SPIN, _validate.MAX_SPIN)
    assert (options.DENSITY.low, options.DENSITY.high) == (_validate.MIN_DENSITY,
                                                           _validate.MAX_DENSITY)


def test_primary_spin_at_the_bound_is_accepted():
    period = tso.BinarySystem(P, S, 3000, 0.1).orbital_period / _validate.MAX_PRIMARY_SPIN
    system = tso.BinarySystem(P, S, 3000, 0.1, primary_spin_period=period * (1 + 1e-12))
    assert system.primary_spin_period == pytest.approx(period)


# ---- 4. the command line names the flag, never the library's argument ---------------------

CLI = [
    (["overlap", "--elongations", "1.01", "1.01", "1e-300"],
     r"--elongations STEP must lie in \[1e-06, 10\] \(got 1e-300\)"),
    (["overlap", "--elongations", "1.01", "10", "0.6"],
     r"--elongations 1\.01 10 0\.6 steps to a/b = 10\.01, past 10"),
    (["overlap", "--elongations", "1.01", "5", "0.5"],
     r"--elongations 5\.01 makes b = .* < c = 190 m for 1991 VH: the largest allowed is 1\.596"),
    (["overlap", "--system", "test"], r"--elongations: the 'test' system has fixed shapes"),
    (["section", "--density", "1e-300"], r"--density must lie in \[1, 100000\] \(got 1e-300\)"),
    (["map", "--density", "1e6"], r"--density must lie in \[1, 100000\] \(got 1e\+06\)"),
    (["section", "--elongation", "5"], r"--elongation 5\.0 makes b = .* < c = 190 m"),
    (["section", "--eccentricity", "0.99"],
     r"--eccentricity must lie in \[0, 0\.7291\) for 1991 VH: at 0\.99 the bodies overlap"),
    (["section", "--thetadot", "1", "1e6"], r"--thetadot must lie in \[-100, 100\] \(got 1e\+06\)"),
    (["energy", "--thetadot=-1e9"], r"--thetadot must lie in \[-100, 100\] \(got -1e\+09\)"),
    (["libration", "--elongation", "1"],
     r"--elongation must be > 1 for libration: a round secondary has no synchronous island"),
    (["energy", "--density", "2000"], r"--density: the 'test' system has fixed shapes"),
    (["systems", "--show", "1991 XX"], r"--show: unknown system '1991 XX'; known systems: "),
    (["map", "--system", "1991 XX"], r"--system: unknown system '1991 XX'"),
    (["benchmark", "--system", "nope"], r"--system: unknown system 'nope'"),
]
API_NAMES = r"(?<![-\w])(elongations?|secondary_density|thetadot_p|theta_p|eccentricity must)\b"


@pytest.mark.parametrize("argv, message", CLI, ids=[" ".join(a) for a, _ in CLI])
def test_cli_names_the_flag(argv, message, tmp_path):
    run = run_cli(*argv, cwd=tmp_path, env=_env(), timeout=120)
    lines = run.stderr.strip().splitlines()
    assert run.returncode == 2, run.stderr
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert lines[0].startswith(f"ti-spinorbit {argv[0]}: error: --"), lines[0]
    assert re.search(message, lines[0]), lines[0]
    assert not re.search(API_NAMES, lines[0]) and "array(" not in lines[0], lines[0]
    assert list(tmp_path.iterdir()) == []
