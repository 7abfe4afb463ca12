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


def plateau(e1, e2, h1, h2):
    """The error levels off: it keeps its sign and falls at an observed order below 1/2
    between the two finest resolutions while above 0.05 %: refinement does not remove it."""
    o = order(e1, e2, h1, h2)
    return o is not None and o < 0.5 and abs(e2) > 0.05


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


def is_newton(r):
    """A static run made with the Newton solver (a primary or a twin)."""
    return r.get("solver") == "newton"


def is_twin(r):
    """A static ladder run's twin: the same run with the other solver (run.py; records before
    the solver reversal had no `twin` field and their twins were the Newton runs)."""
    if "twin" in r:
        return bool(r["twin"])
    return is_newton(r)


def ladder(runs, key, variant=None, solver=None):
    """Ladder runs of a problem, coarse to fine; variant None = all variants. solver None: the
    primary runs (the scene's solver: every table but the solver comparison); "damped" or
    "newton": the runs with that solver, primaries or twins (skipped ones included)."""
    out = [r for r in runs if r["problem"] == key and r["kind"] == "ladder" and
           (variant is None or r["variant"] == variant) and
           (not is_twin(r) if solver is None else r.get("solver") == solver)]
    return sorted(out, key=lambda r: -r["dx"])


def variant_study(p, variant):
    """(param, value) when a ladder variant differs from the sensitivity variant in one
    parameter of the studies (the cantilevers' alpha 1 and 30 ladders), else None."""
    ov = p.get("variant_overrides", {})
    base, mine = ov.get(p.get("sensitivity_variant", ""), {}), ov.get(variant, {})
    diff = {k: v for k, v in mine.items() if base.get(k) != v}
    if len(diff) != 1 or set(base) - set(mine):
        return None
    (k, v), = diff.items()
    if k not in p.get("sensitivity", {}):
        return None
    try:
        return k, float(v)
    except ValueError:
        return k, v


def sensitivity(runs, key, param, p=None):
    """The runs of a sensitivity study: its own runs, and (given the problem p) the ladder
    runs of variants that are one of its values at the sensitivity resolution (not run
    twice)."""
    out = [r for r in runs if r["problem"] == key and r["kind"] == "sensitivity" and
           r["param"] == param]
    if p is not None:
        for r in runs:
            if (r["problem"] == key and r["kind"] == "ladder" and not is_newton(r) and
                    abs(r["dx"] - p["sensitivity_dx"]) < 1e-12):
                vs = variant_study(p, r["variant"])
                if vs and vs[0] == param:
                    out.append(dict(r, param=param, value=vs[1], _variant_run=True))
    return sorted(out, key=lambda r: r["value"])


def mid_run(runs, key, dx, variant, study=False):
    """The ladder run of a variant at dx: the primary, or (study) the one with the sensitivity
    studies' solver (damped: the static problems' studies keep it), their baseline."""
    for r in runs:
        if (r["problem"] == key and r["kind"] == "ladder" and abs(r["dx"] - dx) < 1e-12 and
                r["variant"] == variant and (not is_newton(r) if study else not is_twin(r))):
            return r
    return None


DEFAULTS = {"kernel.support": 2.1, "kernel.correction": "quadratic",
            "kernel.quadrature": "taylor", "hourglass.alpha": 10.0,
            "hourglass.form": "energy", "hourglass.gradient": "corrected",
            "clamp.method": "mirror", "time.cfl": 0.3, "static.tolerance": 1e-5}
PARAM_NAME = {"kernel.support": "kernel.support (H/dx)", "kernel.correction": "kernel.correction",
              "kernel.quadrature": "kernel.quadrature",
              "hourglass.alpha": "hourglass.alpha", "hourglass.form": "hourglass.form",
              "hourglass.gradient": "hourglass.gradient",
              "clamp.method": "clamp method (every [clamp.NAME])",
              "time.cfl": "time.cfl", "static.tolerance": "static.tolerance"}
STUDIES = ["kernel.support", "kernel.correction", "kernel.quadrature", "hourglass.alpha",
           "hourglass.form",
           "hourglass.gradient", "clamp.method", "time.cfl", "static.tolerance"]

# Per problem: value columns of the ladder table: (header, function of a run -> text).
MM = 1000.0


def _mm(name, digits=3):
    return lambda r: f3(val(r, name) * MM if val(r, name) is not None else None, digits)


def _lame_columns(at, extra, u="u"):
    """The bore's displacement and stresses of a Lame problem, read at `at`, then `extra`."""
    return [
        ("%s%s [mm]" % (u, at), _mm("u_a", 6)),
        ("%s%s error %%" % (u, at), lambda r: err(r, "u_a")),
        ("sigma_tt%s [MPa]" % at, lambda r: f3(val(r, "stt_a") / 1e6
                                               if val(r, "stt_a") is not None else None, 2)),
        ("sigma_tt%s error %%" % at, lambda r: err(r, "stt_a")),
        ("sigma_rr%s error %%" % at, lambda r: err(r, "srr_a")),
        ("sigma_tt%s recovered [MPa]" % at, lambda r: f3(val(r, "stt_s") / 1e6
                                                         if val(r, "stt_s") is not None
                                                         else None, 2)),
        ("its error %", lambda r: err(r, "stt_s")),
        ("(a, 0) / (0, a) %", lambda r: "%s / %s" % (err(r, "stt_s_x"), err(r, "stt_s_y"))),
    ] + extra


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
        ("tip w [mm]", _mm("tip", 4)),
        ("error vs FEM %", lambda r: err(r, "tip_vs_fem")),
        ("vs FEM finest mesh %", lambda r: err(r, "tip_vs_fem_finest")),
        ("vs Timoshenko %", lambda r: err(r, "tip")),
        ("extrapolated w [mm]", _mm("tip_extrapolated")),
        ("its error vs FEM %", lambda r: err(r, "tip_extrapolated_vs_fem")),
    ],
    "cantilever_dynamic": [
        ("f [Hz]", lambda r: f3(val(r, "frequency"), 4)),
        ("f vs Timoshenko %", lambda r: err(r, "frequency")),
        ("f vs Euler-Bernoulli %", lambda r: err(r, "frequency_vs_euler_bernoulli")),
        ("mean w [mm]", _mm("mean_deflection")),
        ("w vs Timoshenko %", lambda r: err(r, "mean_deflection")),
        ("w vs FEM %", lambda r: err(r, "mean_deflection_vs_fem")),
        ("w vs static, same dx %", lambda r: f3(r.get("_vs_static"), 2, signed=True)),
        ("time-averaged w vs static %", lambda r: f3(r.get("_avg_vs_static"), 3, signed=True)),
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
        ("w [mm]", _mm("w", 4)),
        ("error vs FEM %", lambda r: err(r, "w_vs_fem")),
        ("vs FEM finest mesh %", lambda r: err(r, "w_vs_fem_finest")),
        ("vs Mindlin %", lambda r: err(r, "w_vs_mindlin")),
        ("vs Kirchhoff %", lambda r: err(r, "w")),
    ],
    "cantilever_large": [
        ("tip u_z [mm]", _mm("tip_uz", 2)),
        ("error vs FEM %", lambda r: err(r, "tip_uz")),
        ("tip u_x [mm]", _mm("tip_ux", 2)),
        ("u_x vs FEM %", lambda r: err(r, "tip_ux")),
        ("extrapolated: u_z %", lambda r: err(r, "tip_uz_extrapolated")),
        ("u_x %", lambda r: err(r, "tip_ux_extrapolated")),
    ],
    "cook_membrane": [
        ("corner u_y [mm]", _mm("corner_uy", 5)),
        ("error vs FEM %", lambda r: err(r, "corner_uy")),
        ("corner u_x [mm]", _mm("corner_ux", 5)),
        ("u_x vs FEM %", lambda r: err(r, "corner_ux")),
        ("edge midpoint u_y vs FEM %", lambda r: err(r, "edge_mid_uy")),
    ],
    "plate_hole": [
        ("end u_x [mm]", _mm("end_ux", 5)),
        ("error vs FEM %", lambda r: err(r, "end_ux")),
        ("Kt at the hole top (probe)", lambda r: f3(val(r, "kt_top"), 3)),
        ("Kt vs FEM %", lambda r: err(r, "kt_top")),
        ("Kt vs Peterson %", lambda r: err(r, "kt_top_vs_peterson")),
    ],
    "lame_ring": _lame_columns("(a)", [("u(0.075) error %", lambda r: err(r, "u_mid"))]),
    "lame_cylinder": _lame_columns("(a, L/2)", [("u_r(a, 0) error %", lambda r: err(r, "u_end"))],
                                   "u_r"),
    "plate_hole_fitted": [
        ("Kt (node)", lambda r: f3(val(r, "kt_top"), 3)),
        ("Kt vs FEM %", lambda r: err(r, "kt_top")),
        ("Kt (kernel probe) vs FEM %", lambda r: err(r, "kt_top_kernel")),
        ("end u_x [mm]", _mm("end_ux", 5)),
        ("end u_x vs FEM %", lambda r: err(r, "end_ux")),
    ],
    "bracket": [
        ("u_x(P) [mm]", _mm("ux_P", 5)),
        ("u_x error vs FEM %", lambda r: err(r, "ux_P")),
        ("u_z(P) [mm]", _mm("uz_P", 5)),
        ("u_z error vs FEM %", lambda r: err(r, "uz_P")),
    ],
}
COLUMNS["cook_membrane_incompressible"] = COLUMNS["cook_membrane"]


def _lame_free_columns(at, extra, u="u"):
    """The free (textbook) Lame problems: the 32 bore nodes' mean and worst, then `extra`,
    then the Newton run's peak memory (these problems have no damped twin, so no solver
    table)."""
    return [
        ("mean %s%s [mm]" % (u, at), _mm("u_a", 6)),
        ("its error %", lambda r: err(r, "u_a")),
        ("worst node's abs. error %", lambda r: f3((r.get("qoi") or {}).get("errors", {})
                                                    .get("u_a_worst"), 2)),
        ("mean sigma_tt%s recovered [MPa]" % at, lambda r: f3(val(r, "stt_s") / 1e6
                                                              if val(r, "stt_s") is not None
                                                              else None, 2)),
        ("its error %", lambda r: err(r, "stt_s")),
        ("worst node's abs. error %", lambda r: f3((r.get("qoi") or {}).get("errors", {})
                                                    .get("stt_s_worst"), 2)),
        ("sigma_rr%s recovered error %%" % at, lambda r: err(r, "srr_s")),
    ] + extra + [
        ("largest particle-probe angle [deg]", lambda r: f3(val(r, "angle_offset_max_deg"),
                                                            2)),
        ("Newton peak memory", lambda r: mem(r.get("peak_rss_mb"))),
    ]


COLUMNS["lame_ring_free"] = _lame_free_columns("(a)", [])
COLUMNS["lame_cylinder_free"] = _lame_free_columns(
    "(a, L/2)", [("u_r(a, 0) error %", lambda r: err(r, "u_end"))], "u_r")


def _s(x):
    return None if x is None else x * MM


