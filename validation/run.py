#!/usr/bin/env python3
"""tlsph validation: error against run time, for the reference problems of docs/method.md section 6.

From the repository root (the build must exist: `bash scripts/setup.sh build`):

  /usr/bin/python3 validation/run.py                  # full ladder + sensitivities (~60 min on
                                                      # 2 cores); writes validation/report/
  /usr/bin/python3 validation/run.py --quick --check  # one coarse run per problem (< 1 min),
                                                      # errors checked against tolerances.json
  /usr/bin/python3 validation/run.py --report-only    # README.md and plots from results.json
  /usr/bin/python3 validation/run.py --derive-tolerances   # tolerances.json from results.json
                                                      # (--only P: P's entries, others kept)
  /usr/bin/python3 validation/run.py --plan           # list the runs, run nothing

`bash scripts/setup.sh validate` installs what is missing, builds and runs the full ladder.

Each run is `build/tlsph run validation/scenes/<problem>.ini --output.directory=<runs>/<id>
--output.fields=none --no-progress --overwrite [overrides]` with OMP_NUM_THREADS = --threads (default: all
cores), one after the other. The runner reads the run's summary.json and probes.csv, extracts
the quantity of interest, and compares it with the reference (validation/references.py, and
the CalculiX solutions of validation/fem.py read from validation/fem/references.json: the
converged value, i.e. the Richardson estimate where the FEM mesh ladder converges
monotonically, else the finest mesh). The full validation first regenerates those FEM
references (validation/fem.py, needs ccx and numpy; --no-fem keeps the committed ones), and
compares the final frame of every static ladder run that has an FEM solution field by field
(`tlsph compare RUN validation/fem/out/CASE.vtu`: displacement and stress error norms). Every
run's record (particles, neighbours, steps, dt, wall time, threads, git commit, the command
that reproduces it, outcome, quantities, errors) goes to validation/report/results.json;
validation/report/README.md and the PNG plots are made from that file (numpy and matplotlib
are needed for the plots only). Exit status 4 (unstable) or 3 (static run not converged) is a
result to report, not a failure of the runner.

Static problems are solved twice at every ladder resolution: with the scene's solver (the
primary run; the static scenes say `[static] solver = newton`) and again with the other solver
(a "twin": `--static.solver=damped`, id `<ladder id>-damped`; record fields `solver`, `twin`,
`twin_of`); not the free Lame bodies, which nothing holds: the damped solver refuses them
(Problem no_twin), so they are Newton runs only. Their sensitivity studies keep the damped
solver (`--static.solver=damped`: the time.cfl study is about the damped dynamics). A Newton
run (primary or twin) is skipped, and recorded as skipped, when its predicted peak memory
exceeds --newton-memory-gb (default 10 GB; the memory model NEWTON_MEMORY below, measured
with the multigrid preconditioner). Each twin's result must agree with its primary: the
relative difference of the problem's headline values below NEWTON_AGREEMENT times the static
tolerance (--check enforces it; the quick check runs a few small twins). Every run's peak
resident memory is measured (wait4's ru_maxrss), and a run above --memory-limit-gb is
stopped.

Running, parsing and checking use the Python standard library only (CI has no numpy).
"""

import argparse
import json
import math
import os
import platform
import shlex
import subprocess
import sys
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

import references as refs  # noqa: E402

# --------------------------------------------------------------------------------------------
# References


FEM_JSON = HERE / "fem" / "references.json"  # validation/fem.py's point values (committed)
BRACKET_FEM_JSON = HERE / "bracket_fem.json"  # validation/bracket_fem.py's (committed)
LAME_CYLINDER_FEM_JSON = HERE / "lame_cylinder_fem.json"  # validation/lame_cylinder_fem.py's
FEM_OUT = HERE / "fem" / "out"  # its VTU files (git-ignored), for `tlsph compare`

# The FEM case (validation/fem.py CASES) of each problem that has one, and whether its VTU is
# compared field by field with the run's final frame (static problems only: a dynamic run's
# last frame is not the equilibrium).
FEM_CASE = {"cantilever_static": "cantilever", "cantilever_dynamic": "cantilever",
            "clamped_plate": "clamped_plate", "cantilever_large": "cantilever_large",
            "cook_membrane": "cook_membrane",
            "cook_membrane_incompressible": "cook_membrane_incompressible",
            "plate_hole": "plate_hole", "plate_hole_fitted": "plate_hole"}
FIELD_PROBLEMS = ["cantilever_static", "clamped_plate", "cantilever_large", "cook_membrane",
                  "cook_membrane_incompressible", "plate_hole"]


def fem_vtu(case):
    """The VTU validation/fem.py writes for a case's reference series (finest mesh)."""
    return FEM_OUT / ("%s.vtu" % case)


def load_fem_references(path=FEM_JSON):
    """validation/fem/references.json (plain json: the quick check has no numpy)."""
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        raise SystemExit("cannot read the FEM references %s (%s): run "
                         "`/usr/bin/python3 validation/fem.py` (needs ccx) or restore the "
                         "committed file" % (rel(path), e))


def fem_point(fem, case, key):
    """(converged, finest) of an FEM point value: converged = the Richardson estimate of the
    case's reference series where its last three meshes converge monotonically, else the
    finest mesh's value."""
    try:
        ref = fem["cases"][case]["reference"]
        finest = ref["values"][key]
    except (KeyError, TypeError):
        raise SystemExit("the FEM references %s have no value %s of case %s: run "
                         "`/usr/bin/python3 validation/fem.py --case %s`"
                         % (rel(FEM_JSON), key, case, case))
    rich = (ref.get("richardson") or {}).get(key)
    return (rich if rich is not None else finest), finest


def fem_summary(fem, cases):
    """What the references of `cases` are: mesh, ccx version, which values are Richardson."""
    out = {}
    for case in cases:
        rec = fem["cases"].get(case)
        if not rec:
            out[case] = {"missing": True}
            continue
        ref = rec["reference"]
        out[case] = {"series": ref.get("series"), "finest_mesh": ref.get("mesh"),
                     "main": ref.get("main"), "ccx_version": rec.get("ccx_version"),
                     "richardson": sorted((ref.get("richardson") or {}).keys()),
                     "vtu": rel(fem_vtu(case)), "vtu_exists": fem_vtu(case).exists()}
    return out


def fem_order(fem, case, key):
    """Observed order of the FEM reference series' last three meshes (None if not monotone)."""
    try:
        rec = fem["cases"][case]
        conv = rec["series"][rec["reference"]["series"]]["convergence"][key]
        return conv.get("observed_order")
    except (KeyError, TypeError):
        return None


def fem_meshes(fem, case):
    try:
        rec = fem["cases"][case]
        return [r["mesh"] for r in rec["series"][rec["reference"]["series"]]["runs"]]
    except (KeyError, TypeError):
        return []


def _fem_mesh(fem, case):
    return ((fem.get("cases", {}).get(case) or {}).get("reference") or {}).get("mesh")


def compute_references(fem_path=FEM_JSON):
    """Reference numbers (docs/method.md section 6, the sources cited in the scene files, and the
    CalculiX models of validation/fem.py read from validation/fem/references.json)."""
    fem = load_fem_references(fem_path)
    r = {}
    # Oscillating plate (Gray, Monaghan & Swift 2001), plane strain.
    E, nu, rho, H, L = 2.0e6, 0.3975, 1000.0, 0.02, 0.2
    K = E / (3.0 * (1.0 - 2.0 * nu))
    T_thin = refs.thin_plate_period(E, nu, rho, H, L)
    f_timo = refs.timoshenko_frequency(E / (1 - nu**2), nu, rho, H, H**3 / 12.0, L,
                                       G=E / (2 * (1 + nu)))
    r["oscillating_plate"] = {
        "period": T_thin,
        "period_timoshenko": 1.0 / f_timo,
        "c0": math.sqrt(K / rho),
        "omega": 2 * math.pi / T_thin,
        "source": "thin-plate theory as in Gray, Monaghan & Swift (2001): omega^2 = E H^2 k^4 / "
                  "(12 rho0 (1 - nu^2)), k = 1.875/L",
    }
    # Cantilever, 3D.
    E, nu, rho, b, L = 1.0e7, 0.3, 1000.0, 0.1, 1.0
    A, I = b * b, b**4 / 12.0
    q = rho * 1.0 * A
    tip_fem, tip_fem_finest = fem_point(fem, "cantilever", "tip_deflection")
    r["cantilever"] = {
        "tip_timoshenko": 0.01516,
        "tip_timoshenko_computed": refs.timoshenko_static_tip(q, E, nu, A, I, L),
        "tip_euler_bernoulli": q * L**4 / (8 * E * I),
        # CalculiX C3D20R, the whole face x = 0 clamped (validation/fem.py case cantilever):
        # the converged value (Richardson) and the finest mesh's
        "tip_fem": tip_fem,
        "tip_fem_finest": tip_fem_finest,
        "tip_fem_mesh": _fem_mesh(fem, "cantilever"),
        "tip_fem_meshes": fem_meshes(fem, "cantilever"),
        "tip_fem_order": fem_order(fem, "cantilever", "tip_deflection"),
        "f_euler_bernoulli": refs.euler_bernoulli_frequency(E, I, rho, A, L),
        "f_timoshenko": refs.timoshenko_frequency(E, nu, rho, A, I, L),
        "f_timoshenko_no_rotary": refs.timoshenko_frequency(E, nu, rho, A, I, L,
                                                            rotary_inertia=False),
        "kappa": refs.rectangle_shear_coefficient(nu),
    }
    # Turek & Hron (2006) CSM1, CSM3.
    r["csm1"] = {"ux": -7.187e-3, "uy": -6.610e-2}
    r["csm3"] = {"ux_mean": -1.4305e-2, "ux_amp": 1.4305e-2, "uy_mean": -6.3607e-2,
                 "uy_amp": 6.5541e-2, "frequency": 1.0995}
    # Clamped square plate.
    E, nu, t, a, qp = 1.0e7, 0.3, 0.05, 0.5, 1000.0
    w_fem, w_fem_finest = fem_point(fem, "clamped_plate", "centre_deflection")
    prev = (((fem["cases"].get("clamped_plate") or {}).get("series") or {})
            .get("previous_reference") or {}).get("runs")
    r["clamped_plate"] = {
        "w_kirchhoff": refs.kirchhoff_plate_deflection(E, nu, t, a, qp),
        "kirchhoff_coefficient_ritz": refs.kirchhoff_clamped_square(nu, n=6),
        "w_mindlin": refs.mindlin_clamped_square(E, nu, t, a, qp, n=6),
        # CalculiX C3D20R, the four side faces clamped in every direction (validation/fem.py
        # case clamped_plate): converged (Richardson of the uniform ladder) and finest mesh
        "w_fem": w_fem,
        "w_fem_finest": w_fem_finest,
        "w_fem_mesh": _fem_mesh(fem, "clamped_plate"),
        "w_fem_meshes": fem_meshes(fem, "clamped_plate"),
        "w_fem_order": fem_order(fem, "clamped_plate", "centre_deflection"),
        # the earlier reference (docs/method.md section 6), 40 x 40 x 4 elements
        "w_fem_previous": prev[0]["values"]["centre_deflection"] if prev else 0.8121e-3,
    }
    # Cantilever under g = 30: Saint Venant-Kirchhoff, NLGEOM.
    c = {"mesh": _fem_mesh(fem, "cantilever_large"),
         "meshes": fem_meshes(fem, "cantilever_large")}
    for k in ("tip_uz", "tip_ux"):
        c[k + "_fem"], c[k + "_fem_finest"] = fem_point(fem, "cantilever_large", k)
        c[k + "_fem_order"] = fem_order(fem, "cantilever_large", k)
    c["tip_uz_linear"] = -30.0 * tip_fem
    r["cantilever_large"] = c
    # Cook's membrane, plane strain, nu = 0.3 and 0.4999.
    for case in ("cook_membrane", "cook_membrane_incompressible"):
        c = {"mesh": _fem_mesh(fem, case), "meshes": fem_meshes(fem, case)}
        for k in ("corner_uy", "corner_ux", "edge_mid_uy"):
            c[k + "_fem"], c[k + "_fem_finest"] = fem_point(fem, case, k)
            c[k + "_fem_order"] = fem_order(fem, case, k)
        r[case] = c
    # Plate with a hole, plane strain.
    c = {"mesh": _fem_mesh(fem, "plate_hole"), "meshes": fem_meshes(fem, "plate_hole")}
    for k in ("kt_top", "end_ux"):
        c[k + "_fem"], c[k + "_fem_finest"] = fem_point(fem, "plate_hole", k)
        c[k + "_fem_order"] = fem_order(fem, "plate_hole", k)
    an = fem["cases"]["plate_hole"].get("analytic") or {}  # fem_point checked the case
    c["kt_peterson"] = an.get("peterson_gross")
    c["kt_heywood"] = an.get("heywood_gross")
    c["traction"] = 1.0e5
    r["plate_hole"] = c
    # The same plate fitted to the surface (gmsh): the same FEM references.
    r["plate_hole_fitted"] = dict(c)
    # Thick-walled cylinder (Lame), plane strain, outer surface clamped: closed form.
    ring = refs.lame_ring(2.0e11, 0.3, 0.05, 0.1, 1.0e8)
    r["lame_ring"] = {"u_a": ring(0.05)[0], "u_mid": ring(0.075)[0],
                      "srr_a": ring(0.05)[1], "stt_a": ring(0.05)[2],
                      "source": "Lame: u_r = A r + B / r, u(b) = 0, sigma_rr(a) = -p"}
    # The same cylinder in 3D, length L = 0.05 m, ends free: CalculiX CAX8 ladder
    # (validation/lame_cylinder_fem.py), converged value (Richardson) at mid-length and at the end.
    cy = json.loads(LAME_CYLINDER_FEM_JSON.read_text())["reference"]
    r["lame_cylinder"] = {"u_a": cy["ur_mid"]["value"], "stt_a": cy["stt_mid"]["value"],
                          "srr_a": cy["srr_mid"]["value"], "u_end": cy["ur_end"]["value"],
                          "source": rel(LAME_CYLINDER_FEM_JSON) + ": CAX8 ladder, Richardson"}
    # The textbook Lame problem: the same ring and cylinder with the outer surface free and
    # nothing holding them (free bodies: Newton leaves the rigid motions out). Closed form;
    # open ends make the 3D cylinder's plane-stress field exact (sigma_zz = 0).
    for key, ps in (("lame_ring_free", True), ("lame_cylinder_free", False)):
        free = refs.lame_free(2.0e11, 0.3, 0.05, 0.1, 1.0e8, plane_strain=ps)
        r[key] = {"u_a": free(0.05)[0], "srr_a": free(0.05)[1], "stt_a": free(0.05)[2],
                  "stt_b": free(0.1)[2], "pressure": 1.0e8,
                  "source": "Lame, outer surface free: k = p a^2/(b^2 - a^2), sigma_tt = "
                            "k (1 + b^2/r^2), u_r = " +
                            ("(1 + nu)/E k ((1 - 2 nu) r + b^2/r) (plane strain)" if ps else
                             "k/E ((1 - nu) r + (1 + nu) b^2/r) (plane stress, open ends)")}
    r["lame_cylinder_free"]["u_end"] = r["lame_cylinder_free"]["u_a"]  # the same at the ends
    r["lame_cylinder_free"]["axial_strain"] = refs.lame_free_axial_strain(2.0e11, 0.3, 0.05,
                                                                          0.1, 1.0e8)
    # L-bracket: CalculiX C3D10, graded mesh ladder (validation/bracket_fem.py).
    br = json.loads(BRACKET_FEM_JSON.read_text())["reference"]
    r["bracket"] = {k: br[k]["reference"] for k in ("ux_P", "uz_P")}
    r["bracket"].update(uncertainty={k: br[k]["uncertainty"] for k in ("ux_P", "uz_P")},
                        source=rel(BRACKET_FEM_JSON) + ": " + br["ux_P"]["from"])
    r["fem"] = {"references": rel(fem_path), "generator": fem.get("generator"),
                "ccx_version": fem.get("ccx_version"),
                "value_used": "Richardson estimate of the reference series where its last three "
                              "meshes converge monotonically, else the finest mesh",
                "cases": fem_summary(fem, sorted(set(FEM_CASE.values())))}
    return r


