"""The same kernels on Taichi's CUDA backend (f64, fast_math off) give the CPU's results to
near the tolerance. Skipped cleanly where no CUDA device is usable.

Taichi runs one arch per process, so the CUDA side runs in a subprocess that writes its
arrays to a file; this process is the CPU side. Bitwise equality is not expected: NVPTX
contracts a·b + c into fused multiply-adds, the CPU backend does not, so trajectories differ
by round-off that the integrator's error control keeps at the tolerance level over these
short runs."""

import functools
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import ti_spinorbit as tso


@functools.lru_cache(maxsize=1)
def cuda_available():
    """True when Taichi can start on CUDA here (checked in a throw-away process)."""
    probe = ("import taichi as ti; ti.init(arch=ti.cuda, enable_fallback=False, "
             "log_level=ti.ERROR); assert ti.lang.impl.current_cfg().arch == ti.cuda")
    try:
        p = subprocess.run([sys.executable, "-c", probe], capture_output=True, timeout=300,
                           env=dict(os.environ, TI_SKIP_VERSION_CHECK="ON"))
    except (OSError, subprocess.TimeoutExpired):
        return False
    return p.returncode == 0


pytestmark = pytest.mark.skipif(not cuda_available(), reason="no CUDA device usable by Taichi")

STARTS = [0.83, 1.0, 1.63, 2.53]
RUN = dict(orbits=30, rtol=1e-12, indicators=True)


def run_on_cuda(tmp_path, model):
    out = tmp_path / f"cuda_{model}.npz"
    script = textwrap.dedent(f"""
        import numpy as np, ti_spinorbit as tso
        assert tso.init("cuda") == "cuda"
        r = tso.surface_of_section(tso.catalog.system("1991 VH"), 0.0, {STARTS!r},
                                   model={model!r}, **{RUN!r})
        np.savez({str(out)!r}, theta_p=r.theta_p, thetadot_p=r.thetadot_p, t=r.t,
                 count=r.count, status=r.status, megno=r.megno, energy_drift=r.energy_drift)
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                       timeout=900)
    assert p.returncode == 0, p.stderr
    return np.load(out)


@pytest.mark.parametrize("model", ["planar", "3d"])
def test_cuda_sections_equal_cpu_to_near_the_tolerance(tmp_path, model):
    gpu = run_on_cuda(tmp_path, model)
    cpu = tso.surface_of_section(tso.catalog.system("1991 VH"), 0.0, STARTS, **RUN,
                                 integrator=tso.Integrator(model=model))
    np.testing.assert_array_equal(gpu["status"], cpu.status)
    np.testing.assert_array_equal(gpu["count"], cpu.count)
    regular = [0, 1, 3]            # the chaotic start (1.63) diverges like any perturbation
    for key, atol in (("thetadot_p", 1e-6), ("theta_p", 1e-4), ("t", 1e-3)):
        np.testing.assert_allclose(gpu[key][regular], getattr(cpu, key)[regular], rtol=0,
                                   atol=atol, err_msg=key)
    np.testing.assert_allclose(gpu["megno"][regular], cpu.megno[regular], atol=0.05)
    assert gpu["megno"][2] > 4 and cpu.megno[2] > 4
    assert np.all(gpu["energy_drift"] < 1e-9)