# Errors whose convergence is tabulated (primary first), and the value they are errors of.
CONVERGENCE = {
    "oscillating_plate": [("period", "period", "thin plate"),
                          ("period_vs_timoshenko", "period", "Timoshenko")],
    "cantilever_static": [("tip_vs_fem", "tip", "FEM"), ("tip", "tip", "Timoshenko")],
    "cantilever_dynamic": [("frequency", "frequency", "Timoshenko"),
                           ("time_average_deflection_vs_fem", "time_average_deflection", "FEM"),
                           ("mean_deflection_vs_fem", "mean_deflection", "FEM"),
                           ("frequency_vs_euler_bernoulli", "frequency", "Euler-Bernoulli"),
                           ("mean_deflection", "mean_deflection", "Timoshenko")],
    "csm1": [("displacement", None, "Turek-Hron"), ("uy", "uy", "Turek-Hron"),
             ("ux", "ux", "Turek-Hron")],
    "csm3": [("frequency", "frequency", "Turek-Hron"), ("uy_amp", "uy_amp", "Turek-Hron"),
             ("uy_mean", "uy_mean", "Turek-Hron")],
    "clamped_plate": [("w_vs_fem", "w", "FEM"), ("w_vs_mindlin", "w", "Mindlin"),
                      ("w", "w", "Kirchhoff")],
    "cantilever_large": [("tip_uz", "tip_uz", "FEM"), ("tip_ux", "tip_ux", "FEM")],
    "cook_membrane": [("corner_uy", "corner_uy", "FEM"), ("corner_ux", "corner_ux", "FEM"),
                      ("edge_mid_uy", "edge_mid_uy", "FEM")],
    "cook_membrane_incompressible": [("corner_uy", "corner_uy", "FEM"),
                                     ("corner_ux", "corner_ux", "FEM"),
                                     ("edge_mid_uy", "edge_mid_uy", "FEM")],
    "plate_hole": [("end_ux", "end_ux", "FEM"), ("kt_top", "kt_top", "FEM"),
                   ("kt_top_vs_peterson", "kt_top", "Peterson")],
    "lame_ring": [("u_a", "u_a", "Lame"), ("stt_s", "stt_s", "Lame"), ("stt_a", "stt_a", "Lame")],
    "lame_cylinder": [("u_a", "u_a", "FEM"), ("stt_s", "stt_s", "FEM"), ("stt_a", "stt_a", "FEM"),
                      ("u_end", "u_end", "FEM")],
    "plate_hole_fitted": [("kt_top", "kt_top", "FEM"), ("end_ux", "end_ux", "FEM"),
                          ("kt_top_kernel", "kt_top_kernel", "FEM")],
    "bracket": [("ux_P", "ux_P", "FEM"), ("uz_P", "uz_P", "FEM")],
    "lame_ring_free": [("stt_s_worst", None, "Lame"), ("u_a", "u_a", "Lame"),
                       ("stt_s", "stt_s", "Lame"), ("u_a_worst", None, "Lame")],
    "lame_cylinder_free": [("stt_s_worst", None, "Lame"), ("u_a", "u_a", "Lame"),
                           ("stt_s", "stt_s", "Lame"), ("u_a_worst", None, "Lame"),
                           ("u_end", "u_end", "Lame")],
}
# Secondary errors shown in the summary (label, error name).
SUMMARY_EXTRA = {
    "oscillating_plate": [("T vs Timoshenko", "period_vs_timoshenko")],
    "cantilever_static": [("w vs Timoshenko", "tip")],
    "cantilever_dynamic": [("mean w vs Timoshenko", "mean_deflection"),
                           ("vs FEM", "mean_deflection_vs_fem"), ("vs static", "_vs_static"),
                           ("time-averaged w vs static", "_avg_vs_static")],
    "csm1": [("u_x", "ux"), ("u_y", "uy")],
    "csm3": [("u_y mean", "uy_mean"), ("u_y amp", "uy_amp")],
    "clamped_plate": [("vs Mindlin", "w_vs_mindlin"), ("vs Kirchhoff", "w")],
    "cantilever_large": [("u_x vs FEM", "tip_ux")],
    "cook_membrane": [("u_x vs FEM", "corner_ux"), ("mid-edge u_y vs FEM", "edge_mid_uy")],
    "cook_membrane_incompressible": [("u_x vs FEM", "corner_ux"),
                                     ("mid-edge u_y vs FEM", "edge_mid_uy")],
    "plate_hole": [("Kt (probe) vs FEM", "kt_top"), ("vs Peterson", "kt_top_vs_peterson")],
    "lame_ring": [("sigma_tt(a) vs Lame", "stt_a"), ("recovered", "stt_s")],
    "lame_cylinder": [("sigma_tt(a, L/2) vs FEM", "stt_a"), ("recovered", "stt_s")],
    "plate_hole_fitted": [("end u_x vs FEM", "end_ux")],
    "bracket": [("u_z(P) vs FEM", "uz_P")],
    "lame_ring_free": [("mean u(a)", "u_a"), ("worst node's u(a), abs.", "u_a_worst"),
                       ("mean sigma_tt(a)", "stt_s")],
    "lame_cylinder_free": [("mean u_r(a)", "u_a"), ("worst node's u_r(a), abs.", "u_a_worst"),
                           ("mean sigma_tt(a)", "stt_s"), ("u_r(a, 0)", "u_end")],
}
# The quantity an error is of, for legends and tables.
ERROR_SYMBOL = {"period": "T", "period_vs_timoshenko": "T", "tip": "w", "tip_vs_fem": "w",
                "frequency": "f", "frequency_vs_euler_bernoulli": "f", "displacement": "abs(u)",
                "uy": "u_y", "ux": "u_x", "uy_amp": "u_y amplitude", "uy_mean": "u_y mean",
                "w": "w", "w_vs_mindlin": "w", "w_vs_fem": "w",
                "mean_deflection": "(max+min)/2 w", "mean_deflection_vs_fem": "(max+min)/2 w",
                "time_average_deflection_vs_fem": "time-averaged w",
                "tip_uz": "tip u_z", "tip_ux": "tip u_x", "corner_uy": "corner u_y",
                "corner_ux": "corner u_x", "edge_mid_uy": "mid-edge u_y", "end_ux": "end u_x",
                "kt_top": "Kt (probe)", "kt_top_vs_peterson": "Kt (probe)",
                "u_a": "u(a)", "stt_a": "sigma_tt(a)", "kt_top_kernel": "Kt (kernel probe)",
                "ux_P": "u_x(P)", "uz_P": "u_z(P)",
                "stt_s_worst": "worst-node sigma_tt(a)", "u_a_worst": "worst-node u(a)"}


# Errors of displacement components taken along the reference's direction (run.py
# pct_along): positive = larger than the reference in its own direction.
ALONG = {"tip_uz", "tip_ux", "corner_uy", "corner_ux", "edge_mid_uy", "end_ux", "ux_P", "uz_P"}


PRIMARY_AGAINST = {"oscillating_plate": "thin plate", "cantilever_static": "FEM",
                   "cantilever_dynamic": "Timoshenko", "csm1": "Turek-Hron",
                   "csm3": "Turek-Hron", "clamped_plate": "FEM", "cantilever_large": "FEM",
                   "cook_membrane": "FEM", "cook_membrane_incompressible": "FEM",
                   "plate_hole": "FEM", "lame_ring": "Lame", "lame_cylinder": "FEM",
                   "plate_hole_fitted": "FEM",
                   "bracket": "FEM", "lame_ring_free": "Lame", "lame_cylinder_free": "Lame"}


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
        ("cantilever_dynamic", "mean_deflection"): c["tip_timoshenko"],
        ("cantilever_dynamic", "mean_deflection_vs_fem"): c["tip_fem"],
        ("cantilever_dynamic", "time_average_deflection_vs_fem"): c["tip_fem"],
        ("clamped_plate", "w"): cp["w_kirchhoff"], ("clamped_plate", "w_vs_mindlin"): cp["w_mindlin"],
        ("clamped_plate", "w_vs_fem"): cp.get("w_fem"),
    }
    cl, ph = R.get("cantilever_large", {}), R.get("plate_hole", {})
    table_.update({
        ("cantilever_large", "tip_uz"): cl.get("tip_uz_fem"),
        ("cantilever_large", "tip_ux"): cl.get("tip_ux_fem"),
        ("plate_hole", "end_ux"): ph.get("end_ux_fem"),
        ("plate_hole", "kt_top"): ph.get("kt_top_fem"),
        ("plate_hole", "kt_top_vs_peterson"): ph.get("kt_peterson"),
        ("plate_hole_fitted", "end_ux"): ph.get("end_ux_fem"),
        ("plate_hole_fitted", "kt_top"): ph.get("kt_top_fem"),
        ("plate_hole_fitted", "kt_top_kernel"): ph.get("kt_top_fem"),
        ("lame_ring", "u_a"): R.get("lame_ring", {}).get("u_a"),
        ("lame_ring", "stt_a"): R.get("lame_ring", {}).get("stt_a"),
        ("lame_ring", "stt_s"): R.get("lame_ring", {}).get("stt_a"),
        ("lame_cylinder", "u_a"): R.get("lame_cylinder", {}).get("u_a"),
        ("lame_cylinder", "stt_a"): R.get("lame_cylinder", {}).get("stt_a"),
        ("lame_cylinder", "stt_s"): R.get("lame_cylinder", {}).get("stt_a"),
        ("lame_cylinder", "u_end"): R.get("lame_cylinder", {}).get("u_end"),
        ("bracket", "ux_P"): R.get("bracket", {}).get("ux_P"),
        ("lame_ring_free", "u_a"): R.get("lame_ring_free", {}).get("u_a"),
        ("lame_ring_free", "stt_s"): R.get("lame_ring_free", {}).get("stt_a"),
        ("lame_cylinder_free", "u_a"): R.get("lame_cylinder_free", {}).get("u_a"),
        ("lame_cylinder_free", "stt_s"): R.get("lame_cylinder_free", {}).get("stt_a"),
        ("lame_cylinder_free", "u_end"): R.get("lame_cylinder_free", {}).get("u_end"),
        ("bracket", "uz_P"): R.get("bracket", {}).get("uz_P"),
    })
    for case in ("cook_membrane", "cook_membrane_incompressible"):
        for k in ("corner_uy", "corner_ux", "edge_mid_uy"):
            table_[(case, k)] = R.get(case, {}).get(k + "_fem")
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


def with_static_comparison(runs):
    """Copies of the runs; each dynamic-cantilever run gets `_vs_static`: its mean tip
    deflection against the static cantilever's tip with the same dx and the same overrides,
    in %, where that static run exists."""
    out = [dict(r) for r in runs]
    static = [r for r in out if r["problem"] == "cantilever_static" and r.get("qoi") and
              not is_twin(r)]

    def settings(r):
        return {k: v for k, v in r["overrides"].items() if k != "static.solver"}

    for r in out:
        if r["problem"] != "cantilever_dynamic" or val(r, "mean_deflection") is None:
            continue
        for s in static:
            if abs(s["dx"] - r["dx"]) < 1e-12 and settings(s) == settings(r):
                w = val(s, "tip")
                if w:
                    r["_vs_static"] = 100.0 * (val(r, "mean_deflection") - w) / w
                    if val(r, "time_average_deflection") is not None:
                        r["_avg_vs_static"] = 100.0 * (val(r, "time_average_deflection") -
                                                       w) / w
                break
    return out


def extra_error(r, name):
    if name.startswith("_"):
        e = r.get(name)
    else:
        e = ((r.get("qoi") or {}).get("errors") or {}).get(name)
    return None if e is None else e


def twin_cell(runs, r, p=None):
    """The summary's last column: at the finest resolution of a static problem, the solver of
    the primary run and the twin's wall time (the other solver), with Newton's speed-up; for
    a problem that has no twins (p's newton.no_twin) the reason."""
    if not r.get("solver"):
        return "-"
    why = ((p or {}).get("newton") or {}).get("no_twin")
    if why:
        return "%s; no twin (%s)" % (r["solver"], why)
    other = "damped" if r["solver"] == "newton" else "newton"
    t = counterpart(runs, r, other)
    if t is None:
        return "%s; no %s twin" % (r["solver"], other)
    if t.get("outcome") == "skipped":
        if t.get("predicted_memory_gb") is None:  # a twin skipped for its run time
            return "%s; %s not run (%s)" % (r["solver"], other, t.get("skipped", ""))
        return "%s; %s not run (memory: %.0f GB predicted)" % (
            r["solver"], other, t.get("predicted_memory_gb") or 0)
    if not converged(t):
        return "%s; %s %s" % (r["solver"], other, t.get("outcome") or str(t.get("rc")))
    d, n = (r, t) if r["solver"] == "damped" else (t, r)
    return "%s; %s %.1f (Newton %s)" % (r["solver"], other, t["wall_seconds"],
                                       x_text(speedup(d, n)))


def target_at_text(p, variant, lad, tgt):
    """The summary's 'met' cell of a problem whose target is held at one resolution of one
    variant (p["target_at"]): every named error within tgt[1] % there."""
    ta = p["target_at"]
    n, tv = ta["per_thickness"], ta.get("variant", "")
    if variant != tv:
        return "- (the target is for %s)" % variant_label(p, tv)
    r = next((x for x in lad if x["per_thickness"] == n), None)
    names = [tgt[0]] + list(ta.get("errors") or [])
    es = [((r or {}).get("qoi") or {}).get("errors", {}).get(k) for k in names]
    if r is None or None in es:
        return "not run at %d through" % n
    ok = all(abs(x) <= tgt[1] for x in es) and not r.get("energy_growth")
    return "%s (at %d through: %s)" % ("yes" if ok else "**no**", n, ", ".join(
        "%s %s" % (k, f3(x, 2, signed=k != tgt[0])) for k, x in zip(names, es)))


def target_lines(p, runs, key):
    """A problem section's statement of a target held at one resolution of one variant."""
    ta, tgt = p.get("target_at"), p.get("target")
    if not ta or not tgt:
        return []
    tv = ta.get("variant", "")
    names = [tgt[0]] + list(ta.get("errors") or [])
    return ["**Target**: %s within %g %% at %d through (%s): %s." % (
        " and ".join("`%s`" % k for k in names), tgt[1], ta["per_thickness"],
        variant_label(p, tv), target_at_text(p, tv, ladder(runs, key, tv), tgt)), ""]


