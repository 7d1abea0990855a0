"""Paper §8 (Naidu & Margot 2015, text; script study14): does chaos delay synchronisation? Tides in the equations.

The paper concludes (its §8) that chaotic spin-orbit exchanges outweigh tides and YORP, so
that synchronisation is delayed. Here the tide is put into the equations of motion
(``perturbations=[tso.Tides(...)]``, docs/physics.md §13) and the time to capture into
synchronous rotation is measured directly, for 1991 VH, 2003 YT1 and 2004 DC:

* Chaotic ensemble: starts (θ_p uniform in [0°, 180°), θ̇_p/n uniform in a band of the
  chaotic sea between the synchronous island and the next large island above it: 1991 VH
  1.3–2.1 (2:1 island at 2.31), 2003 YT1 1.1–2.6 (5:2 at 2.85), 2004 DC 1.2–4.0 (4:1 at 4.29))
  kept only if chaotic at t = 0: MEGNO ⟨Y⟩ > 4 after ``SCREEN_ORBITS`` orbits without tides
  (``surface_of_section(..., indicators=True)``), as the chaos maps classify, and not
  synchronous to begin with: without tides the long axis turns past the primary within
  ``CIRCULATION_ORBITS`` orbits (chaotic starts whose α never circulates, "chaotic
  librators" in the layer around the synchronous island, are dropped; their share is
  printed).
* Regular reference: the same starts (same θ_p, same initial spin) with the secondary made
  nearly spherical, a/b = 1.01 at the same mass, volume and c (``catalog.system(name,
  elongation=1.01)``): no chaotic zone (its 1:1 and 3:2 islands are separated by invariant
  curves, docs/physics.md §9.2), so the tide despins it regularly, as in the decoupled
  estimate.
* Tide: constant time lag on the secondary, ``Tides(body="secondary", time_lag=600 s)``, k2
  the rubble-pile default (1e-5 R[km], R the volume-equivalent radius), and ``strength`` S
  chosen per system so that the decoupled e-folding time of θ̇ − n of the nominal secondary,
  τ = a⁶ C / (3 k2 G M_p² R⁵ Δt S) (docs/physics.md §13.1), is 50 orbits (``FULL``; runs of
  2000 orbits = 40 τ, 48 members per ensemble; quick mode 20 orbits, 150, 6). Runs at S/2
  and (``QUARTER``: 1991 VH, 2003 YT1) S/4, each lasting 40 of its own τ, test the weak-tide
  regime: there capture times scale as 1/S, so t_capture / τ (= t_capture × S up to a
  constant, both printed) must agree between strengths.
* Tides + YORP: the same tide plus ``YORP(body="secondary", coefficient=+5e-4)`` (the paper's
  f_Y, spinning up, against the tide), its strength set so that its spin acceleration equals
  the tide's at |θ̇ − n| = ``YORP_OFFSET`` n: it shifts the decoupled tidal equilibrium up by
  0.1 n. (At the tide's own strength factor the paper's f_Y = 5e-4 would equal the tide at
  |θ̇ − n| = 6.6 n (1991 VH), 156 n (2003 YT1), 256 n (2004 DC) for Δt = 600 s: YORP would
  win outright and break the synchronous islands of the last two; the ratio printed as
  "YORP/tide at equal strength".) YORP takes its mean-distance form (``distance="mean"``):
  a constant offset of the tidal equilibrium is the experiment, and the strength S speeds up
  the spin dynamics but not the heliocentric orbit, which would modulate YORP on it.

Capture into synchronous rotation (the definition used for every member): let φ(t) be the
angle α between the secondary's long axis and the line to the primary, unwrapped modulo the
body's 180° symmetry (unwrap 2α, halve), and φ̄(t) its running mean over one orbital period
(this removes the forced libration f − M of an eccentric orbit). A member is captured at
t_c, the earliest time after which φ̄ stays inside a band narrower than 180° to the end of the
run (the long axis never again turns past the primary: α librates, the mean spin equals the
mean motion), provided the run continues at least ``WINDOW_FRACTION`` of its length (and 20
orbits) after t_c; otherwise the member is not captured in the run (censored at the run's
end minus that window). Capture into a 3:2 or 2:1 resonance does not count (α circulates
there). Only members with ``accuracy.usable`` status count.

Statistics: per ensemble the median and quartiles of t_c (not-captured members count as
later than any capture, so a quantile beyond the captured fraction reads "> run"), with
bootstrap 68 % intervals (``BOOTSTRAP`` resamplings of the members); the delay factor is the
ratio of the chaotic and regular medians, its interval from resampling both ensembles.

Measured (full mode, 48 members per ensemble; experiments/README.md, "Study 14"): chaos
does not delay synchronisation here, it hastens it or makes it possible. 1991 VH: median t_c
0.89 τ for the chaotic ensemble at S/4 (0.80 τ at S/2, 0.39 τ at S: t_c / τ settles between
S/2 and S/4, the weak-tide limit), 1.90 τ for the regular one (1.88, 1.80): delay factor 0.47
(68 %: 0.45–0.54) at S/4, 0.42 (0.34–0.50) at S/2. 2003 YT1 and 2004 DC: the regular
secondary settles at 1.26 n (5:4 resonance, above the pseudo-synchronous 1.195 n) and at
1.57 n (pseudo-synchronous 1.557 n), and 0–4 % of it is synchronised within 40 τ, while 65–81 %
(2003 YT1; median t_c 8.0, 10.3, 10.8 τ at S, S/2, S/4) and 46–52 % (2004 DC; median 30 τ at
S/2) of the chaotic ensembles are, the latter after the tide, pumped by the chaotic spin, has
shrunk the orbit by about 10 %. YORP (+0.1 n equivalent, at S) keeps every regular secondary
from synchronising and does not slow the chaotic captures (median 0.33 τ against 0.39 τ,
4.8 τ against 8.0 τ; 48 % against 46 % of 2004 DC captured).

Prints: per system and variant, τ and S, the captured fraction, the median and quartiles of
t_c (orbits and in units of τ), the delay factor with its interval, and the final mean spin.
"""

