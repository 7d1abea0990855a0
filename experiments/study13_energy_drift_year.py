"""Paper §3 (Naidu & Margot 2015, text; script study13): energy and angular-momentum drift per year, in the paper's terms.

The paper's energy-check system (docs/physics.md §7.3; the paper's Fig. 1 system, 5 days in study01)
integrated for one year (207 orbits of 42.3 h) at the paper's fractional tolerance 1e-15.
The paper states its accuracy as the drift of the totals relative to the orbital energy and
relative to the energy that orbit and spins exchange; this study prints exactly those:

* ΔE/|E_orb|: largest |E(t) − E(0)| over the run divided by |E_orb(0)|, the orbital energy
  |P|²/2m + V; ΔE/E_exch: the same divided by E_exch, the largest excursion of the orbital
  energy |E_orb(t) − E_orb(0)| (the energy traded with the spins);
* ΔL/|L_orb| and ΔL/L_exch: the same for the angular momentum about the orbit normal;
* the drift rate per year from a straight-line fit of E(t) − E(0) (and L) against time, with
  the evidence that the growth is linear: the fit's R² and the largest drift in each quarter
  of the run, which grows ~1 : 2 : 3 : 4 for linear growth (~1 : 1.4 : 1.7 : 2 for a random walk).

``--quick`` integrates 10 days and EXTRAPOLATES the fitted rate to a year (labelled so);
the full run integrates the year (about 2 s on one core: the year is cheap, 1 member).
"""

import numpy as np

from _common import parse, save

DAY = 86400.0
YEAR = 365.25 * DAY
RTOL = 1e-15


def _quarters(t, drift):
    """Largest |drift| over [0, k T/4] for k = 1..4."""
    T = t[-1]
    return [float(np.max(np.abs(drift[t <= k * T / 4 + 1e-9 * T]))) for k in (1, 2, 3, 4)]


def _linear(t, drift):
    """Slope (per year) and R² of a least-squares straight line (with intercept)."""
    A = np.vstack([t / YEAR, np.ones_like(t)]).T
    coef, *_ = np.linalg.lstsq(A, drift, rcond=None)
    fit = A @ coef
    ss = np.sum((drift - drift.mean()) ** 2)
    r2 = 1.0 - np.sum((drift - fit) ** 2) / ss if ss > 0 else float("nan")
    return float(coef[0]), float(r2)


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    system = tso.catalog.system("test")
    spin2 = 2 * np.pi / tso.catalog.secondary_spin_period("test") / system.mean_motion
    days = 10.0 if args.quick else 365.25
    orbits = days * DAY / system.orbital_period
    # ~40 samples per primary rotation resolve the exchange (as in study01)
    per_orbit = int(np.ceil(40 * system.orbital_period / system.primary_spin_period))
    ts = tso.time_series(system, 0.0, spin2, orbits=orbits, samples_per_orbit=per_orbit,
                         rtol=RTOL)
    ok = np.isfinite(ts.t[0])
    t = ts.t[0, ok]
    E = ts.energy[0, ok]
    E_orb = ts.energy_orbit[0, ok]
    Lz = (ts.angmom_orbit[0, ok, 2] + ts.angmom_primary[0, ok, 2] + ts.angmom_secondary[0, ok, 2])
    L_orb = ts.angmom_orbit[0, ok, 2]
    dE, dL = E - E[0], Lz - Lz[0]
    E_exch = float(np.max(np.abs(E_orb - E_orb[0])))
    L_exch = float(np.max(np.abs(L_orb - L_orb[0])))
    rate_E, r2_E = _linear(t, dE)
    rate_L, r2_L = _linear(t, dL)
    scale = "extrapolated from 10 days" if args.quick else "measured over one year"
    numbers = {
        "status": ts.status_names[0],
        "days integrated": days, "orbits": float(orbits), "rtol": RTOL,
        "max |dE|/|E_orb|": float(np.max(np.abs(dE)) / abs(E_orb[0])),
        "max |dE|/E_exch": float(np.max(np.abs(dE)) / E_exch),
        "max |dL|/|L_orb|": float(np.max(np.abs(dL)) / abs(L_orb[0])),
        "max |dL|/L_exch": float(np.max(np.abs(dL)) / L_exch),
        "E_exch/|E_orb|": E_exch / abs(E_orb[0]), "L_exch/|L_orb|": L_exch / abs(L_orb[0]),
        f"dE/|E_orb| per year ({scale})": rate_E / abs(E_orb[0]),
        f"dE/E_exch per year ({scale})": rate_E / E_exch,
        f"dL/|L_orb| per year ({scale})": rate_L / abs(L_orb[0]),
        f"dL/L_exch per year ({scale})": rate_L / L_exch,
        "R2 of the linear fit (E, L)": [r2_E, r2_L],
        "max |dE| by quarter / first quarter": list(np.array(_quarters(t, dE)) / max(_quarters(t, dE)[0], 1e-300)),
        "max |dL| by quarter / first quarter": list(np.array(_quarters(t, dL)) / max(_quarters(t, dL)[0], 1e-300)),
    }
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    td = t / DAY
    axes[0].plot(td, dE / abs(E_orb[0]), "k", lw=0.6, label=r"$\Delta E/|E_{\rm orb}|$")
    axes[0].plot(td, (rate_E * t / YEAR) / abs(E_orb[0]), "C3--", lw=1,
                 label=f"linear fit: {rate_E / abs(E_orb[0]):.2e} per year (R² {r2_E:.3f})")
    axes[0].set_ylabel(r"$\Delta E / |E_{\rm orb}(0)|$")
    axes[1].plot(td, dL / abs(L_orb[0]), "k", lw=0.6)
    axes[1].plot(td, (rate_L * t / YEAR) / abs(L_orb[0]), "C3--", lw=1,
                 label=f"linear fit: {rate_L / abs(L_orb[0]):.2e} per year (R² {r2_L:.3f})")
    axes[1].set_ylabel(r"$\Delta L_z / |L_{\rm orb}(0)|$")
    axes[1].set_xlabel("time (days)")
    for ax in axes:
        ax.legend(fontsize=8)
    axes[0].set_title(f"Paper §3: energy-check system, rtol {RTOL:.0e}, {days:g} days "
                      f"(energy exchanged {E_exch / abs(E_orb[0]):.1e} of $|E_{{\\rm orb}}|$)", fontsize=9)
    save(args, "study13_energy_drift_year", fig,
         {"t_days": td, "dE_J": dE, "dLz": dL, "E_orbit_J": E_orb, "L_orbit_z": L_orb},
         {"paper": "§3", "system": system.describe(), "rtol": RTOL, "days": days,
          "samples_per_orbit": per_orbit}, numbers, started)


if __name__ == "__main__":
    main()