def readme(data, plots, plot_note):
    runs, R, P, meta = data["runs"], data["references"], data["problems"], data["meta"]
    runs = with_static_comparison(runs)
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
        L.append("| binary | built from a clean export of the commit (`git archive %s`); scenes "
                 "and runner from the working tree |" % git.get("commit", "?")[:12])
    at_run = {}
    for r in runs:
        at_run[r.get("git", "?")] = at_run.get(r.get("git", "?"), 0) + 1
    if set(at_run) != {git.get("commit")}:
        L.append("| commit at each run's time | %s (each record's `git`; a reused run keeps the "
                 "state of its own run) |" % ", ".join(
                     "`%s` (%d runs)" % (c, n) for c, n in sorted(at_run.items(),
                                                               key=lambda x: -x[1])))
    L.append("| machine | %s, %s cores; %s |" % (m.get("cpu", "?"), m.get("cores", "?"),
                                                  m.get("platform", "")))
    L.append("| build | `%s/tlsph` (%s) %s |" % (m.get("build_dir", "build"),
                                                   m.get("build_type", "?"),
                                                   m.get("tlsph_version", "")))
    L.append("| threads | OMP_NUM_THREADS=%s, OMP_WAIT_POLICY=%s |" % (
        m.get("threads", "?"), meta.get("omp_wait_policy") or "(default)"))
    reused = sum(1 for r in runs if r.get("reused"))
    skipped = sum(1 for r in runs if r.get("outcome") == "skipped" and
                  r.get("predicted_memory_gb") is not None)
    slow = sum(1 for r in runs if r.get("outcome") == "skipped" and
               r.get("predicted_memory_gb") is None)
    L.append("| runs | %d%s%s, started %s%s |" % (
        len(runs) - skipped - slow, " (and %d Newton runs skipped for their predicted memory, "
        "not run)" % skipped if skipped else "",
        " (and %d damped twins not run for their estimated run time)" % slow if slow else "",
        meta.get("started", "?"),
        "; %d of them reused from an earlier invocation of the same ladder (`--reuse`: same "
        "command, run after the scene file last changed; their wall times are those measured "
        "then)" % reused if reused else ""))
    adopted = [r for r in runs if r.get("adopted_from")]
    if adopted:
        L.append("| adopted runs | %d of the reused runs were adopted from an earlier "
                 "invocation: each record's `adopted_from` has the command it was made with, "
                 "checked at the adoption to equal the current one but for the checkout path "
                 "and the run directory |" % len(adopted))
    L.append("| wall time | %.0f s for all runs (%.1f min), of which the ladders %.0f s "
             "(the static ladders' twins %.0f s of them) and the sensitivity studies "
             "%.0f s |" % (
                 total_wall, total_wall / 60.0,
                 sum(r.get("wall_runner") or 0 for r in runs if r["kind"] == "ladder"),
                 sum(r.get("wall_runner") or 0 for r in runs if r["kind"] == "ladder" and
                     is_twin(r)),
                 sum(r.get("wall_runner") or 0 for r in runs if r["kind"] == "sensitivity")))
    L.append("| command | `%s%s` |" % (
        "OMP_WAIT_POLICY=%s " % meta["omp_wait_policy"] if meta.get("omp_wait_policy") else "",
        meta.get("runner_command", "")))
    # FEM references: this invocation's and those of the earlier ones it was merged with
    fem_rows, seen, mt = [], set(), meta
    while mt:
        fi = mt.get("fem")
        cases = [c for c in (fi or {}).get("cases", []) if c not in seen]
        if cases:
            seen.update(cases)
            fem_rows.append("%s for %s (%s%s)" % (
                "regenerated by validation/fem.py" if fi.get("regenerated") else
                "`%s` as found" % fi.get("references", "validation/fem/references.json"),
                ", ".join(cases), fi.get("note", ""),
                "; no VTU: %s" % ", ".join(fi["missing_vtu"]) if fi.get("missing_vtu") else
                ""))
        mt = mt.get("merged_with")
    if fem_rows:
        L.append("| FEM references | %s |" % "; ".join(fem_rows))
    loads = [x for r in runs for x in (r.get("loadavg") or [])]
    if loads:
        L.append("| load average (1 min) | %.1f to %.1f over the runs (median %.1f) on %s cores: "
                 "the machine was shared with other jobs |" % (
                     min(loads), max(loads), sorted(loads)[len(loads) // 2],
                     m.get("cores", "?")))
    L.append("")
    L.append("The machine was shared with other jobs (load average above), so wall times are "
             "noisy and longer than on an idle machine (each run records the load average "
             "before and after it in `results.json`). Errors are signed: "
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
        if tgt and p.get("target_at"):
            met = target_at_text(p, variant, lad, tgt)
        elif tgt and e is not None:
            met = "yes" if abs(e) <= tgt[1] and not fin.get("energy_growth") else "**no**"
            if fin["dx"] > min(p["ladder"]) + 1e-12:
                met = "- (%s; the target is for %d per thickness)" % (
                    "within" if met == "yes" else "above",
                    int(round(p["thickness"] / min(p["ladder"]))))
        hs = [r["dx"] for r in lad]
        pe = [primary_error(r) for r in lad]
        o = order_text(pe[-2], pe[-1], hs[-2], hs[-1]) if len(lad) >= 2 else "-"
        if len(lad) >= 2 and plateau(pe[-2], pe[-1], hs[-2], hs[-1]):
            o += " (**plateau**)"
            met = "**no** (a plateau)" if met.startswith("yes") else met
        q = fin.get("qoi") or {}
        title = p["title"] + ("" if not variant else ", " + variant_label(p, variant))
        extra = ", ".join("%s %s" % (label, f3(extra_error(fin, name), 2, signed=True))
                          for label, name in SUMMARY_EXTRA.get(key, [])
                          if extra_error(fin, name) is not None)
        rows.append([title, "%s (%s)" % (p["qoi"], error_label(
                         q.get("primary", "-"), PRIMARY_AGAINST.get(key, "reference"))),
                     "%d / %s" % (fin["per_thickness"], g(fin["dx"], 4)),
                     err(fin, q.get("primary", "")) if q else outcome(fin),
                     extra or "-",
                     "%s %%" % tgt[1] if tgt else "-", met, o,
                     "%.1f" % (fin.get("wall_seconds") or 0), twin_cell(runs, fin, p)])
    L += table(["problem", "quantity (error)", "finest: per thickness / dx", "error %",
                "other errors at the finest, %", "target", "met", "order (last pair)",
                "wall s", "static: solver; twin's wall s"], rows)
    L.append("")
    L.append("Details, what limits each target, and the sensitivity studies follow. "
             "Order = observed order of the error against the reference between the two finest "
             "resolutions, `log(e1/e2)/log(dx1/dx2)`; a plateau (the error keeps its sign and "
             "falls at an order below 1/2 while above 0.05 %) fails the target.")
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

    L += solvers_section(P, runs, meta)

    # References
    L += references_section(R)

    # Per problem
    for key, p in P.items():
        L += problem_section(key, p, runs, R)

    L += alpha_spread_section(P, runs)

    # Sensitivities
    L.append("## Sensitivity studies")
    L.append("")
    L.append("One resolution per problem (stated in each heading: the second of its ladder "
             "in 2D, the coarsest in 3D, see 'What was cut'); one setting changed at a time "
             "from the "
             "defaults (support 2.1 dx, quadratic correction, hourglass alpha 10 in the energy "
             "form on the corrected F, mirrored clamps, CFL 0.3, static tolerance 1e-5 in the "
             "validation scenes); the default row is the ladder run, and the cantilevers' "
             "alpha 1 and 30 rows are their ladder variants. The static problems' studies "
             "use the damped solver (`--static.solver=damped`: the CFL study is about the "
             "damped dynamics), so their default row is the ladder's damped run (the twin "
             "where the scene's solver is Newton). `clamp method = fixed` sets "
             "`method = fixed` on every `[clamp.NAME]` of the scene. Exit status 4 "
             "(`unstable`) is a result: the guard's message is quoted under the table. `hg "
             "min` is the smallest value of the `hourglass` column of energies.csv: the "
             "penalty's energy for the energy form (never negative), the textbook force's "
             "work for `hourglass.form = ganzenmueller` (negative when it feeds energy in).")
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


# --------------------------------------------------------------------------------------------
# Static problems: the damped dynamics against Newton (a primary run and its twin, run.py)

TIE = 1.1  # a speed-up within 10 % either way: a tie on the shared machine


def counterpart(runs, r, solver):
    """The ladder run with the same problem, variant and dx as r made with `solver` (r itself
    if it is), or None."""
    if r.get("solver") == solver:
        return r
    for x in runs:
        if (x.get("solver") == solver and x["kind"] == "ladder" and
                x["problem"] == r["problem"] and x["variant"] == r["variant"] and
                abs(x["dx"] - r["dx"]) < 1e-12):
            return x
    return None


def newton_twin(runs, r):
    """The Newton run beside a damped ladder run (its primary or its twin), or None."""
    return counterpart(runs, r, "newton")


def solver_pairs(runs, key, variant):
    """[(damped run, Newton run or None)] of a ladder, coarse to fine (the primaries' sizes;
    a size without a damped run is left out)."""
    out = []
    for r in ladder(runs, key, variant):
        d = counterpart(runs, r, "damped")
        if d is not None:
            out.append((d, counterpart(runs, r, "newton")))
    return out


def has_twins(runs, key):
    return any(is_twin(r) and r["problem"] == key for r in runs)


def primary_solver_of(runs, key):
    """The solver of a static problem's primary runs (the scene's), or None."""
    for r in runs:
        if r["problem"] == key and r["kind"] == "ladder" and not is_twin(r):
            return r.get("solver")
    return None


def converged(r):
    return bool(r and r.get("outcome") == "converged" and r.get("wall_seconds"))


def speedup(d, n):
    """Damped wall time over Newton's (> 1: Newton faster), or None."""
    if converged(d) and converged(n):
        return d["wall_seconds"] / n["wall_seconds"]
    return None


def mem(mb):
    """Peak resident memory, given in MiB (ru_maxrss / 1024), in binary units."""
    if not mb:
        return "-"
    if mb < 10:
        return "%.1f MiB" % mb
    return "%.0f MiB" % mb if mb < 1000 else "%.2f GiB" % (mb / 1024.0)


def x_text(sp):
    return "-" if sp is None else ("%.3gx" % sp if sp < 10 else "%.0fx" % sp)


def newton_stats(n):
    st = (n or {}).get("newton") or {}
    if not st:
        return "-"
    return "%s it, %s CG, %s fact.%s" % (
        st.get("iterations"), st.get("krylov_iterations"), st.get("factorisations"),
        ", %d load steps" % st["load_steps"] if (st.get("load_steps") or 1) > 1 else "")


def preconditioner_text(n):
    """The Newton run's preconditioner: the multigrid (levels) or the Cholesky factor."""
    st = (n or {}).get("newton") or {}
    if not st:
        return "-"
    lv = st.get("levels")
    if lv and lv > 1:
        return "multigrid, %d levels" % lv
    return "Cholesky"


def agreement_of(d, n):
    """The agreement check of a pair (stored in the twin's record)."""
    return (n or {}).get("agreement") or (d or {}).get("agreement") or {}


def agreement_text(n, d=None):
    a = agreement_of(d, n)
    if a.get("max_checked") is None:
        return a.get("reason", "-") if a else "-"
    return "%.1e%s" % (a["max_checked"], "" if a.get("ok") else " **FAIL**")


def skip_text(n):
    return "skipped: predicted %.0f GB > %g GB" % (
        n.get("predicted_memory_gb") or float("nan"),
        _budget(n))


def _budget(n):
    import re
    m = re.search(r"the budget ([0-9.]+) GB", n.get("skipped") or "")
    return float(m.group(1)) if m else 10.0


def solver_verdict(pairs):
    """(sentence, Newton wins at every size with none skipped) for one ladder's pairs."""
    rows = []
    for d, n in pairs:
        k = d["per_thickness"]
        if n is None:
            continue
        if d.get("outcome") == "skipped":
            rows.append((k, "newton", "damped not run (run time)", None))
            continue
        if n.get("outcome") == "skipped":
            rows.append((k, "damped", "Newton not run (predicted %.0f GB)"
                         % (n.get("predicted_memory_gb") or float("nan")), None))
            continue
        sp = speedup(d, n)
        if sp is None:
            rows.append((k, "damped" if converged(d) else "?",
                         "Newton %s" % (n.get("outcome") or n.get("rc")), None))
            continue
        rows.append((k, "newton" if sp > 1 else "damped", "%s" % x_text(sp), sp))
    if not rows:
        return "no Newton twins run.", False
    speeds = "; ".join("%d through: %s" % (k, t) for k, _, t, _ in rows)
    ties = [k for k, _, _, sp in rows if sp is not None and 1 / TIE <= sp <= TIE]
    tie = (" (within 10 %% at %s through: a tie on the shared machine)" %
           ", ".join(str(k) for k in ties)) if ties else ""
    who = [w for _, w, _, _ in rows]
    ks = [k for k, _, _, _ in rows]
    if all(w == "newton" for w in who):
        return ("**Newton wins at every size of the ladder** (%d to %d through; speed-up of "
                "Newton over the damped solver: %s)%s." % (ks[0], ks[-1], speeds, tie), True)
    if all(w == "damped" for w in who):
        return ("**The damped solver wins at every size** (%d to %d through; speed-up of "
                "Newton: %s)%s." % (ks[0], ks[-1], speeds, tie), False)
    for i in range(1, len(who)):
        if all(w == "newton" for w in who[:i]) and all(w == "damped" for w in who[i:]):
            return ("**Newton wins up to %d through, the damped solver from %d through on** "
                    "(speed-up of Newton: %s)%s." % (ks[i - 1], ks[i], speeds, tie), False)
        if all(w == "damped" for w in who[:i]) and all(w == "newton" for w in who[i:]):
            return ("**The damped solver wins up to %d through, Newton from %d through on** "
                    "(speed-up of Newton: %s)%s." % (ks[i - 1], ks[i], speeds, tie), False)
    return ("No clear crossover (speed-up of Newton: %s)%s." % (speeds, tie), False)


def solver_table(key, p, runs, variant):
    """Per resolution: the damped run and its Newton twin (wall time, speed-up, memory, the
    Newton statistics, and the twin's agreement)."""
    pairs = solver_pairs(runs, key, variant)
    if not any(n for _, n in pairs):
        return []
    q = (pairs[0][0].get("qoi") or {}).get("primary", "")
    rows = []
    for d, n in pairs:
        skipped = n is not None and n.get("outcome") == "skipped"
        st = (n or {}).get("newton") or {}
        if d.get("outcome") == "skipped":  # the damped twin, not run for its run time
            rows.append([d["per_thickness"], particles(n), err(n, q), d.get("skipped", ""),
                         "-", f3(n.get("wall_seconds"), 2), mem(n.get("peak_rss_mb")), "-",
                         newton_stats(n), preconditioner_text(n),
                         g(st.get("matrix_nonzeros"), 3), g(st.get("factor_nonzeros"), 3),
                         "-"])
            continue
        rows.append([
            d["per_thickness"], particles(d), err(n if converged(n) else d, q),
            "%s (%s steps)" % (f3(d.get("wall_seconds"), 1), d.get("steps") or "-"),
            mem(d.get("peak_rss_mb")),
            skip_text(n) if skipped else (f3((n or {}).get("wall_seconds"), 2) if n else
                                          "not run"),
            "-" if skipped or not n else mem(n.get("peak_rss_mb")),
            x_text(speedup(d, n)),
            "-" if skipped else newton_stats(n), "-" if skipped else preconditioner_text(n),
            g(st.get("matrix_nonzeros"), 3), g(st.get("factor_nonzeros"), 3),
            "-" if skipped or not n else agreement_text(n, d)])
    prim = primary_solver_of(runs, key) or "damped"
    twin = "damped" if prim == "newton" else "newton"
    L = ["**Damped dynamics against Newton%s** (the primary run uses the scene's solver, "
         "%s; its twin is the same run with `--static.solver=%s`; error = the Newton run's "
         "(the damped one's agrees, last column); wall time as the program measures it; "
         "memory = peak resident set; K and factor = the stored entries (lower triangle) of "
         "the matrix CHOLMOD factorises and of its factor: the assembled stiffness with the "
         "Cholesky preconditioner, the coarsest level with the multigrid; last column: the "
         "largest relative difference of %s "
         "between the two, which must be below %g x the static tolerance)" % (
             (", " + variant_label(p, variant)) if len(p["variants"]) > 1 else "",
             prim, twin,
             " and ".join(((p.get("newton") or {}).get("agree") or ["the headline"])),
             (p.get("newton") or {}).get("agreement_factor", 10)), ""]
    L += table(["per thickness", "particles (ghosts)", "error %% (%s)" % q,
                "damped wall s", "damped memory", "Newton wall s", "Newton memory",
                "speed-up", "Newton: iterations, CG, factorisations", "preconditioner",
                "K entries", "factor entries", "Newton vs damped (rel.)"], rows)
    L.append("")
    L.append(solver_verdict(pairs)[0])
    L.append("")
    return L


def loglog_slope(xs, ys):
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x and y]
    if len(pts) < 2:
        return None
    mx = sum(a for a, _ in pts) / len(pts)
    my = sum(b for _, b in pts) / len(pts)
    sxx = sum((a - mx) ** 2 for a, _ in pts)
    return sum((a - mx) * (b - my) for a, b in pts) / sxx if sxx > 0 else None


def solvers_section(P, runs, meta):
    static = [(k, p) for k, p in P.items() if p.get("static") and has_twins(runs, k)]
    if not static:
        return []
    nm = meta.get("newton") or {}
    mt = meta.get("merged_with")
    while not nm and mt:
        nm = mt.get("newton") or {}
        mt = mt.get("merged_with")
    budget = nm.get("memory_budget_gb", 10.0)
    factor = nm.get("agreement_factor", 10.0)
    L = ["## Static problems: damped dynamics or Newton", ""]
    prim = {k: primary_solver_of(runs, k) for k, _ in static}
    newton_first = [short_title(k, p) for k, p in static if prim[k] == "newton"]
    L.append("Every static ladder run is made with both solvers, right after each other so "
             "that both see the same machine load: the primary run with the scene's `[static] "
             "solver` (%s) and its twin with the other one (`--static.solver=...`, run id "
             "`<primary id>-<solver>`). Newton (docs/static.md) iterates on the tangent "
             "stiffness K with conjugate gradients, preconditioned by default (`preconditioner "
             "= auto`) by a geometric multigrid from 15,000 scalar unknowns on (unless a "
             "Poisson's ratio >= 0.45: Cook's nearly incompressible membrane), else by a "
             "CHOLMOD Cholesky factor of the assembled K. Both solvers stop at the same "
             "out-of-balance ratio (the scene's `[static] tolerance`, 1e-5), so they reach the "
             "same equilibrium: the runner checks that every Newton result differs from the "
             "damped one by less than %g x the tolerance (relative; `--check` enforces it), "
             "and the errors against the references are then the same, so the two fronts of "
             "error against wall time differ only in the wall time. A Newton run whose "
             "predicted peak memory exceeds %g GB is not run (the runner's memory model, "
             "anchored at measured runs and updated from the Newton runs it has made; "
             "`skipped` below). Memory is the peak resident set of the run (the kernel's "
             "ru_maxrss), wall time the program's own. The machine was shared (load average "
             "in the header), so ratios within 10 %% are ties." % (
                 "Newton for %s" % ", ".join(newton_first) if newton_first else
                 "the damped solver", factor, budget))
    L.append("")
    alone = [short_title(k, p) for k, p in P.items()
             if ((p.get("newton") or {}).get("no_twin"))]
    if alone:
        L.append("Not in this section: %s (%s); their Newton runs' wall time and peak "
                 "memory are in their own sections." % (
                     "; ".join(alone), next((p.get("newton") or {})["no_twin"]
                                            for p in P.values()
                                            if (p.get("newton") or {}).get("no_twin"))))
        L.append("")
    rows = []
    for key, p in static:
        for variant in p["variants"]:
            pairs = solver_pairs(runs, key, variant)
            if not any(n for _, n in pairs):
                continue
            text, everywhere = solver_verdict(pairs)
            rows.append([short_title(key, p) + ("" if not variant else
                                                ", " + variant_label(p, variant)),
                         text, "**yes**" if everywhere else "no"])
    L.append("**Which solver wins, and from which size on** (generated from the tables in "
             "each problem's section; speed-up = damped wall time / Newton wall time)")
    L.append("")
    L += table(["problem", "verdict", "Newton wins everywhere?"], rows)
    L.append("")
    yes = [r[0] for r in rows if r[2] == "**yes**"]
    no = [r[0] for r in rows if r[2] != "**yes**"]
    if yes:
        L.append("Newton is faster at every ladder size of: %s. Not at every size: %s." % (
            "; ".join(yes), "; ".join(no) or "none"))
        L.append("")
    # the memory
    L.append("**What Newton costs in memory** (default variant of each problem; K entries = "
             "the stored lower triangle of the matrix CHOLMOD factorises, one entry per coupled "
             "pair of unknowns (the neighbours of neighbours), and factor = its supernodal "
             "Cholesky factor's entries, 8 bytes each: with the Cholesky preconditioner the "
             "assembled K itself, with the multigrid its coarsest level (the run's "
             "summary.json reports that level's), so K per particle is given for the "
             "Cholesky runs only; the peak resident memory of the Newton run holds K, the "
             "preconditioner (the factor, or the coarse levels and the MLS transfers) and the "
             "solver's vectors)")
    L.append("")
    rows, fits, ratios = [], [], []
    for key, p in static:
        variant = p["variants"][0]
        pairs = solver_pairs(runs, key, variant)
        xs, rss_n = [], []
        for d, n in pairs:
            st = (n or {}).get("newton") or {}
            npart = (d.get("particles") or 0) + (d.get("ghost_particles") or 0)
            if n is not None and n.get("outcome") == "skipped":
                rows.append([short_title(key, p), d["per_thickness"], particles(d), "-", "-",
                             "-", "-", skip_text(n), mem(d.get("peak_rss_mb")), "-"])
                continue
            if not st:
                continue
            nz, fz = st.get("matrix_nonzeros"), st.get("factor_nonzeros")
            ratio = (n["peak_rss_mb"] / d["peak_rss_mb"]
                     if n.get("peak_rss_mb") and d.get("peak_rss_mb") else None)
            chol = preconditioner_text(n) == "Cholesky"
            rows.append([short_title(key, p), d["per_thickness"], particles(d),
                         preconditioner_text(n), g(nz, 3),
                         f3(nz / float(d["particles"]), 0) if chol and nz and d.get("particles")
                         else "-", g(fz, 3), mem(n.get("peak_rss_mb")),
                         mem(d.get("peak_rss_mb")), x_text(ratio) if ratio else "-"])
            if ratio and npart > 20000:
                ratios.append((ratio, short_title(key, p), d["per_thickness"]))
            xs.append(npart)
            rss_n.append(n.get("peak_rss_mb"))
        if len(xs) >= 3:
            fits.append("%s %s" % (short_title(key, p),
                                   f3(loglog_slope(xs[1:], rss_n[1:]), 2)))
    L += table(["problem", "per thickness", "particles (ghosts)", "preconditioner",
                "K entries", "per particle", "factor entries", "Newton peak memory",
                "damped peak memory", "Newton / damped memory"], rows)
    L.append("")
    if ratios:
        lo, hi = min(ratios), max(ratios)
        L.append("Above 20,000 particles Newton needs %.1f (%s, %d through) to %.1f (%s, %d "
                 "through) times the damped run's memory. Growth of Newton's peak memory with "
                 "the particle count N (particles and ghosts; least-squares exponent b in "
                 "`~ N^b` over all but the coarsest run, whose resident set is mostly the "
                 "program itself): %s. The damped solver stores no matrix: its memory grows "
                 "as N." % (lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
                            "; ".join(fits) or "-"))
        L.append("")
    sk = [r for r in runs if is_newton(r) and r.get("outcome") == "skipped"]
    if sk:
        L.append("Not run (predicted memory over the %g GB budget): %s." % (
            budget, "; ".join("`%s` (%s)" % (r["id"], r.get("skipped", "")) for r in sk)))
        L.append("")
    return L


def meshes_text(meshes):
    return ", ".join(m.lstrip("n") if m.startswith("n") else m for m in meshes or []) or "?"


def rich_text(order):
    return ("Richardson, observed order %.2f" % order if order is not None
            else "finest mesh: no monotone convergence")


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
    fem = R.get("fem", {})
    fc = fem.get("cases", {})

    def mesh_of(case):
        return (fc.get(case) or {}).get("finest_mesh", "?")

    L.append("- **FEM references** (`validation/fem.py`, CalculiX %s, numbers in `%s`; how "
             "each model matches its scene: `validation/fem/README.md`): every case is run on "
             "a ladder of meshes of 20-node hexahedra (C3D20R, reduced integration) refined "
             "by 2; the reference value is the **converged** one, the Richardson estimate "
             "from the last three meshes where they converge monotonically (else the finest "
             "mesh), and the finest mesh's value is kept alongside (the 'vs FEM finest mesh' "
             "columns). Common to all models: the scene's geometry in metres, rho0 = 1000 "
             "kg/m^3, `*ELASTIC` E and nu (linear elastic in a linear step, Saint "
             "Venant-Kirchhoff with NLGEOM); clamped = every displacement component zero at "
             "every node of the face, as tlsph's mirrored clamp puts u = 0 on the face; "
             "tractions as dead loads (consistent nodal forces of each 8-node face), gravity "
             "as a dead body force (`*DLOAD GRAV`); nodal U and S (ccx's extrapolated and "
             "averaged integration-point stresses). Plane strain (Cook, plate with a hole): "
             "one layer of C3D20R with u_z = 0 at every node, whose solution is then "
             "z-independent (checked to 1e-13). The full validation regenerates these "
             "references before its runs (unless `--no-fem`); the field errors compare each "
             "static ladder run's final frame with the finest mesh's VTU (`tlsph compare`)."
             % (fem.get("ccx_version", "?"), fem.get("references", "validation/fem/"
                                                                   "references.json")))
    L.append("- **Cantilever, static**: the 3D FEM with the whole face x = 0 clamped (case "
             "`cantilever`, linear, meshes %s): **%.6f m** converged (%s; an order below 2 "
             "is the clamp's edge singularity), %.6f m on the finest mesh; the "
             "reference of the headline error. The clamped face cannot contract, which "
             "stiffens the root against the beam theory's; the mirrored clamp (the default) "
             "puts u = 0 on that face too, so the FEM is the like-for-like reference. The "
             "scene is neo-Hookean; at this load NLGEOM with Saint Venant-Kirchhoff changes "
             "the FEM deflection by -0.017 %%, so the linear FEM is the reference. Second "
             "column: Timoshenko tip deflection 0.01516 m (the headline in earlier reports; "
             "`qL^4/(8EI) + qL^2/(2 kappa G A)` evaluates to %.5f m with Cowper's kappa = "
             "%.4f and 0.015156 with 5/6), Euler-Bernoulli %.4f m."
             % (meshes_text(c.get("tip_fem_meshes")), c["tip_fem"],
                rich_text(c.get("tip_fem_order")), c.get("tip_fem_finest", float("nan")),
                c["tip_timoshenko_computed"], c["kappa"], c["tip_euler_bernoulli"]))
    L.append("- **Cantilever, dynamic**: Euler-Bernoulli f1 = 1.8751^2/(2 pi) sqrt(EI/(rho A "
             "L^4)) = %.4f Hz. Slenderness L/h = 10: the clamped-free Timoshenko beam (shear "
             "kappa = %.4f, rotary inertia), solved by bisection on its frequency determinant "
             "in `validation/references.py`, gives **%.4f Hz** (%+.2f %%; %.4f Hz without "
             "rotary inertia). The error is taken against the Timoshenko value; the "
             "Euler-Bernoulli error is tabulated too. The beam oscillates about its static "
             "equilibrium, so the mean tip deflection is compared with the static Timoshenko "
             "and FEM values and with the static ladder's tip at the same dx and settings: "
             "(max+min)/2 as asked for, which the higher modes excited by the sudden load "
             "bias high by about 1.5 %%, and the time average over whole periods, which they "
             "do not." % (
                 c["f_euler_bernoulli"], c["kappa"], c["f_timoshenko"],
                 100 * (c["f_timoshenko"] / c["f_euler_bernoulli"] - 1),
                 c["f_timoshenko_no_rotary"]))
    L.append("- **Turek & Hron (2006) CSM1/CSM3**: point A = tip centre. CSM1 u_x = -7.187e-3, "
             "u_y = -6.610e-2 m; CSM3 u_x = -1.4305e-2 +- 1.4305e-2, u_y = -6.3607e-2 +- "
             "6.5541e-2 m, f = 1.0995 Hz. CSM3 values are extracted over t >= one reference "
             "period (0.9095 s) to the end: mean = (max+min)/2, amplitude = (max-min)/2, "
             "frequency from the times of successive extrema of u_y (each refined by a "
             "parabola through three samples).")
    L.append("- **Clamped square plate** (a/t = 10): the 3D FEM of the same plate (case "
             "`clamped_plate`: 0.5 x 0.5 x 0.05 m, E = 10 MPa, nu = 0.3, 1 kPa as a dead "
             "traction on the top face, the four side faces clamped in every direction, as "
             "the mirrored clamp's u = 0 on the face; linear, uniform meshes %s), "
             "centre mid-surface deflection **%.4f mm** converged (%s), "
             "%.4f mm on the finest mesh: the headline's reference. The earlier reference "
             "%.4f mm (40 x 40 x 4 elements, docs/method.md section 6) is not converged through "
             "the thickness (the deflection converges at order about 1 there: the edge "
             "singularity where the clamped faces meet the top and bottom). w/t is below "
             "2 %%, so the material law (Saint Venant-Kirchhoff in the scene) does not "
             "matter (NLGEOM: +0.14 %%). Second columns: a Ritz solution of the Mindlin "
             "(first-order shear, kappa = 5/6) clamped plate in `validation/references.py`, "
             "**%.4f mm** (%+.1f %% over Kirchhoff; the same code on the Kirchhoff energy "
             "returns the coefficient %.6f, the tabulated 0.00126, which checks it), and "
             "Kirchhoff `w = 0.00126 q a^4/D` = %.4f mm (Timoshenko & Woinowsky-Krieger, "
             "Theory of Plates and Shells, table 35): most of the difference between the "
             "Kirchhoff number and a 3D solid is the shear deformation."
             % (meshes_text(cp.get("w_fem_meshes")), cp.get("w_fem", float("nan")) * MM,
                rich_text(cp.get("w_fem_order")),
                cp.get("w_fem_finest", float("nan")) * MM,
                cp.get("w_fem_previous", float("nan")) * MM,
                cp["w_mindlin"] * MM, 100 * (cp["w_mindlin"] / cp["w_kirchhoff"] - 1),
                cp["kirchhoff_coefficient_ritz"], cp["w_kirchhoff"] * MM))
    cl = R.get("cantilever_large")
    if cl:
        L.append("- **Cantilever under g = 30 m/s^2** (`cantilever_large.ini`, Saint "
                 "Venant-Kirchhoff): case `cantilever_large`, CalculiX NLGEOM with `*ELASTIC` "
                 "(which is Saint Venant-Kirchhoff under NLGEOM: the scene's material), the "
                 "whole face x = 0 clamped, gravity 30 m/s^2 as a dead load applied in "
                 "increments of at most 0.1 of the step (the scene ramps it over 0.5 s and "
                 "relaxes with kinetic damping; only the equilibrium is compared), meshes "
                 "%s: tip (1, 0, 0) u_z = **%.5f m**, u_x = **%.5f m** converged "
                 "(%s), %.5f / %.5f m on the finest mesh. The linear "
                 "deflection would be %.4f m: the large deflection is %.0f %% less. No "
                 "analytic second column." % (
                     meshes_text(cl.get("meshes")), cl["tip_uz_fem"], cl["tip_ux_fem"],
                     rich_text(cl.get("tip_uz_fem_order")),
                     cl["tip_uz_fem_finest"], cl["tip_ux_fem_finest"], cl["tip_uz_linear"],
                     100 * (1 - cl["tip_uz_fem"] / cl["tip_uz_linear"])))
    for case, nu in (("cook_membrane", "0.3"), ("cook_membrane_incompressible", "0.4999")):
        ck = R.get(case)
        if not ck:
            continue
        L.append("- **Cook's membrane, nu = %s** (`%s.ini`; Cook 1974, scaled to metres): "
                 "case `%s`, plane strain (one layer of C3D20R, u_z = 0), linear elastic, the "
                 "edge x = 0 clamped (every node), the edge x = 0.048 loaded by a uniform "
                 "shear traction 6250 Pa along +y as consistent nodal forces (F = 100 N per "
                 "metre; the scene shares the same total force equally among the right edge's "
                 "surface particles and ramps it over 5 ms), n x n meshes, n = %s: corner "
                 "(0.048, 0.060) u_y = **%.5f mm**, u_x = %.5f mm, edge midpoint u_y = %.5f mm "
                 "converged (corner u_y: %s), %.5f mm (corner u_y) on the finest mesh. The "
                 "scene "
                 "uses the fixed clamp (the mirror cannot be built where the slanted bottom "
                 "edge meets the clamped one): its u = 0 sits at the first ghost layer, dx/2 "
                 "outside x = 0, so the SPH membrane is effectively dx/2 longer than the FEM "
                 "one (an O(dx) error).%s" % (
                     nu, case, case, meshes_text(ck.get("meshes")), ck["corner_uy_fem"] * MM,
                     ck["corner_ux_fem"] * MM, ck["edge_mid_uy_fem"] * MM,
                     rich_text(ck.get("corner_uy_fem_order")),
                     ck["corner_uy_fem_finest"] * MM,
                     " C3D20R (reduced integration) does not lock: the FEM ladder converges "
                     "from below without a plateau." if case.endswith("incompressible")
                     else ""))
    ph = R.get("plate_hole")
    if ph:
        L.append("- **Plate with a hole** (`plate_hole.ini`): case `plate_hole`, plane strain "
                 "(one layer of C3D20R, u_z = 0), linear elastic, the face x = 0 clamped, "
                 "the face x = 0.4 loaded by t_x = 100 kPa as consistent nodal forces (the "
                 "scene: a traction on the surface layer of particles, ramped over 20 ms), a "
                 "mesh graded towards the hole with mid-edge nodes on the circle, nc = %s "
                 "elements per quarter of the hole: Kt = sigma_xx(0.2, 0.06) / t_x = "
                 "**%.4f** converged (%s; %.4f on the finest mesh), u_x(0.4, 0.05) = "
                 "**%.5f mm**. Second column for Kt: Howland's solution as fitted in "
                 "Peterson's Stress Concentration Factors (Pilkey & Pilkey 2008, chart 4.1) "
                 "on the gross section for d/W = 0.2, %.3f (Heywood's formula %.3f): a long "
                 "strip pulled at both ends, where here one end is clamped 0.2 m from the "
                 "hole, so the FEM is the like-for-like reference. The SPH Kt is read by a kernel probe at the hole's top: the "
                 "Shepard-weighted average of the particles' stresses over the probe's "
                 "support (radius 2.1 dx), which smooths the peak and so reads below the "
                 "point value at every dx; the field errors (`tlsph compare`) show the "
                 "stresses particle by particle." % (
                     meshes_text(ph.get("meshes")), ph["kt_top_fem"],
                     rich_text(ph.get("kt_top_fem_order")), ph["kt_top_fem_finest"],
                     ph["end_ux_fem"] * MM, ph.get("kt_peterson") or float("nan"),
                     ph.get("kt_heywood") or float("nan")))
    lr = R.get("lame_ring")
    if lr:
        L.append("- **Lame ring** (`lame_ring.ini`): closed form of the thick-walled cylinder "
                 "a = 0.05 <= r <= b = 0.1 m, plane strain, internal pressure 100 MPa, "
                 "u(b) = 0 (the outer surface clamped): u_r = A r + B / r, A = -B / b^2, "
                 "B = p / (2 (lambda + mu) / b^2 + 2 mu / a^2): u(a) = **%.5e m**, "
                 "sigma_tt(a) = **%.4e Pa**, sigma_rr(a) = %.4e Pa, u(0.075) = %.5e m "
                 "(validation/references.py `lame_ring`)." % (
                     lr["u_a"], lr["stt_a"], lr["srr_a"], lr["u_mid"]))
    lc = R.get("lame_cylinder")
    if lc:
        L.append("- **Lame cylinder, 3D** (`lame_cylinder.ini`): the ring's cross-section "
                 "extruded to L = 0.05 m (validation/geometry/lame_cylinder.geo), ends free, "
                 "the outer surface clamped; CalculiX CAX8 (axisymmetric, quadratic) on "
                 "n x n meshes to n = 256, Richardson: u_r(a, L/2) = **%.6e m**, "
                 "sigma_tt(a, L/2) = **%.5e Pa** (nodal), sigma_rr(a, L/2) = %.4e Pa, "
                 "u_r(a, 0) = %.6e m; a C3D10 model of the same gmsh geometry agrees to "
                 "4e-4 (validation/lame_cylinder_fem.py, lame_cylinder_fem.json)." % (
                     lc["u_a"], lc["stt_a"], lc["srr_a"], lc["u_end"]))
    lf, cf = R.get("lame_ring_free"), R.get("lame_cylinder_free")
    if lf:
        L.append("- **Free Lame ring and cylinder** (`lame_ring_free.ini`, "
                 "`lame_cylinder_free.ini`): the textbook problem, the same ring and "
                 "cylinder with the outer surface free and nothing holding them (free "
                 "bodies; validation/references.py `lame_free`): k = p a^2/(b^2 - a^2), "
                 "sigma_rr = k (1 - b^2/r^2), sigma_tt = k (1 + b^2/r^2): sigma_tt(a) = "
                 "**%.6e Pa** (5/3 p), sigma_rr(a) = %.4e Pa, sigma_tt(b) = %.4e Pa. Ring, "
                 "plane strain: u_r = (1 + nu)/E k ((1 - 2 nu) r + b^2/r), u(a) = **%.6e m**.%s"
                 " The same at every point of the bore: each of the 32 bore nodes is compared "
                 "with it." % (
                     lf["stt_a"], lf["srr_a"], lf["stt_b"], lf["u_a"],
                     (" Cylinder, open ends (sigma_zz = 0, the plane-stress field exact in "
                      "3D, uniform axial strain %.4e): u_r = k/E ((1 - nu) r + (1 + nu) "
                      "b^2/r), u_r(a) = **%.6e m** at every z, the ends included." % (
                          cf["axial_strain"], cf["u_a"])) if cf else ""))
    if R.get("plate_hole_fitted") and ph:
        L.append("- **Plate with a hole, fitted** (`plate_hole_fitted.ini`): the same FEM "
                 "references as the plate with a hole (Kt = %.4f, u_x(0.4, 0.05) = %.5f mm)."
                 % (ph["kt_top_fem"], ph["end_ux_fem"] * MM))
    br = R.get("bracket")
    if br:
        L.append("- **L-bracket** (`bracket.ini`, geometry examples/bracket.geo): CalculiX "
                 "C3D10 (validation/bracket_fem.py, %s), P = (0, 0, 0.06): u_x = **%.5f mm** "
                 "(+- %.5f), u_z = **%.5f mm** (+- %.5f)." % (
                     br.get("source"), br["ux_P"] * MM, br["uncertainty"]["ux_P"] * MM,
                     br["uz_P"] * MM, br["uncertainty"]["uz_P"] * MM))
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
                          "(max+min)/2 over 0 < t <= 1.9 s (about 3 periods, 6 crossings); "
                          "the mean deflection is that (max+min)/2, against the static "
                          "references and the static ladder's tip at the same dx (same "
                          "settings). (max+min)/2 is biased high: the sudden load excites "
                          "higher modes as well, and the largest deflection is about 2.03, "
                          "not 2, times the static one. The time average of u_z over whole "
                          "periods (first crossing to the last an even number later) has no "
                          "such bias: its difference from the static run is the last "
                          "deflection column.",
    "csm1": "abs(u) error = |u - u_ref| / |u_ref| for the displacement vector of point A (the "
            "headline); the components separately: u_x and u_y are negative, so a positive "
            "component error means a smaller magnitude (too stiff), a negative one too soft. "
            "Extrapolated: `2 u(0.33) - u(0.31)`.",
    "csm3": "Over t >= 0.9095 s to the end (3.0 s): about 2.3 periods.",
    "clamped_plate": "Centre deflection from the kernel probe at the mid-surface centre; the "
                     "headline error is against the converged 3D FEM (CalculiX C3D20R, "
                     "Richardson of the uniform mesh ladder).",
    "cantilever_large": "Saint Venant-Kirchhoff, gravity 30 m/s^2 ramped over 0.5 s, kinetic "
                        "damping to equilibrium. Tip displacement from the kernel probe at "
                        "(1, 0, 0); errors of the components taken along the FEM's direction "
                        "(positive = larger displacement than the FEM, too soft); "
                        "'extrapolated' = `2 u(0.95) - u(0.9)` from two interior probes. "
                        "No sensitivity studies (budget).",
    "cook_membrane": "'Per thickness' = particles along the loaded edge (0.016 m). Corner "
                     "and edge-midpoint displacements from kernel probes at (0.048, 0.060) "
                     "and (0.048, 0.052); errors along the FEM's direction (positive = "
                     "larger, too soft). Fixed clamp (see the references). No sensitivity "
                     "studies.",
    "cook_membrane_incompressible": "As Cook's membrane with nu = 0.3; the wave speed (and "
                                    "so the number of steps) is 35 times larger. A test of "
                                    "volumetric locking: the FEM (C3D20R, reduced "
                                    "integration) does not lock. The displacements converge "
                                    "to the FEM, the stress field does not (relative L2 "
                                    "60-90 %): at nu = 0.4999 the pressure is the bulk "
                                    "modulus (1.7e10 Pa) times the volumetric strain, so a "
                                    "volumetric noise of 1e-7 in either solution (the "
                                    "particles' stresses; the FEM's nodal stresses "
                                    "extrapolated from reduced integration points) is a "
                                    "stress error of the order of the stresses themselves. "
                                    "Which side carries it was not investigated here.",
    "plate_hole": "'Per thickness' = particles across the hole's diameter (0.02 m; 5 times "
                  "that across the width). u_x at the loaded end's centre (0.4, 0.05) from a "
                  "kernel probe; Kt = sigma_xx / t_x from the stress probe at the hole's top "
                  "(0.2, 0.06). A kernel probe averages the particles' stresses over its "
                  "support (Shepard weights), so it smooths the peak: its Kt reads well "
                  "below the FEM's point value and converges with the support's size (O(dx)), "
                  "not as a nodal value would; the field errors below compare the stresses "
                  "particle by particle.",
}


