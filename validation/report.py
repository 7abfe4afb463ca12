"""validation/report/README.md and the PNG plots, from results.json (see run.py).

The README is written with the standard library; the plots need numpy and matplotlib
(python3-numpy, python3-matplotlib), imported only in make_plots().
"""

import math
from pathlib import Path

# --------------------------------------------------------------------------------------------
# helpers


def f3(x, digits=3, signed=False):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return ("%+.*f" if signed else "%.*f") % (digits, x)


def g(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return "%.*g" % (digits, x)


def err(r, name, digits=2):
    q = r.get("qoi")
    if not q:
        return "-"
    e = q["errors"].get(name)
    if e is None:
        return "-"
    mark = " (!)" if r.get("energy_growth") else ""
    return "%+.*f%s" % (digits, e, mark)


def val(r, name):
    q = r.get("qoi")
    return q["values"].get(name) if q else None


def outcome(r):
    if r.get("rc") == 1:
        return "set-up error (exit 1)"
    o = r.get("outcome") or ("exit %s" % r.get("rc"))
    if r.get("energy_growth") and o == "finished":
        o = "finished, energy grows"
    return o


def particles(r):
    if r.get("particles") is None:
        return "-"
    return "%d (%d)" % (r["particles"], r.get("ghost_particles") or 0)


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return out


def primary_error(r):
    q = r.get("qoi")
    if not q:
        return None
    return q["errors"].get(q["primary"])


def order(e1, e2, h1, h2):
    """Observed order of the error between two resolutions; None when undefined (a zero
    error, or a change of sign: the error passed through zero)."""
    if e1 is None or e2 is None or e1 == 0 or e2 == 0 or (e1 > 0) != (e2 > 0):
        return None
    return math.log(abs(e1) / abs(e2)) / math.log(h1 / h2)


def order_text(e1, e2, h1, h2):
    if e1 is not None and e2 is not None and e1 != 0 and e2 != 0 and (e1 > 0) != (e2 > 0):
        return "sign change"
    return f3(order(e1, e2, h1, h2), 2)


def richardson(hs, qs):
    """Self-convergence of the last three values: q(h) = q_inf + C h^p. Returns (p, q_inf) or
    (None, None) when the differences change sign (not in the asymptotic range)."""
    (h1, h2, h3), (q1, q2, q3) = hs[-3:], qs[-3:]
    if None in (q1, q2, q3):
        return None, None
    d12, d23 = q1 - q2, q2 - q3
    if d23 == 0 or d12 == 0 or (d12 > 0) != (d23 > 0):
        return None, None
    ratio = d12 / d23

    def f(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - ratio

    lo, hi = 0.05, 8.0
    if (f(lo) > 0) == (f(hi) > 0):
        return None, None
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if (f(mid) > 0) == (f(lo) > 0):
            lo = mid
        else:
            hi = mid
    p = 0.5 * (lo + hi)
    C = d23 / (h2**p - h3**p)
    return p, q3 - C * h3**p


def ladder(runs, key, variant=None):
    """Ladder runs of a problem, coarse to fine; variant None = all variants."""
    out = [r for r in runs if r["problem"] == key and r["kind"] == "ladder" and
           (variant is None or r["variant"] == variant)]
    return sorted(out, key=lambda r: -r["dx"])


def sensitivity(runs, key, param):
    return sorted([r for r in runs if r["problem"] == key and r["kind"] == "sensitivity" and
                   r["param"] == param], key=lambda r: r["value"])


def mid_run(runs, key, dx, variant):
    for r in runs:
        if (r["problem"] == key and r["kind"] == "ladder" and abs(r["dx"] - dx) < 1e-12 and
                r["variant"] == variant):
            return r
    return None


DEFAULTS = {"kernel.support": 2.1, "kernel.correction": "quadratic", "hourglass.alpha": 10.0,
            "time.cfl": 0.3, "static.tolerance": 1e-5}
PARAM_NAME = {"kernel.support": "kernel.support (H/dx)", "kernel.correction": "kernel.correction",
              "hourglass.alpha": "hourglass.alpha",
              "time.cfl": "time.cfl", "static.tolerance": "static.tolerance"}

# Per problem: value columns of the ladder table: (header, function of a run -> text).
MM = 1000.0


def _mm(name):
    return lambda r: f3(val(r, name) * MM if val(r, name) is not None else None, 3)


COLUMNS = {
    "oscillating_plate": [
        ("T [s]", lambda r: f3(val(r, "period"), 5)),
        ("error vs thin plate %", lambda r: err(r, "period")),
        ("vs Timoshenko %", lambda r: err(r, "period_vs_timoshenko")),
        ("T from v_y, error %", lambda r: err(r, "period_from_velocity")),
        ("periods measured", lambda r: f3(val(r, "periods_measured"), 2)),
        ("energy drift %", lambda r: g(r.get("energy_drift_pct"), 2)),
    ],
    "cantilever_static": [
        ("tip w [mm]", _mm("tip")),
        ("error vs Timoshenko %", lambda r: err(r, "tip")),
        ("vs FEM %", lambda r: err(r, "tip_vs_fem")),
        ("extrapolated w [mm]", _mm("tip_extrapolated")),
        ("its error %", lambda r: err(r, "tip_extrapolated")),
    ],
    "cantilever_dynamic": [
        ("f [Hz]", lambda r: f3(val(r, "frequency"), 4)),
        ("error vs Timoshenko %", lambda r: err(r, "frequency")),
        ("vs Euler-Bernoulli %", lambda r: err(r, "frequency_vs_euler_bernoulli")),
        ("mean w [mm]", _mm("mean_deflection")),
        ("its error %", lambda r: err(r, "mean_deflection")),
        ("energy drift %", lambda r: g(r.get("energy_drift_pct"), 2)),
    ],
    "csm1": [
        ("u_x [mm]", _mm("ux")), ("u_y [mm]", _mm("uy")),
        ("error u_x %", lambda r: err(r, "ux")), ("error u_y %", lambda r: err(r, "uy")),
        ("error abs(u) %", lambda r: err(r, "displacement")),
        ("extrapolated: u_x %", lambda r: err(r, "ux_extrapolated")),
        ("u_y %", lambda r: err(r, "uy_extrapolated")),
    ],
    "csm3": [
        ("f [Hz]", lambda r: f3(val(r, "frequency"), 4)),
        ("error f %", lambda r: err(r, "frequency")),
        ("u_y mean +- amp [mm]", lambda r: "%s +- %s" % (
            f3(_s(val(r, "uy_mean")), 2), f3(_s(val(r, "uy_amp")), 2))),
        ("errors %", lambda r: "%s / %s" % (err(r, "uy_mean"), err(r, "uy_amp"))),
        ("u_x mean +- amp [mm]", lambda r: "%s +- %s" % (
            f3(_s(val(r, "ux_mean")), 2), f3(_s(val(r, "ux_amp")), 2))),
        ("errors %", lambda r: "%s / %s" % (err(r, "ux_mean"), err(r, "ux_amp"))),
        ("energy drift %", lambda r: g(r.get("energy_drift_pct"), 2)),
    ],
    "clamped_plate": [
        ("w [mm]", _mm("w")),
        ("error vs Kirchhoff %", lambda r: err(r, "w")),
        ("vs Mindlin %", lambda r: err(r, "w_vs_mindlin")),
    ],
}


def _s(x):
    return None if x is None else x * MM


# Errors whose convergence is tabulated (primary first), and the value they are errors of.
CONVERGENCE = {
    "oscillating_plate": [("period", "period", "thin plate"),
                          ("period_vs_timoshenko", "period", "Timoshenko")],
    "cantilever_static": [("tip", "tip", "Timoshenko"), ("tip_vs_fem", "tip", "FEM")],
    "cantilever_dynamic": [("frequency", "frequency", "Timoshenko"),
                           ("frequency_vs_euler_bernoulli", "frequency", "Euler-Bernoulli")],
    "csm1": [("displacement", None, "Turek-Hron"), ("uy", "uy", "Turek-Hron"),
             ("ux", "ux", "Turek-Hron")],
    "csm3": [("frequency", "frequency", "Turek-Hron"), ("uy_amp", "uy_amp", "Turek-Hron"),
             ("uy_mean", "uy_mean", "Turek-Hron")],
    "clamped_plate": [("w", "w", "Kirchhoff"), ("w_vs_mindlin", "w", "Mindlin")],
}
# The quantity an error is of, for legends and tables.
ERROR_SYMBOL = {"period": "T", "period_vs_timoshenko": "T", "tip": "w", "tip_vs_fem": "w",
                "frequency": "f", "frequency_vs_euler_bernoulli": "f", "displacement": "abs(u)",
                "uy": "u_y", "ux": "u_x", "uy_amp": "u_y amplitude", "uy_mean": "u_y mean",
                "w": "w", "w_vs_mindlin": "w"}


def error_label(name, against):
    return "%s vs %s" % (ERROR_SYMBOL.get(name, name), against)


def reference_value(R, key, error_name):
    c, cs, cp = R.get("cantilever", {}), R.get("csm3", {}), R.get("clamped_plate", {})
    table_ = {
        ("oscillating_plate", "period"): R["oscillating_plate"]["period"],
        ("oscillating_plate", "period_vs_timoshenko"): R["oscillating_plate"]["period_timoshenko"],
        ("cantilever_static", "tip"): c["tip_timoshenko"],
        ("cantilever_static", "tip_vs_fem"): c["tip_fem"],
        ("cantilever_dynamic", "frequency"): c["f_timoshenko"],
        ("cantilever_dynamic", "frequency_vs_euler_bernoulli"): c["f_euler_bernoulli"],
        ("csm1", "uy"): R["csm1"]["uy"], ("csm1", "ux"): R["csm1"]["ux"],
        ("csm3", "frequency"): cs["frequency"], ("csm3", "uy_amp"): cs["uy_amp"],
        ("csm3", "uy_mean"): cs["uy_mean"],
        ("clamped_plate", "w"): cp["w_kirchhoff"], ("clamped_plate", "w_vs_mindlin"): cp["w_mindlin"],
    }
    return table_.get((key, error_name))


# --------------------------------------------------------------------------------------------


def write_report(data, report_dir):
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    plots, plot_note = [], ""
    try:
        plots = make_plots(data, report_dir)
    except ImportError as e:
        plot_note = ("(plots not regenerated: %s; install python3-numpy python3-matplotlib and "
                     "run `validation/run.py --report-only`)" % e)
    text = readme(data, plots, plot_note)
    tmp = report_dir / "README.md.tmp"
    tmp.write_text(text)
    tmp.replace(report_dir / "README.md")


def readme(data, plots, plot_note):
    runs, R, P, meta = data["runs"], data["references"], data["problems"], data["meta"]
    L = []
    L.append("# tlsph validation report: error against run time")
    L.append("")
    L.append("Generated by `validation/run.py` from `results.json` (next to this file), which "
             "holds every run's record and the exact command that reproduces it. Regenerate "
             "this page and the plots with `/usr/bin/python3 validation/run.py --report-only`; "
             "rerun everything with `bash scripts/setup.sh validate`.")
    L.append("")
    m = meta.get("machine", {})
    git = meta.get("git", {})
    total_wall = sum(r.get("wall_runner") or 0 for r in runs)
    L.append("| | |")
    L.append("|---|---|")
    L.append("| commit | `%s` |" % git.get("commit", "?"))
    if git.get("binary_built_from_export"):
        wt = git.get("working_tree", {})
        changed = ", ".join("`%s`" % c[3:] for c in wt.get("changed", [])[:10])
        L.append("| binary | built from `git archive %s` (a clean export of the commit, so that "
                 "work in progress in the shared tree could not enter it); scenes and runner "
                 "from the working tree%s |" % (
                     git.get("commit", "?")[:12],
                     ", where these files differed from the commit: " + changed
                     if changed else ""))
    if git.get("changed"):
        L.append("| uncommitted at run time | %s |" % ", ".join(
            "`%s`" % c[3:] for c in git["changed"][:12]) + (" ..." if len(git["changed"]) > 12
                                                          else ""))
    L.append("| machine | %s, %s cores; %s |" % (m.get("cpu", "?"), m.get("cores", "?"),
                                                  m.get("platform", "")))
    L.append("| build | `%s/tlsph` (%s) %s |" % (m.get("build_dir", "build"),
                                                   m.get("build_type", "?"),
                                                   m.get("tlsph_version", "")))
    L.append("| threads | OMP_NUM_THREADS=%s, OMP_WAIT_POLICY=%s |" % (
        m.get("threads", "?"), meta.get("omp_wait_policy") or "(default)"))
    reused = sum(1 for r in runs if r.get("reused"))
    L.append("| runs | %d, started %s%s |" % (
        len(runs), meta.get("started", "?"),
        "; %d of them reused from an earlier invocation of the same ladder (`--reuse`: same "
        "command, run after the scene file last changed; their wall times are those measured "
        "then)" % reused if reused else ""))
    L.append("| wall time | %.0f s for all runs (%.1f min), of which the ladders %.0f s and "
             "the sensitivity studies %.0f s |" % (
                 total_wall, total_wall / 60.0,
                 sum(r.get("wall_runner") or 0 for r in runs if r["kind"] == "ladder"),
                 sum(r.get("wall_runner") or 0 for r in runs if r["kind"] == "sensitivity")))
    L.append("| command | `%s` |" % meta.get("runner_command", ""))
    L.append("")
    L.append("The machine was shared with other jobs, so wall times are noisy (each run records "
             "the load average before and after it in `results.json`). Errors are signed: "
             "`100 (value - reference) / |reference|`; `(!)` marks a run whose energy books "
             "drift by more than 1 % (energy grows: its numbers are not to be trusted).")
    L.append("")

    # Summary
    L.append("## Summary")
    L.append("")
    rows = []
    for key, p, variant in ((k, p, v) for k, p in P.items() for v in p["variants"]):
        lad = ladder(runs, key, variant)
        if not lad:
            continue
        fin = lad[-1]
        e = primary_error(fin)
        tgt = p.get("target")
        met = "-"
        if tgt and e is not None:
            met = "yes" if abs(e) <= tgt[1] and not fin.get("energy_growth") else "**no**"
        hs = [r["dx"] for r in lad]
        pe = [primary_error(r) for r in lad]
        o = order_text(pe[-2], pe[-1], hs[-2], hs[-1]) if len(lad) >= 2 else "-"
        q = fin.get("qoi") or {}
        title = p["title"] + ("" if not variant else ", " + variant_label(p, variant))
        rows.append([title, "%s (%s)" % (p["qoi"], q.get("primary", "-")),
                     "%d / %s" % (fin["per_thickness"], g(fin["dx"], 4)),
                     err(fin, q.get("primary", "")) if q else outcome(fin),
                     "%s %%" % tgt[1] if tgt else "-", met, o,
                     "%.0f" % (fin.get("wall_seconds") or 0)])
    L += table(["problem", "quantity (error)", "finest: per thickness / dx", "error %",
                "target", "met", "order (last pair)", "wall s"], rows)
    L.append("")
    L.append("Details, what limits each target, and the sensitivity studies follow. "
             "Order = observed order of the error against the reference between the two finest "
             "resolutions, `log(e1/e2)/log(dx1/dx2)`.")
    L.append("")

    # Hand-written findings for this run, if any (validation/report_notes.md).
    notes = Path(__file__).resolve().parent / "report_notes.md"
    if notes.exists():
        L.append("## Findings")
        L.append("")
        L.append("_Written by hand from the tables below (validation/report_notes.md, included "
                 "verbatim); check them against the tables whenever the report is "
                 "regenerated._")
        L.append("")
        L += notes.read_text().rstrip("\n").split("\n")
        L.append("")

    # References
    L += references_section(R)

    # Per problem
    for key, p in P.items():
        L += problem_section(key, p, runs, R)

    # Sensitivities
    L.append("## Sensitivity studies")
    L.append("")
    L.append("One resolution per problem (the 'mid' one of its ladder); one parameter changed "
             "at a time from the defaults (support 2.1 dx, quadratic correction, alpha 10, CFL "
             "0.3, static tolerance 1e-5 in the validation scenes); the default row is the "
             "ladder run. Exit status 4 "
             "(`unstable`) is a result. `hg work min` is the most negative value the hourglass "
             "work reached (a negative value means the hourglass force fed energy in).")
    L.append("")
    for key, p in P.items():
        L += sensitivity_section(key, p, runs)

    L += defaults_section(P, runs)
    L += cuts_section(P, runs)

    # Plots
    L.append("## Plots")
    L.append("")
    if plot_note:
        L.append(plot_note)
        L.append("")
    for fname, caption in plots:
        L.append("**%s** — %s" % (fname, caption))
        L.append("")
        L.append("![%s](%s)" % (fname, fname))
        L.append("")
    return "\n".join(L) + "\n"


def references_section(R):
    L = ["## References", ""]
    op, c, cp = R["oscillating_plate"], R["cantilever"], R["clamped_plate"]
    L.append("- **Oscillating plate** (Gray, Monaghan & Swift 2001): thin-plate theory, plane "
             "strain, `omega^2 = E H^2 k^4 / (12 rho0 (1 - nu^2))`, `k = 1.875/L` -> "
             "T = %.5f s (the reference for the error). A Timoshenko beam with the plane-strain "
             "modulus `E/(1-nu^2)`, shear (kappa = 10(1+nu)/(12+11nu)) and rotary inertia, "
             "solved by `validation/references.py`, gives T = %.5f s (%+.2f %%): L/H = 10 is "
             "not thin." % (op["period"], op["period_timoshenko"],
                            100 * (op["period_timoshenko"] / op["period"] - 1)))
    L.append("- **Cantilever, static**: Timoshenko tip deflection 0.01516 m (the reference; "
             "`qL^4/(8EI) + qL^2/(2 kappa G A)` evaluates to %.5f m with Cowper's kappa = %.4f "
             "and 0.015156 with 5/6), Euler-Bernoulli %.4f m; converged 3D FEM with the whole "
             "face x = 0 clamped 0.01501 m (also tabulated: the clamped face cannot contract, "
             "which stiffens the root)." % (c["tip_timoshenko_computed"], c["kappa"],
                                            c["tip_euler_bernoulli"]))
    L.append("- **Cantilever, dynamic**: Euler-Bernoulli f1 = 1.8751^2/(2 pi) sqrt(EI/(rho A "
             "L^4)) = %.4f Hz. Slenderness L/h = 10: the clamped-free Timoshenko beam (shear "
             "kappa = %.4f, rotary inertia), solved by bisection on its frequency determinant "
             "in `validation/references.py`, gives **%.4f Hz** (%+.2f %%; %.4f Hz without "
             "rotary inertia). The error is taken against the Timoshenko value; the "
             "Euler-Bernoulli error is tabulated too." % (
                 c["f_euler_bernoulli"], c["kappa"], c["f_timoshenko"],
                 100 * (c["f_timoshenko"] / c["f_euler_bernoulli"] - 1),
                 c["f_timoshenko_no_rotary"]))
    L.append("- **Turek & Hron (2006) CSM1/CSM3**: point A = tip centre. CSM1 u_x = -7.187e-3, "
             "u_y = -6.610e-2 m; CSM3 u_x = -1.4305e-2 +- 1.4305e-2, u_y = -6.3607e-2 +- "
             "6.5541e-2 m, f = 1.0995 Hz. CSM3 values are extracted over t >= one reference "
             "period (0.9095 s) to the end: mean = (max+min)/2, amplitude = (max-min)/2, "
             "frequency from the times of successive extrema of u_y (each refined by a "
             "parabola through three samples).")
    L.append("- **Clamped square plate** (a/t = 10): Kirchhoff `w = 0.00126 q a^4/D` = %.4f mm "
             "(Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, table 35; the "
             "reference for the error). Thick-plate estimate: a Ritz solution of the Mindlin "
             "(first-order shear, kappa = 5/6) clamped plate in `validation/references.py` "
             "gives **%.4f mm** (%+.1f %% over Kirchhoff); the same code on the Kirchhoff "
             "energy returns the coefficient %.6f (the tabulated 0.00126), which checks it. "
             "Most of the difference between the Kirchhoff number and a 3D solid is this "
             "shear deformation." % (cp["w_kirchhoff"] * MM, cp["w_mindlin"] * MM,
                                     100 * (cp["w_mindlin"] / cp["w_kirchhoff"] - 1),
                                     cp["kirchhoff_coefficient_ritz"]))
    L.append("")
    return L


NOTES = {
    "oscillating_plate": "Period from the linearly interpolated zero crossings of the tip "
                         "probe's u_y over 0 < t <= 0.8 s (about 3.1 periods: 6 crossings, "
                         "2.5 periods between the first and the last); the period from the "
                         "crossings of v_y is a cross-check.",
    "cantilever_static": "Tip deflection from the first-order kernel probe at (1, 0, 0); the "
                         "'extrapolated' column is `2 u(0.95) - u(0.9)` from two interior "
                         "probes, a check that does not lean on the surface particles.",
    "cantilever_dynamic": "Frequency from the crossings of the tip u_z through its mean "
                          "(max+min)/2 over 0 < t <= 1.9 s (about 3 periods, 6 crossings).",
    "csm1": "abs(u) error = |u - u_ref| / |u_ref| for the displacement vector of point A (the "
            "headline); the components separately: u_x and u_y are negative, so a positive "
            "component error means a smaller magnitude (too stiff), a negative one too soft. "
            "Extrapolated: `2 u(0.33) - u(0.31)`.",
    "csm3": "Over t >= 0.9095 s to the end (3.0 s): about 2.3 periods.",
    "clamped_plate": "Centre deflection from the kernel probe at the mid-surface centre.",
}


def problem_section(key, p, runs, R):
    L = ["## %s" % p["title"], "", "Scene `%s`. %s" % (p["scene"], NOTES.get(key, "")), ""]
    variants = p["variants"]
    for variant in variants:
        lad = ladder(runs, key, variant)
        if not lad:
            continue
        if len(variants) > 1:
            L.append("**%s**" % variant_label(p, variant))
            L.append("")
        cols = COLUMNS[key]
        rows = []
        for r in lad:
            rows.append([g(r["dx"], 4), r["per_thickness"], particles(r),
                         f3(r.get("neighbours_mean"), 1), r.get("steps") or "-",
                         g(r.get("dt"), 3), f3(r.get("wall_seconds"), 1), outcome(r)] +
                        [fn(r) for _, fn in cols])
        L += table(["dx [m]", "per thickness", "particles (ghosts)", "mean nb", "steps",
                    "dt [s]", "wall s", "outcome"] + [h for h, _ in cols], rows)
        L.append("")
        # convergence
        conv_rows = []
        hs = [r["dx"] for r in lad]
        for name, value_name, against in CONVERGENCE[key]:
            es = [(r.get("qoi") or {}).get("errors", {}).get(name) for r in lad]
            if all(e is None for e in es):
                continue
            orders = []
            for i in range(1, len(lad)):
                o = order_text(es[i - 1], es[i], hs[i - 1], hs[i])
                orders.append("%d->%d: %s" % (lad[i - 1]["per_thickness"], lad[i]["per_thickness"],
                                              o))
            rich = "-"
            if value_name and len(lad) >= 3:
                qs = [val(r, value_name) for r in lad]
                pr, qinf = richardson(hs, qs)
                ref = reference_value(R, key, name)
                if pr is not None and ref:
                    rich = "p = %.2f, value %s, error %+.2f %%" % (
                        pr, g(qinf, 5), 100 * (qinf - ref) / abs(ref))
                elif pr is None:
                    rich = "no fit (differences change sign or shrink too slowly: not " \
                           "in the asymptotic range)"
            conv_rows.append([error_label(name, against),
                              "; ".join(orders), rich])
        if conv_rows:
            L += table(["error", "observed order between resolutions",
                        "Richardson, last three (self-convergence)"], conv_rows)
            L.append("")
    return L


def variant_label(p, variant):
    ov = p.get("variant_overrides", {}).get(variant, {})
    if not ov:
        if variant.startswith("Vf"):
            return "V_f = " + variant[2:]
        return "defaults" if not variant else variant
    return ", ".join("%s = %s" % (k.split(".")[-1] if "amplitude" in k else k, v)
                     for k, v in ov.items()).replace("amplitude_over_c0", "V_f")


def sens_value(param, v):
    return v if isinstance(v, str) else "%g" % v


def base_value(p, param):
    """The value of `param` in the run the sensitivity study of problem p starts from."""
    ov = p.get("variant_overrides", {}).get(p.get("sensitivity_variant", ""), {})
    if param in ov:
        try:
            return float(ov[param])
        except ValueError:
            return ov[param]
    return DEFAULTS[param]


def base_run(runs, key, p):
    return mid_run(runs, key, p["sensitivity_dx"], p.get("sensitivity_variant",
                                                          p["variants"][0]))


def sensitivity_section(key, p, runs):
    params = list(p.get("sensitivity", {}).keys())
    if not params:
        return []
    variant = p.get("sensitivity_variant", p["variants"][0])
    base = base_run(runs, key, p)
    L = ["### %s — at %d per thickness (dx = %s)%s" % (
        p["title"], int(round(p["thickness"] / p["sensitivity_dx"])), g(p["sensitivity_dx"], 4),
        (", starting from the %s ladder run" % variant_label(p, variant))
        if p.get("variant_overrides", {}).get(variant) else ""), ""]
    cols = COLUMNS[key]
    rows = []
    for param in params:
        rs = sensitivity(runs, key, param)
        if base:
            rs = sorted(rs + [dict(base, param=param, value=base_value(p, param), _default=True)],
                        key=lambda r: r["value"])
        for r in rs:
            rows.append(["%s = %s%s" % (PARAM_NAME[param], sens_value(param, r["value"]),
                                        " (ladder run)" if r.get("_default") else ""),
                         f3(r.get("neighbours_mean"), 1), r.get("steps") or "-",
                         g(r.get("dt"), 3), f3(r.get("wall_seconds"), 1), outcome(r),
                         g(r.get("hourglass_work_min"), 2)] + [fn(r) for _, fn in cols])
    cross = sorted([r for r in runs if r["problem"] == key and r["kind"] == "cross"],
                   key=lambda r: sorted(r["value"].items()))
    for r in cross:
        rows.append([", ".join("%s = %g" % (k, v) for k, v in r["value"].items()),
                     f3(r.get("neighbours_mean"), 1), r.get("steps") or "-",
                     g(r.get("dt"), 3), f3(r.get("wall_seconds"), 1), outcome(r),
                     g(r.get("hourglass_work_min"), 2)] + [fn(r) for _, fn in cols])
    L += table(["setting", "mean nb", "steps", "dt [s]", "wall s", "outcome", "hg work min"] +
               [h for h, _ in cols], rows)
    L.append("")
    for r in runs:
        if r["problem"] == key and r["kind"] != "ladder" and r.get("stderr"):
            msg = r["stderr"].strip().splitlines()[-1] if r["stderr"].strip() else ""
            L.append("- `%s`: %s" % (r["id"], msg.replace(str(Path(__file__).resolve().parent
                                                              .parent) + "/", "")))
    if any(r["problem"] == key and r["kind"] != "ladder" and r.get("stderr") for r in runs):
        L.append("")
    return L


def defaults_section(P, runs):
    L = ["## Chosen defaults", ""]
    L.append("The runner does not choose; it lists the numbers "
             "that bear on `kernel.support`, `kernel.correction`, `hourglass.alpha` and "
             "`time.cfl` (one parameter varied at a time, at each problem's sensitivity "
             "resolution; headline error in %, `unstable` = exit status 4, `(!)` = energy grows "
             "by more than 1 %, wall time in s in brackets, `*` = the ladder run the study "
             "starts from).")
    L.append("")
    for param in ("kernel.support", "kernel.correction", "hourglass.alpha", "time.cfl",
                  "static.tolerance"):
        studied = [(key, p) for key, p in P.items() if param in p.get("sensitivity", {})]
        if not studied:
            continue
        values = sorted({r["value"] for r in runs if r["kind"] == "sensitivity" and
                         r["param"] == param} | {base_value(p, param) for _, p in studied})
        rows = []
        for key, p in studied:
            base = base_run(runs, key, p)
            cells = []
            for v in values:
                star = ""
                if v == base_value(p, param):
                    r, star = base, "*"
                else:
                    r = next((x for x in sensitivity(runs, key, param) if x["value"] == v), None)
                if r is None:
                    cells.append("")
                    continue
                q = r.get("qoi")
                if q and r.get("outcome") != "unstable":
                    cells.append("%s%s [%s]" % (err(r, q["primary"]), star,
                                                f3(r.get("wall_seconds"), 0)))
                else:
                    cells.append("%s%s [%s]" % (outcome(r), star, f3(r.get("wall_seconds"), 0)))
            label = p["title"].split(",")[0] + (" (%s)" % key)
            sv = p.get("sensitivity_variant", "")
            if p.get("variant_overrides", {}).get(sv):
                label += ", from " + variant_label(p, sv)
            rows.append([label] + cells)
        L.append("**%s**" % PARAM_NAME[param])
        L.append("")
        L += table(["problem"] + [sens_value(param, v) + (" (default)" if v == DEFAULTS[param]
                                                          else "") for v in values], rows)
        L.append("")
    decision = Path(__file__).resolve().parent / "defaults.md"
    L += decision.read_text().rstrip("\n").split("\n") if decision.exists() else [
        "> (no validation/defaults.md: the decision is not written down)"]
    L.append("")
    return L


def cuts_section(P, runs):
    L = ["## What was cut to keep the ladder near 30 minutes on 2 cores", ""]
    L.append("- Sensitivity studies run at one resolution per problem (the second of its "
             "ladder), one parameter at a time.")
    L.append("- The 3D dynamic cantilever's study has only alpha 3, the linear correction and "
             "CFL 0.4, from its alpha = 1 ladder run (each run costs about a minute; the static "
             "cantilever, same beam, has the full study). CSM3's has support 2.5 and 3.0, alpha "
             "0 and 50, CFL 0.4 and the linear correction (CSM1, same beam, has the full "
             "study).")
    L.append("- alpha = 100 is not run for the 3D static cantilever (with a stiff penalty "
             "kinetic damping needs ten times the steps: 2-3 minutes a run; alpha 50 there "
             "shows the trend).")
    L.append("- CFL 0.1 only on the oscillating plate (alone, and with alpha 50 and 100, to tell "
             "a time-step limit from an instability of the equations); for a static problem "
             "the step changes only the path to equilibrium, and CFL 0.4, 0.5 and 0.6 show that "
             "below the limit the step does not change the results.")
    L.append("- CSM3 is simulated to 3.0 s (about 3.3 periods; the window after the first "
             "period holds about 2.3 periods) rather than 4 periods or more.")
    L.append("- The static scenes stop at a residual of 1e-5 (the sensitivity tables show "
             "1e-4, the program's default, and 1e-6).")
    L.append("- Ladders: the static cantilever stops at 12 particles through the section (16, "
             "about 42k particles and 4-8 minutes, is not needed: the error is below the "
             "target from 8 on), the dynamic cantilever at 10 (and at 8 for the default "
             "settings, which go unstable), the clamped plate at 8 through its thickness.")
    L.append("")
    return L


# --------------------------------------------------------------------------------------------
# Plots


def _minor_label(v, digits):
    """A minor tick label on a log axis for the leading digits given ('0.3', '20'), else ''."""
    text = "%g" % v
    lead = text.lstrip("0.")
    return text if lead and lead[0] in digits else ""


def make_plots(data, report_dir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    runs, R, P = data["runs"], data["references"], data["problems"]
    out = []
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]

    # 1. error against wall time
    fig, ax = plt.subplots(figsize=(8.5, 6))
    for i, (key, p) in enumerate(P.items()):
        for j, variant in enumerate(p["variants"]):
            lad = [r for r in ladder(runs, key, variant)
                   if primary_error(r) is not None and r.get("wall_seconds")]
            if not lad:
                continue
            x = [r["wall_seconds"] for r in lad]
            y = [max(abs(primary_error(r)), 1e-3) for r in lad]
            label = p["title"].split(",")[0].split(" (")[0] + (" " + variant if variant else "")
            label += " [%s]" % (lad[0]["qoi"]["primary"])
            ax.loglog(x, y, "o-" if j == 0 else "s--", color=colours[i % len(colours)],
                      label=label)
            for r, xx, yy in zip(lad, x, y):
                ax.annotate("%d" % r["per_thickness"], (xx, yy), textcoords="offset points",
                            xytext=(4, 4), fontsize=7, color=colours[i % len(colours)])
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: _minor_label(v, "25")))
    ax.tick_params(axis="y", which="minor", labelsize=7)
    ax.set_xlabel("wall time of the run [s] (2 cores)")
    ax.set_ylabel("|error| against the reference [%]")
    ax.set_title("Error against run time (labels: particles through the thickness)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7.5, loc="best")
    fig.tight_layout()
    fig.savefig(report_dir / "error_vs_wall_time.png", dpi=110)
    plt.close(fig)
    out.append(("error_vs_wall_time.png",
                "headline |error| of each problem against the wall time of the run, one point "
                "per resolution (labelled by particles through the thickness). The clamped "
                "plate's error is against Kirchhoff, which a/t = 10 plate does not follow "
                "(see the Mindlin line in the next plot)."))

    # 2. error against dx, with the fitted slope
    keys = list(P.keys())
    fig, axes = plt.subplots(2, 3, figsize=(13, 8))
    for ax, key in zip(axes.flat, keys):
        p = P[key]
        for k, (name, _, against) in enumerate(CONVERGENCE[key][:2]):
            for j, variant in enumerate(p["variants"]):
                lad = [r for r in ladder(runs, key, variant)
                       if (r.get("qoi") or {}).get("errors", {}).get(name) is not None]
                if len(lad) < 2:
                    continue
                h = np.array([r["dx"] for r in lad])
                signed = np.array([r["qoi"]["errors"][name] for r in lad])
                e = np.maximum(np.abs(signed), 1e-4)
                colour = colours[(2 * k + j) % len(colours)]
                if np.all(signed > 0) or np.all(signed < 0):
                    slope = "slope %.2f" % np.polyfit(np.log(h), np.log(e), 1)[0]
                else:
                    slope = "sign change, no slope"
                ls = (":" if k else "-") if j == 0 else "--"
                ax.loglog(h, e, ls, color=colour,
                          label="%s%s: %s" % (error_label(name, against),
                                              (" " + variant_label(p, variant))
                                              if len(p["variants"]) > 1 else "", slope))
                marker = "o^sD"[(2 * k + j) % 4]
                pos = signed > 0
                ax.plot(h[pos], e[pos], marker, color=colour, ls="none")
                ax.plot(h[~pos], e[~pos], marker, color=colour, ls="none", mfc="white")
        tgt = p.get("target")
        if tgt:
            ax.axhline(tgt[1], color="grey", ls="--", lw=0.8)
            ax.text(ax.get_xlim()[0], tgt[1], " target %g %%" % tgt[1], fontsize=7,
                    va="bottom", color="grey")
        ax.set_title(p["title"].split(",")[0].split(" (")[0] + " — " + p["qoi"], fontsize=9)
        # label the ladder's dx values themselves, in plain numbers
        dxs = sorted({r["dx"] for r in ladder(runs, key)})
        ax.xaxis.set_major_locator(FixedLocator(dxs))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%.3g" % v))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: _minor_label(v, "235")))
        ax.tick_params(axis="both", which="both", labelsize=7)
        ax.set_xlabel("dx [m]")
        ax.set_ylabel("|error| [%]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(report_dir / "error_vs_dx.png", dpi=110)
    plt.close(fig)
    out.append(("error_vs_dx.png",
                "|error| against dx for each problem, with the least-squares slope over the "
                "ladder (the observed order); filled markers: error > 0, open: error < 0 "
                "(where the sign changes no slope is fitted). Where two references are shown, the second is "
                "the better model of the same problem (Timoshenko for the plate and the "
                "cantilever frequency, the 3D FEM for the static cantilever, Mindlin for the "
                "clamped plate); for CSM1 the vector error and u_y."))

    # 3. time histories
    def hist_runs(key, variant=None):
        return [r for r in ladder(runs, key, variant) if r.get("history")]


    op = R["oscillating_plate"]
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for ax, variant, vf in zip(axes, ("Vf0.01", "Vf0.001"), (0.01, 0.001)):
        for i, r in enumerate(hist_runs("oscillating_plate", variant)):
            hst = r["history"]
            t = np.array(hst["time"])
            u = np.array([np.nan if v is None else v for v in hst["tip_uy"]])
            ax.plot(t, u * MM, color=colours[i], lw=1.2,
                    label="%d per thickness (T error %s %%)" % (r["per_thickness"],
                                                                err(r, "period")))
        tt = np.linspace(0, 0.8, 800)
        amp = vf * op["c0"] / op["omega"]
        ax.plot(tt, amp * np.sin(op["omega"] * tt) * MM, "k--", lw=1,
                label="thin-plate mode, T = %.4f s, amplitude V_f c0/omega" % op["period"])
        ax.set_ylabel("tip u_y [mm]")
        ax.set_title("Oscillating plate, V_f = %g" % vf, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7.5, loc="lower left")
    axes[-1].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(report_dir / "history_oscillating_plate.png", dpi=110)
    plt.close(fig)
    out.append(("history_oscillating_plate.png",
                "tip transverse displacement against time, all resolutions, with the thin-plate "
                "reference (a sine of the reference period whose amplitude is the initial tip "
                "speed over omega)."))

    c = R["cantilever"]
    fig, ax = plt.subplots(figsize=(9, 4.5))
    pc = P["cantilever_dynamic"]
    for i, r in enumerate(hist_runs("cantilever_dynamic")):
        hst = r["history"]
        t = np.array(hst["time"])
        u = np.array([np.nan if v is None else v for v in hst["tip_uz"]])
        ax.plot(t, -u * MM, color=colours[i], lw=1.2 if r["variant"] else 0.8,
                ls="-" if r["variant"] else ":",
                label="%s, %d per thickness: %s" % (
                    variant_label(pc, r["variant"]), r["per_thickness"],
                    "f error %s %%" % err(r, "frequency") if r.get("qoi") else outcome(r)))
    tt = np.linspace(0, 1.9, 800)
    d = c["tip_timoshenko"]
    ax.plot(tt, d * (1 - np.cos(2 * np.pi * c["f_timoshenko"] * tt)) * MM, "k--", lw=1,
            label="one-mode reference: static Timoshenko w (1 - cos 2 pi f t), f = %.4f Hz"
                  % c["f_timoshenko"])
    ax.set_ylim(-5, 55)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("tip deflection -u_z [mm]")
    ax.set_title("Cantilever, gravity applied suddenly", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper center", ncol=2)
    fig.tight_layout()
    fig.savefig(report_dir / "history_cantilever_dynamic.png", dpi=110)
    plt.close(fig)
    out.append(("history_cantilever_dynamic.png",
                "tip deflection against time, all resolutions (an unstable run stops where "
                "its record ends; the axis is clipped), with the one-mode reference."))

    cs = R["csm3"]
    fig, axes = plt.subplots(2, 1, figsize=(11.5, 7), sharex=True)
    for ax, comp in zip(axes, ("ux", "uy")):
        mean, amp = cs[comp + "_mean"], cs[comp + "_amp"]
        ax.axhspan((mean - amp) * MM, (mean + amp) * MM, color="0.9",
                   label="reference mean +- amplitude")
        ax.axhline(mean * MM, color="k", ls="--", lw=0.8)
        ax.axhline((mean - amp) * MM, color="k", ls=":", lw=0.8)
        ax.axhline((mean + amp) * MM, color="k", ls=":", lw=0.8)
        for i, r in enumerate(hist_runs("csm3")):
            hst = r["history"]
            t = np.array(hst["time"])
            u = np.array([np.nan if v is None else v for v in hst["A_" + comp]])
            ax.plot(t, u * MM, color=colours[i], lw=1.1,
                    label="%d per thickness (f error %s %%)" % (r["per_thickness"],
                                                                err(r, "frequency")))
        ax.axvline(1 / 1.0995, color="grey", lw=0.8)
        ax.set_ylabel("point A u_%s [mm]" % comp[1])
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7.5, loc="center left", bbox_to_anchor=(1.01, 0.5))
    axes[0].set_title("Turek-Hron CSM3 (the window for mean, amplitude and frequency starts at "
                      "the grey line)", fontsize=10)
    axes[-1].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(report_dir / "history_csm3.png", dpi=110)
    plt.close(fig)
    out.append(("history_csm3.png",
                "point A displacement against time, all resolutions, with the reference band "
                "mean +- amplitude (dashed: mean; dotted: the extremes)."))

    # 4. sensitivities
    # The clamped plate is shown against Mindlin (its Kirchhoff error is mostly the model's).
    # CSM1 by the magnitude of u_y (its headline, a vector norm, has no sign).
    plot_error = {"clamped_plate": "w_vs_mindlin", "csm1": "uy"}
    plot_sign = {"csm1": -1.0}
    plot_label = {"clamped_plate": " (w vs Mindlin)", "csm1": " (abs(u_y))"}

    def sens_error(r, key):
        q = r.get("qoi")
        e = q["errors"].get(plot_error.get(key, q["primary"])) if q else None
        return None if e is None else plot_sign.get(key, 1.0) * e

    params = ["kernel.support", "hourglass.alpha", "time.cfl"]
    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    for ax, param in zip(axes, params):
        k = 0
        for i, (key, p) in enumerate(P.items()):
            if param not in p.get("sensitivity", {}):
                continue
            colour = colours[i % len(colours)]
            base = base_run(runs, key, p)
            rs = sensitivity(runs, key, param) + ([dict(base, value=base_value(p, param))]
                                                  if base else [])
            rs = sorted(rs, key=lambda r: r["value"])
            good = [r for r in rs if sens_error(r, key) is not None and
                    r.get("outcome") != "unstable" and not r.get("energy_growth")]
            label = key + plot_label.get(key, "")
            sv = p.get("sensitivity_variant", "")
            if p.get("variant_overrides", {}).get(sv):
                label += " (" + variant_label(p, sv) + ")"
            ax.plot([r["value"] for r in good], [sens_error(r, key) for r in good], "o-",
                    color=colour, label=label)
            # failed runs: a cross (unstable or energy growth) or a triangle (set-up error)
            # at the bottom of the axis, staggered per problem so none hides another
            yb = -26 - 1.6 * k
            k += 1
            for r in rs:
                if r.get("outcome") == "unstable" or r.get("energy_growth"):
                    ax.plot([r["value"]], [yb], "x", color=colour, ms=8, mew=2)
                elif r.get("rc") == 1:
                    ax.plot([r["value"]], [yb], "v", color=colour, ms=7, mfc="white")
        ax.axvline(DEFAULTS[param], color="grey", lw=0.8, ls="--")
        ax.axhline(0, color="k", lw=0.6)
        if param == "hourglass.alpha":
            ax.set_xscale("symlog", linthresh=1.0)
            ax.set_xlim(-0.3, 130)
        ax.set_ylim(-36, 40)
        ax.set_xlabel(param)
        ax.set_ylabel("headline error [%]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    fig.suptitle("Sensitivities at each problem's middle resolution; below -25 %: x = unstable "
                 "or energy grows, triangle = set-up error", fontsize=10)
    fig.tight_layout()
    fig.savefig(report_dir / "sensitivity.png", dpi=110)
    plt.close(fig)
    out.append(("sensitivity.png",
                "signed headline error against each parameter at the sensitivity resolution "
                "(dashed line: the default; the clamped plate against Mindlin, CSM1 by the "
                "magnitude of u_y). For deflections and periods a positive error means too "
                "soft, for frequencies too stiff. Runs that went "
                "unstable or gained energy (x) and set-up errors (triangles) are marked in the "
                "band below -25 %, one row per problem."))
    return out
