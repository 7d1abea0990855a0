"""Bad input is refused with a message that names the parameter, the value and what is allowed.

One table for the public API (constructors, catalogue, entry points, tso.init) and one for the
command line (``cli.main`` in-process: exit status 2 and exactly one line on stderr). Rows
marked ``gap(...)`` are checks still missing in a module this file does not own: they are
strict xfails, so the row turns into a failure (XPASS) the moment the check lands and the
mark must then be removed. Also: ``_validate.available_memory`` / ``require_memory``."""

import math
import re

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import _validate, cli

NAN, INF = math.nan, math.inf


def gap(where):
    return pytest.mark.xfail(strict=True, reason=f"needs check in {where}")


P = tso.Sphere(600, 1581)
S = tso.Ellipsoid(245, 163, 150, 2000)


class Abort(Exception):
    """Raised by a progress callback to stop a run whose input should have been refused."""


def abort(fraction):
    raise Abort(fraction)


# (id, call taking the 1991 VH system, exception type, message regex)
API_CASES = [
    # bodies
    ("sphere-negative-radius", lambda vh: tso.Sphere(-1, 1000), ValueError,
     r"^radius must be a finite number > 0 \(got -1\)"),
    ("sphere-negative-density", lambda vh: tso.Sphere(1, -1000), ValueError,
     r"^density must be a finite number > 0 \(got -1000\)"),
    ("sphere-nan-density", lambda vh: tso.Sphere(1, NAN), ValueError,
     r"^density must be a finite number > 0 \(got nan\)"),
    ("sphere-inf-density", lambda vh: tso.Sphere(1, INF), ValueError,
     r"^density must be a finite number > 0 \(got inf\)"),
    ("sphere-no-density-or-mass", lambda vh: tso.Sphere(1), ValueError,
     r"give exactly one of density \(kg/m\^3\) or mass \(kg\)"),
    ("ellipsoid-a-lt-b", lambda vh: tso.Ellipsoid(1, 2, 0.5, 1000), ValueError,
     r"a >= b >= c \(got a=1, b=2, c=0.5\)"),
    ("ellipsoid-b-lt-c", lambda vh: tso.Ellipsoid(3, 1, 2, 1000), ValueError,
     r"a >= b >= c \(got a=3, b=1, c=2\)"),
    ("ellipsoid-negative-c", lambda vh: tso.Ellipsoid(3, 2, -1, 1000), ValueError,
     r"^c must be a finite number > 0 \(got -1\)"),
    ("ellipsoid-negative-mass", lambda vh: tso.Ellipsoid(3, 2, 1, mass=-5), ValueError,
     r"^mass must be a finite number > 0 \(got -5\)"),
    ("ellipsoid-text-axis", lambda vh: tso.Ellipsoid("3", 2, 1, 1000), TypeError,
     r"^a must be a number \(got '3'\)"),
    ("body-negative-mass", lambda vh: tso.Body(-1.0, {(2, 0, 0): 1.0}, 1.0), ValueError,
     r"^mass must be a finite number > 0 \(got -1.0\)"),
    ("body-bad-integral-key", lambda vh: tso.Body(1.0, {(17, 0, 0): 1.0}, 1.0), ValueError,
     r"key \(17, 0, 0\) is not \(l, m, n\) with l \+ m \+ n in 2..16"),
    ("body-key-above-order", lambda vh: tso.Body(1.0, {(5, 0, 0): 1.0}, 1.0, order=4),
     ValueError, r"key \(5, 0, 0\) has degree 5, above order=4"),
    ("body-nan-integral", lambda vh: tso.Body(1.0, {(2, 0, 0): NAN}, 1.0), ValueError,
     r"^integrals\[\(2, 0, 0\)\] must be finite \(got nan\)"),
    ("body-not-principal-frame", lambda vh: tso.Body(1.0, {(2, 0, 0): 1.0, (1, 1, 0): 0.5}, 1.0),
     ValueError, r"principal-axis frame"),
    # binary systems
    ("system-e-one", lambda vh: tso.BinarySystem(P, S, 3000, 1.0), ValueError,
     r"^e must lie in \[0.0, 1.0\) \(got 1.0\)"),
    ("system-e-negative", lambda vh: tso.BinarySystem(P, S, 3000, -0.1), ValueError,
     r"^e must lie in \[0.0, 1.0\) \(got -0.1\)"),
    ("system-e-nan", lambda vh: tso.BinarySystem(P, S, 3000, NAN), ValueError,
     r"^e must lie in \[0.0, 1.0\) \(got nan\)"),
    ("system-a-negative", lambda vh: tso.BinarySystem(P, S, -3000, 0.1), ValueError,
     r"^a must be a finite number > 0 \(got -3000\)"),
    ("system-bodies-overlap", lambda vh: tso.BinarySystem(P, S, 500, 0.1), ValueError,
     r"bodies overlap at pericentre: a\(1-e\) = 450 m must exceed the sum of bounding radii "
     r"845 m"),
    ("system-not-a-body", lambda vh: tso.BinarySystem("big", S, 3000, 0.1), TypeError,
     r"^primary must be a ti_spinorbit Body .*got str"),
    ("system-zero-spin-period", lambda vh: tso.BinarySystem(P, S, 3000, 0.1, primary_spin_period=0),
     ValueError, r"^primary_spin_period must be non-zero"),
    # catalogue
    ("catalog-unknown-name", lambda vh: tso.catalog.system("1991 XX"), ValueError,
     r"^unknown system '1991 XX'; known systems: test, 1991 VH"),
    ("catalog-name-not-text", lambda vh: tso.catalog.system(5), TypeError,
     r"^system name must be a string \(got 5\)"),
    ("catalog-e-one", lambda vh: tso.catalog.system("1991 VH", eccentricity=1), ValueError,
     r"^eccentricity must lie in \[0.0, 1.0\) \(got 1\)"),
    ("catalog-e-overlap", lambda vh: tso.catalog.system("1991 VH", eccentricity=0.99), ValueError,
     r"bodies overlap at pericentre"),
    ("catalog-elongation-below-1", lambda vh: tso.catalog.system("1991 VH", elongation=0.5),
     ValueError, r"^elongation must lie in \[1.0, 10.0\] \(got 0.5\)"),
    ("catalog-elongation-nan", lambda vh: tso.catalog.system("1991 VH", elongation=NAN),
     ValueError, r"^elongation must lie in \[1.0, 10.0\] \(got nan\)"),
    ("catalog-elongation-b-below-c", lambda vh: tso.catalog.system("1991 VH", elongation=5),
     ValueError, r"elongation 5 makes b = .* < c = 190 m for 1991 VH: the largest allowed is 1.596"),
    ("catalog-negative-density", lambda vh: tso.catalog.system("1991 VH", secondary_density=-1),
     ValueError, r"^secondary_density must be a finite number > 0 \(got -1\)"),
    ("catalog-test-fixed-shape", lambda vh: tso.catalog.system("test", elongation=1.2), ValueError,
     r"fixed shapes: only eccentricity may be changed"),
    # surface of section and time series
    ("section-zero-orbits", lambda vh: tso.surface_of_section(vh, 0, 1.0, 0), ValueError,
     r"^orbits must be a finite number > 0 \(got 0\)"),
    ("section-nan-orbits", lambda vh: tso.surface_of_section(vh, 0, 1.0, NAN), ValueError,
     r"^orbits must be a finite number > 0 \(got nan\)"),
    ("section-rtol-zero", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1, rtol=0), ValueError,
     r"^rtol must lie in \[1e-16, 0.01\] \(got 0\)"),
    ("section-rtol-large", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1, rtol=0.1), ValueError,
     r"^rtol must lie in \[1e-16, 0.01\] \(got 0.1\)"),
    ("section-atol-negative", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                                                integrator=tso.Integrator(atol=-1)), ValueError,
     r"^atol must lie in \(0, 0.01\] \(absolute tolerance on the scaled state, whose "
     r"components are O\(1\); got -1\)$"),
    ("section-nan-theta", lambda vh: tso.surface_of_section(vh, NAN, 1.0, 1), ValueError,
     r"^theta_p must be finite"),
    ("section-inf-thetadot", lambda vh: tso.surface_of_section(vh, 0, INF, 1), ValueError,
     r"^thetadot_p must be finite"),
    ("section-system-unknown-name", lambda vh: tso.surface_of_section("1991 XX", 0, 1.0, 1),
     ValueError, r"^unknown system '1991 XX'; known systems: "),
    ("section-system-none", lambda vh: tso.surface_of_section(None, 0, 1.0, 1), TypeError,
     r"^system must be a BinarySystem, a catalogue name or a non-empty list of them \(got None\)$"),
    ("section-broadcast", lambda vh: tso.surface_of_section([vh, vh], 0, [1.0, 2.0, 3.0], 1),
     ValueError, r"cannot broadcast 2 systems, theta_p of shape \(\) and thetadot_p of shape \(3,\)"),
    ("section-order", lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                                        integrator=tso.Integrator(order=17)), ValueError,
     r"^order must be 0 or an integer in \[2, 16\] \(got 17\)"),
    ("section-escape-distance-negative",
     lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                       integrator=tso.Integrator(escape_distance=-1)), ValueError,
     r"^escape_distance must be a finite number > 1 \(units of a\) \(got -1\)"),
    ("section-escape-distance-nan",
     lambda vh: tso.surface_of_section(vh, 0, 1.0, 1,
                                       integrator=tso.Integrator(escape_distance=NAN)), ValueError,
     r"^escape_distance must be a finite number > 1 \(units of a\) \(got nan\)"),
    ("section-orbits-absurd",
     lambda vh: tso.surface_of_section(vh, 0, 1.0, 1e12, run=tso.Run(progress=abort)), ValueError,
     r"^orbits must lie in \(0, 1e\+07\] \(got 1e\+12\)"),
    ("time-series-zero-orbits", lambda vh: tso.time_series(vh, 0, 1.0, 0), ValueError,
     r"^orbits must be a finite number > 0 \(got 0\)"),
    ("time-series-orbits-absurd",
     lambda vh: tso.time_series(vh, 0, 1.0, 2e7, run=tso.Run(progress=abort)), ValueError,
     r"^orbits must lie in \(0, 1e\+07\] \(got 2e\+07\)"),
    ("time-series-zero-samples", lambda vh: tso.time_series(vh, 0, 1.0, 1, samples_per_orbit=0),
     ValueError, r"^samples_per_orbit must be an integer in \[1, 100000\] \(got 0\)"),
    ("time-series-rtol", lambda vh: tso.time_series(vh, 0, 1.0, 1, rtol=1), ValueError,
     r"^rtol must lie in \[1e-16, 0.01\] \(got 1\)"),
    # chaos map, overlap, libration
    ("map-zero-orbits", lambda vh: tso.chaos_map(vh, [0.0], [1.0], 0), ValueError,
     r"^orbits must be a finite number > 0 \(got 0\)"),
    ("map-empty-axis", lambda vh: tso.chaos_map(vh, [], [1.0], 1), ValueError,
     r"^theta_p must be a non-empty 1-D array \(got shape \(0,\)\)"),
    ("map-nan-axis", lambda vh: tso.chaos_map(vh, [NAN], [1.0], 1), ValueError,
     r"^theta_p must be finite"),
    ("map-unknown-system", lambda vh: tso.chaos_map("1991 XX", [0.0], [1.0], 1), ValueError,
     r"^unknown system '1991 XX'; known systems: "),
    ("map-system-number", lambda vh: tso.chaos_map(5, [0.0], [1.0], 1), TypeError,
     r"^system must be a BinarySystem or a catalogue name \(got 5\)$"),
    ("overlap-unknown-system",
     lambda vh: tso.overlap_threshold("1991 XX", elongations=[1.02], orbits=5), ValueError,
     r"^unknown system '1991 XX'"),
    ("overlap-elongation-below-1",
     lambda vh: tso.overlap_threshold("1991 VH", elongations=[0.9], orbits=5), ValueError,
     r"^elongations must lie in \(1.0, 10.0\]"),
    ("overlap-zero-orbits",
     lambda vh: tso.overlap_threshold("1991 VH", elongations=[1.02], orbits=0), ValueError,
     r"^orbits must be a finite number > 0"),
    ("overlap-no-elongations",
     lambda vh: tso.overlap_threshold("1991 VH", elongations=[], orbits=5), ValueError,
     r"^elongations must be a non-empty 1-D array of a/b values in \(1, 10\] \(got \[\]\)"),
    ("overlap-2d-elongations",
     lambda vh: tso.overlap_threshold("1991 VH", elongations=[[1.02, 1.03]], orbits=5),
     ValueError, r"^elongations must be a non-empty 1-D array .*\(got \[\[1.02, 1.03\]\]\)"),
    ("libration-unknown-system", lambda vh: tso.relaxed_libration("1991 XX"), ValueError,
     r"^unknown system '1991 XX'; known systems: "),
    ("libration-zero-orbits", lambda vh: tso.relaxed_libration(vh, orbits=0), ValueError,
     r"^orbits must be a finite number > 0 \(got 0\)"),
    ("libration-rtol-large", lambda vh: tso.relaxed_libration(vh, orbits=5, rtol=1.0), ValueError,
     r"^rtol must lie in \[1e-16, 0.01\] \(got 1.0\)"),
    ("libration-rtol-zero", lambda vh: tso.relaxed_libration(vh, orbits=5, rtol=0),
     ValueError, r"^rtol must lie in \[1e-16, 0.01\] \(got 0\)"),
    ("libration-even-zoom", lambda vh: tso.relaxed_libration(vh, orbits=5, zoom_candidates=10),
     ValueError, r"^zoom_candidates must be odd \(got 10\)"),
    ("libration-few-candidates", lambda vh: tso.relaxed_libration(vh, orbits=5, candidates=[1, 2, 3]),
     ValueError, r"^candidates must hold at least 5 ascending values"),
    ("libration-round-secondary",
     lambda vh: tso.relaxed_libration(tso.BinarySystem(P, tso.Sphere(100, 2000), 3000, 0.1)),
     ValueError, r"secondary must be elongated \(B > A, omega0 > 0\)"),
    # mutual potential, init
    ("potential-order", lambda vh: tso.mutual_potential(P, S, [3000, 0, 0], np.eye(3), order=1),
     ValueError, r"^order must be 0 or an integer in \[2, 16\] \(got 1\)"),
    ("potential-nan-R", lambda vh: tso.mutual_potential(P, S, [NAN, 0, 0], np.eye(3)), ValueError,
     r"^R must be finite"),
    ("potential-not-rotation", lambda vh: tso.mutual_potential(P, S, [3000, 0, 0], 2 * np.eye(3)),
     ValueError, r"^S must be a rotation matrix"),
    ("potential-R-shape", lambda vh: tso.mutual_potential(P, S, [3000, 0], np.eye(3)), ValueError,
     r"R must be \(\.\.\., 3\) and S \(\.\.\., 3, 3\) .*got \(2,\) and \(3, 3\)"),
    ("potential-R-zero", lambda vh: tso.mutual_potential(P, S, [0, 0, 0], np.eye(3)),
     ValueError, r"^bodies overlap: \|R\| = 0 m must exceed the sum of bounding radii \(845 m\)"),
    ("potential-R-inside-contact",
     lambda vh: tso.mutual_potential(P, S, [[3000, 0, 0], [0, 800, 0]], np.eye(3)[None].repeat(2, 0)),
     ValueError, r"^bodies overlap: \|R\| = 800 m must exceed the sum of bounding radii \(845 m\)"),
    ("potential-text-R", lambda vh: tso.mutual_potential(P, S, ["3000", 0, 0], np.eye(3)),
     TypeError, r"^R must be a number"),
    ("potential-not-a-body",
     lambda vh: tso.mutual_potential("big", S, [3000, 0, 0], np.eye(3)), TypeError,
     r"^primary must be a ti_spinorbit Body .*\(got str\)"),
    ("potential-secondary-not-a-body",
     lambda vh: tso.mutual_potential(P, None, [3000, 0, 0], np.eye(3)), TypeError,
     r"^secondary must be a ti_spinorbit Body .*\(got NoneType\)"),
    ("init-unknown-arch", lambda vh: tso.init(arch="tpu"), ValueError,
     r"^arch must be one of cpu, x64, arm64, cuda, vulkan, metal, opengl, gpu \(got 'tpu'\)"),
    ("init-arch-not-text", lambda vh: tso.init(arch=5), ValueError,
     r"^arch must be one of cpu, x64, arm64, cuda, vulkan, metal, opengl, gpu \(got 5\)"),
    ("init-arch-empty", lambda vh: tso.init(arch=""), ValueError,
     r"^arch must be one of .* \(got ''\)"),
]