NOTES.update({
    "lame_ring": "Body from gmsh (validation/geometry/lame_ring.geo, quadrangles): the "
                 "particles are the mesh's corner nodes; the pressure acts on the \"bore\" "
                 "nodes, the \"outer\" nodes are held (nodal clamp). 'Per thickness' = "
                 "elements through the wall (0.05 m). u(a) and sigma_tt(a) are the means of "
                 "the nodes at (a, 0) (u_x, sigma_yy) and (0, a) (u_y, sigma_xx), read by "
                 "nearest-particle probes (the particle's own stress); 'recovered': the "
                 "same nodes' stress recovered from the bore and its pressure (surface "
                 "probes, docs/method.md section 3.5). u(0.075) from a kernel probe.",
    "lame_cylinder": "Body from gmsh (validation/geometry/lame_cylinder.geo, "
                     "OpenCASCADE solid, tetrahedra): particles = the mesh's corner "
                     "nodes, pressure on \"bore\", nodal clamp on \"outer\". 'Per thickness' "
                     "= elements through the wall. u_r and sigma_tt at mid-length are the "
                     "means of the nodes at (a, 0, L/2) and (0, a, L/2) (nearest-particle "
                     "probes, the particle's own stress; 'recovered': surface probes at "
                     "the same nodes, docs/method.md section 3.5); u_r(a, 0) at the free "
                     "end.",
    "plate_hole_fitted": "The plate with a hole of `plate_hole.ini`, the body from gmsh "
                         "(validation/geometry/plate_hole.geo, quadrangles fitted to the "
                         "hole): nodal clamp on \"left\", the traction on \"right\" with "
                         "each node's share of the edge. Kt from the node at the hole's "
                         "top (nearest-particle probe, the particle's own stress); the kernel "
                         "probe's smoothed Kt for comparison with `plate_hole`.",
    "lame_ring_free": "The textbook Lame problem: the ring of `lame_ring.ini` (the same gmsh "
                      "body, material and bore pressure) with its outer surface free and "
                      "nothing holding it: a free body, which `[static] solver = newton` "
                      "solves leaving the rigid motions out (the displacement reported with "
                      "zero mean translation and rotation); the damped solver refuses it, so "
                      "there is no damped twin. 32 bore points every 11.25 degrees: u_r of "
                      "the nearest particle and the hoop stress recovered at the nearest bore "
                      "particle (surface probes, docs/method.md section 3.5), both at the "
                      "particle's own polar angle (that of its displacement, radial in the "
                      "exact solution; the particles sit up to half their spacing off the "
                      "probe points). 'mean' = the 32 nodes' mean, 'worst node' = the "
                      "largest |error| of the 32: the headline, node by node. sigma_rr "
                      "recovered = -p by construction (its normal part is the bore's "
                      "traction). 'Per thickness' = elements through the wall (0.05 m).",
    "lame_cylinder_free": "The textbook Lame problem in 3D: the open-ended cylinder of "
                          "`lame_cylinder.ini` (the same gmsh body) with its outer surface "
                          "and ends free and nothing holding it (a free body: Newton only, "
                          "no damped twin). With open ends the plane-stress Lame field is "
                          "exact in 3D, so u_r(a) and sigma_tt(a) are the same everywhere on "
                          "the bore, the ends included. 32 bore points at mid-length as in "
                          "the 2D ring (nearest particle's u_r, hoop stress recovered at the "
                          "nearest bore particle, each at the particle's own polar angle); "
                          "u_r(a, 0) = u_x of the particle at (a, 0, 0) on the free end.",
    "bracket": "The L-bracket of examples/bracket.ini (3D, gmsh tetrahedra from CAD, "
               "particles = corner nodes; nodal clamp on the bore, pressure on the arm's "
               "face). 'Per thickness' = elements through the 10 mm walls (dx = 5, 3.5, "
               "2.5, 1.75, 1.25, 1.0 mm). u_x and u_z of the arm's top corner P = (0, 0, 0.06) from a "
               "kernel probe, errors along the FEM's direction (positive = too soft).",
})