import numpy as np

from _common import parse, save

SYSTEMS = ("1991 VH", "2003 YT1", "2004 DC")
BANDS = {"1991 VH": (1.3, 2.1), "2003 YT1": (1.1, 2.6), "2004 DC": (1.2, 4.0)}
TIME_LAG = 600.0          # s; only k2 Δt S enters the dissipative part
YORP_COEFFICIENT = 5e-4   # the paper's f_Y, spin-up
YORP_OFFSET = 0.1         # YORP's spin acceleration = the tide's at |θ̇ − n| = 0.1 n
#: Ensemble size, decoupled e-folding time τ (orbits) at strength S, run length (orbits = 40 τ).
FULL = {"members": 48, "tau": 50.0, "orbits": 2000}
QUICK = {"members": 6, "tau": 20.0, "orbits": 150}
SCREEN_ORBITS = 150
#: Systems also run at S/4 (160 τ orbits): where the regular reference synchronises, to follow
#: the delay factor towards weak tides.
QUARTER = ("1991 VH", "2003 YT1")
CIRCULATION_ORBITS = 20   # a kept start's long axis turns past the primary within this
MEGNO_CHAOTIC = 4.0
WINDOW_FRACTION = 0.05
SAMPLES_PER_ORBIT = 16    # unwraps 2α while |θ̇ − ḟ| < 4 n
RTOL = 1e-10
BOOTSTRAP = 2000
BATCH_SAMPLES = 262144    # samples per time_series call (members x samples): bounds memory
SEED = 14
PLOT_MEAN = 5             # orbits averaged in the spin panels (the figure's size; t_c uses 1)


def despin_rate(system, strength=1.0):
    """γ = 3 k2 G M_p² R⁵ Δt S / (a⁶ C), 1/s: the decoupled circular-orbit despin rate of the
    secondary, dω/dt = −γ (ω − n) (docs/physics.md §13.1); C its moment about the spin axis."""
    import ti_spinorbit as tso

    a, b, _ = system.secondary.semi_axes
    C = system.secondary.mass * (a * a + b * b) / 5.0
    tide = tso.Tides(body="secondary", time_lag=TIME_LAG, strength=strength)
    return tide.coefficient(system) * TIME_LAG / (system.a ** 6 * C)


def strength_for(system, tau_orbits):
    """Tide strength S giving the nominal secondary an e-folding despin time of tau_orbits."""
    return 1.0 / (tau_orbits * system.orbital_period * despin_rate(system))