@pytest.mark.parametrize("name, call, error, message", API_CASES,
                         ids=[getattr(c, "values", c)[0] for c in API_CASES])
def test_api_refuses_bad_input(vh, name, call, error, message):
    with pytest.raises(error, match=message):
        call(vh)


def test_init_names_the_environment_variable(monkeypatch):
    monkeypatch.setenv(tso.runtime.ARCH_ENV, "tpu")
    with pytest.raises(ValueError, match=r"^the environment variable TI_SPINORBIT_ARCH must be "
                                         r"one of cpu, .* \(got 'tpu'\)"):
        tso.init()


# (argv, message regex after "ti-spinorbit <command>: error: ")
CLI_CASES = [
    (["section", "--orbits", "0"], r"--orbits must lie in \(0, 1e\+07\] \(got 0\)"),
    (["section", "--orbits", "2e7"], r"--orbits must lie in \(0, 1e\+07\] \(got 2e\+07\)"),
    (["section", "--orbits", "nan"], r"--orbits must lie in \(0, 1e\+07\] \(got nan\)"),
    (["section", "--orbits", "many"], r"argument --orbits: invalid float value: 'many'"),
    (["section", "--rtol", "0"], r"--rtol must lie in \[1e-16, 0.01\] \(got 0\)"),
    (["section", "--rtol", "0.5"], r"--rtol must lie in \[1e-16, 0.01\] \(got 0.5\)"),
    (["section", "--elongation", "0.5"], r"--elongation must lie in \[1, 10\] \(got 0.5\)"),
    (["section", "--elongation", "5"], r"elongation 5(\.0)? makes b = .* < c = 190 m"),
    (["section", "--density", "-5"], r"--density must lie in \[1, 100000\] \(got -5\)"),
    (["section", "--density", "inf"], r"--density must lie in \[1, 100000\] \(got inf\)"),
    (["section", "--eccentricity", "1"], r"--eccentricity must lie in \[0, 1\) \(got 1\)"),
    (["section", "--eccentricity", "-0.1"], r"--eccentricity must lie in \[0, 1\) \(got -0.1\)"),
    (["section", "--eccentricity", "0.99"], r"bodies overlap at pericentre"),
    (["section", "--system", "1991 XX"], r"unknown system '1991 XX'; known systems:"),
    (["section", "--theta-p", "inf"], r"--theta-p must lie in \[-360, 360\] \(got inf\)"),
    (["section", "--thetadot", "1", "nan"], r"--thetadot must lie in \[-100, 100\] \(got nan\)"),
    (["section", "--bogus"], r"unrecognized arguments: --bogus"),
    (["section", "--arch", "tpu"], r"argument --arch: invalid choice: 'tpu'"),
    (["section", "--out", "/no/such/folder/s.png"], r"--out: folder '/no/such/folder' does not exist"),
    (["section", "--out", "s.txt"], r"--out must end in .png, .pdf, .svg \(got 's.txt'\)"),
    (["section", "--data", "s.csv"], r"--data must end in .npz \(got 's.csv'\)"),
    (["map", "--grid", "0", "4"], r"--grid must lie in \[1, 1024\] \(got 0\)"),
    (["map", "--grid", "4", "2000"], r"--grid must lie in \[1, 1024\] \(got 2000\)"),
    (["map", "--grid", "4"], r"argument --grid: expected 2 arguments"),
    (["map", "--grid", "4", "4.5"], r"argument --grid: invalid int value: '4.5'"),
    (["map", "--thetadot-range", "2", "1"], r"--thetadot-range needs LO < HI \(got 2 1\)"),
    (["overlap", "--elongations", "0.9", "1.1", "0.01"],
     r"--elongations START must lie in \(1, 10\] \(got 0.9\)"),
    (["overlap", "--elongations", "1.1", "1.01", "0.01"],
     r"--elongations STOP must lie in \[1.1, 10\] \(got 1.01\)"),
    (["overlap", "--elongations", "1.01", "1.1", "0"],
     r"--elongations STEP must lie in \[1e-06, 10\] \(got 0\)"),
    (["overlap", "--elongations", "1.01", "9", "0.0001"],
     r"--elongations: at most 1001 elongations per scan"),
    (["overlap", "--eccentricity", "1.5"], r"--eccentricity must lie in \[0, 1\) \(got 1.5\)"),
    (["libration", "--xtol", "0"], r"--xtol must lie in \[1e-12, 0.1\] \(got 0\)"),
    (["libration", "--candidates", "1", "0.5", "11"], r"--candidates HI must lie in \(1, 100\]"),
    (["libration", "--candidates", "0.2", "1.3", "3"],
     r"--candidates N must be an integer in \[5, 10001\] \(got 3\)"),
    (["energy", "--max-drift", "0"], r"--max-drift must lie in \(0, 1\] \(got 0\)"),
    (["energy", "--samples-per-orbit", "0"], r"--samples-per-orbit must lie in \[1, 100000\]"),
    (["energy", "--elongation", "1.2"], r"fixed shapes: only eccentricity may be changed"),
    (["benchmark", "--members", "0"], r"--members must lie in \[1, 1048576\] \(got 0\)"),
    (["benchmark", "--members", "2000000"], r"--members must lie in \[1, 1048576\] \(got 2000000\)"),
    (["benchmark", "--out", "b.png"], r"--out must end in .json \(got 'b.png'\)"),
    (["benchmark", "--repeat", "0"], r"--repeat must lie in \[1, 100\] \(got 0\)"),
    (["figures", "--only", "0"], r"--only must lie in \[1, 99\] \(got 0\)"),
]