def problem_section(key, p, runs, R):
    L = ["## %s" % p["title"], "", "Scene `%s`. %s" % (p["scene"], NOTES.get(key, "")), ""]
    L += target_lines(p, runs, key)
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
            # a Newton run has iterations, not time steps
            newton = r.get("solver") == "newton" and r.get("newton")
            rows.append([g(r["dx"], 4), r["per_thickness"], particles(r),
                         f3(r.get("neighbours_mean"), 1),
                         newton_stats(r) if newton else (r.get("steps") or "-"),
                         "-" if newton else g(r.get("dt"), 3), f3(r.get("wall_seconds"), 1),
                         outcome(r)] +
                        [fn(r) for _, fn in cols])
        L += table(["dx [m]", "per thickness", "particles (ghosts)", "mean nb",
                    "steps (Newton: iterations)", "dt [s]", "wall s", "outcome"] +
                   [h for h, _ in cols], rows)
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
                        pr, g(qinf, 5), 100 * (qinf - ref) / (ref if name in ALONG
                                                              else abs(ref)))
                elif pr is None:
                    rich = "no fit (differences change sign or shrink too slowly: not " \
                           "in the asymptotic range)"
            conv_rows.append([error_label(name, against),
                              "; ".join(orders), rich])
        if conv_rows:
            L += table(["error", "observed order between resolutions",
                        "Richardson, last three (self-convergence)"], conv_rows)
            L.append("")
        L += solver_table(key, p, runs, variant)
    L += field_section(key, p, runs)
    return L