def yorp_strength(system, tide_strength):
    """YORP strength whose spin acceleration T/C equals the tide's γ × YORP_OFFSET n."""
    import ti_spinorbit as tso

    a, b, _ = system.secondary.semi_axes
    C = system.secondary.mass * (a * a + b * b) / 5.0
    per_unit = tso.YORP(body="secondary", coefficient=YORP_COEFFICIENT).torque(system) / C
    return despin_rate(system, tide_strength) * YORP_OFFSET * system.mean_motion / per_unit


def decoupled_despin(round_system, nominal, tau_orbits, thetadot_p):
    """The decoupled estimate for the regular secondary (docs/physics.md §8.9, §13.1): the
    orbit-averaged tide dω/dt = −γ' [Ω(e) ω − N(e) n] relaxes ω exponentially (rate γ' Ω(e),
    γ' = γ C/C' for the round secondary's moment C') to the pseudo-synchronous N/Ω; the spin
    reaches the synchronous island's separatrix 1 + ω0' sqrt|H(1, e)| (units of n) after
    ln((ω_i − N/Ω) / (1 + w − N/Ω)) / (γ' Ω) if N/Ω lies below it, else never. Returns
    (N/Ω, w, times in orbits per start, inf where never)."""
    from ti_spinorbit.model import analytic

    big_omega, big_n = analytic.tidal_torque_factors(round_system.e)
    ps = big_n / big_omega
    w = float(analytic.resonance_half_width(1, round_system.omega0, round_system.e))
    ratio = despin_rate(round_system) / despin_rate(nominal)       # C / C'
    rate = ratio * big_omega / tau_orbits                            # per orbit
    top = 1.0 + w
    if ps >= top:
        return ps, w, np.full(len(thetadot_p), np.inf)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.log((np.asarray(thetadot_p) - ps) / (top - ps)) / rate
    return ps, w, np.where(np.asarray(thetadot_p) > top, t, 0.0)


def capture_time(t_orb, alpha_deg, window):
    """Capture time (orbits) of one member from its sampled α (degrees) at times t_orb
    (orbits, SAMPLES_PER_ORBIT per orbit), or NaN if not captured with ``window`` orbits to
    spare (the definition is in the module docstring)."""
    ok = np.isfinite(alpha_deg) & np.isfinite(t_orb)
    a, t = alpha_deg[ok], t_orb[ok]
    if a.size < 2 * SAMPLES_PER_ORBIT:
        return np.nan
    phi = np.degrees(np.unwrap(np.radians(2.0 * a))) / 2.0
    mean = np.convolve(phi, np.ones(SAMPLES_PER_ORBIT) / SAMPLES_PER_ORBIT, mode="valid")
    span = (np.maximum.accumulate(mean[::-1]) - np.minimum.accumulate(mean[::-1]))[::-1]
    inside = np.flatnonzero(span < 180.0)          # suffix ranges shrink: the first is t_c
    if inside.size == 0:
        return np.nan
    tc = t[inside[0]]
    return tc if t[-1] - tc >= window else np.nan