@pytest.mark.parametrize("argv, message", CLI_CASES, ids=[" ".join(a) for a, _ in CLI_CASES])
def test_cli_refuses_bad_flags_in_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)           # nothing may be written, and nowhere else
    assert cli.main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in captured.err, captured.err
    assert lines[0].startswith(f"ti-spinorbit {argv[0]}: error: "), lines[0]
    assert re.search(message, lines[0]), lines[0]
    assert captured.out == "" and list(tmp_path.iterdir()) == []


def test_cli_without_a_command(capsys):
    assert cli.main([]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["ti-spinorbit: error: the following arguments are required: command"]


def test_cli_reports_memory_in_one_line(capsys, tmp_path, monkeypatch):
    """A run too large for the machine stops before it allocates, with the sizes and advice."""
    monkeypatch.setattr(_validate, "available_memory", lambda: 1024)
    code = cli.main(["section", "--thetadot", "1", "--orbits", "2", "--quiet",
                     "--out", str(tmp_path / "s.png")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert re.search(r"needs .* GiB, .* GiB available; ", err[0]), err[0]


# ---- text is not a number ---------------------------------------------------------------

@pytest.mark.parametrize("check", [_validate.require_finite, _validate.require_positive,
                                   lambda n, v: _validate.require_range(n, v, 0, 1),
                                   _validate.require_count])
@pytest.mark.parametrize("value", ["3", b"3", ["1", "2"], object()])
def test_validators_refuse_text_and_objects(check, value):
    with pytest.raises(TypeError, match=r"^x must be a number \(got "):
        check("x", value)


# ---- memory -----------------------------------------------------------------------------

def test_available_memory_reads_meminfo():
    with open("/proc/meminfo") as f:
        kib = next(int(line.split()[1]) for line in f if line.startswith("MemAvailable:"))
    got = _validate.available_memory()
    # MemAvailable moves a little between the two reads
    assert got == pytest.approx(kib * 1024, rel=0.05)


def test_available_memory_falls_back_to_sysconf_then_none(monkeypatch):
    monkeypatch.setattr(_validate, "_psutil_available_memory", lambda: None)   # no psutil

    def no_file(*args, **kwargs):
        raise OSError("no /proc here")

    monkeypatch.setattr(_validate, "open", no_file, raising=False)
    pages = {"SC_AVPHYS_PAGES": 1000, "SC_PAGE_SIZE": 4096}
    monkeypatch.setattr(_validate.os, "sysconf", lambda name: pages[name])
    assert _validate.available_memory() == 4096000

    def unsupported(name):
        raise ValueError(f"unrecognized configuration name {name!r}")

    monkeypatch.setattr(_validate.os, "sysconf", unsupported)
    assert _validate.available_memory() is None


def test_require_memory_threshold_and_message():
    gib = 2**30
    assert _validate.require_memory("the map", 0.8 * 4 * gib, "fewer members", available=4 * gib) \
        == 0.8 * 4 * gib
    with pytest.raises(_validate.InsufficientMemoryError) as err:
        _validate.require_memory("the map", 8 * gib, "use fewer members", available=4 * gib)
    assert str(err.value) == "the map needs 8 GiB, 4 GiB available; use fewer members"
    assert isinstance(err.value, ValueError) and isinstance(err.value, MemoryError)


def test_require_memory_unknown_availability_checks_nothing(monkeypatch):
    monkeypatch.setattr(_validate, "available_memory", lambda: None)
    assert _validate.require_memory("anything", 1e30, "advice") == 1e30