def pct_of(x):
    return None if x is None else 100.0 * x


def field_section(key, p, runs):
    """'Field errors against FEM': the `tlsph compare` norms of each ladder run's final
    frame (run.py stores them in the record's `fields`)."""
    recs = [r for r in runs if r["problem"] == key and r["kind"] == "ladder" and
            isinstance(r.get("fields"), dict) and not is_twin(r)]
    if not recs:
        return []
    recs.sort(key=lambda r: (p["variants"].index(r["variant"])
                             if r["variant"] in p["variants"] else 99, -r["dx"]))
    f0 = recs[0]["fields"]
    L = ["**Field errors against FEM** (`tlsph compare RUN %s`, the run's final frame against "
         "the finest FEM mesh; the FEM fields interpolated at the particles' reference "
         "positions, ghosts left out; relative L2 = sqrt(sum |e|^2 / sum |fem|^2) over the "
         "particles, max = the largest |e| over the largest |fem|; the stress in the "
         "Frobenius norm, whose largest values sit at the clamp's edges and, for the plate, "
         "at the hole, where the FEM's own nodal stresses are mesh-dependent too)" %
         f0.get("fem_vtu", "?"), ""]
    rows, skipped = [], []
    multi = len({r["variant"] for r in recs}) > 1
    for r in recs:
        f = r["fields"]
        label = [variant_label(p, r["variant"])] if multi else []
        if "displacement" not in f:
            why = f.get("skipped") or f.get("error") or "no comparison"
            skipped.append("%s: %s" % (r["id"], why))
            rows.append(label + [g(r["dx"], 4), r["per_thickness"], "-", "-", "-", "-", "-",
                                 why])
            continue
        d, st = f["displacement"], f.get("cauchy_stress") or {}
        rows.append(label + [
            g(r["dx"], 4), r["per_thickness"],
            "%s/%s" % (f.get("compared_particles"), f.get("body_particles")),
            f3(pct_of(d.get("l2_relative")), 3), f3(pct_of(d.get("max_relative")), 3),
            f3(pct_of(st.get("l2_relative")), 2), f3(pct_of(st.get("max_relative")), 1),
            "; ".join(f.get("warnings") or []) or "-"])
    L += table((["variant"] if multi else []) +
               ["dx [m]", "per thickness", "particles compared", "displacement L2 %",
                "displacement max %", "stress L2 %", "stress max %", "warnings"], rows)
    L.append("")
    if skipped and len(skipped) == len(recs):
        L.append("Not compared: " + "; ".join(skipped[:3]) + ".")
        L.append("")
    return L


def alpha_variants(p):
    """{alpha: variant} for a problem whose ladder variants differ only in hourglass.alpha
    (the default variant at the default alpha)."""
    out = {}
    for v in p["variants"]:
        if not p.get("variant_overrides", {}).get(v):
            out[DEFAULTS["hourglass.alpha"]] = v
        else:
            vs = variant_study(p, v)
            if vs and vs[0] == "hourglass.alpha":
                out[vs[1]] = v
    return dict(sorted(out.items()))


def spread(values, ref):
    """max - min of the values in % of ref; None when one is missing."""
    if not values or None in values or not ref:
        return None
    return 100.0 * (max(values) - min(values)) / abs(ref)