def run_ensemble(system, theta_p, thetadot_p, perturbations, orbits):
    """Integrate the starts with the perturbations; per member: capture time (orbits, NaN
    not captured), usable flag, final mean spin θ̇/n (last 20 orbits), relative change of the
    orbit-averaged distance (start to end, 20 orbits each), and the orbit-averaged spin
    history (one value per orbit) for the figure; plus the run's seconds and the result's
    perturbations (described for the archive)."""
    import ti_spinorbit as tso
    from ti_spinorbit.engine.accuracy import usable
    from ti_spinorbit.model.perturbations import describe

    window = max(20.0, WINDOW_FRACTION * orbits)
    spo, P = SAMPLES_PER_ORBIT, system.orbital_period
    out = {k: [] for k in ("tc", "usable", "final_spin", "dr", "spin_history")}
    seconds, described = 0.0, None
    batch = max(1, BATCH_SAMPLES // (orbits * spo))
    for lo in range(0, len(theta_p), batch):
        sl = slice(lo, lo + batch)
        ts = tso.time_series(system, theta_p[sl], thetadot_p[sl], orbits=orbits,
                             samples_per_orbit=spo, rtol=RTOL, perturbations=perturbations)
        seconds += ts.seconds
        described = describe(ts.perturbations)
        good = usable(ts.status)
        for k in range(ts.t.shape[0]):
            t = ts.t[k] / P
            out["tc"].append(capture_time(t, ts.alpha[k], window) if good[k] else np.nan)
            out["usable"].append(bool(good[k]))
            spin = ts.thetadot[k, : (ts.t.shape[1] - 1) // spo * spo].reshape(-1, spo).mean(1)
            r = ts.r[k, : (ts.t.shape[1] - 1) // spo * spo].reshape(-1, spo).mean(1)
            out["final_spin"].append(float(np.mean(spin[-20:])))
            out["dr"].append(float(np.mean(r[-20:]) / np.mean(r[:20]) - 1.0))
            out["spin_history"].append(spin)
        del ts
    res = {k: np.array(v) for k, v in out.items()}
    res["seconds"], res["perturbations"] = seconds, described
    return res


def quantiles(tc, usable_mask):
    """Quartiles (25, 50, 75 %) of the capture times of the usable members, not-captured ones
    counted as later than the run (inf: a quantile beyond the captured fraction)."""
    x = np.where(np.isfinite(tc), tc, np.inf)[usable_mask]
    if x.size == 0:
        return np.full(3, np.nan)
    return np.quantile(x, [0.25, 0.5, 0.75], method="inverted_cdf")


def bootstrap_median(tc, usable_mask, rng):
    """BOOTSTRAP medians of the members resampled with replacement (inf: not captured)."""
    x = np.where(np.isfinite(tc), tc, np.inf)[usable_mask]
    idx = rng.integers(0, x.size, size=(BOOTSTRAP, x.size))
    return np.quantile(x[idx], 0.5, axis=1, method="inverted_cdf")


def interval(samples):
    """68 % bootstrap interval (16th, 84th percentile), inf where beyond the run."""
    return np.quantile(samples, [0.16, 0.84], method="inverted_cdf")


def chaotic_starts(system, band, members, rng, quick):
    """``members`` starts in the band that are chaotic at t = 0 (MEGNO > 4 without tides),
    drawn from candidates; also returns the candidates' chaotic share."""
    import ti_spinorbit as tso
    from ti_spinorbit.engine.accuracy import usable

    n = 3 * members
    tp, td = rng.uniform(0.0, 180.0, n), rng.uniform(band[0], band[1], n)
    orbits = 60 if quick else SCREEN_ORBITS
    sec = tso.surface_of_section(system, tp, td, orbits=orbits, rtol=RTOL, indicators=True)
    chaotic = usable(sec.status) & (sec.megno > MEGNO_CHAOTIC)
    ts = tso.time_series(system, tp, td, orbits=CIRCULATION_ORBITS,
                         samples_per_orbit=SAMPLES_PER_ORBIT, rtol=RTOL)
    t = ts.t / system.orbital_period
    turning = np.array([np.isnan(capture_time(t[k], ts.alpha[k], 0.0)) or
                        capture_time(t[k], ts.alpha[k], 0.0) > 0 for k in range(n)])
    keep = chaotic & turning & usable(ts.status)
    idx = np.flatnonzero(keep)[:members]
    if idx.size < members:
        raise RuntimeError(f"{system.name}: only {idx.size} of {n} candidate starts are chaotic "
                           "and circulating")
    shares = (float(chaotic.mean()), float((chaotic & ~turning).sum() / max(1, chaotic.sum())))
    return tp[idx], td[idx], sec.megno[idx], shares


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    quick = args.quick
    setup = QUICK if quick else FULL
    members, orbits, tau1 = setup["members"], setup["orbits"], setup["tau"]
    variants = [("chaotic", "nominal", 1.0, False), ("chaotic, S/2", "nominal", 0.5, False),
                ("chaotic + YORP", "nominal", 1.0, True), ("regular", "round", 1.0, False),
                ("regular, S/2", "round", 0.5, False), ("regular + YORP", "round", 1.0, True)]
    colors = {"chaotic": "tab:blue", "chaotic, S/2": "tab:cyan", "chaotic, S/4": "tab:green",
              "chaotic + YORP": "tab:purple", "regular": "tab:red", "regular, S/2": "tab:orange",
              "regular, S/4": "tab:olive", "regular + YORP": "tab:brown"}
    fig, axes = plt.subplots(2, 3, figsize=(13.5, 8.8))
    numbers, arrays, parameters = {}, {}, {"members": members, "orbits": orbits,
                                           "tau_orbits": [tau1, 2 * tau1],
                                           "circulation_orbits": CIRCULATION_ORBITS, "rtol": RTOL,
                                           "time_lag_s": TIME_LAG, "bands": BANDS,
                                           "screen_orbits": 60 if quick else SCREEN_ORBITS,
                                           "megno_chaotic": MEGNO_CHAOTIC,
                                           "window_fraction": WINDOW_FRACTION,
                                           "samples_per_orbit": SAMPLES_PER_ORBIT,
                                           "yorp_offset_n": YORP_OFFSET, "bootstrap": BOOTSTRAP,
                                           "seed": SEED, "perturbations": {}}
    for col, name in enumerate(SYSTEMS):
        nominal = tso.catalog.system(name)
        shapes = {"nominal": nominal, "round": tso.catalog.system(name, elongation=1.01)}
        S = strength_for(nominal, tau1)
        rng = np.random.default_rng([SEED, col])   # per system: starts independent of variants
        tp, td, megno, (share, librating) = chaotic_starts(nominal, BANDS[name], members, rng,
                                                           quick)
        key = name.replace(" ", "")
        arrays.update({f"{key}_theta_p": tp, f"{key}_thetadot_p": td, f"{key}_megno0": megno})
        a, b, _ = nominal.secondary.semi_axes
        C = nominal.secondary.mass * (a * a + b * b) / 5.0
        equal = (tso.YORP(body="secondary", coefficient=YORP_COEFFICIENT, strength=S)
                 .torque(nominal) / C) / (despin_rate(nominal, S) * nominal.mean_motion)
        numbers[f"{name} strength S (tau = {tau1:g} orbits)"] = float(S)
        numbers[f"{name} chaotic share of candidates"] = share
        numbers[f"{name} share of chaotic candidates not circulating (dropped)"] = librating
        numbers[f"{name} YORP/tide at equal strength (|thetadot - n| / n where equal)"] = \
            float(equal)
        ps, w, t_dec = decoupled_despin(shapes["round"], nominal, tau1, td)
        numbers[f"{name} pseudo-synchronous spin N/Omega"] = float(ps)
        numbers[f"{name} a/b = 1.01 synchronous half-width"] = w
        numbers[f"{name} regular: decoupled estimate, median time to the island (orbits)"] = \
            float(np.median(t_dec))
        results, boots = {}, {}
        ax_spin, ax_cdf = axes[0, col], axes[1, col]
        weakest = [("chaotic, S/4", "nominal", 0.25, False), ("regular, S/4", "round", 0.25, False)]
        for label, shape, factor, yorp in variants + (weakest if name in QUARTER else []):
            system = shapes[shape]
            perts = [tso.Tides(body="secondary", time_lag=TIME_LAG, strength=factor * S)]
            if yorp:
                perts.append(tso.YORP(body="secondary", coefficient=YORP_COEFFICIENT,
                                      strength=yorp_strength(nominal, factor * S),
                                      distance="mean"))
            run = int(round(orbits / factor))           # every run lasts 40 of its own τ
            res = run_ensemble(system, tp, td, perts, run)
            results[label] = res
            tau = tau1 / factor
            q = quantiles(res["tc"], res["usable"])
            boots[label] = bootstrap_median(res["tc"], res["usable"], rng)
            lo, hi = interval(boots[label])
            frac = float(np.mean(np.isfinite(res["tc"][res["usable"]])))
            tag = f"{name} {label}"
            numbers[f"{tag}: usable"] = int(res["usable"].sum())
            numbers[f"{tag}: captured fraction"] = frac
            numbers[f"{tag}: t_c quartiles (orbits)"] = [float(v) for v in q]
            numbers[f"{tag}: median 68% interval (orbits)"] = [float(lo), float(hi)]
            numbers[f"{tag}: median t_c / tau"] = float(q[1] / tau)
            numbers[f"{tag}: median t_c x strength (orbits)"] = float(q[1] * factor * S)
            numbers[f"{tag}: final spin median"] = float(np.median(res["final_spin"]))
            numbers[f"{tag}: orbit-averaged distance change median"] = float(np.median(res["dr"]))
            parameters["perturbations"][tag] = res["perturbations"]
            slug = label.replace(" ", "").replace(",", "_").replace("+", "_")
            for k in ("tc", "usable", "final_spin", "dr"):
                arrays[f"{key}_{slug}_{k}"] = res[k]
            # cumulative captured fraction against t / τ (the weak-tide regime collapses S, S/2)
            ok = res["usable"]
            tcs = np.sort(res["tc"][ok][np.isfinite(res["tc"][ok])]) / tau
            y = np.arange(1, tcs.size + 1) / max(1, ok.sum())
            ax_cdf.step(np.r_[0.0, tcs, run / tau], np.r_[0.0, y, y[-1] if y.size else 0.0],
                        where="post", color=colors[label],
                        ls="--" if label.startswith("regular") else "-",
                        label=f"{label} (median {_fmt_med(q[1], tau)})")
        for label, shape in (("chaotic", "nominal"), ("regular", "round")):   # at strength S
            hist = results[label]["spin_history"]
            for k in range(min(2, len(hist))):
                smooth = np.convolve(hist[k], np.ones(PLOT_MEAN) / PLOT_MEAN, mode="valid")
                t = (np.arange(smooth.size) + 0.5 * PLOT_MEAN) / tau1
                ax_spin.plot(t, smooth, lw=0.5, color=colors[label],
                             ls="-" if label == "chaotic" else "--",
                             label=f"{label} (a/b = {_ab(shapes[shape]):.2f})"
                             if k == 0 else None)
        for base in ("", ", S/2", " + YORP") + ((", S/4",) if name in QUARTER else ()):
            c, r = boots["chaotic" + base], boots["regular" + base]
            with np.errstate(invalid="ignore", divide="ignore"):
                ratio = c / r
            chaotic, regular = results["chaotic" + base], results["regular" + base]
            med_c = quantiles(chaotic["tc"], chaotic["usable"])[1]
            med_r = quantiles(regular["tc"], regular["usable"])[1]
            ratio = ratio[~np.isnan(ratio)]             # inf/inf: neither captured
            lo, hi = interval(ratio) if ratio.size else (np.nan, np.nan)
            with np.errstate(invalid="ignore"):     # inf/inf: neither captured, undetermined
                factor = float(med_c / med_r)
            numbers[f"{name} delay factor chaotic/regular{base} (median ratio, 68%)"] = [
                factor, float(lo), float(hi)]
        ax_spin.axhline(ps, color="0.3", ls=":", lw=0.8,
                        label=rf"pseudo-synchronous $N/\Omega$ = {ps:.3f}")
        ax_spin.axhline(1.0 + w, color="tab:red", ls="-.", lw=0.6,
                        label=f"top of the a/b = 1.01 synchronous island, {1 + w:.3f}")
        tc = results["chaotic"]["tc"]
        late = np.nanquantile(tc, 0.75) / tau1 if np.isfinite(tc).any() else orbits / tau1
        ax_spin.set_xlim(0, min(orbits / tau1, max(4.0, 1.5 * late)))
        ax_spin.set_xlabel(r"$t/\tau$")
        ax_spin.set_ylabel(rf"$\dot\theta/n$, {PLOT_MEAN}-orbit mean")
        ax_spin.set_title(rf"{name}: $\tau$ = {tau1:g} orbits, S = {S:.3g}, e = {nominal.e:g}",
                          fontsize=8)
        ax_spin.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
        ax_cdf.set_xscale("log")
        ax_cdf.set_xlim(0.05, orbits / tau1 * 2)
        ax_cdf.set_ylim(0, 1.02)
        ax_cdf.set_xlabel(r"capture time $t_c/\tau$")
        ax_cdf.set_ylabel("fraction captured (synchronous)")
        ax_cdf.set_title(rf"{name}: {members} chaotic starts, $\dot\theta_p/n$ "
                         rf"{BANDS[name][0]:g}–{BANDS[name][1]:g}, runs of 40$\tau$ "
                         f"({orbits} orbits at S)", fontsize=8)
        ax_cdf.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)
    fig.suptitle("Naidu & Margot 2015, §8: capture into synchronous rotation under tides "
                 r"(constant time lag, strength S; $\tau$ the decoupled despin e-folding time), "
                 "chaotic secondary against a/b = 1.01", fontsize=9)
    save(args, "study14_chaos_delays_sync", fig, arrays, parameters, numbers, started)


def _ab(system):
    a, b, _ = system.secondary.semi_axes
    return a / b


def _fmt_med(value, tau):
    return "> run" if not np.isfinite(value) else rf"{value / tau:.2f}$\tau$"


if __name__ == "__main__":
    main()