# --------------------------------------------------------------------------------------------
# Reading a run


def read_series(path):
    """A tlsph CSV series: '#' preamble lines, a header row, numbers. Returns {column: list};
    {} for a missing file, NaN for a field that is not a number, and a row cut short (a run
    stopped while writing) is dropped."""
    header, rows = None, []
    try:
        with open(path) as f:
            for line in f:
                line = line.strip()
                if not line or line.startswith("#"):
                    continue
                if header is None:
                    header = line.split(",")
                    continue
                vals = []
                for x in line.split(","):
                    try:
                        vals.append(float(x))
                    except ValueError:
                        vals.append(float("nan"))
                if len(vals) == len(header):
                    rows.append(vals)
    except OSError:
        return {}
    if header is None:
        return {}
    return {h: [r[i] for r in rows] for i, h in enumerate(header)}


def finite(values):
    return all(math.isfinite(v) for v in values)


def crossings(t, u, level, band, t_min=0.0):
    """Times where u crosses `level` (linear interpolation between samples), with hysteresis:
    a crossing counts only once u has gone beyond level +- band on the other side, so ripples
    of higher modes near a crossing are not counted twice."""
    out = []
    state = 0
    last_cross = None
    for i in range(1, len(t)):
        if t[i] < t_min:
            continue
        a, b = u[i - 1] - level, u[i] - level
        if t[i - 1] >= t_min and a != b and ((a < 0) != (b < 0)) and a != 0.0:
            last_cross = t[i - 1] + (t[i] - t[i - 1]) * a / (a - b)
        s = 1 if b > band else (-1 if b < -band else 0)
        if s != 0:
            if state != 0 and s != state and last_cross is not None:
                out.append(last_cross)
            state = s
    return out


def extrema_between(t, u, level, cross):
    """Time and value of the extremum of u - level between successive crossings, refined by
    a parabola through the largest sample and its neighbours."""
    out = []
    for c0, c1 in zip(cross, cross[1:]):
        idx = [i for i in range(len(t)) if c0 < t[i] < c1]
        if len(idx) < 3:
            continue
        k = max(idx, key=lambda i: abs(u[i] - level))
        if k - 1 < 0 or k + 1 >= len(t):
            continue
        u0, u1, u2 = u[k - 1], u[k], u[k + 1]
        h = 0.5 * (t[k + 1] - t[k - 1])
        den = u0 - 2 * u1 + u2
        s = 0.5 * (u0 - u2) / den if den != 0 else 0.0
        s = max(-1.0, min(1.0, s))
        out.append((t[k] + s * h, u1 - 0.25 * (u0 - u2) * s))
    return out


def period_from_crossings(cross):
    if len(cross) < 2:
        return None
    return 2.0 * (cross[-1] - cross[0]) / (len(cross) - 1)