def alpha_spread_section(P, runs):
    L = ["## Alpha spread: how much of each cantilever result is the choice of alpha", ""]
    L.append("The cantilevers' ladders are run at alpha = 1, 10 (the default) and 30 (ladder "
             "variants; the energy penalty on the corrected F, mirrored clamp). Spread = "
             "(max - min) over the three alphas, in % of the alpha-10 value. Errors in "
             "brackets: against Timoshenko / against the converged clamped-face FEM; "
             "frequencies against the Timoshenko beam.")
    L.append("")
    a10 = DEFAULTS["hourglass.alpha"]
    for key, qname, errs, label, unit, scale, digits in (
            ("cantilever_static", "tip", ("tip", "tip_vs_fem"), "tip w", "mm", MM, 3),
            ("cantilever_dynamic", "mean_deflection", ("mean_deflection",
                                                       "mean_deflection_vs_fem"),
             "mean w (max+min)/2", "mm", MM, 3),
            ("cantilever_dynamic", "frequency", ("frequency",), "f", "Hz", 1.0, 4)):
        if key not in P:
            continue
        p = P[key]
        av = alpha_variants(p)
        if len(av) < 2:
            continue
        dxs = sorted({r["dx"] for v in av.values() for r in ladder(runs, key, v)},
                     reverse=True)
        rows = []
        for dx in dxs:
            cells, vals = [], []
            n = None
            for a, v in av.items():
                r = mid_run(runs, key, dx, v)
                if r is None:
                    cells.append("not run")
                    vals.append(None)
                    continue
                n = r["per_thickness"]
                x = val(r, qname)
                vals.append(x)
                if x is None:
                    cells.append(outcome(r))
                    continue
                cells.append("%s (%s)" % (f3(x * scale, digits),
                                          " / ".join(err(r, e) for e in errs)))
            ref = vals[list(av).index(a10)] if a10 in av else None
            present = [x for x in vals if x is not None]
            sp = spread(present, ref) if len(present) >= 2 else None
            rows.append([n, g(dx, 4)] + cells +
                        [f3(sp, 2) + ("" if len(present) == len(vals) else
                                      " (of %d)" % len(present)) if sp is not None else "-"])
        L.append("**%s, %s [%s]**" % (p["title"].split(",")[0] +
                                       (" (static)" if key == "cantilever_static" else
                                        " (dynamic)"), label, unit))
        L.append("")
        L += table(["per thickness", "dx [m]"] + ["alpha = %g%s" % (a, " (default)" if a == a10
                                                                   else "") for a in av] +
                   ["spread, % of alpha 10"], rows)
        L.append("")
        extra = [r for param_run in [sensitivity(runs, key, "hourglass.alpha", p)]
                 for r in param_run if not r.get("_variant_run")]
        if extra:
            L.append("At %d per thickness the sensitivity study adds: %s." % (
                int(round(p["thickness"] / p["sensitivity_dx"])),
                "; ".join("alpha = %g: %s" % (
                    r["value"], ("%s %s (%s)" % (f3(val(r, qname) * scale, digits), unit,
                                                 " / ".join(err(r, e) for e in errs)))
                    if val(r, qname) is not None else outcome(r)) for r in extra)))
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
                                                          p["variants"][0]), study=True)


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
        rs = sensitivity(runs, key, param, p)
        if base:
            rs = sorted(rs + [dict(base, param=param, value=base_value(p, param), _default=True)],
                        key=lambda r: r["value"])
        for r in rs:
            rows.append(["%s = %s%s" % (PARAM_NAME[param], sens_value(param, r["value"]),
                                        " (ladder run)" if r.get("_default") else
                                        " (ladder variant)" if r.get("_variant_run") else ""),
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
    L += table(["setting", "mean nb", "steps", "dt [s]", "wall s", "outcome", "hg min [J]"] +
               [h for h, _ in cols], rows)
    L.append("")
    msgs = [r for r in runs if r["problem"] == key and r["kind"] != "ladder" and
            r.get("stderr")]
    for r in msgs:
        L.append("- `%s` (exit %s): %s" % (r["id"], r.get("rc"), guard_message(r["stderr"])))
    if msgs:
        L.append("")
    return L


def guard_message(stderr):
    """The first lines of a failed run's stderr: the guard's message (what, where) and its
    likely cause, or the set-up error; the repository path left out."""
    root = str(Path(__file__).resolve().parent.parent) + "/"
    lines = [ln.strip() for ln in stderr.strip().splitlines() if ln.strip()]
    first = [i for i, ln in enumerate(lines) if ln.startswith("tlsph")]
    keep = lines[first[0]:first[0] + 2] if first else lines[-1:]
    return " ".join("`%s`" % ln.replace(root, "").replace("`", "'") for ln in keep)


def defaults_section(P, runs):
    L = ["## Chosen defaults", ""]
    L.append("The runner does not choose; it lists the numbers "
             "that bear on `kernel.support`, `kernel.correction`, `hourglass.alpha`, "
             "`hourglass.form`, `hourglass.gradient`, the clamp method, `time.cfl` and "
             "`static.tolerance` (one setting varied at a time, at each problem's sensitivity "
             "resolution; headline error in %, `unstable` = exit status 4, `(!)` = energy grows "
             "by more than 1 %, wall time in s in brackets, `*` = the ladder run the study "
             "starts from).")
    L.append("")
    for param in STUDIES:
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
                    r = next((x for x in sensitivity(runs, key, param, p)
                              if x["value"] == v), None)
                if r is None:
                    cells.append("")
                    continue
                q = r.get("qoi")
                if q and r.get("outcome") != "unstable":
                    cells.append("%s%s [%s]" % (err(r, q["primary"]), star,
                                                f3(r.get("wall_seconds"), 0)))
                else:
                    cells.append("%s%s [%s]" % (outcome(r), star, f3(r.get("wall_seconds"), 0)))
            label = p["title"].split(",")[0].split(" (")[0] + (" (%s)" % key)
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
    L = ["## What was cut to keep the ladder near an hour on 2 cores", ""]

    def at(key):
        p = P.get(key)
        return int(round(p["thickness"] / p["sensitivity_dx"])) if p else "?"

    L.append("- Sensitivity studies run at one resolution per problem, one setting at a time: "
             "the second of the ladder for the 2D problems (%s per thickness); **the 3D "
             "problems at their coarsest** (static cantilever %s, dynamic cantilever %s, "
             "clamped plate %s per thickness): a 3D run at 8 through costs 1-4 minutes on "
             "the shared machine and each study has 10-15 runs. At 4 per thickness the "
             "penalty and the clamp weigh more than at the finer resolutions; the "
             "cantilevers' alpha spread (alpha 1 and 30 ladder variants at every resolution) "
             "shows how the alpha effect shrinks." % (
                 at("csm1"), at("cantilever_static"), at("cantilever_dynamic"),
                 at("clamped_plate")))
    L.append("- The dynamic cantilever's alpha 1 and 30 variants stop at 8 per thickness "
             "(the alpha-10 ladder goes to 10): 10 through cost 218 s at alpha 10 on the shared "
             "machine, and alpha 30 needs a third more steps.")
    L.append("- No combined studies (e.g. alpha 100 with a smaller CFL); the time-step rule's "
             "margins with alpha are mapped by `validation/stability.py` "
             "(validation/report/stability.md). CFL 0.1 is no longer run on the oscillating "
             "plate: 0.4 and 0.5 show that below the limit the step does not change the "
             "results; 0.8 probes beyond the limit.")
    L.append("- CSM3 is simulated to 3.0 s (about 3.3 periods; the window after the first "
             "period holds about 2.3 periods) rather than 4 periods or more; the dynamic "
             "cantilever to 1.9 s (about 3 periods).")
    L.append("- The static scenes stop at a residual of 1e-5, the program's default (the "
             "sensitivity tables show 1e-4 and 1e-6).")
    L.append("- Ladders: the static cantilever goes to 16 particles through the section at "
             "alpha 10 only (its alpha 1 and 30 variants stop at 12), the dynamic cantilever "
             "to 10, the clamped plate to 16 through its thickness (410k particles), the "
             "large-deflection cantilever to 10, the Turek-Hron and oscillating plates to 16, "
             "Cook's membranes to 32 along the loaded edge, the plate with a hole to 32 "
             "across the hole.")
    L.append("- The problems with CalculiX references only (large-deflection cantilever, "
             "Cook's membranes, plate with a hole) have no sensitivity studies.")
    sk = [r for r in runs if is_newton(r) and r.get("outcome") == "skipped"]
    if sk:
        L.append("- Newton runs not run because their predicted peak memory exceeds the "
                 "budget (the machine has 24 GB and is shared): %s. The damped solver's runs "
                 "at those sizes are in the tables." % "; ".join(
                     "%s at %d through (%.0f GB predicted)" % (
                         r["problem"], r["per_thickness"], r.get("predicted_memory_gb") or 0)
                     for r in sk))
    L.append("")
    return L


# --------------------------------------------------------------------------------------------
# Plots


def _minor_label(v, digits):
    """A minor tick label on a log axis for the leading digits given ('0.3', '20'), else ''."""
    text = "%g" % v
    lead = text.lstrip("0.")
    return text if lead and lead[0] in digits else ""


def plot_variants(p):
    """The variants drawn in the error plots: not the cantilevers' alpha variants (they have
    their own table, the alpha spread)."""
    return [v for v in p["variants"] if not v.startswith("alpha")]


def legend_variant(p, variant):
    """A variant in a plot legend: its settings, or its name (the run id's part: 'ic-s2.5')
    where the settings are too long for a legend."""
    label = variant_label(p, variant)
    return variant if variant and len(label) > 24 else label


def short_title(key, p):
    t = p["title"].split(",")[0].split(" (")[0]
    return t + (" (nu = 0.4999)" if key == "cook_membrane_incompressible" else "")


def solver_plots(plt, np, runs, P, report_dir, colours):
    """static_solvers.png: per static problem both fronts (error against wall time), and the
    memory of both solvers against the particle count."""
    from matplotlib.ticker import FuncFormatter
    static = [(k, p) for k, p in P.items() if p.get("static") and has_twins(runs, k)]
    if not static:
        return []
    n = len(static) + 1
    ncol = 4
    nrow = (n + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.6 * nrow), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax, (key, p) in zip(axes.flat, static):
        variant = p["variants"][0]
        pairs = solver_pairs(runs, key, variant)
        for solver, style, colour in (("damped", "o-", colours[0]), ("newton", "D--",
                                                                      colours[1])):
            rs = [d if solver == "damped" else nn for d, nn in pairs]
            rs = [r for r in rs if r and primary_error(r) is not None and r.get("wall_seconds")]
            if not rs:
                continue
            x = [r["wall_seconds"] for r in rs]
            y = [max(abs(primary_error(r)), 1e-3) for r in rs]
            ax.loglog(x, y, style, color=colour, mfc="white" if solver == "newton" else None,
                      label=solver)
            for r, xx, yy in zip(rs, x, y):
                ax.annotate("%d" % r["per_thickness"], (xx, yy), textcoords="offset points",
                            xytext=(4, 4) if solver == "damped" else (5, -10), fontsize=7,
                            color=colour)
        skipped = [d["per_thickness"] for d, nn in pairs
                   if nn is not None and nn.get("outcome") == "skipped"]
        q = (pairs[0][0].get("qoi") or {}).get("primary", "") if pairs else ""
        ax.set_title("%s [%s]%s" % (short_title(key, p), q,
                                    "\nNewton not run at %s through (memory)" %
                                    ", ".join(map(str, skipped)) if skipped else ""),
                     fontsize=8.5)
        ax.set_xlabel("wall time [s]", fontsize=8)
        ax.set_ylabel("|error| [%]", fontsize=8)
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: _minor_label(v, "2346")))
        ax.tick_params(labelsize=7)
        ax.tick_params(axis="y", which="minor", labelsize=6)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    ax = axes.flat[len(static)]
    for i, (key, p) in enumerate(static):
        pairs = solver_pairs(runs, key, p["variants"][0])
        c = colours[i % len(colours)]
        for solver, style in (("damped", "o-"), ("newton", "D--")):
            pts = [((d.get("particles") or 0) + (d.get("ghost_particles") or 0),
                    (d if solver == "damped" else nn).get("peak_rss_mb"))
                   for d, nn in pairs if (d if solver == "damped" else nn) is not None]
            pts = [(a, b) for a, b in pts if a and b]
            if pts:
                ax.loglog([a for a, _ in pts], [b for _, b in pts], style, color=c,
                          mfc="white" if solver == "newton" else None,
                          label=short_title(key, p) if solver == "damped" else None)
    ax.set_xlabel("particles (with ghosts)", fontsize=8)
    ax.set_ylabel("peak resident memory [MB]", fontsize=8)
    ax.set_title("memory: damped (solid) and Newton (dashed)", fontsize=8.5)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(report_dir / "static_solvers.png", dpi=110)
    plt.close(fig)
    return [("static_solvers.png",
             "each static problem's two fronts, headline |error| against wall time: the damped "
             "solver (circles) and Newton (open diamonds), labelled by particles per "
             "thickness; the errors agree (the twins' check), so a front to the left is the "
             "faster solver at that size. Last panel: peak resident memory of both solvers "
             "against the particle count (Newton's: K and the multigrid hierarchy, or the "
             "Cholesky factor below 15,000 unknowns and for Cook's nearly incompressible "
             "membrane).")]