def energy_drift(energies):
    """(total(end) - total(0)) / E_scale in %, E_scale the largest kinetic + strain + |hourglass|
    or |external work| over the first fifth of the run (before any blow-up)."""
    tot = energies.get("total")
    if not tot:
        return None
    n = max(2, len(tot) // 5)
    scale = max(max(k + s + abs(h), abs(w)) for k, s, h, w in
                zip(energies["kinetic"][:n], energies["strain"][:n], energies["hourglass"][:n],
                    energies["external_work"][:n]))
    if scale <= 0 or not finite([tot[0], tot[-1]]):
        return None
    return 100.0 * (tot[-1] - tot[0]) / scale


ENERGY_GROWTH_PCT = 1.0  # a run whose energy books drift by more is flagged "energy-growth"


def pct(value, reference):
    if value is None or reference is None or not math.isfinite(value):
        return None
    return 100.0 * (value - reference) / abs(reference)


def pct_along(value, reference):
    """Signed % error of a displacement component relative to the reference's direction:
    positive = larger than the reference in its own direction (too soft), whatever the
    component's sign."""
    if value is None or reference is None or not math.isfinite(value):
        return None
    return 100.0 * (value - reference) / reference


# --------------------------------------------------------------------------------------------
# Quantities of interest. Each extractor returns {"values": {...}, "errors": {...} (signed %),
# "primary": name of the error that is the problem's headline, "notes": [...]}.


def extract_oscillating_plate(series, summary, R):
    ref = R["oscillating_plate"]
    t, uy, vy = series["time"], series["tip_uy"], series["tip_vy"]
    amp = max(abs(v) for v in uy)
    cu = crossings(t, uy, 0.0, 0.05 * amp, t_min=1e-12)
    vamp = max(abs(v) for v in vy)
    cv = crossings(t, vy, 0.0, 0.05 * vamp, t_min=1e-12)
    T_u, T_v = period_from_crossings(cu), period_from_crossings(cv)
    values = {"period": T_u, "period_from_velocity": T_v, "crossings": len(cu),
              "periods_measured": (cu[-1] - cu[0]) / T_u if T_u else None,
              "tip_amplitude": amp}
    return {"values": values,
            "errors": {"period": pct(T_u, ref["period"]),
                       "period_vs_timoshenko": pct(T_u, ref["period_timoshenko"]),
                       "period_from_velocity": pct(T_v, ref["period"])},
            "primary": "period"}


def extract_cantilever_static(series, summary, R):
    ref = R["cantilever"]
    w = -series["tip_uz"][-1]
    w95, w90 = -series["x095_uz"][-1], -series["x090_uz"][-1]
    w_ex = 2 * w95 - w90
    return {"values": {"tip": w, "tip_extrapolated": w_ex, "tip_ux": series["tip_ux"][-1]},
            "errors": {"tip_vs_fem": pct(w, ref["tip_fem"]),
                       "tip": pct(w, ref["tip_timoshenko"]),
                       "tip_vs_fem_finest": pct(w, ref["tip_fem_finest"]),
                       "tip_extrapolated_vs_fem": pct(w_ex, ref["tip_fem"]),
                       "tip_extrapolated": pct(w_ex, ref["tip_timoshenko"])},
            "primary": "tip_vs_fem"}


def extract_cantilever_dynamic(series, summary, R):
    ref = R["cantilever"]
    t, uz = series["time"], series["tip_uz"]
    hi, lo = max(uz), min(uz)
    mean, amp = 0.5 * (hi + lo), 0.5 * (hi - lo)
    cr = crossings(t, uz, mean, 0.05 * amp, t_min=1e-12)
    T = period_from_crossings(cr)
    f = 1.0 / T if T else None
    # (max+min)/2 is not quite the static deflection: the sudden load excites higher modes
    # too, and the largest deflection is their peaks' sum (about 2.03 times the static one
    # here), so (max+min)/2 sits about 1.5 % above it. The time average over whole periods
    # (between the first crossing and the last one an even number of crossings later) is the
    # static deflection, higher modes aside.
    avg = None
    if len(cr) >= 3:
        a, b = cr[0], cr[len(cr) - 1 - (len(cr) - 1) % 2]
        num = den = 0.0
        for i in range(1, len(t)):
            lo_, hi_ = max(t[i - 1], a), min(t[i], b)
            if hi_ > lo_:
                num += 0.5 * (uz[i] + uz[i - 1]) * (hi_ - lo_)
                den += hi_ - lo_
        avg = -num / den if den > 0 else None
    return {"values": {"frequency": f, "crossings": len(cr),
                       "periods_measured": (cr[-1] - cr[0]) / T if T else None,
                       "mean_deflection": -mean, "amplitude": amp,
                       "max_deflection": -lo, "time_average_deflection": avg},
            "errors": {"frequency": pct(f, ref["f_timoshenko"]),
                       "frequency_vs_euler_bernoulli": pct(f, ref["f_euler_bernoulli"]),
                       "mean_deflection": pct(-mean, ref["tip_timoshenko"]),
                       "mean_deflection_vs_fem": pct(-mean, ref["tip_fem"]),
                       "time_average_deflection": pct(avg, ref["tip_timoshenko"]),
                       "time_average_deflection_vs_fem": pct(avg, ref["tip_fem"])},
            "primary": "frequency"}


def extract_csm1(series, summary, R):
    ref = R["csm1"]
    ux, uy = series["A_ux"][-1], series["A_uy"][-1]
    ex_x = 2 * series["x033_ux"][-1] - series["x031_ux"][-1]
    ex_y = 2 * series["x033_uy"][-1] - series["x031_uy"][-1]
    norm_ref = math.hypot(ref["ux"], ref["uy"])

    def vec_err(x, y):
        return 100.0 * math.hypot(x - ref["ux"], y - ref["uy"]) / norm_ref

    return {"values": {"ux": ux, "uy": uy, "ux_extrapolated": ex_x, "uy_extrapolated": ex_y},
            "errors": {"displacement": vec_err(ux, uy), "ux": pct(ux, ref["ux"]),
                       "uy": pct(uy, ref["uy"]),
                       "displacement_extrapolated": vec_err(ex_x, ex_y),
                       "ux_extrapolated": pct(ex_x, ref["ux"]),
                       "uy_extrapolated": pct(ex_y, ref["uy"])},
            "primary": "displacement"}


CSM3_WINDOW_START = 1.0 / 1.0995  # one reference period


def csm3_signal(t, u):
    """Mean, amplitude, and frequency (from successive extrema) of u over t >= one period."""
    idx = [i for i in range(len(t)) if t[i] >= CSM3_WINDOW_START]
    if len(idx) < 10:
        return None
    tw, uw = [t[i] for i in idx], [u[i] for i in idx]
    hi, lo = max(uw), min(uw)
    mean, amp = 0.5 * (hi + lo), 0.5 * (hi - lo)
    cr = crossings(tw, uw, mean, 0.05 * amp)
    ext = extrema_between(tw, uw, mean, cr)
    f = None
    if len(ext) >= 2:
        f = (len(ext) - 1) / (2.0 * (ext[-1][0] - ext[0][0]))
    Tc = period_from_crossings(cr)
    return {"mean": mean, "amp": amp, "frequency": f,
            "frequency_from_crossings": 1.0 / Tc if Tc else None, "extrema": len(ext),
            "window": [tw[0], tw[-1]]}


def extract_csm3(series, summary, R):
    ref = R["csm3"]
    t = series["time"]
    sx = csm3_signal(t, series["A_ux"])
    sy = csm3_signal(t, series["A_uy"])
    ex_y = [2 * a - b for a, b in zip(series["x033_uy"], series["x031_uy"])]
    ex_x = [2 * a - b for a, b in zip(series["x033_ux"], series["x031_ux"])]
    sey, sex = csm3_signal(t, ex_y), csm3_signal(t, ex_x)
    v = {"frequency": sy["frequency"], "frequency_from_crossings": sy["frequency_from_crossings"],
         "extrema": sy["extrema"], "window": sy["window"],
         "ux_mean": sx["mean"], "ux_amp": sx["amp"], "uy_mean": sy["mean"], "uy_amp": sy["amp"],
         "uy_mean_extrapolated": sey["mean"], "uy_amp_extrapolated": sey["amp"],
         "ux_mean_extrapolated": sex["mean"], "ux_amp_extrapolated": sex["amp"]}
    e = {"frequency": pct(v["frequency"], ref["frequency"]),
         "frequency_from_crossings": pct(v["frequency_from_crossings"], ref["frequency"])}
    for k in ("ux_mean", "ux_amp", "uy_mean", "uy_amp"):
        e[k] = pct(v[k], ref[k])
        e[k + "_extrapolated"] = pct(v[k + "_extrapolated"], ref[k])
    return {"values": v, "errors": e, "primary": "frequency"}


def extract_clamped_plate(series, summary, R):
    ref = R["clamped_plate"]
    w = -series["centre_uz"][-1]
    return {"values": {"w": w},
            "errors": {"w_vs_fem": pct(w, ref["w_fem"]), "w": pct(w, ref["w_kirchhoff"]),
                       "w_vs_mindlin": pct(w, ref["w_mindlin"]),
                       "w_vs_fem_finest": pct(w, ref["w_fem_finest"])},
            "primary": "w_vs_fem"}


def extract_cantilever_large(series, summary, R):
    ref = R["cantilever_large"]
    uz, ux = series["tip_uz"][-1], series["tip_ux"][-1]
    ex_z = 2 * series["x095_uz"][-1] - series["x090_uz"][-1]
    ex_x = 2 * series["x095_ux"][-1] - series["x090_ux"][-1]
    return {"values": {"tip_uz": uz, "tip_ux": ux, "tip_uz_extrapolated": ex_z,
                       "tip_ux_extrapolated": ex_x},
            "errors": {"tip_uz": pct_along(uz, ref["tip_uz_fem"]),
                       "tip_ux": pct_along(ux, ref["tip_ux_fem"]),
                       "tip_uz_vs_fem_finest": pct_along(uz, ref["tip_uz_fem_finest"]),
                       "tip_uz_extrapolated": pct_along(ex_z, ref["tip_uz_fem"]),
                       "tip_ux_extrapolated": pct_along(ex_x, ref["tip_ux_fem"])},
            "primary": "tip_uz"}


def extract_cook(case):
    def extract(series, summary, R):
        ref = R[case]
        v = {"corner_uy": series["corner_uy"][-1], "corner_ux": series["corner_ux"][-1],
             "edge_mid_uy": series["edge_mid_uy"][-1]}
        e = {k: pct_along(v[k], ref[k + "_fem"]) for k in v}
        e["corner_uy_vs_fem_finest"] = pct_along(v["corner_uy"], ref["corner_uy_fem_finest"])
        return {"values": v, "errors": e, "primary": "corner_uy"}
    extract.__name__ = "extract_" + case
    return extract


def extract_plate_hole(series, summary, R):
    ref = R["plate_hole"]
    ux = series["end_ux"][-1]
    kt = series["hole_top_sxx"][-1] / ref["traction"]
    return {"values": {"end_ux": ux, "kt_top": kt,
                       "hole_top_syy": series["hole_top_syy"][-1]},
            "errors": {"end_ux": pct_along(ux, ref["end_ux_fem"]),
                       "kt_top": pct(kt, ref["kt_top_fem"]),
                       "kt_top_vs_peterson": pct(kt, ref.get("kt_peterson")),
                       "end_ux_vs_fem_finest": pct_along(ux, ref["end_ux_fem_finest"])},
            "primary": "end_ux"}


def extract_plate_hole_fitted(series, summary, R):
    ref = R["plate_hole_fitted"]
    ux = series["end_ux"][-1]
    kt = series["hole_top_sxx"][-1] / ref["traction"]  # the node at the hole's top, its own
    kt_k = series["hole_top_kernel_sxx"][-1] / ref["traction"]  # Shepard-smoothed
    return {"values": {"end_ux": ux, "kt_top": kt, "kt_top_kernel": kt_k},
            "errors": {"kt_top": pct(kt, ref["kt_top_fem"]),
                       "end_ux": pct_along(ux, ref["end_ux_fem"]),
                       "kt_top_kernel": pct(kt_k, ref["kt_top_fem"]),
                       "kt_top_vs_peterson": pct(kt, ref.get("kt_peterson"))},
            "primary": "kt_top"}


def extract_lame_ring(series, summary, R):
    """Radial displacement and hoop stress at the bore, read at its nodes on both axes: at
    (a, 0) u_r = u_x, sigma_tt = sigma_yy; at (0, a) u_r = u_y, sigma_tt = sigma_xx."""
    ref = R["lame_ring"]
    u_x, u_y = series["bore_x_ux"][-1], series["bore_y_uy"][-1]
    s_x, s_y = series["bore_x_syy"][-1], series["bore_y_sxx"][-1]
    r_x, r_y = series["bore_x_sxx"][-1], series["bore_y_syy"][-1]
    v = {"u_a": 0.5 * (u_x + u_y), "u_a_x": u_x, "u_a_y": u_y, "stt_a": 0.5 * (s_x + s_y),
         "stt_a_x": s_x, "stt_a_y": s_y, "srr_a": 0.5 * (r_x + r_y)}
    e = {"u_a": pct(v["u_a"], ref["u_a"]), "stt_a": pct(v["stt_a"], ref["stt_a"]),
         "u_a_x": pct(u_x, ref["u_a"]), "u_a_y": pct(u_y, ref["u_a"]),
         "stt_a_x": pct(s_x, ref["stt_a"]), "stt_a_y": pct(s_y, ref["stt_a"]),
         "srr_a": pct(v["srr_a"], ref["srr_a"])}
    if "surf_x_syy" in series:  # the stress recovered from the bore and its pressure
        s_x, s_y = series["surf_x_syy"][-1], series["surf_y_sxx"][-1]
        v.update({"stt_s": 0.5 * (s_x + s_y), "stt_s_x": s_x, "stt_s_y": s_y})
        e.update({"stt_s": pct(v["stt_s"], ref["stt_a"]), "stt_s_x": pct(s_x, ref["stt_a"]),
                  "stt_s_y": pct(s_y, ref["stt_a"])})
    if "mid_x_ux" in series:  # the 2D ring's kernel probe inside the wall
        v["u_mid"] = series["mid_x_ux"][-1]
        e["u_mid"] = pct(v["u_mid"], ref["u_mid"])
    return {"values": v, "errors": e, "primary": "u_a"}


def extract_lame_cylinder(series, summary, R):
    """The ring's quantities at mid-length of the 3D cylinder, from the bore nodes at
    (a, 0, L/2) and (0, a, L/2); u_r at the free end from the node at (a, 0, 0)."""
    out = extract_lame_ring(series, summary, {"lame_ring": R["lame_cylinder"]})
    ref = R["lame_cylinder"]
    ue = series["end_x_ux"][-1]
    out["values"]["u_end"] = ue
    out["errors"]["u_end"] = pct(ue, ref["u_end"])
    return out


LAME_FREE_NODES = 32  # the free Lame scenes' bore probes n00..n31, s00..s31


def _wrap(angle):
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def _particle_angle(ux, uy, theta):
    """A bore particle's polar angle, from its displacement: radial in the exact solution
    (nothing rotates a free body's solution: the solver reports it with zero mean rotation),
    so this is the particle's own angle up to the solution's tangential error, which moves
    u_r and sigma_tt at second order only. The particles sit up to half their spacing off the
    probe points (3.5 degrees at 8 through), which the probe's angle theta would read as a
    first-order error (sigma_tt rotated towards sigma_rr: up to -0.6 %). theta itself where
    the displacement points more than a probe spacing away from it (a wrong solution, which
    must show)."""
    phi = math.atan2(uy, ux)
    return phi if abs(_wrap(phi - theta)) <= 2.0 * math.pi / LAME_FREE_NODES else theta


def extract_lame_free(key):
    """The textbook Lame ring or cylinder (outer surface free, a free body): at each of the 32
    bore probes j (theta_j = 2 pi j / 32; in 3D at mid-length) the radial displacement of the
    nearest particle (nXX) and the hoop stress recovered at the nearest bore particle (sXX),
    both at the particle's own polar angle (_particle_angle): u_r = cos u_x + sin u_y,
    sigma_tt = sin^2 sxx + cos^2 syy - 2 sin cos sxy. Reported: their means (u_a, stt_s) and
    the largest |error| over the 32 nodes (u_a_worst, stt_s_worst: the headline, node by
    node); in 3D also u_x of the particle at (a, 0, 0) on the free end (u_end)."""
    def extract(series, summary, R):
        ref = R[key]
        n = LAME_FREE_NODES
        ur, stt, srr, offsets = [], [], [], []
        for j in range(n):
            theta = 2.0 * math.pi * j / n
            ux, uy = series["n%02d_ux" % j][-1], series["n%02d_uy" % j][-1]
            phi = _particle_angle(ux, uy, theta)
            ur.append(math.cos(phi) * ux + math.sin(phi) * uy)
            sp = "s%02d_" % j
            phi = _particle_angle(series[sp + "ux"][-1], series[sp + "uy"][-1], theta)
            offsets.append(abs(math.degrees(_wrap(phi - theta))))
            c, s = math.cos(phi), math.sin(phi)
            sxx, syy, sxy = series[sp + "sxx"][-1], series[sp + "syy"][-1], series[sp + "sxy"][-1]
            stt.append(s * s * sxx + c * c * syy - 2.0 * s * c * sxy)
            srr.append(c * c * sxx + s * s * syy + 2.0 * s * c * sxy)
        eu = [pct(u, ref["u_a"]) for u in ur]
        es = [pct(x, ref["stt_a"]) for x in stt]
        ju = max(range(n), key=lambda i: abs(eu[i]))
        js = max(range(n), key=lambda i: abs(es[i]))
        v = {"u_a": sum(ur) / n, "u_a_min": min(ur), "u_a_max": max(ur),
             "stt_s": sum(stt) / n, "stt_s_min": min(stt), "stt_s_max": max(stt),
             "srr_s": sum(srr) / n, "u_a_worst_node": ju, "stt_s_worst_node": js,
             "angle_offset_max_deg": max(offsets)}
        e = {"u_a": pct(v["u_a"], ref["u_a"]), "u_a_worst": abs(eu[ju]),
             "stt_s": pct(v["stt_s"], ref["stt_a"]), "stt_s_worst": abs(es[js]),
             "srr_s": pct(v["srr_s"], ref["srr_a"])}
        if "end_x_ux" in series:  # the 3D cylinder's free end, (a, 0, 0)
            v["u_end"] = series["end_x_ux"][-1]
            e["u_end"] = pct(v["u_end"], ref["u_end"])
        return {"values": v, "errors": e, "primary": "stt_s_worst"}
    extract.__name__ = "extract_" + key
    return extract


def extract_bracket(series, summary, R):
    ref = R["bracket"]
    ux, uz = series["P_ux"][-1], series["P_uz"][-1]
    return {"values": {"ux_P": ux, "uz_P": uz},
            "errors": {"ux_P": pct_along(ux, ref["ux_P"]), "uz_P": pct_along(uz, ref["uz_P"])},
            "primary": "ux_P"}


# --------------------------------------------------------------------------------------------
# Problems


class Problem:
    def __init__(self, key, title, scene, dim, thickness, ladder, quick_dx, sens_dx, extract,
                 static, qoi, unit, target=None, variants=None, sensitivity=None,
                 checked=None, cross=None, quick_variant=0, sens_variant=0,
                 variant_ladders=None, clamps=None, newton_memory=None, quick_twin=False,
                 agree=None, twin_skip=None, no_twin=None, target_at=None):
        self.key, self.title, self.scene, self.dim = key, title, scene, dim
        self.thickness, self.ladder = thickness, ladder
        self.quick_dx, self.sens_dx = quick_dx, sens_dx
        self.extract, self.static, self.qoi, self.unit = extract, static, qoi, unit
        self.target = target  # (error name, |error| % at the finest resolution)
        # where the target is evaluated when not at each variant's finest resolution:
        # {"per_thickness": n, "variant": name, "errors": [more error names held to it]}
        self.target_at = target_at
        self.variants = variants or [("", {})]
        self.sensitivity = sensitivity or {}
        self.checked = checked or []  # error names the quick check compares
        self.cross = cross or []  # combined settings, e.g. {alpha, cfl}: does the dt rule hold?
        self.quick_variant = quick_variant  # the variant the quick check runs
        self.sens_variant = sens_variant  # the variant the sensitivity studies start from
        self.variant_ladders = variant_ladders or {}  # variant -> its own (shorter) ladder
        self.clamps = clamps or []  # the scene's [clamp.NAME] sections (the clamp.method study)
        # static problems: the Newton runs' memory model (n_ref per thickness, peak GB there,
        # exponent of n; NEWTON_MEMORY), whether the quick check runs the quick run's twin, and
        # the values (qoi["values"]) whose Newton-damped agreement is checked
        self.newton_memory = newton_memory
        self.quick_twin = quick_twin
        self.agree = agree or []
        # ladder resolutions whose twin is not run, with the reason (recorded as skipped)
        self.twin_skip = twin_skip or {}
        # a static problem with no twins at all, and why (a body nothing holds: the damped
        # solver refuses it): its ladder runs are Newton only, and no twin records
        self.no_twin = no_twin


# The 3D problems' sensitivity studies run at the coarsest ladder resolution (4 per thickness),
# the 2D ones at the second (8): cut to keep the full ladder near an hour on 2 cores (3D runs
# at 8 through cost 1-4 minutes each on the shared machine). The cantilevers' alpha spread
# (ladder variants at every resolution) shows what the penalty does at the finer ones.
#
# Sensitivity values; the defaults (support 2.1, quadratic correction, hourglass alpha 10 in
# the energy form on the corrected F, mirrored clamps, CFL 0.3, the scenes' static tolerance
# 1e-5) are the ladder run at the same resolution. alpha 1 and 30 are also ladder variants of
# the two cantilevers (the "alpha spread"); where such a variant has the sensitivity
# resolution it is the study's run (not run twice). The CFL values bracket the measured limit
# of the quadratic correction (near 0.5 for alpha 0..100: validation/report/stability.md).
SUPPORT = [2.0, 2.5, 3.0]
ALPHA = [0.1, 1.0, 30.0, 100.0]
CFL = [0.4, 0.5, 0.6]
TOL = [1e-4, 1e-6]
LINEAR = ["linear"]
NODAL = ["nodal"]  # kernel.quadrature: the one-point energy sum instead of the default taylor


def hourglass_studies(clamped):
    """alpha, the textbook force, the penalty on the linear F and (where the scene has a clamp)
    the old fixed ghost-layer clamp: one at a time, from the defaults."""
    d = {"hourglass.alpha": ALPHA, "hourglass.form": ["ganzenmueller"],
         "hourglass.gradient": ["linear"]}
    if clamped:
        d["clamp.method"] = ["fixed"]
    return d


# Ladder variants at other alphas: how much of each result is the penalty's choice?
ALPHA_VARIANTS = [("alpha1", {"hourglass.alpha": "1"}), ("alpha30", {"hourglass.alpha": "30"})]
DYNAMIC_ALPHA_LADDER = [0.025, 0.0125]  # 10 through cut (budget)
STATIC_ALPHA_LADDER = [0.025, 0.0125, 0.01, 0.1 / 12]  # 16 through cut (budget)

# The static problems' Newton runs (the primaries since the multigrid preconditioner; and the
# twins of a scene whose solver is damped) and their memory. With `[static] preconditioner =
# auto` Newton stores the assembled stiffness K and either the CHOLMOD factor (below 15,000
# scalar unknowns, or Poisson's ratio >= 0.45: Cook's nearly incompressible membrane) or the
# multigrid hierarchy (K's Galerkin coarse levels and the MLS transfers), whose size grows about
# as the particle count N (measured: Newton's peak memory ~ N^0.97-1.17 over the 3D ladders,
# 2.1-2.7 times the damped run's above 20,000 particles). Each static problem has a model of
# the peak resident memory, GB(n) = GB_ref (n / n_ref)^exponent (n = particles per
# thickness), anchored at the finest Newton run of the problem measured by the runner (wait4
# ru_maxrss; 2 threads on the 2-core machine, binary of commit 27c1e8e, 2026-11-29; the full
# validation of the solver reversal). Exponent in 3D: the one between the two finest runs of
# the problem (3.0-3.4: N grows as n^3 and slightly faster); in 2D 2.5, a bound (the finest
# runs grow as n^1.5-1.7; the Cholesky factor as N log N). The runner predicts each Newton
# run's memory from the finest Newton run of the
# same problem it has measured so far (else from this anchor), with the larger of the model's
# exponent and the one observed between the two finest measured runs when both exceed
# MEMORY_FLOOR_GB (below that the program's fixed size and the switch between the Cholesky
# factor and the multigrid dominate), and skips the run when the prediction exceeds
# --newton-memory-gb.
NEWTON_BUDGET_GB = 10.0
MEMORY_LIMIT_GB = 10.5  # any run (damped or Newton) above this resident size is stopped
MEMORY_FLOOR_GB = 0.5
NEWTON_MEMORY = {  # measured peak resident memory of the Newton runs (multigrid from 15,000
    # unknowns), GB: 0.045, 0.11, 0.24, 0.35, 0.91 at 4, 8, 10, 12, 16 through
    "cantilever_static": (16, 0.91, 3.3),
    "cantilever_large": (10, 0.24, 3.4),  # 0.045, 0.11, 0.24 at 4, 8, 10
    "clamped_plate": (16, 7.6, 3.0),  # 0.15, 0.50, 1.28, 1.87, 7.6 at 4, 6, 8, 10, 16
    "csm1": (16, 0.062, 2.5),  # Cholesky at every size (at most 9,056 unknowns)
    "cook_membrane": (32, 0.13, 2.5),  # Cholesky at every size (at most 12,020 unknowns)
    "cook_membrane_incompressible": (32, 0.12, 2.5),  # Cholesky (nu = 0.4999)
    "plate_hole": (32, 0.65, 2.5),  # 0.10, 0.20, 0.65 at 8, 16, 32 (Cholesky at 8)
}
# A twin agrees with its primary when every checked value differs by less than
# NEWTON_AGREEMENT times the static tolerance (relative): both stop at an out-of-balance ratio
# below the tolerance, and the displacement error that leaves is of the same order (measured:
# 1e-7 to 4e-5 relative at tolerance 1e-5).
NEWTON_AGREEMENT = 10.0

# The free Lame problems (bodies nothing holds): the damped solver refuses them, Newton only.
FREE_BODY_NO_TWIN = ("a body nothing holds: the damped solver is refused (\"solver = newton "
                     "solves a body nothing holds\"), Newton only")
# Their Newton memory models (n_ref, GB at n_ref, exponent; NEWTON_MEMORY), anchored at the
# largest peak measured at the finest resolution (2 threads, 2026-12-07): the ring 0.22, 0.25,
# 0.25 GB at 32 through (defaults, ic-s2.5, lin-s2.5); the cylinder at 16 through 1.66 GB with
# lin-s2.5 (multigrid) and 5.08 GB at the defaults, where the multigrid stalled on the free
# body and Newton fell back to a Cholesky factor (4.4e8 entries, 475 s); 0.25 and 0.34 GB at
# 8. Exponents: the 2D bound of the other 2D problems, the clamped cylinder's 3.0.
LAME_FREE_MEMORY = {"lame_ring_free": (32, 0.25, 2.5), "lame_cylinder_free": (16, 5.08, 3.0)}

# The mesh bodies with a pressure-loaded curved surface, also with the gradient correction that
# makes a uniform stress balance its tractions (docs/method.md section 3.4).
# Mesh bodies default to support 2.5 and the integration constraint (linear in 2D, uniform in
# 3D); "noic-s2.1" is the lattice's default without the constraint, for comparison.
NOIC = ("noic-s2.1", {"kernel.integration_constraint": "false", "kernel.support": "2.1"})
UNIFORM = ("uniform", {"kernel.integration_constraint": "uniform"})
LINEAR = ("linear", {"kernel.integration_constraint": "linear"})
LAME_VARIANTS = [("", {}), NOIC]

PROBLEMS = [
    Problem("oscillating_plate", "Oscillating plate (Gray, Monaghan & Swift 2001), 2D",
            "oscillating_plate.ini", 2, 0.02, [0.005, 0.0025, 0.00125], 0.005, 0.0025,
            extract_oscillating_plate, False, "period", "s", target=("period", 3.0),
            variants=[("Vf0.01", {}), ("Vf0.001", {"initial.mode.amplitude_over_c0": "0.001"})],
            sensitivity=dict({"kernel.support": SUPPORT, "kernel.correction": LINEAR,
                              "kernel.quadrature": NODAL,
                              "time.cfl": CFL + [0.8]}, **hourglass_studies(False)),
            checked=["period"]),
    Problem("cantilever_static", "Cantilever under self-weight, static, 3D",
            "cantilever_static.ini", 3, 0.1, [0.025, 0.0125, 0.01, 0.1 / 12, 0.00625], 0.025,
            0.025, extract_cantilever_static, True, "tip deflection", "m",
            target=("tip_vs_fem", 0.5), variants=[("", {})] + ALPHA_VARIANTS,
            variant_ladders={v: STATIC_ALPHA_LADDER for v, _ in ALPHA_VARIANTS},
            sensitivity=dict({"kernel.support": SUPPORT, "kernel.correction": LINEAR,
                              "kernel.quadrature": NODAL,
                              "time.cfl": CFL, "static.tolerance": TOL},
                             **hourglass_studies(True)),
            checked=["tip_vs_fem", "tip", "tip_extrapolated"], clamps=["root"],
            newton_memory=NEWTON_MEMORY["cantilever_static"], quick_twin=True,
            agree=["tip"]),
    Problem("cantilever_dynamic", "Cantilever, gravity applied suddenly, 3D",
            "cantilever_dynamic.ini", 3, 0.1, [0.025, 0.0125, 0.01], 0.025, 0.025,
            extract_cantilever_dynamic, False, "first bending frequency", "Hz",
            variants=[("", {})] + ALPHA_VARIANTS,
            variant_ladders={v: DYNAMIC_ALPHA_LADDER for v, _ in ALPHA_VARIANTS},
            sensitivity=dict({"kernel.correction": LINEAR,
                              "kernel.quadrature": NODAL, "time.cfl": CFL},
                             **hourglass_studies(True)),
            checked=["frequency", "mean_deflection", "time_average_deflection_vs_fem"],
            clamps=["root"]),
    Problem("csm1", "Turek & Hron CSM1, static, 2D", "turek_hron_csm1.ini", 2, 0.02,
            [0.005, 0.0025, 0.00125], 0.005, 0.0025, extract_csm1, True,
            "tip displacement (point A)", "m", target=("displacement", 2.0),
            sensitivity=dict({"kernel.support": SUPPORT, "kernel.correction": LINEAR,
                              "kernel.quadrature": NODAL,
                              "time.cfl": CFL, "static.tolerance": TOL},
                             **hourglass_studies(True)),
            checked=["displacement", "ux", "uy"], clamps=["root"],
            newton_memory=NEWTON_MEMORY["csm1"], quick_twin=True, agree=["ux", "uy"]),
    Problem("csm3", "Turek & Hron CSM3, dynamic, 2D", "turek_hron_csm3.ini", 2, 0.02,
            [0.005, 0.0025, 0.00125], 0.005, 0.0025, extract_csm3, False,
            "frequency", "Hz", target=("frequency", 2.0),
            sensitivity=dict({"kernel.support": [2.5, 3.0], "kernel.correction": LINEAR,
                              "kernel.quadrature": NODAL,
                              "time.cfl": CFL}, **hourglass_studies(True)),
            checked=["frequency", "uy_mean", "uy_amp", "ux_mean", "ux_amp"], clamps=["root"]),
    Problem("clamped_plate", "Clamped square plate under pressure, static, 3D",
            "clamped_plate.ini", 3, 0.05, [0.0125, 0.05 / 6, 0.00625, 0.005, 0.003125], 0.0125,
            0.0125, extract_clamped_plate, True, "centre deflection", "m",
            target=("w_vs_fem", 0.5),
            sensitivity=dict({"kernel.support": SUPPORT, "kernel.correction": LINEAR,
                              "kernel.quadrature": NODAL,
                              "time.cfl": CFL, "static.tolerance": TOL},
                             **hourglass_studies(True)),
            checked=["w_vs_fem"], clamps=["left", "right", "front", "back"],
            newton_memory=NEWTON_MEMORY["clamped_plate"], agree=["w"]),
    # The problems with CalculiX references only (validation/fem.py): ladders, no sensitivity
    # studies (budget). "Per thickness": through the section (cantilever), along the loaded
    # edge (Cook, 0.016 m), across the hole's diameter (plate with a hole, 0.02 m).
    Problem("cantilever_large", "Cantilever under a large self-weight (g = 30), static, 3D",
            "cantilever_large.ini", 3, 0.1, [0.025, 0.0125, 0.01], 0.025, 0.025,
            extract_cantilever_large, True, "tip displacement u_z", "m",
            checked=["tip_uz", "tip_ux"], clamps=["root"],
            newton_memory=NEWTON_MEMORY["cantilever_large"], quick_twin=True,
            agree=["tip_uz", "tip_ux"]),
    Problem("cook_membrane", "Cook's membrane, plane strain, nu = 0.3, static, 2D",
            "cook_membrane.ini", 2, 0.016, [0.002, 0.001, 0.0005], 0.002, 0.002,
            extract_cook("cook_membrane"), True, "corner displacement u_y", "m",
            checked=["corner_uy", "corner_ux"], clamps=["left"],
            newton_memory=NEWTON_MEMORY["cook_membrane"], agree=["corner_uy", "corner_ux"]),
    Problem("cook_membrane_incompressible",
            "Cook's membrane, nearly incompressible (nu = 0.4999), static, 2D",
            "cook_membrane_incompressible.ini", 2, 0.016, [0.002, 0.001, 0.0005], 0.002, 0.002,
            extract_cook("cook_membrane_incompressible"), True, "corner displacement u_y", "m",
            checked=["corner_uy", "corner_ux"], clamps=["left"],
            newton_memory=NEWTON_MEMORY["cook_membrane_incompressible"], quick_twin=True,
            agree=["corner_uy", "corner_ux"]),
    Problem("plate_hole", "Plate with a central hole in tension, plane strain, static, 2D",
            "plate_hole.ini", 2, 0.02, [0.0025, 0.00125, 0.000625], 0.0025, 0.0025,
            extract_plate_hole, True, "end displacement u_x", "m",
            checked=["end_ux", "kt_top"], clamps=["left"],
            newton_memory=NEWTON_MEMORY["plate_hole"], agree=["end_ux", "kt_top"]),
    # Bodies meshed by gmsh (particles = the mesh's corner nodes; nodal clamps and pressure
    # loads on its physical groups). Newton memory anchors: the finest Newton runs measured
    # (0.22, 1.37, 0.42 GB). "Per thickness": through the wall (Lame ring, 0.05 m),
    # across the hole's diameter (0.02 m), through the bracket's 10 mm walls.
    Problem("lame_ring", "Thick-walled cylinder (Lame) under internal pressure, gmsh body, "
            "plane strain, static, 2D", "lame_ring.ini", 2, 0.05,
            [0.05 / 8, 0.05 / 16, 0.05 / 32], 0.05 / 8, 0.05 / 8, extract_lame_ring, True,
            "bore radial displacement u(a)", "m", target=("u_a", 1.0),
            checked=["u_a", "stt_a", "stt_s"], clamps=["outer"], newton_memory=(32, 0.22, 2.5),
            quick_twin=True, agree=["u_a", "stt_a"],
            variants=LAME_VARIANTS + [UNIFORM]),
    Problem("lame_cylinder", "Thick-walled cylinder in 3D (Lame) under internal pressure, "
            "gmsh body, ends free, static", "lame_cylinder.ini", 3, 0.05,
            [0.05 / 8, 0.05 / 16], 0.05 / 8, 0.05 / 8, extract_lame_cylinder, True,
            "bore radial displacement u_r(a, L/2)", "m", target=("u_a", 1.0),
            checked=["u_a", "stt_a", "stt_s", "u_end"], clamps=["outer"],
            newton_memory=(16, 1.09, 3.0), agree=["u_a", "stt_a"],
            variants=LAME_VARIANTS + [LINEAR]),
    # The textbook Lame problem: the same ring and cylinder with the outer surface free and
    # nothing holding them (free bodies: the Newton solver leaves the rigid motions out and
    # reports the displacement with zero mean translation and rotation). The damped solver
    # refuses such a body, so these have no damped twins. Headline: the worst of the 32 bore
    # nodes' recovered hoop stress; the target: u(a) and that worst within 1 % at 16 through
    # the wall at the defaults.
    Problem("lame_ring_free", "Free thick-walled cylinder (textbook Lame): internal pressure, "
            "outer surface free, nothing holding it, gmsh body, plane strain, static, 2D",
            "lame_ring_free.ini", 2, 0.05, [0.05 / 8, 0.05 / 16, 0.05 / 32], 0.05 / 8,
            0.05 / 8, extract_lame_free("lame_ring_free"), True,
            "worst bore hoop stress (32 nodes)", "Pa",
            target=("stt_s_worst", 1.0),
            target_at={"per_thickness": 16, "variant": "", "errors": ["u_a", "u_a_worst"]},
            checked=["u_a", "u_a_worst", "stt_s", "stt_s_worst"],
            newton_memory=LAME_FREE_MEMORY["lame_ring_free"], no_twin=FREE_BODY_NO_TWIN,
            variants=[("", {}), NOIC, UNIFORM]),
    Problem("lame_cylinder_free", "Free thick-walled cylinder in 3D (textbook Lame): internal "
            "pressure, outer surface and ends free, nothing holding it, gmsh body, static",
            "lame_cylinder_free.ini", 3, 0.05, [0.05 / 8, 0.05 / 16], 0.05 / 8, 0.05 / 8,
            extract_lame_free("lame_cylinder_free"), True,
            "worst bore hoop stress (32 nodes, L/2)", "Pa",
            target=("stt_s_worst", 1.0),
            target_at={"per_thickness": 16, "variant": "", "errors": ["u_a", "u_a_worst"]},
            checked=["u_a", "u_a_worst", "stt_s", "stt_s_worst", "u_end"],
            newton_memory=LAME_FREE_MEMORY["lame_cylinder_free"], no_twin=FREE_BODY_NO_TWIN),
    Problem("plate_hole_fitted", "Plate with a central hole in tension, gmsh body fitted to "
            "the hole, plane strain, static, 2D", "plate_hole_fitted.ini", 2, 0.02,
            [0.0025, 0.00125, 0.000625], 0.0025, 0.0025, extract_plate_hole_fitted, True,
            "Kt at the hole's top", "-", target=("kt_top", 3.0),
            checked=["kt_top", "end_ux"], clamps=["left"], newton_memory=(32, 1.37, 2.5),
            agree=["end_ux", "kt_top"],
            # the damped twin's cost grows about 8 times per halving of dx (particles x steps)
            twin_skip={0.000625: "damped twin not run: estimated ~45 min on the shared 2-core "
                                 "machine (43 s at 8, 339 s at 16 across the hole; ~8x per "
                                 "halving of dx)"}),
    Problem("bracket", "L-bracket from CAD (examples/bracket.geo), gmsh body, static, 3D",
            "bracket.ini", 3, 0.01, [0.005, 0.0035, 0.0025, 0.00175, 0.00125, 0.001], 0.005, 0.005,
            extract_bracket, True, "arm corner displacement u_x(P)", "m",
            target=("ux_P", 0.3), checked=["ux_P", "uz_P"], clamps=["bolt"],
            newton_memory=(6, 0.42, 3.0), agree=["ux_P", "uz_P"]),
]
BY_KEY = {p.key: p for p in PROBLEMS}
DEFAULTS = {"kernel.support": 2.1, "kernel.correction": "quadratic",
            "kernel.quadrature": "taylor", "hourglass.alpha": 10.0,
            "hourglass.form": "energy", "hourglass.gradient": "corrected",
            "clamp.method": "mirror", "time.cfl": 0.3, "static.tolerance": 1e-5}
SHORT = {"kernel.support": "H", "kernel.correction": "", "kernel.quadrature": "",
         "hourglass.alpha": "alpha",
         "hourglass.form": "hg", "hourglass.gradient": "hggrad", "clamp.method": "clamp",
         "time.cfl": "cfl", "static.tolerance": "tol"}


def fmt(x):
    """Shortest round-trip text of a number ('0.0125', '0.008333333333333333', '10')."""
    if isinstance(x, str):
        return x
    if float(x) == int(x) and abs(x) < 1e6:
        return str(int(x))
    return repr(float(x))


def per_thickness(problem, dx):
    return int(round(problem.thickness / dx))


def run_id(problem, variant, dx, param=None, value=None, twin=None):
    """The run's id (its directory name): problem, variant, particles per thickness, the
    sensitivity value, and for a static ladder's twin the twin's solver."""
    parts = [problem.key]
    if variant:
        parts.append(variant)
    parts.append("n%d" % per_thickness(problem, dx))
    if isinstance(value, dict):
        parts += ["%s%s" % (SHORT[k], fmt(v)) for k, v in value.items()]
    elif param:
        parts.append("%s%s" % (SHORT[param], fmt(value)))
    if twin:
        parts.append(twin)
    return "-".join(parts)


def study_overrides(problem, param, value):
    """The scene keys a sensitivity value sets: one key, or for clamp.method the method of
    every clamp section of the scene."""
    if param == "clamp.method":
        return {"clamp.%s.method" % c: value for c in problem.clamps}
    return {param: "%g" % value if param == "static.tolerance" else fmt(value)}


SOLVERS = ("damped", "newton")
SENSITIVITY_SOLVER = "damped"  # the static problems' sensitivity studies (see the docstring)


def primary_solver(problem):
    """The static solver of a static problem's scene ([static] solver; the program's default
    is damped), None for a dynamic problem."""
    if not problem.static:
        return None
    v = scene_value(ROOT / "validation" / "scenes" / problem.scene, "static", "solver")
    v = (v or "damped").lower()
    if v not in SOLVERS:
        raise SystemExit("%s: [static] solver = %s (one of %s)" % (problem.scene, v,
                                                                   ", ".join(SOLVERS)))
    return v


def other_solver(solver):
    return "damped" if solver == "newton" else "newton"


def plan_runs(quick, sensitivity, only, twins=True):
    """The runs to do, in order: ladders (coarse to fine; a static problem's twin, the same run
    with the other solver, right after its primary run, under the same machine load), then
    sensitivities (a static problem's with SENSITIVITY_SOLVER). A sensitivity run with the same
    settings as a ladder run (an alpha variant's damped twin at the sensitivity resolution) is
    not run twice: the report takes the ladder run. The quick plan has the twins of the
    problems marked quick_twin only."""
    runs = []

    def ladder_run(p, name, ov, dx, with_twin):
        solver = primary_solver(p)
        runs.append(dict(problem=p.key, variant=name, dx=dx, kind="ladder", param=None,
                         value=None, overrides=dict(ov), solver=solver, twin=None))
        if p.static and twins and with_twin and not p.no_twin:
            o = dict(ov)
            o["static.solver"] = other_solver(solver)
            runs.append(dict(problem=p.key, variant=name, dx=dx, kind="ladder", param=None,
                             value=None, overrides=o, solver=o["static.solver"],
                             twin=o["static.solver"]))
            if dx in p.twin_skip:
                runs[-1]["skip_reason"] = p.twin_skip[dx]

    def study_solver(p, o):
        """A static problem's sensitivity run: SENSITIVITY_SOLVER, given explicitly when the
        scene's solver is another."""
        if not p.static:
            return None
        if primary_solver(p) != SENSITIVITY_SOLVER:
            o["static.solver"] = SENSITIVITY_SOLVER
        return SENSITIVITY_SOLVER

    for p in PROBLEMS:
        if only and p.key not in only:
            continue
        if quick:
            name, ov = p.variants[p.quick_variant]
            ladder_run(p, name, ov, p.quick_dx, p.quick_twin)
            continue
        for name, ov in p.variants:
            for dx in p.variant_ladders.get(name, p.ladder):
                ladder_run(p, name, ov, dx, True)
    done = {(r["problem"], r["dx"], tuple(sorted(r["overrides"].items()))) for r in runs}
    if not quick and sensitivity:
        for p in PROBLEMS:
            if only and p.key not in only:
                continue
            name, ov = p.variants[p.sens_variant]
            for param, values in p.sensitivity.items():
                for v in values:
                    o = dict(ov)
                    o.update(study_overrides(p, param, v))
                    solver = study_solver(p, o)
                    if (p.key, p.sens_dx, tuple(sorted(o.items()))) in done:
                        continue
                    runs.append(dict(problem=p.key, variant=name, dx=p.sens_dx,
                                     kind="sensitivity", param=param, value=v, overrides=o,
                                     solver=solver))
            for combo in p.cross:
                o = dict(ov)
                o.update({k: fmt(v) for k, v in combo.items()})
                solver = study_solver(p, o)
                runs.append(dict(problem=p.key, variant=name, dx=p.sens_dx, kind="cross",
                                 param="+".join(combo), value=dict(combo), overrides=o,
                                 solver=solver))
    for r in runs:
        p = BY_KEY[r["problem"]]
        r["id"] = run_id(p, r["variant"], r["dx"], r["param"], r["value"], r.get("twin"))
        if r.get("twin"):
            r["twin_of"] = run_id(p, r["variant"], r["dx"], r["param"], r["value"])
    return runs


# --------------------------------------------------------------------------------------------
# Newton runs' memory prediction; a twin's agreement with its primary


def predict_newton_gb(problem, n, measured):
    """Predicted peak resident memory [GB] of the problem's Newton run at n per thickness,
    and how it was predicted. measured: [(n, GB)] of the problem's Newton runs measured so
    far."""
    n0, gb0, expo = problem.newton_memory or (None, None, None)
    pts = sorted((m, gb) for m, gb in measured if gb)
    basis = "model %g GB at %d through, exponent %g" % (gb0, n0, expo) if n0 else None
    if pts:
        n1, gb1 = pts[-1]
        lower = [q for q in pts if q[0] < n1 and q[1] > MEMORY_FLOOR_GB]
        if lower and expo is not None and gb1 > MEMORY_FLOOR_GB:
            obs = math.log(gb1 / lower[-1][1]) / math.log(n1 / lower[-1][0])
            expo = max(expo, obs)
        elif expo is None:
            expo = 3.0 * problem.dim / 2.0
        n0, gb0 = n1, gb1
        basis = "measured %.3g GB at %d through, exponent %.2f" % (gb1, n1, expo)
    if n0 is None:
        return None, "no model"
    return gb0 * (n / float(n0)) ** expo, basis


def scene_value(scene, section, key):
    """A key of a scene file's section (text, comments stripped), or None."""
    current = None
    for line in Path(scene).read_text().splitlines():
        line = line.split("#", 1)[0].split(";", 1)[0].strip()
        if line.startswith("[") and line.endswith("]"):
            current = line[1:-1].strip()
        elif current == section and "=" in line:
            k, v = (x.strip() for x in line.split("=", 1))
            if k == key:
                return v
    return None


def static_tolerance(problem, run):
    v = run["overrides"].get("static.tolerance") or scene_value(
        ROOT / "validation" / "scenes" / problem.scene, "static", "tolerance")
    return float(v) if v else 1e-5  # the program's default


def agreement(problem, newton_rec, damped_rec):
    """The Newton run's values against the damped run's (one is the primary, the other its
    twin): relative differences (Newton - damped) / |damped| of every value and the check of
    the problem's agree-values against NEWTON_AGREEMENT x the tolerance; both runs must have
    converged."""
    tol = static_tolerance(problem, damped_rec)
    out = {"damped_run": damped_rec["id"], "newton_run": newton_rec["id"],
           "static_tolerance": tol,
           "limit": NEWTON_AGREEMENT * tol, "checked": {}, "relative_differences": {}}
    qn, qd = newton_rec.get("qoi"), damped_rec.get("qoi")
    if not qn or not qd:
        out["ok"] = False
        out["reason"] = "no result: newton %s, damped %s" % (
            newton_rec.get("outcome") or newton_rec.get("rc"),
            damped_rec.get("outcome") or damped_rec.get("rc"))
        return out
    for k, vn in qn["values"].items():
        vd = qd["values"].get(k)
        if (isinstance(vn, float) and isinstance(vd, float) and math.isfinite(vn) and
                math.isfinite(vd) and vd != 0):
            out["relative_differences"][k] = (vn - vd) / abs(vd)
    for k in problem.agree:
        out["checked"][k] = out["relative_differences"].get(k)
    vals = list(out["checked"].values())
    out["max_checked"] = max(abs(v) for v in vals) if vals and None not in vals else None
    out["ok"] = bool(out["max_checked"] is not None and out["max_checked"] <= out["limit"] and
                     newton_rec.get("outcome") == "converged" and
                     damped_rec.get("outcome") == "converged")
    return out


def skipped_newton(problem, run, predicted, basis, budget, git):
    rec = dict(run)
    rec.pop("compare_fields", None)
    rec.update(command=None, git=git["commit"], per_thickness=per_thickness(problem, run["dx"]),
               rc=None, outcome="skipped", qoi=None, wall_runner=0.0, reused=False,
               predicted_memory_gb=predicted, memory_prediction=basis,
               skipped="predicted peak memory %.1f GB > the budget %g GB (%s)" % (
                   predicted, budget, basis))
    return rec


# --------------------------------------------------------------------------------------------
# Running


def rel(path):
    try:
        return str(Path(path).resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


def git_state():
    env = dict(os.environ, GIT_OPTIONAL_LOCKS="0")  # read-only: never refresh the index

    def git(*args):
        try:
            return subprocess.run(["git", "-C", str(ROOT), "--no-optional-locks", *args],
                                  capture_output=True, text=True, env=env,
                                  timeout=60).stdout.rstrip("\n")
        except (OSError, subprocess.SubprocessError):
            return ""

    head = git("rev-parse", "HEAD").strip() or "unknown"
    changed = [line for line in git("status", "--porcelain").splitlines()
               if line.strip() and not line[3:].startswith(("validation/runs/",
                                                            "validation/report/"))]
    return {"commit": head + ("-dirty" if changed else ""), "changed": changed}


def machine_info(threads, build_dir):
    cpu = ""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    version = ""
    try:
        version = subprocess.run([str(Path(build_dir) / "tlsph"), "--version"],
                                 capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        pass
    build_type = ""
    try:
        for line in open(Path(build_dir) / "CMakeCache.txt"):
            if line.startswith("CMAKE_BUILD_TYPE:"):
                build_type = line.split("=", 1)[1].strip()
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "threads": threads,
            "platform": platform.platform(), "python": platform.python_version(),
            "tlsph_version": version, "build_dir": rel(build_dir), "build_type": build_type}


def scene_end_time(scene):
    """[time] end of a scene file (the first and the final frame only when it is the output
    interval)."""
    section = None
    for line in Path(scene).read_text().splitlines():
        line = line.split("#", 1)[0].split(";", 1)[0].strip()
        if line.startswith("[") and line.endswith("]"):
            section = line[1:-1].strip()
        elif section == "time" and "=" in line:
            k, v = (x.strip() for x in line.split("=", 1))
            if k == "end":
                return float(v)
    raise ValueError("%s: no [time] end" % scene)


FIELD_OUTPUT = "displacement cauchy_stress flags"


def wants_fields(problem, run):
    """Field comparison with the FEM: ladder runs (primaries and twins) of the static problems
    that have an FEM VTU, in the full validation only (the quick check writes no frames)."""
    return bool(run.get("compare_fields") and run["kind"] == "ladder" and
                problem.key in FIELD_PROBLEMS)


def build_command(problem, run, build_dir, runs_dir):
    scene = ROOT / "validation" / "scenes" / problem.scene
    outdir = Path(runs_dir) / run["id"]
    if wants_fields(problem, run):
        # the first and the final frame only (a static run writes its converged state)
        output = ["--output.fields=" + FIELD_OUTPUT,
                  "--output.every_time=" + fmt(scene_end_time(scene))]
    else:
        output = ["--output.fields=none"]
    argv = [str(Path(build_dir) / "tlsph"), "run", str(scene),
            "--output.directory=" + str(outdir)] + output + [
            "--no-progress", "--overwrite", "--scene.dx=" + fmt(run["dx"])]
    for k, v in run["overrides"].items():
        argv.append("--%s=%s" % (k, v))
    env = ["OMP_NUM_THREADS=%d" % run["threads"]]
    if run.get("wait_policy"):
        env.append("OMP_WAIT_POLICY=" + run["wait_policy"])
    shown = env + [rel(argv[0])] + argv[1:2] + [rel(scene)]
    shown += ["--output.directory=" + rel(outdir)] + argv[4:]
    return argv, outdir, " ".join(shlex.quote(a) for a in shown)


def rss_kb(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return 0


def run_measured(argv, env, timeout, memory_limit_gb, log_dir):
    """Runs argv with stdout and stderr to files in log_dir. Returns (rc, stderr text, peak
    resident memory in MB or None). rc is "timeout" or "memory-limit" when the watchdog
    stopped the run (after `timeout` s, or above `memory_limit_gb` resident). The peak is the
    child's ru_maxrss (wait4), the kernel's count of its largest resident set."""
    out_path, err_path = log_dir / "runner_stdout.txt", log_dir / "runner_stderr.txt"
    with open(out_path, "w") as out, open(err_path, "w") as err:
        proc = subprocess.Popen(argv, cwd=ROOT, env=env, stdout=out, stderr=err)
    stop, why = threading.Event(), []
    limit_kb = memory_limit_gb * 1024 * 1024 if memory_limit_gb else None

    def watch():
        t0 = time.monotonic()
        while not stop.wait(0.2):
            if time.monotonic() - t0 > timeout:
                why.append("timeout")
            elif limit_kb and rss_kb(proc.pid) > limit_kb:
                why.append("memory-limit")
            if why:
                try:
                    os.kill(proc.pid, 9)  # the child only: it is not reaped before stop is set
                except OSError:
                    pass
                return

    th = threading.Thread(target=watch, daemon=True)
    th.start()
    try:
        os.waitid(os.P_PID, proc.pid, os.WEXITED | os.WNOWAIT)  # exited, not yet reaped
    finally:
        stop.set()
        th.join()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    rc = why[0] if why else proc.returncode
    try:
        err_text = err_path.read_text(errors="replace")
    except OSError:
        err_text = ""
    err_text = err_text[:2000]
    if why:
        err_text += "\nkilled by validation/run.py: %s (%s)" % (
            why[0], "after %s s" % timeout if why[0] == "timeout" else
            "resident memory above %g GB" % memory_limit_gb)
    return rc, err_text, usage.ru_maxrss / 1024.0


def execute(problem, run, build_dir, runs_dir, R, git, reuse, timeout,
            memory_limit_gb=MEMORY_LIMIT_GB):
    argv, outdir, shown = build_command(problem, run, build_dir, runs_dir)
    rec = dict(run)
    rec.pop("compare_fields", None)
    rec.update(command=shown, git=git["commit"],
               per_thickness=per_thickness(problem, run["dx"]))
    sidecar = outdir / "runner.json"
    reused = False
    if reuse and sidecar.exists():
        try:
            old = json.loads(sidecar.read_text())
            scene_changed = (ROOT / "validation" / "scenes" / problem.scene).stat().st_mtime
            if (old.get("argv") == argv and old.get("rc") in (0, 3, 4) and
                    sidecar.stat().st_mtime > scene_changed):
                rec.update(rc=old["rc"], wall_runner=old["wall_runner"],
                           loadavg=old.get("loadavg"), git=old.get("git", git["commit"]),
                           peak_rss_mb=old.get("peak_rss_mb"))
                if old.get("stderr"):
                    rec["stderr"] = old["stderr"]
                if old.get("adopted_from"):  # a run renamed to the id it now has
                    rec["adopted_from"] = old["adopted_from"]
                reused = True
        except (OSError, ValueError):
            pass
    if not reused:
        outdir.mkdir(parents=True, exist_ok=True)
        for name in ("summary.json", "probes.csv", "energies.csv", "compare.json"):
            (outdir / name).unlink(missing_ok=True)
        for old_frame in list(outdir.glob("*.vtu")) + list(outdir.glob("*.pvd")):
            old_frame.unlink()
        env = dict(os.environ, OMP_NUM_THREADS=str(run["threads"]))
        if run.get("wait_policy"):
            env["OMP_WAIT_POLICY"] = run["wait_policy"]
        env.pop("CI", None)
        load0 = os.getloadavg()[0]
        t0 = time.monotonic()
        rc, err, peak = run_measured(argv, env, timeout, memory_limit_gb, outdir)
        wall = time.monotonic() - t0
        rec.update(rc=rc, wall_runner=wall, loadavg=[load0, os.getloadavg()[0]],
                   peak_rss_mb=peak)
        # An unstable run (exit 4) is a result: its stderr is the guard's message (what,
        # where, the likely cause), kept with the record; so is a failure's.
        if rc != 0 and err.strip():
            rec["stderr"] = err
        sidecar.write_text(json.dumps({"argv": argv, "rc": rc, "wall_runner": wall,
                                       "loadavg": rec["loadavg"], "git": git["commit"],
                                       "peak_rss_mb": peak, "stderr": rec.get("stderr")},
                                      indent=1))
    rec["reused"] = reused
    summary = {}
    try:
        summary = json.loads((outdir / "summary.json").read_text())
    except (OSError, ValueError):
        pass
    for k in ("particles", "ghost_particles", "neighbours_min", "neighbours_mean",
              "gradient_correction",
              "neighbours_max", "support_over_dx", "hourglass_alpha", "hourglass_form",
              "hourglass_gradient", "cfl", "dt", "dt_rule_hourglass_speed",
              "dt_rule_limited_by", "steps", "simulated_time", "wall_seconds", "threads",
              "outcome", "residual", "particle_steps_per_second", "instability",
              "static_solver", "newton"):
        rec[k] = summary.get(k)
    rec["qoi"] = None
    try:
        series = read_series(outdir / "probes.csv")
        energies = read_series(outdir / "energies.csv")
    except OSError:
        series, energies = {}, {}
    if energies:
        rec["energy_drift_pct"] = energy_drift(energies)
        # the `hourglass` column: the penalty's energy (form = energy, >= 0) or the textbook
        # force's work (form = ganzenmueller; negative when it feeds energy in)
        rec["hourglass_work_min"] = min(energies.get("hourglass") or [0.0])
    drift = rec.get("energy_drift_pct")
    rec["energy_growth"] = bool(drift is not None and drift > ENERGY_GROWTH_PCT)
    if rec.get("outcome") in ("finished", "converged", "not-converged") and series:
        try:
            rec["qoi"] = problem.extract(series, summary, R)
        except (KeyError, ValueError, TypeError, ZeroDivisionError, IndexError) as e:
            rec["qoi"] = None
            rec["extract_error"] = "%s: %s" % (type(e).__name__, e)
    if not problem.static and run["kind"] == "ladder" and series.get("time"):
        rec["history"] = decimate(series, HISTORY_COLUMNS.get(problem.key, []))
    if wants_fields(problem, run):
        rec["fields"] = compare_fields(problem, rec, build_dir, outdir)
    return rec


def compare_fields(problem, rec, build_dir, outdir):
    """`tlsph compare RUN FEM.vtu --json RUN/compare.json --no-output` on the run's final
    frame: the displacement and stress error norms against the FEM solution (docs/compare.md)."""
    case = FEM_CASE[problem.key]
    vtu = fem_vtu(case)
    out = {"fem_case": case, "fem_vtu": rel(vtu)}
    if not vtu.exists():
        out["skipped"] = "no FEM VTU %s (run /usr/bin/python3 validation/fem.py)" % rel(vtu)
        return out
    if rec.get("outcome") not in ("converged", "finished", "not-converged"):
        out["skipped"] = "run did not finish (%s)" % (rec.get("outcome") or rec.get("rc"))
        return out
    js = outdir / "compare.json"
    js.unlink(missing_ok=True)
    argv = [str(Path(build_dir) / "tlsph"), "compare", str(outdir), str(vtu), "--json",
            str(js), "--no-output"]
    out["command"] = " ".join(shlex.quote(a) for a in
                              [rel(argv[0]), "compare", rel(outdir), rel(vtu), "--json",
                               rel(js), "--no-output"])
    try:
        proc = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=1800)
        if proc.returncode != 0:
            out["error"] = "exit %d: %s" % (proc.returncode, (proc.stderr or "")[-1000:].strip())
            return out
        data = json.loads(js.read_text())
    except (OSError, ValueError, subprocess.SubprocessError) as e:
        out["error"] = "%s: %s" % (type(e).__name__, e)
        return out
    for k in ("frame", "time", "step", "body_particles", "compared_particles",
              "outside_particles"):
        out[k] = data.get(k)
    if isinstance(out.get("frame"), str):
        out["frame"] = rel(out["frame"])
    for name, f in (data.get("fields") or {}).items():
        out[name] = {k: f.get(k) for k in ("unit", "compared", "l2_relative", "rms_absolute",
                                          "max_absolute", "max_at", "max_reference",
                                          "max_relative")}
    out["notes"] = data.get("notes") or []
    out["warnings"] = data.get("warnings") or []
    return out


# Probe columns kept (decimated) in results.json for the time-history plots.
HISTORY_COLUMNS = {"oscillating_plate": ["tip_uy"], "cantilever_dynamic": ["tip_uz"],
                   "csm3": ["A_ux", "A_uy"]}


def decimate(series, columns, points=1500):
    n = len(series["time"])
    step = max(1, n // points)
    idx = list(range(0, n, step))
    if idx[-1] != n - 1:
        idx.append(n - 1)
    out = {"time": [series["time"][i] for i in idx]}
    for c in columns:
        if c in series:
            out[c] = [series[c][i] if math.isfinite(series[c][i]) else None for i in idx]
    return out


# --------------------------------------------------------------------------------------------
# Results file


def load_results(path):
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


def save_json(path, data):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=False) + "\n")
    tmp.replace(path)


def problems_table():
    return {p.key: {"title": p.title, "scene": "validation/scenes/" + p.scene, "dim": p.dim,
                    "thickness": p.thickness, "ladder": p.ladder, "quick_dx": p.quick_dx,
                    "sensitivity_dx": p.sens_dx, "qoi": p.qoi, "unit": p.unit,
                    "static": p.static, "target": p.target,
                    **({"target_at": p.target_at} if p.target_at else {}),
                    "variants": [v for v, _ in p.variants], "checked": p.checked,
                    "variant_overrides": {v: o for v, o in p.variants},
                    "quick_variant": p.variants[p.quick_variant][0],
                    "sensitivity_variant": p.variants[p.sens_variant][0],
                    "variant_ladders": p.variant_ladders,
                    "sensitivity": p.sensitivity, "cross": p.cross,
                    "solver": primary_solver(p),
                    "newton": ({"memory_model": dict(zip(("n_ref", "gb_ref", "exponent"),
                                                         p.newton_memory))
                                if p.newton_memory else None,
                                "agree": p.agree, "quick": p.quick_twin,
                                "twin_solver": (None if p.no_twin else
                                                other_solver(primary_solver(p))),
                                **({"no_twin": p.no_twin} if p.no_twin else {}),
                                "sensitivity_solver": SENSITIVITY_SOLVER,
                                "agreement_factor": NEWTON_AGREEMENT}
                               if p.static else None)}
            for p in PROBLEMS}


# --------------------------------------------------------------------------------------------
# Tolerances and the quick check

MARGIN_PP, MARGIN_REL = 0.2, 0.10


def derive_tolerances(results, path, only=None):
    """tolerances.json from results.json; with `only`, those problems' checks are derived and
    the other problems' entries of the existing file kept as they are (their derivation
    stays the commit that made it)."""
    checks, kept_from = {}, None
    if only:
        try:
            old = json.loads(Path(path).read_text())
        except (OSError, ValueError):
            old = None
        if old:
            own = {run_id(q, q.variants[q.quick_variant][0], q.quick_dx) for q in PROBLEMS
                   if q.key in only}
            checks = {k: v for k, v in old["checks"].items() if k not in own}
            kept_from = {"problems": sorted({q.key for q in PROBLEMS} - set(only)),
                         "derived_from": old.get("derived_from")}
    runs = {r["id"]: r for r in results["runs"]}
    for p in PROBLEMS:
        if only and p.key not in only:
            continue
        run = dict(problem=p.key, variant=p.variants[p.quick_variant][0], dx=p.quick_dx)
        rid = run_id(p, run["variant"], run["dx"])
        r = runs.get(rid)
        if not r or not r.get("qoi"):
            raise SystemExit("derive-tolerances: no result for %s in the report" % rid)
        entry = {"outcome": r["outcome"], "errors": {}}
        for name in p.checked:
            e = r["qoi"]["errors"][name]
            entry["errors"][name] = {
                "report_pct": round(e, 4),
                "max_abs_pct": round(abs(e) + max(MARGIN_PP, MARGIN_REL * abs(e)), 3)}
        checks[rid] = entry
    data = {
        "about": "Quick-check tolerances (validation/run.py --quick --check), derived by "
                 "validation/run.py --derive-tolerances from validation/report/results.json: "
                 "for each checked error, max_abs_pct = |error in the full report at the same "
                 "resolution and settings| + max(%.1f percentage points, %d %% of that error), "
                 "a margin for compiler and platform differences only. Regenerate after a "
                 "change of physics that the full report documents; never loosen by hand."
                 % (MARGIN_PP, int(100 * MARGIN_REL)),
        "derived_from": {"commit": results["meta"].get("git", {}).get("commit"),
                         "generated": results["meta"].get("finished")},
        "checks": {q_id: checks[q_id] for q_id in
                   [run_id(q, q.variants[q.quick_variant][0], q.quick_dx) for q in PROBLEMS]
                   if q_id in checks},
    }
    if kept_from:
        data["derived_from"]["problems"] = sorted(only)
        data["kept"] = kept_from
    save_json(path, data)
    return data


def check_agreement(records):
    """Returns (rows, ok): each twin's agreement with its primary (main() stored it in the
    twin's record). rows: (run id, value, relative difference Newton - damped, limit,
    verdict). A pair with a run skipped for memory is no failure; a pair that ran and does not
    agree (or did not converge) is."""
    rows, ok = [], True
    by_id = {r["id"]: r for r in records}
    for r in records:
        if not r.get("twin"):
            continue
        prim = by_id.get(r.get("twin_of")) or {}
        if r.get("outcome") == "skipped" or prim.get("outcome") == "skipped":
            continue
        a = r.get("agreement") or {}
        if not a.get("checked"):
            rows.append((r["id"], "-", None, a.get("limit"),
                         "FAIL (%s)" % (a.get("reason") or "no primary run to compare with")))
            ok = False
            continue
        conv = r.get("outcome") == "converged" and prim.get("outcome") == "converged"
        for name, d in a["checked"].items():
            good = d is not None and abs(d) <= a["limit"] and conv
            ok &= good
            rows.append((r["id"], name, d, a["limit"],
                         "ok" if good else "FAIL" + ("" if conv else " (%s)" % r.get("outcome"))))
    return rows, ok


def check_against(tolerances, records):
    """Returns (rows, ok). rows: (run id, quantity, error %, tolerance %, verdict)."""
    rows, ok = [], True
    recs = {r["id"]: r for r in records}
    for rid, entry in tolerances["checks"].items():
        r = recs.get(rid)
        if r is None:
            rows.append((rid, "-", None, None, "NOT RUN"))
            ok = False
            continue
        if r.get("outcome") != entry["outcome"]:
            rows.append((rid, "outcome", None, None,
                         "FAIL (%s, expected %s)" % (r.get("outcome"), entry["outcome"])))
            ok = False
            continue
        for name, tol in entry["errors"].items():
            e = (r.get("qoi") or {}).get("errors", {}).get(name)
            good = e is not None and abs(e) <= tol["max_abs_pct"]
            ok &= good
            rows.append((rid, name, e, tol["max_abs_pct"], "ok" if good else "FAIL"))
    return rows, ok


# --------------------------------------------------------------------------------------------
# FEM references


def regenerate_fem(plan, no_fem):
    """The full validation regenerates the FEM references its problems need (validation/fem.py,
    CalculiX; imported here only: it needs numpy) into validation/fem/references.json and
    validation/fem/out/*.vtu, unless --no-fem is given or ccx is missing: then the committed
    references and the existing VTUs are used. Returns what was done, for results.json."""
    cases = sorted({FEM_CASE[r["problem"]] for r in plan if r["problem"] in FEM_CASE})
    info = {"cases": cases}
    if not cases:
        info["note"] = "no problem with an FEM reference in this run"
        return info
    if no_fem:
        info["note"] = "--no-fem: the committed references.json and the existing VTUs used"
    else:
        try:
            import fem
            fem.ccx_path()
        except ImportError as e:
            info["note"] = "validation/fem.py cannot run (%s): committed references used" % e
        except Exception as e:  # fem.FemError: no ccx
            info["note"] = "%s: committed references used" % e
        else:
            print("FEM references: validation/fem.py for %s (CalculiX %s)" % (
                ", ".join(cases), fem.ccx_version()), flush=True)
            t0 = time.monotonic()
            try:
                fem.run_cases(cases, out_dir=FEM_OUT, json_path=FEM_JSON)
                info["regenerated"] = True
                info["note"] = "regenerated by validation/fem.py before the runs"
            except Exception as e:  # fem.FemError, OSError
                info["note"] = ("validation/fem.py failed (%s): the references.json on disk "
                                "used" % e)
            info["seconds"] = round(time.monotonic() - t0, 1)
    missing = [c for c in cases if not fem_vtu(c).exists()]
    if missing:
        info["missing_vtu"] = [rel(fem_vtu(c)) for c in missing]
    print("FEM references: %s%s" % (info["note"], "; no VTU for %s (field errors skipped)"
                                    % ", ".join(missing) if missing else ""), flush=True)
    return info


# --------------------------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--quick", action="store_true",
                    help="one coarse resolution per problem, no sensitivities")
    ap.add_argument("--check", action="store_true",
                    help="compare the errors with validation/tolerances.json; exit 1 on failure")
    ap.add_argument("--report-only", action="store_true",
                    help="regenerate README.md and plots from results.json, run nothing")
    ap.add_argument("--derive-tolerances", action="store_true",
                    help="write validation/tolerances.json from the report's results.json")
    ap.add_argument("--plan", action="store_true", help="list the runs and exit")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1,
                    help="OMP_NUM_THREADS for every run (default: all cores, %(default)s)")
    env_policy = os.environ.get("OMP_WAIT_POLICY", "").lower()
    ap.add_argument("--omp-wait-policy", default=env_policy if env_policy in ("passive", "active")
                    else "", choices=["passive", "active", ""],
                    help="OMP_WAIT_POLICY for every run (default: the runner's own "
                         "OMP_WAIT_POLICY if set, else unset: the OpenMP runtime's "
                         "own policy, which is what a user gets). On a machine shared with "
                         "other busy jobs 'passive' avoids the collapse of spinning barriers "
                         "(10x slower runs seen), at a cost of 15-60 %% on an idle machine")
    ap.add_argument("--binary-commit", default="",
                    help="the commit the binary was built from when that is not the working "
                         "tree (an export made with `git archive COMMIT`); recorded instead of "
                         "the working tree's state")
    ap.add_argument("--build-dir", default=str(ROOT / "build"),
                    help="where build/tlsph is (default: %(default)s)")
    ap.add_argument("--runs-dir", default=None,
                    help="where the runs' output directories go (default: validation/runs, "
                         "or validation/runs/quick with --quick)")
    ap.add_argument("--report-dir", default=str(HERE / "report"),
                    help="README.md, results.json, plots (default: %(default)s)")
    ap.add_argument("--tolerances", default=str(HERE / "tolerances.json"),
                    help="the quick check's tolerances (default: %(default)s)")
    ap.add_argument("--only", default="",
                    help="comma-separated problems (%s); their runs replace those in "
                         "results.json, the others are kept" % ", ".join(BY_KEY))
    ap.add_argument("--no-sensitivity", action="store_true", help="ladders only")
    ap.add_argument("--reuse", action="store_true",
                    help="reuse a run directory whose last run had the same command and is "
                         "newer than its scene file (for development and for resuming an "
                         "interrupted ladder: the binary and commit are not compared)")
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per run")
    ap.add_argument("--no-twins", "--no-newton", dest="no_twins", action="store_true",
                    help="no twins of the static ladders (the runs with the other solver)")
    ap.add_argument("--newton-memory-gb", type=float, default=NEWTON_BUDGET_GB,
                    help="skip a Newton run whose predicted peak memory exceeds this "
                         "(default %(default)s GB)")
    ap.add_argument("--memory-limit-gb", type=float, default=MEMORY_LIMIT_GB,
                    help="stop any run whose resident memory exceeds this (default "
                         "%(default)s GB; 0: no limit)")
    ap.add_argument("--no-fem", action="store_true",
                    help="full validation: do not regenerate the FEM references with "
                         "validation/fem.py (CalculiX); use the committed "
                         "validation/fem/references.json and the VTUs in validation/fem/out/ "
                         "that exist")
    args = ap.parse_args(argv)

    args.build_dir = str(Path(args.build_dir).resolve())
    args.report_dir = str(Path(args.report_dir).resolve())
    args.tolerances = str(Path(args.tolerances).resolve())
    if args.runs_dir:
        args.runs_dir = str(Path(args.runs_dir).resolve())
    only = [s for s in args.only.split(",") if s]
    for s in only:
        if s not in BY_KEY:
            ap.error("unknown problem %r (one of %s)" % (s, ", ".join(BY_KEY)))
    report_dir = Path(args.report_dir)
    results_path = report_dir / "results.json"

    if args.report_only:
        import report
        results = load_results(results_path)
        if not results:
            raise SystemExit("no %s: run the ladder first" % rel(results_path))
        report.write_report(results, report_dir)
        print("wrote %s and plots" % rel(report_dir / "README.md"))
        return 0
    if args.derive_tolerances:
        results = load_results(results_path)
        if not results:
            raise SystemExit("no %s: run the ladder first" % rel(results_path))
        data = derive_tolerances(results, args.tolerances, only)
        print("wrote %s (%d checks)" % (rel(args.tolerances), len(data["checks"])))
        return 0

    runs_dir = Path(args.runs_dir) if args.runs_dir else (
        HERE / "runs" / "quick" if args.quick else HERE / "runs")
    plan = plan_runs(args.quick, not args.no_sensitivity, only, not args.no_twins)
    for r in plan:
        r["threads"] = args.threads
        r["wait_policy"] = args.omp_wait_policy
        r["compare_fields"] = not args.quick  # field errors against the FEM VTU: full only
    if args.plan:
        for r in plan:
            p = BY_KEY[r["problem"]]
            note = ""
            if r.get("skip_reason"):
                note = "   # SKIPPED: " + r["skip_reason"]
            elif r.get("solver") == "newton":
                gb, basis = predict_newton_gb(p, per_thickness(p, r["dx"]), [])
                if gb is not None:
                    note = "   # predicted %.2g GB%s" % (
                        gb, ": SKIPPED (> %g GB)" % args.newton_memory_gb
                        if gb > args.newton_memory_gb else "")
            print("%-45s %s%s" % (r["id"], build_command(p, r, args.build_dir, runs_dir)[2],
                                  note))
        print("%d runs" % len(plan))
        return 0

    tlsph = Path(args.build_dir) / "tlsph"
    if not tlsph.exists():
        raise SystemExit("%s not found: build first (bash scripts/setup.sh build) or pass "
                         "--build-dir" % tlsph)
    tolerances = None
    if args.check:
        try:
            tolerances = json.loads(Path(args.tolerances).read_text())
        except (OSError, ValueError) as e:
            raise SystemExit("cannot read %s: %s" % (args.tolerances, e))

    fem_info = {"references": rel(FEM_JSON), "regenerated": False}
    if not args.quick:
        fem_info.update(regenerate_fem(plan, args.no_fem))
    R = compute_references()
    fem_info["used"] = R["fem"]["cases"]
    git = git_state()
    if args.binary_commit:
        git = {"commit": args.binary_commit, "binary_built_from_export": True,
               "working_tree": git, "changed": []}
    started = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    t_start = time.monotonic()
    meta = {"runner_command": " ".join(["/usr/bin/python3", "validation/run.py"] +
                                       [shlex.quote(a) for a in (argv or sys.argv[1:])]),
            "started": started, "git": git,
            "machine": machine_info(args.threads, args.build_dir),
            "omp_wait_policy": args.omp_wait_policy,
            "quick": args.quick, "fem": fem_info,
            "newton": {"twins": not args.no_twins, "memory_budget_gb": args.newton_memory_gb,
                       "primary_solver": {p.key: primary_solver(p) for p in PROBLEMS
                                          if p.static},
                       "sensitivity_solver": SENSITIVITY_SOLVER,
                       "memory_limit_gb": args.memory_limit_gb,
                       "agreement_factor": NEWTON_AGREEMENT,
                       "memory_measure": "peak resident set of each run (wait4 ru_maxrss)"}}

    if args.quick:
        out_path = runs_dir / "quick-results.json"
        previous = None
    else:
        out_path = results_path
        previous = load_results(results_path) if only else None
    # --only: the other problems' runs are kept; with --no-sensitivity the --only problems'
    # sensitivity studies too (only their ladders are rerun)
    kept = [r for r in (previous or {}).get("runs", []) if r["problem"] not in only or
            (args.no_sensitivity and r["kind"] != "ladder")]
    for r in kept:  # a flag an earlier runner version left in its records
        if not isinstance(r.get("fields"), dict):
            r.pop("fields", None)
    records = []

    def save():
        data = {"schema": 1, "meta": dict(meta), "references": R, "problems": problems_table(),
                "runs": kept + records}
        if previous and only:
            data["meta"]["merged_with"] = previous.get("meta")
        save_json(out_path, data)
        return data

    print("tlsph validation: %d runs, %d threads, runs in %s" % (len(plan), args.threads,
                                                                 rel(runs_dir)))
    print("%-40s %9s %6s %8s %8s %7s  %-13s %s" % ("run", "particles", "nb", "steps",
                                                    "wall s", "MB", "outcome", "error %"))
    by_id = {}
    for r in plan:
        p = BY_KEY[r["problem"]]
        rec = None
        if r.get("skip_reason"):
            rec = dict(r)
            rec.pop("compare_fields", None)
            rec.update(command=None, git=git["commit"], rc=None, outcome="skipped", qoi=None,
                       per_thickness=per_thickness(p, r["dx"]), wall_runner=0.0,
                       reused=False, skipped=r["skip_reason"])
        elif r.get("solver") == "newton":
            measured = [(x["per_thickness"], x["peak_rss_mb"] / 1024.0) for x in records
                        if x["problem"] == p.key and x.get("solver") == "newton" and
                        x.get("peak_rss_mb") and x.get("outcome") == "converged"]
            gb, basis = predict_newton_gb(p, per_thickness(p, r["dx"]), measured)
            if gb is not None and gb > args.newton_memory_gb:
                rec = skipped_newton(p, r, gb, basis, args.newton_memory_gb, git)
        if rec is None:
            rec = execute(p, r, args.build_dir, runs_dir, R, git, args.reuse, args.timeout,
                          args.memory_limit_gb)
            if r.get("solver") == "newton":
                rec["predicted_memory_gb"], rec["memory_prediction"] = gb, basis
        if r.get("twin"):
            prim = by_id.get(r["twin_of"])
            if prim is None:
                rec["agreement"] = {"ok": False, "reason": "primary run %s not in this "
                                    "invocation" % r["twin_of"]}
            elif "skipped" not in (rec.get("outcome"), prim.get("outcome")):
                nd = (rec, prim) if rec.get("solver") == "newton" else (prim, rec)
                rec["agreement"] = agreement(p, *nd)
        records.append(rec)
        by_id[rec["id"]] = rec
        q = rec.get("qoi")
        err = q["errors"].get(q["primary"]) if q else None
        extra = ""
        if rec.get("skipped"):
            extra = "  " + rec["skipped"]
        elif rec.get("agreement"):
            a = rec["agreement"]
            extra = "  newton vs damped: %s" % (
                "max %.1e (limit %.0e) %s" % (a["max_checked"], a["limit"],
                                              "ok" if a["ok"] else "FAIL")
                if a.get("max_checked") is not None else a.get("reason", "FAIL"))
        print("%-40s %9s %6s %8s %8s %7s  %-13s %s%s" % (
            rec["id"], rec.get("particles"),
            "%.1f" % rec["neighbours_mean"] if rec.get("neighbours_mean") else "-",
            rec.get("steps"), "%.1f" % rec["wall_runner"],
            "%.0f" % rec["peak_rss_mb"] if rec.get("peak_rss_mb") else "-",
            rec.get("outcome") or rec.get("rc"),
            "%+.3f (%s)" % (err, q["primary"]) if err is not None else "-", extra), flush=True)
        meta["elapsed_seconds"] = time.monotonic() - t_start
        save()
    meta["finished"] = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    meta["elapsed_seconds"] = time.monotonic() - t_start
    data = save()
    print("total %.0f s (sum of run wall times %.0f s); results in %s" % (
        meta["elapsed_seconds"], sum(r["wall_runner"] for r in records), rel(out_path)))

    status = 0
    if not args.quick:
        try:
            import report
            report.write_report(data, report_dir)
            print("wrote %s and plots" % rel(report_dir / "README.md"))
        except ImportError as e:
            print("no report plots (%s): install python3-numpy python3-matplotlib, then "
                  "run with --report-only" % e)
    if args.check:
        if only:  # --only: the other problems' checks are not this invocation's
            own = {run_id(q, q.variants[q.quick_variant][0], q.quick_dx) for q in PROBLEMS
                   if q.key in only}
            tolerances = dict(tolerances, checks={k: v for k, v in tolerances["checks"].items()
                                                  if k in own})
        rows, ok = check_against(tolerances, records)
        print()
        print("%-36s %-26s %10s %10s  %s" % ("run", "error", "error %", "max |%|", "verdict"))
        for rid, name, e, tol, verdict in rows:
            print("%-36s %-26s %10s %10s  %s" % (rid, name, "%+.3f" % e if e is not None else "-",
                                                "%.3f" % tol if tol is not None else "-",
                                                verdict))
        arows, aok = check_agreement(records)
        if arows:
            print()
            print("%-36s %-26s %10s %10s  %s" % ("twin", "value", "Newton-damped",
                                                 "limit", "verdict"))
            for rid, name, d, lim, verdict in arows:
                print("%-36s %-26s %10s %10s  %s" % (
                    rid, name, "%+.1e" % d if d is not None else "-",
                    "%.0e" % lim if lim is not None else "-", verdict))
        ok = ok and aok
        print("validation check: %s" % ("PASSED" if ok else "FAILED"))
        status = 0 if ok else 1
    return status


if __name__ == "__main__":
    sys.exit(main())