def make_plots(data, report_dir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    runs, R, P = data["runs"], data["references"], data["problems"]
    runs = with_static_comparison(runs)
    out = []
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]

    # 1. error against wall time
    fig, ax = plt.subplots(figsize=(12.5, 6.5))
    for i, (key, p) in enumerate(P.items()):
        for j, variant in enumerate(plot_variants(p)):
            lad = [r for r in ladder(runs, key, variant)
                   if primary_error(r) is not None and r.get("wall_seconds")]
            if not lad:
                continue
            x = [r["wall_seconds"] for r in lad]
            y = [max(abs(primary_error(r)), 1e-3) for r in lad]
            label = short_title(key, p) + (" " + variant if variant else "")
            label += " [%s]" % (lad[0]["qoi"]["primary"])
            ax.loglog(x, y, "o-" if j == 0 else "s--", color=colours[i % len(colours)],
                      label=label)
            for r, xx, yy in zip(lad, x, y):
                ax.annotate("%d" % r["per_thickness"], (xx, yy), textcoords="offset points",
                            xytext=(4, 4), fontsize=7, color=colours[i % len(colours)])
            # the static ladders' other front (the twins that ran), same colour, dotted
            prim = primary_solver_of(runs, key)
            other = {"newton": "damped", "damped": "newton"}.get(prim)
            nl = [r for r in ladder(runs, key, variant, solver=other) if is_twin(r) and
                  primary_error(r) is not None and r.get("wall_seconds")] if other else []
            if nl:
                ax.loglog([r["wall_seconds"] for r in nl],
                          [max(abs(primary_error(r)), 1e-3) for r in nl], "D:",
                          color=colours[i % len(colours)], mfc="white",
                          label=short_title(key, p) + " " + other)
                for r in nl:
                    ax.annotate("%d" % r["per_thickness"],
                                (r["wall_seconds"], max(abs(primary_error(r)), 1e-3)),
                                textcoords="offset points", xytext=(-10, -9), fontsize=6.5,
                                color=colours[i % len(colours)])
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: _minor_label(v, "25")))
    ax.tick_params(axis="y", which="minor", labelsize=7)
    ax.set_xlabel("wall time of the run [s] (2 cores)")
    ax.set_ylabel("|error| against the reference [%]")
    ax.set_title("Error against run time (labels: particles through the thickness)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    fig.savefig(report_dir / "error_vs_wall_time.png", dpi=110)
    plt.close(fig)
    out.append(("error_vs_wall_time.png",
                "headline |error| of each problem against the wall time of the run, one point "
                "per resolution (labelled by particles through the thickness), at the "
                "defaults (the cantilevers' alpha variants are in the alpha-spread table). "
                "The static cantilever, the clamped plate and the problems with CalculiX "
                "references only are against the converged FEM values. Static problems: "
                "solid line = the scene's solver (Newton with the multigrid preconditioner "
                "where the scene says `[static] solver = newton`), dotted line with open "
                "diamonds = the twin with the other solver (`--static.solver=damped`; same "
                "errors, other wall times)."))
    out += solver_plots(plt, np, runs, P, report_dir, colours)

    # 2. error against dx, with the fitted slope
    keys = [k for k in P.keys() if k in CONVERGENCE]
    nrows = (len(keys) + 2) // 3
    fig, axes = plt.subplots(nrows, 3, figsize=(13, 4 * nrows), squeeze=False)
    for ax in axes.flat[len(keys):]:
        ax.set_visible(False)
    for ax, key in zip(axes.flat, keys):
        p = P[key]
        for k, (name, _, against) in enumerate(CONVERGENCE[key][:2]):
            for j, variant in enumerate(plot_variants(p)):
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
                                              (" " + legend_variant(p, variant))
                                              if len(plot_variants(p)) > 1 else "",
                                              slope))
                marker = "o^sD"[(2 * k + j) % 4]
                pos = signed > 0
                ax.plot(h[pos], e[pos], marker, color=colour, ls="none")
                ax.plot(h[~pos], e[~pos], marker, color=colour, ls="none", mfc="white")
        tgt = p.get("target")
        if tgt:
            ax.axhline(tgt[1], color="grey", ls="--", lw=0.8)
            ax.text(ax.get_xlim()[0], tgt[1], " target %g %%" % tgt[1], fontsize=7,
                    va="bottom", color="grey")
        ax.set_title(short_title(key, p) + " — " + p["qoi"], fontsize=9)
        # label the ladder's dx values themselves, in plain numbers
        dxs = sorted({r["dx"] for v in plot_variants(p) for r in ladder(runs, key, v)})
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
                "a second reference or quantity (Timoshenko for the plate's period and for "
                "the static cantilever, whose headline is the converged 3D FEM, the FEM for "
                "the dynamic cantilever's time-averaged deflection, Mindlin for the clamped "
                "plate, u_x for the large-deflection cantilever and Cook's membranes, the "
                "probe's Kt for the plate with a hole); for CSM1 the vector error and u_y. At "
                "the defaults; the cantilevers' alpha variants are in the alpha-spread "
                "table. The Lame problems' variants are named by their run ids (ic = "
                "integration_constraint true, lin = linear, s2.5 = support 2.5); the free "
                "Lame problems' headline is the largest |error| of the 32 bore nodes."))

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
    fig, ax = plt.subplots(figsize=(10, 5))
    pc = P["cantilever_dynamic"]
    styles = {v: ls for v, ls in zip(pc["variants"], ["-", ":", "--", "-."])}
    res = sorted({r["per_thickness"] for r in hist_runs("cantilever_dynamic")})
    for r in hist_runs("cantilever_dynamic"):
        hst = r["history"]
        t = np.array(hst["time"])
        u = np.array([np.nan if v is None else v for v in hst["tip_uz"]])
        ax.plot(t, -u * MM, color=colours[res.index(r["per_thickness"]) % len(colours)],
                lw=1.2 if not r["variant"] else 0.9, ls=styles.get(r["variant"], "-"),
                label="%s, %d per thickness: %s" % (
                    variant_label(pc, r["variant"]), r["per_thickness"],
                    "f %s %%, mean w %s %%" % (err(r, "frequency"), err(r, "mean_deflection"))
                    if r.get("qoi") else outcome(r)))
    tt = np.linspace(0, 1.9, 800)
    d = c["tip_timoshenko"]
    ax.plot(tt, d * (1 - np.cos(2 * np.pi * c["f_timoshenko"] * tt)) * MM, "k--", lw=1,
            label="one-mode reference: static Timoshenko w (1 - cos 2 pi f t), f = %.4f Hz"
                  % c["f_timoshenko"])
    ax.set_ylim(-5, 60)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("tip deflection -u_z [mm]")
    ax.set_title("Cantilever, gravity applied suddenly", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6.5, loc="upper center", ncol=2)
    fig.tight_layout()
    fig.savefig(report_dir / "history_cantilever_dynamic.png", dpi=110)
    plt.close(fig)
    out.append(("history_cantilever_dynamic.png",
                "tip deflection against time, every ladder run (colour: resolution; line "
                "style: alpha 10, 1, 30; an unstable run would stop where its record ends), "
                "with the one-mode reference (errors: frequency against Timoshenko, mean "
                "deflection against the static Timoshenko value)."))

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
    # CSM1 by the magnitude of u_y (its headline, a vector norm, has no sign).
    plot_error = {"csm1": "uy"}
    plot_sign = {"csm1": -1.0}
    plot_label = {"csm1": " (abs(u_y))", "clamped_plate": " (w vs FEM)",
                  "cantilever_static": " (w vs FEM)"}

    def sens_error(r, key):
        q = r.get("qoi")
        e = q["errors"].get(plot_error.get(key, q["primary"])) if q else None
        return None if e is None else plot_sign.get(key, 1.0) * e

    def failed(r):
        return r.get("outcome") == "unstable" or r.get("energy_growth") or r.get("rc") == 1 \
            or sens_error(r, r["problem"]) is None

    def study(key, p, param):
        base = base_run(runs, key, p)
        rs = sensitivity(runs, key, param, p) + ([dict(base, value=base_value(p, param))]
                                                 if base else [])
        return sorted(rs, key=lambda r: r["value"])

    params = ["kernel.support", "hourglass.alpha", "time.cfl"]
    # one y range for the three line plots, from the values that are there
    ys = [sens_error(r, key) for key, p in P.items() for param in params
          if param in p.get("sensitivity", {}) for r in study(key, p, param) if not failed(r)]
    ylo, yhi = (min(ys + [0.0]), max(ys + [0.0])) if ys else (-1.0, 1.0)
    pad = 0.08 * (yhi - ylo or 1.0)
    band = ylo - pad  # failed runs are marked below the lowest value
    fig, axes = plt.subplots(1, 4, figsize=(20, 5.5),
                             gridspec_kw={"width_ratios": [1, 1.25, 1, 1.35]})
    for ax, param in zip(axes, params):
        k = 0
        for i, (key, p) in enumerate(P.items()):
            if param not in p.get("sensitivity", {}):
                continue
            colour = colours[i % len(colours)]
            rs = study(key, p, param)
            good = [r for r in rs if not failed(r)]
            label = "%s at %d/t%s" % (key, int(round(p["thickness"] / p["sensitivity_dx"])),
                                      plot_label.get(key, ""))
            ax.plot([r["value"] for r in good], [sens_error(r, key) for r in good], "o-",
                    color=colour, label=label)
            # failed runs: a cross (unstable or energy growth) or a triangle (set-up error)
            # below the lowest value, staggered per problem so none hides another
            yb = band - pad * (0.6 + 0.5 * k)
            k += 1
            for r in rs:
                if r.get("rc") == 1:
                    ax.plot([r["value"]], [yb], "v", color=colour, ms=7, mfc="white")
                elif failed(r):
                    ax.plot([r["value"]], [yb], "x", color=colour, ms=8, mew=2)
        ax.axvline(DEFAULTS[param], color="grey", lw=0.8, ls="--")
        ax.axhline(0, color="k", lw=0.6)
        ax.axhline(band, color="grey", lw=0.5, ls=":")
        if param == "hourglass.alpha":
            ax.set_xscale("log")
            ax.set_xlim(0.07, 140)
            ax.xaxis.set_major_locator(FixedLocator([0.1, 1, 10, 30, 100]))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_ylim(band - pad * 4, yhi + pad * 2)
        ax.set_xlabel(param + (" (log)" if param == "hourglass.alpha" else ""))
        ax.set_ylabel("headline error [%]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6.5, loc="upper left" if param != "time.cfl" else "best")
    # categorical studies: the change of the headline error from the default, in points
    ax = axes[3]
    cats = [("kernel.correction", "linear", "linear F\n(correction)"),
            ("kernel.quadrature", "nodal", "nodal energy\nsum"),
            ("hourglass.form", "ganzenmueller", "Ganzenmueller\nform"),
            ("hourglass.gradient", "linear", "penalty on\nlinear F"),
            ("clamp.method", "fixed", "fixed ghost\nclamp")]
    keys = [k for k, p in P.items() if p.get("sensitivity")]
    width = 0.8 / max(1, len(keys))
    deltas = []
    for ii, key in enumerate(keys):
        i = list(P).index(key)
        p = P[key]
        base = base_run(runs, key, p)
        eb = sens_error(base, key) if base else None
        for j, (param, v, _) in enumerate(cats):
            if param not in p.get("sensitivity", {}):
                continue
            r = next((x for x in sensitivity(runs, key, param, p) if x["value"] == v), None)
            x = j - 0.4 + width * (ii + 0.5)
            if r is None:
                continue
            if failed(r) or eb is None:
                deltas.append((x, None, colours[i % len(colours)], r))
                continue
            d = sens_error(r, key) - eb
            deltas.append((x, d, colours[i % len(colours)], r))
            ax.bar(x, d, width, color=colours[i % len(colours)],
                   label=key if j == next(jj for jj, c in enumerate(cats)
                                          if c[0] in p.get("sensitivity", {})) else None)
    ds = [d for _, d, _, _ in deltas if d is not None] + [0.0]
    lo, hi = min(ds), max(ds)
    padc = 0.1 * (hi - lo or 1.0)
    for x, d, colour, r in deltas:
        if d is None:
            ax.plot([x], [lo - padc], "v" if r.get("rc") == 1 else "x", color=colour, ms=8,
                    mew=2, mfc="white")
    ax.set_xticks(range(len(cats)))
    ax.set_xticklabels([c[2] for c in cats], fontsize=8)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylim(lo - 3 * padc, hi + 2 * padc)
    ax.set_ylabel("headline error minus the default's [points]")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=6.5, loc="best")
    ax.set_title("one setting changed from the defaults", fontsize=9)
    fig.suptitle("Sensitivities at each problem's sensitivity resolution (n/t = particles "
                 "through the thickness); below the dotted line: x = unstable (exit 4) or "
                 "energy grows, triangle = set-up error", fontsize=10)
    fig.tight_layout()
    fig.savefig(report_dir / "sensitivity.png", dpi=110)
    plt.close(fig)
    out.append(("sensitivity.png",
                "signed headline error against kernel.support, hourglass.alpha (log axis, "
                "0.1 to 100; the cantilever's alpha 1 and 30 are its ladder variants) and "
                "time.cfl at each problem's sensitivity resolution (dashed line: the default; "
                "the clamped plate against the FEM, CSM1 by the magnitude of u_y); right: how "
                "far the linear correction, the textbook Ganzenmueller force, the energy "
                "penalty on the linear F and the old fixed ghost-layer clamp move the headline "
                "error from the default's, in percentage points. For deflections and periods a "
                "positive error means too soft, for frequencies too stiff. Runs that went "
                "unstable or gained energy (x) and set-up errors (triangles) are marked below "
                "the dotted line, one row per problem."))
    return out
