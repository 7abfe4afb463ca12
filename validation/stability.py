#!/usr/bin/env python3
"""tlsph stability map: where does the explicit step stop being stable, case by case?

From the repository root (the build must exist: `bash scripts/setup.sh build`):

  /usr/bin/python3 validation/stability.py                 # the whole map (~15-25 min on 2
                                                           # cores); writes validation/report/
  /usr/bin/python3 validation/stability.py --plan          # list the cases and runs, run nothing
  /usr/bin/python3 validation/stability.py --only a,f      # some cases (group letters, case
                                                           # keys or fnmatch patterns)
  /usr/bin/python3 validation/stability.py --report-only   # stability.md + plots from the JSON

`bash scripts/setup.sh stability` installs what is missing, builds and runs the whole map.

Cases (scenes in validation/stability/, each file says what it is and why):
  a. near-incompressible neo-Hookean, nu = 0.45, 0.49, 0.499: a block compressed by 30 %, a
     column bending in its first mode;
  b. the same cantilever in steel and in rubber (the same dimensionless problem);
  c. large deformation: a column twisted by 180 degrees (prescribed rotation of its top
     layer), a cantilever bent to a tip rotation over 60 degrees, a bar compressed to J = 0.5
     and one stretched to 2;
  d. hourglass coefficient alpha = 0.1, 1, 10, 30, 100 on an undamped 2D and 3D cantilever;
  e. long undamped runs, 20 periods, 2D and 3D (4 particles through the thickness);
  f. a bar struck at one end (velocity step): front speed and stress against 1D theory,
     without and with artificial viscosity.

For every case: one run at the default time-step rule (no [time] cfl given), then a sweep of
--time.cfl over CFL_VALUES in increasing order that stops at the first unstable value, and one
bisection between the last stable and the first unstable value (if 0.2 is already unstable,
0.1 is tried first). Unstable means exit status 4 (a [guard] check failed: non-finite state,
inverted material, or energy books off by more than [guard] energy_error, 5 % by default).

Each run is `build/tlsph run validation/stability/<scene>.ini --output.directory=
validation/runs/stability/<id> --output.fields=none --no-progress --overwrite [overrides]` with
OMP_NUM_THREADS = --threads (default: all cores), one after another. Recorded per run: exit
status, outcome, wall time, steps, dt, the energy drift max_t |total(t) - total(0)| / max_t
(kinetic + strain) from energies.csv (total is the balance of the energy books, so it
includes the work of loads and boundaries and what damping removed), every field of
summary.json (the predicted-step fields, whatever their names, are picked out), the last
lines of stderr (the guard's message), and per case a few physical quantities from probes.csv
(twist angle, tip rotation, stretch, front speed...). Records go to
validation/report/stability.json; validation/report/stability.md and the PNG plots
(stability_*.png) are made from that file (numpy and matplotlib are needed for the plots
only). A case that is unstable at the default rule is a result: the report names it, with
its energy history and the guard's message.

Running and parsing use the Python standard library only.
"""

import argparse
import fnmatch
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SCENES = HERE / "stability"
REPORT = HERE / "report"
RUNS = HERE / "runs" / "stability"
JSON_PATH = REPORT / "stability.json"
MD_PATH = REPORT / "stability.md"

CFL_VALUES = [0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0, 1.2, 1.5]
UNSTABLE_EXIT = 4
HISTORY_POINTS = 200  # energy-history samples kept per default or unstable run for the plots
STDERR_LINES = 25
WAIT_POLICY = None  # OMP_WAIT_POLICY of the runs (--wait-policy)

# --------------------------------------------------------------------------------------------
# Reading a run


def finite(x):
    return x is not None and isinstance(x, (int, float)) and math.isfinite(x)


def energy_drift(e):
    """max |total - total_0| / max (kinetic + strain), over the rows with finite books; also
    the same at the end of the run, signed, and the largest hourglass energy relative to the
    same scale."""
    tot = e.get("total")
    if not tot:
        return {}
    rows = [i for i in range(len(tot)) if all(math.isfinite(e[k][i]) for k in
                                               ("total", "kinetic", "strain"))]
    if not rows:
        return {"finite_rows": 0}
    t0 = tot[rows[0]]
    scale = max(e["kinetic"][i] + e["strain"][i] for i in rows)
    out = {"finite_rows": len(rows), "rows": len(tot), "scale": scale}
    if scale > 0 and len(rows) >= 2:  # one row (t = 0) says nothing about a drift
        out["drift"] = max(abs(tot[i] - t0) for i in rows) / scale
        out["drift_end"] = (tot[rows[-1]] - t0) / scale
        if "hourglass" in e:
            out["hourglass_max"] = max(abs(e["hourglass"][i]) for i in rows
                                       if math.isfinite(e["hourglass"][i])) / scale
    return out


def history(e, points=HISTORY_POINTS):
    """A thinned copy of the energy series for the plots (every row kept near the end, where
    an instability shows)."""
    n = len(e.get("time", []))
    if n == 0:
        return None
    keep = sorted(set(list(range(0, n, max(1, n // points))) + list(range(max(0, n - 20), n))))
    out = {}
    for k in ("time", "kinetic", "strain", "hourglass", "total"):
        if k in e:
            out[k] = [float("%.6g" % e[k][i]) if math.isfinite(e[k][i]) else None for i in keep]
    return out


# --------------------------------------------------------------------------------------------
# Quantities of interest per kind of scene (from probes.csv). Each returns a flat dict.


def q_tip_amplitude(p, name="tip", axis="uy"):
    """Tip amplitude in the first and the last fifth of the run, and their ratio (> 1: the
    undamped vibration grows)."""
    t, u = p.get("time"), p.get(name + "_" + axis)
    if not t or not u or len(t) < 10:
        return {}
    n = len(t)
    first = [abs(x) for x in u[: max(2, n // 5)] if math.isfinite(x)]
    last = [abs(x) for x in u[-max(2, n // 5):] if math.isfinite(x)]
    out = {"tip_amplitude_first": max(first) if first else None,
           "tip_amplitude_last": max(last) if last else None}
    if first and last and max(first) > 0:
        out["amplitude_ratio"] = max(last) / max(first)
    # periods from the zero crossings of the tip velocity or displacement
    cross = []
    for i in range(1, n):
        a, b = u[i - 1], u[i]
        if math.isfinite(a) and math.isfinite(b) and (a < 0) != (b < 0) and a != b:
            cross.append(t[i - 1] + (t[i] - t[i - 1]) * a / (a - b))
    if len(cross) >= 3:
        out["period"] = 2.0 * (cross[-1] - cross[0]) / (len(cross) - 1)
        out["periods_simulated"] = t[-1] / out["period"]
    return out


def unwrap(angles):
    out, shift = [], 0.0
    for i, a in enumerate(angles):
        if i and math.isfinite(a) and math.isfinite(angles[i - 1]):
            d = a - angles[i - 1]
            if d > math.pi:
                shift -= 2 * math.pi
            elif d < -math.pi:
                shift += 2 * math.pi
        out.append(a + shift)
    return out


def q_twist(p):
    """Twist angle (degrees) of the corner probes about the column axis (0.025, 0.025)."""
    out = {}
    for name, z in (("mid", 0.1), ("top", 0.1875)):
        if name + "_ux" not in p:
            continue
        ang = [math.atan2(0.025 + uy, 0.025 + ux) - math.pi / 4
               for ux, uy in zip(p[name + "_ux"], p[name + "_uy"])]
        ang = unwrap(ang)
        fin = [a for a in ang if math.isfinite(a)]
        if fin:
            out["twist_%s_deg" % name] = math.degrees(fin[-1])
    return out


def q_tip_rotation(p):
    """Tip rotation (degrees) of the segment between the probes at x = 0.09 and the tip."""
    if "tip_ux" not in p:
        return {}
    rot = []
    for a, b, c, d in zip(p["tip_ux"], p["tip_uy"], p["x009_ux"], p["x009_uy"]):
        rot.append(math.degrees(math.atan2(-(b - d), 0.01 + a - c)))
    fin = [r for r in rot if math.isfinite(r)]
    if not fin:
        return {}
    return {"tip_rotation_end_deg": fin[-1], "tip_rotation_max_deg": max(fin),
            "tip_uy_end": p["tip_uy"][len(fin) - 1]}


def q_stretch(p):
    """Stretch lambda_1 = J (nu = 0) between the probes at x = 0.0125 and 0.0375."""
    if "a_ux" not in p:
        return {}
    lam = [1.0 + (b - a) / 0.025 for a, b in zip(p["a_ux"], p["b_ux"])]
    fin = [x for x in lam if math.isfinite(x)]
    if not fin:
        return {}
    return {"stretch_end": fin[-1], "stretch_min": min(fin), "stretch_max": max(fin)}


def q_block(p):
    if "side_ux" not in p:
        return {}
    fin = [x for x in p["side_ux"] if math.isfinite(x)]
    return {"bulge_end": fin[-1]} if fin else {}


IMPACT_V0, IMPACT_C, IMPACT_E, IMPACT_RHO = 1.0, 100.0, 1.0e7, 1000.0
IMPACT_TIMES = [0.001, 0.002, 0.003]


def q_impact(p):
    """Front speed (arrival of v = v0/2 at each probe, least-squares line), the mean velocity
    and stress behind the front, the velocity overshoot, and the profiles at IMPACT_TIMES.
    Probe xNNN sits at x = NNN mm on the centre line."""
    t = p.get("time")
    if not t:
        return {}
    names = sorted({k[:-3] for k in p if k.startswith("x") and k.endswith("_vx")},
                   key=lambda n: int(n[1:]))
    xs = [int(n[1:]) / 1000.0 for n in names]
    arrivals = []
    for x, n in zip(xs, names):
        v = p[n + "_vx"]
        for i in range(1, len(t)):
            if math.isfinite(v[i]) and v[i] >= 0.5 * IMPACT_V0 > v[i - 1]:
                ta = t[i - 1] + (t[i] - t[i - 1]) * (0.5 * IMPACT_V0 - v[i - 1]) / (v[i] - v[i - 1])
                arrivals.append((x, ta))
                break
    out = {"theory_c": IMPACT_C, "theory_stress": -IMPACT_RHO * IMPACT_C * IMPACT_V0,
           "theory_v": IMPACT_V0}
    if len(arrivals) >= 3:
        n = len(arrivals)
        mx = sum(a[0] for a in arrivals) / n
        mt = sum(a[1] for a in arrivals) / n
        sxx = sum((a[0] - mx) ** 2 for a in arrivals)
        sxt = sum((a[0] - mx) * (a[1] - mt) for a in arrivals)
        if sxt > 0:
            out["front_speed"] = sxx / sxt
            out["front_speed_error_pct"] = 100.0 * (out["front_speed"] / IMPACT_C - 1.0)
    profiles = {}
    for tp in IMPACT_TIMES:
        i = min(range(len(t)), key=lambda k: abs(t[k] - tp))
        vel = [p[n + "_vx"][i] for n in names]
        mid = [0.5 * (xs[k] + xs[k + 1]) for k in range(len(xs) - 1)]
        sig = [IMPACT_E * (p[names[k + 1] + "_ux"][i] - p[names[k] + "_ux"][i]) /
               (xs[k + 1] - xs[k]) for k in range(len(xs) - 1)]
        profiles["%g" % tp] = {"time": t[i], "x": xs, "v": [float("%.6g" % v) for v in vel],
                               "x_stress": mid, "stress": [float("%.6g" % s) for s in sig]}
    out["profiles"] = profiles
    # behind the front at the last profile time: probes more than 0.05 m behind it
    tp = IMPACT_TIMES[-1]
    prof = profiles["%g" % tp]
    front = IMPACT_C * prof["time"]
    v_behind = [v for x, v in zip(prof["x"], prof["v"]) if x < front - 0.05 and finite(v)]
    s_behind = [s for x, s in zip(prof["x_stress"], prof["stress"]) if x < front - 0.05
                and finite(s)]
    if v_behind:
        out["v_behind_mean"] = sum(v_behind) / len(v_behind)
        out["v_behind_max"] = max(v_behind)
        out["v_overshoot_pct"] = 100.0 * (max(v_behind) / IMPACT_V0 - 1.0)
    if s_behind:
        out["stress_behind_mean"] = sum(s_behind) / len(s_behind)
        out["stress_error_pct"] = 100.0 * (out["stress_behind_mean"] / out["theory_stress"] - 1.0)
    # the largest speed anywhere over the run: ringing ahead of and behind the front
    vmax = [max(abs(x) for x in p[n + "_vx"] if math.isfinite(x)) for n in names
            if n + "_vx" in p]
    if vmax:
        out["v_max_any"] = max(vmax)
    return out


EXTRACT = {
    "block": q_block,
    "column": lambda p: q_tip_amplitude(p, "top", "ux"),
    "beam": lambda p: q_tip_amplitude(p, "tip", "uy"),
    "beam3d": lambda p: q_tip_amplitude(p, "tip", "uz"),
    "twist": q_twist,
    "tip_rotation": q_tip_rotation,
    "stretch": q_stretch,
    "impact": q_impact,
}

# --------------------------------------------------------------------------------------------
# Cases


class Case:
    def __init__(self, key, group, title, scene, overrides=None, extract=None, requires=None,
                 note=""):
        self.key, self.group, self.title, self.scene = key, group, title, scene
        self.overrides = overrides or {}
        self.extract = extract
        self.requires = requires  # a scene key that must exist (tlsph check), else skipped
        self.note = note


GROUPS = {
    "a": "Near-incompressible neo-Hookean (nu -> 1/2)",
    "b": "Steel beside rubber, same resolution",
    "c": "Large deformation",
    "d": "Hourglass coefficient alpha, undamped cantilevers",
    "e": "Long undamped runs (20 periods)",
    "f": "Bar struck at one end (velocity step)",
}

NU = [("045", "0.45"), ("049", "0.49"), ("0499", "0.499")]
ALPHAS = ["0.1", "1", "10", "30", "100"]
STEEL = {"material.beam.youngs_modulus": "210e9", "material.beam.density": "7850",
         "time.end": "0.00456"}
AV_VARIANTS = [("av", "1", "2", "Monaghan's q1 = 1, q2 = 2"),
               ("av_light", "0.1", "0", "light, q1 = 0.1, q2 = 0")]

CASES = []
for tag, nu in NU:
    CASES.append(Case("a_block_nu" + tag, "a", "block compressed 30 %%, 2D, nu = %s" % nu,
                      "compress_block.ini", {"material.rubber.poisson_ratio": nu}, "block"))
for tag, nu in NU:
    CASES.append(Case("a_column_nu" + tag, "a", "column, first bending mode, 2D, nu = %s" % nu,
                      "column_bending.ini", {"material.rubber.poisson_ratio": nu}, "column"))
CASES += [
    Case("b_beam_rubber", "b", "cantilever, rubber (E = 10 MPa, rho 1000), 2D",
         "beam_vibration.ini", {}, "beam"),
    Case("b_beam_steel", "b", "cantilever, steel (E = 210 GPa, rho 7850), 2D",
         "beam_vibration.ini", STEEL, "beam",
         note="Steel and rubber are the same dimensionless problem (same nu, same V_f, the "
              "run covers two periods of each): the measured limits, drifts and step counts "
              "must agree; a difference would mean an absolute (unit-dependent) threshold "
              "somewhere."),
    Case("c_twist", "c", "column twisted 180 degrees, 3D", "twist_column.ini", {}, "twist"),
    Case("c_cantilever_large", "c", "cantilever, tip rotation ~75 degrees, 2D",
         "cantilever_large.ini", {}, "tip_rotation"),
    Case("c_compress_J05", "c", "bar compressed to J = 0.5, 2D", "bar_uniaxial.ini", {},
         "stretch",
         note="What to look for: near J = 0.5 the free lateral faces of a compressed "
              "neo-Hookean solid can wrinkle (Biot's surface instability, at a stretch of 0.544 "
              "for an incompressible one in plane strain; the critical stretch depends on the "
              "compressibility), and with no intrinsic wavelength the discretisation picks the "
              "particle scale. In the development runs the kinetic and hourglass energies jumped "
              "as the stretch reached about 0.5, while the energy books stayed balanced: a "
              "physical instability resolved at the particle scale, not a failing time step. "
              "The drift, max hourglass and stretch columns show what this run did."),
    Case("c_tension_2", "c", "bar stretched to 2, 2D", "bar_uniaxial.ini",
         {"prescribe.right.value": "0.0475 0"}, "stretch"),
]
for a in ALPHAS:
    CASES.append(Case("d_2d_alpha" + a, "d", "2D cantilever, alpha = " + a, "cantilever_2d.ini",
                      {"hourglass.alpha": a}, "beam"))
for a in ALPHAS:
    CASES.append(Case("d_3d_alpha" + a, "d", "3D cantilever, alpha = " + a, "cantilever_3d.ini",
                      {"hourglass.alpha": a}, "beam3d"))
CASES += [
    Case("e_long_2d", "e", "2D cantilever (4 through), 20 periods or more", "cantilever_2d.ini",
         {"time.end": "5.6"}, "beam"),
    Case("e_long_3d", "e", "3D cantilever (4 through), 20 periods or more", "cantilever_3d.ini",
         {"time.end": "14"}, "beam3d"),
    Case("f_impact", "f", "bar struck at one end, no artificial viscosity", "bar_impact.ini", {},
         "impact"),
]
for tag, q1, q2, what in AV_VARIANTS:
    CASES.append(Case("f_impact_" + tag, "f", "bar struck at one end, artificial viscosity " + what,
                      "bar_impact.ini",
                      {"artificial_viscosity.linear": q1, "artificial_viscosity.quadratic": q2},
                      "impact", requires="artificial_viscosity.linear"))
BY_KEY = {c.key: c for c in CASES}


def select(only):
    if not only:
        return list(CASES)
    pats = [s for part in only for s in part.replace(",", " ").split()]

    def matches(pat, c):
        # a case key selects that case only; otherwise a group letter, a pattern (d_3d_*) or
        # a prefix of keys (d_3d)
        if pat in BY_KEY:
            return pat == c.key
        return pat == c.group or fnmatch.fnmatch(c.key, pat) or c.key.startswith(pat + "_")

    out = [c for c in CASES if any(matches(pat, c) for pat in pats)]
    unknown = [p for p in pats if not any(matches(p, c) for c in CASES)]
    if unknown:
        sys.exit("stability.py: --only: no case matches %s (cases: %s)" %
                 (", ".join(unknown), ", ".join(sorted(set(c.group for c in CASES)) +
                                               [c.key for c in CASES])))
    return out


# --------------------------------------------------------------------------------------------
# Running


# rel, git_state and machine_info are the validation runner's own (validation/run.py).
from run import git_state, machine_info, read_series, rel  # noqa: E402



def fmt_cfl(c):
    return ("%.4f" % c).rstrip("0").rstrip(".")


def run_id(case, cfl, suffix=""):
    return case.key + ("__default" if cfl is None else "__cfl" + fmt_cfl(cfl)) + suffix


def argv_for(case, cfl, build_dir, check=False, extra=None, suffix=""):
    # Paths relative to the repository root, where the runs start (summary.json records them).
    argv = [str(Path(build_dir) / "tlsph"), "check" if check else "run", rel(SCENES / case.scene)]
    if not check:
        argv += ["--output.directory=" + rel(RUNS / run_id(case, cfl, suffix)),
                 "--output.fields=none", "--no-progress", "--overwrite"]
    for k, v in case.overrides.items():
        argv.append("--%s=%s" % (k, v))
    if cfl is not None:
        # The sweep measures the cfl rule alone: the operator's cap on the step would hold
        # every run below its limit.
        argv.append("--time.cfl=" + fmt_cfl(cfl))
        argv.append("--time.spectral_limit=false")
    argv += extra or []
    return argv


def shown(argv, threads):
    return " ".join(["OMP_NUM_THREADS=%d" % threads, rel(argv[0])] +
                    [shlex.quote(a) for a in argv[1:]])


def feature_available(case, build_dir):
    """True if `tlsph check` accepts the case's required key (exit status 0)."""
    if not case.requires:
        return True, ""
    argv = argv_for(case, None, build_dir, check=True)
    try:
        r = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.SubprocessError) as e:
        return False, str(e)
    if r.returncode == 0:
        return True, ""
    lines = (r.stderr.strip() or r.stdout.strip()).splitlines()
    return False, "exit %d: %s" % (r.returncode, lines[-1] if lines else "")


def check_text(case, build_dir):
    """`tlsph check` of the case at the default rule: its 'time' line (dt and the rule) and
    any line that mentions a stable or predicted step."""
    try:
        r = subprocess.run(argv_for(case, None, build_dir, check=True), cwd=ROOT,
                           capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.SubprocessError) as e:
        return {"rc": None, "error": str(e)}
    lines = [l for l in r.stdout.splitlines()
             if l.startswith("time") or "stable" in l.lower() or "predicted" in l.lower()
             or "hourglass" in l.lower() or l.startswith("particles")]
    out = {"rc": r.returncode, "lines": lines,
           "error": r.stderr.strip()[-500:] if r.returncode else ""}
    # dx and the largest dilatational wave speed, for the rule-independent Courant number
    # dt c / dx (the check prints 'dx = ... m' and '... wave speed ... m/s' per material)
    speeds = []
    for l in r.stdout.splitlines():
        try:
            if l.startswith("particles") and "dx = " in l:
                out["dx"] = float(l.split("dx = ", 1)[1].split()[0])
            if l.startswith("material") and "wave speed" in l:
                speeds.append(float(l.split("wave speed", 1)[1].split()[0]))
        except (ValueError, IndexError):
            pass
    if speeds:
        out["wave_speed"] = max(speeds)
    return out


PREDICTED_HINTS = ("dt", "cfl", "stable", "predicted", "time_step", "timestep", "wave_speed",
                   "step_limit", "hourglass_stiff")


def predicted_fields(summary):
    return {k: v for k, v in summary.items()
            if any(h in k.lower() for h in PREDICTED_HINTS) and k not in ("steps",)}


def execute(case, cfl, build_dir, threads, timeout, git, extra=None, suffix=""):
    argv = argv_for(case, cfl, build_dir, extra=extra, suffix=suffix)
    outdir = RUNS / run_id(case, cfl, suffix)
    if outdir.exists():
        shutil.rmtree(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    if WAIT_POLICY:
        env["OMP_WAIT_POLICY"] = WAIT_POLICY
        rec_env = "OMP_WAIT_POLICY=" + WAIT_POLICY
    else:
        rec_env = ""
    rec = {"id": run_id(case, cfl, suffix), "case": case.key, "group": case.group, "cfl": cfl,
           "command": (rec_env + " " if rec_env else "") + shown(argv, threads),
           "git": git["commit"], "threads": threads}
    try:
        rec["loadavg"] = os.getloadavg()[0]  # load before the run: wall times are only
    except OSError:                          # comparable on a quiet machine
        pass
    t0 = time.monotonic()
    try:
        r = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=timeout)
        rc, out, err = r.returncode, r.stdout, r.stderr
    except subprocess.TimeoutExpired as e:
        rc = None
        out = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
        err = e.stderr.decode() if isinstance(e.stderr, bytes) else (e.stderr or "")
        err += "\nstability.py: killed after the %g s timeout" % timeout
    rec["wall_runner"] = time.monotonic() - t0
    (outdir / "stdout.txt").write_text(out)
    (outdir / "stderr.txt").write_text(err)
    rec["exit"] = rc
    rec["status"] = ("stable" if rc == 0 else "unstable" if rc == UNSTABLE_EXIT else
                     "timeout" if rc is None else "error")
    rec["stderr"] = "\n".join(err.strip().splitlines()[-STDERR_LINES:])
    summary = {}
    try:
        summary = json.loads((outdir / "summary.json").read_text())
    except (OSError, ValueError):
        pass
    rec["summary"] = {k: v for k, v in summary.items()
                      if k not in ("pvd", "energies", "probes", "command", "source")}
    for k in ("outcome", "dt", "steps", "simulated_time", "wall_seconds", "particles",
              "dimension"):
        rec[k] = summary.get(k)
    rec["cfl_used"] = summary.get("cfl")  # the [time] cfl the run used (the default's value)
    rec["predicted"] = predicted_fields(summary)
    e = read_series(outdir / "energies.csv")
    rec["energy"] = energy_drift(e)
    rec["drift"] = rec["energy"].get("drift")
    if cfl is None or rec["status"] != "stable":
        rec["history"] = history(e)
    if case.extract:
        try:
            rec["quantities"] = EXTRACT[case.extract](read_series(outdir / "probes.csv"))
        except (KeyError, ValueError, ZeroDivisionError) as ex:
            rec["quantities"] = {"error": repr(ex)}
    return rec


def describe(rec):
    d = rec.get("drift")
    return "%-32s %-9s exit %s  dt %s  steps %s  wall %.1f s  drift %s" % (
        rec["id"], rec["status"], rec["exit"],
        "%.4g" % rec["dt"] if finite(rec.get("dt")) else "-",
        rec.get("steps"), rec["wall_runner"], "%.3g" % d if finite(d) else "-")


def check_dt(case, cfl, build_dir):
    """dt that `tlsph check` prints for the case at this cfl (None if it cannot be read)."""
    try:
        r = subprocess.run(argv_for(case, cfl, build_dir, check=True), cwd=ROOT,
                           capture_output=True, text=True, timeout=120)
        for line in r.stdout.splitlines():
            if line.startswith("time") and "dt = " in line:
                return float(line.split("dt = ", 1)[1].split()[0])
    except (OSError, subprocess.SubprocessError, ValueError, IndexError):
        pass
    return None


def sweep(case, build_dir, threads, timeout, git, cfl_values, log):
    """Default run, then the CFL sweep with one bisection. Returns the records. A sweep value
    equal to the default's cfl whose dt (`tlsph check`) is the default run's dt is the same
    run: its record is copied from the default run, marked `reused`."""
    recs = []

    def go(cfl):
        d = recs[0] if recs else None
        if d is not None and cfl is not None and d.get("cfl_used") == cfl and finite(d.get("dt")):
            dt = check_dt(case, cfl, build_dir)
            if dt is not None and abs(dt - d["dt"]) <= 1e-5 * d["dt"]:
                rec = json.loads(json.dumps(d))
                rec.update(id=run_id(case, cfl), cfl=cfl, reused=d["id"], wall_runner=0.0,
                           history=None)
                recs.append(rec)
                log(describe(rec) + "  (the default run: same cfl and dt)")
                return rec["status"]
        rec = execute(case, cfl, build_dir, threads, timeout, git)
        recs.append(rec)
        log(describe(rec))
        return rec["status"]

    go(None)
    d = recs[0]
    if d["status"] == "unstable" and finite(d.get("steps")) and d["steps"] > 0:
        # Unstable at the default rule: the energy history is the result to show, and the
        # scene's energies.csv rows may be too sparse to see it (a blow-up within one guard
        # interval leaves one or two rows). The same run again with about 2000 rows up to the
        # stop; it goes into the plot only, not into the map.
        every = max(1, int(d["steps"]) // 2000)
        h = execute(case, None, build_dir, threads, timeout, git,
                    extra=["--output.series_every_steps=%d" % every], suffix="_history")
        if h.get("history") and h.get("steps") == d.get("steps"):
            d["history"] = h["history"]
            d["history_note"] = ("energy history from the same run repeated with "
                                 "--output.series_every_steps=%d" % every)
        log("   (energy history of the default run: %s, %s rows, stopped at step %s)" % (
            h["id"], (h.get("energy") or {}).get("rows"), h.get("steps")))
    stable_max = unstable_min = None
    stop_note = ""
    for c in cfl_values:
        s = go(c)
        if s == "stable":
            stable_max = c
            continue
        if s == "unstable":
            unstable_min = c
        else:  # an error or a timeout says nothing about stability: stop, no bisection
            stop_note = "the sweep stopped at cfl %s: %s (exit %s)" % (
                fmt_cfl(c), s, recs[-1]["exit"])
        break
    if unstable_min is not None and stable_max is None and unstable_min > 0.1:
        lower = round(unstable_min / 2, 4)
        if go(lower) == "stable":
            stable_max = lower
        else:
            unstable_min = lower
    if stable_max is not None and unstable_min is not None:
        mid = round(0.5 * (stable_max + unstable_min), 4)
        if go(mid) == "stable":
            stable_max = mid
        else:
            unstable_min = mid
    # Keep the records small: energy histories of the default run and of the lowest unstable
    # cfl only, probe profiles of the default run only.
    for r in recs:
        if r["cfl"] is not None:
            if r["cfl"] != unstable_min:
                r.pop("history", None)
            if isinstance(r.get("quantities"), dict):
                r["quantities"].pop("profiles", None)
    return recs, {"stable_max": stable_max, "unstable_min": unstable_min,
                  "sweep_note": stop_note}


# --------------------------------------------------------------------------------------------
# Records


def load_results():
    try:
        return json.loads(JSON_PATH.read_text())
    except (OSError, ValueError):
        return {"meta": {}, "cases": {}, "records": []}


def save_results(res):
    REPORT.mkdir(parents=True, exist_ok=True)
    tmp = JSON_PATH.with_suffix(".json.tmp")

    def clean(x):  # strict JSON: non-finite numbers become null
        if isinstance(x, float) and not math.isfinite(x):
            return None
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v) for v in x]
        return x

    def one(x):
        return json.dumps(clean(x), separators=(",", ":"), allow_nan=False)

    # One line per case and per record: small, and diffs stay readable.
    lines = ['{"meta":' + one(res.get("meta", {})) + ',', '"cases":{']
    items = list(res.get("cases", {}).items())
    lines += ["%s:%s%s" % (one(k), one(v), "," if i + 1 < len(items) else "")
              for i, (k, v) in enumerate(items)]
    lines += ["},", '"records":[']
    recs = res.get("records", [])
    lines += [one(r) + ("," if i + 1 < len(recs) else "") for i, r in enumerate(recs)]
    lines += ["]}"]
    tmp.write_text("\n".join(lines) + "\n")
    json.loads(tmp.read_text())
    os.replace(tmp, JSON_PATH)


def case_summary(case, recs, limits, skipped=""):
    d = next((r for r in recs if r["cfl"] is None), None)
    out = {"key": case.key, "group": case.group, "title": case.title, "scene": case.scene,
           "overrides": case.overrides, "skipped": skipped, "note": case.note}
    out.update(limits or {})
    if d:
        out["default"] = {k: d.get(k) for k in ("status", "exit", "cfl_used", "dt", "steps",
                                                 "wall_runner", "drift", "particles",
                                                 "dimension")}
        out["predicted"] = d.get("predicted", {})
        dt0 = d.get("dt")
        lim = limits.get("stable_max") if limits else None
        at = next((r for r in recs if r["cfl"] == lim), None) if lim is not None else None
        if at and finite(at.get("dt")) and finite(dt0) and dt0 > 0:
            out["dt_stable_max"] = at["dt"]
            out["dt_margin"] = at["dt"] / dt0  # measured largest stable dt / the default dt
        un = limits.get("unstable_min") if limits else None
        atu = next((r for r in recs if r["cfl"] == un), None) if un is not None else None
        if atu and finite(atu.get("dt")):
            out["dt_unstable_min"] = atu["dt"]
    return out


# --------------------------------------------------------------------------------------------
# Report


def fnum(x, spec="%.3g"):
    return spec % x if finite(x) else "-"


def status_mark(s):
    return {"stable": "stable", "unstable": "**UNSTABLE**", "error": "error",
            "timeout": "timeout"}.get(s, s or "-")


def limit_text(c):
    a, b = c.get("stable_max"), c.get("unstable_min")
    if c.get("skipped"):
        return "skipped"
    if a is None and b is None:
        return c.get("sweep_note") or "-"
    if b is None:
        return ">= %s (stable at every value tried%s)" % (
            fmt_cfl(a), "; " + c["sweep_note"] if c.get("sweep_note") else "")
    if a is None:
        return "< %s" % fmt_cfl(b)
    return "%s - %s" % (fmt_cfl(a), fmt_cfl(b))


def quantity_text(case_key, q):
    if not q:
        return ""
    if "error" in q:
        return "extraction failed: " + q["error"]
    parts = []
    for k, spec, unit in (("twist_top_deg", "%.1f", " deg"), ("twist_mid_deg", "%.1f", " deg"),
                          ("tip_rotation_end_deg", "%.1f", " deg"),
                          ("tip_rotation_max_deg", "%.1f", " deg"),
                          ("stretch_end", "%.3f", ""), ("stretch_min", "%.3f", ""),
                          ("stretch_max", "%.3f", ""), ("bulge_end", "%.4g", " m"),
                          ("amplitude_ratio", "%.3f", ""), ("period", "%.4g", " s"),
                          ("periods_simulated", "%.1f", ""),
                          ("front_speed", "%.2f", " m/s"), ("front_speed_error_pct", "%+.2f", " %"),
                          ("stress_behind_mean", "%.4g", " Pa"),
                          ("stress_error_pct", "%+.2f", " %"),
                          ("v_overshoot_pct", "%+.1f", " %")):
        if k in q and finite(q[k]):
            parts.append("%s %s%s" % (k, spec % q[k], unit))
    return ", ".join(parts)


def make_plots(res, log):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        log("stability.py: matplotlib not available, no plots")
        return []
    files = []
    for old in REPORT.glob("stability_*.png"):  # a plot not made again is stale
        old.unlink()
    cases = [c for c in res["cases"].values()]
    order = [c.key for c in CASES if c.key in res["cases"]]
    cases = [res["cases"][k] for k in order]
    recs = res["records"]
    by_case = {}
    for r in recs:
        by_case.setdefault(r["case"], []).append(r)
    colour = {"stable": "#2ca02c", "unstable": "#d62728", "error": "#7f7f7f",
              "timeout": "#ff7f0e"}

    # 1. the map: against the cfl setting, and against the Courant number dt c / dx (c the
    # dilatational wave speed), which does not depend on what the step rule does with cfl
    height = 0.32 * len(cases) + 1.6
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(15, height), sharey=True,
                                  gridspec_kw={"width_ratios": [1, 1]})
    xmax = 0.1
    for row, c in enumerate(cases):
        y = len(cases) - 1 - row
        cdx = (c["wave_speed"] / c["dx"]) if finite(c.get("wave_speed")) and \
            finite(c.get("dx")) and c["dx"] > 0 else None
        for r in by_case.get(c["key"], []):
            cour = r["dt"] * cdx if cdx and finite(r.get("dt")) else None
            if r["cfl"] is None:
                x = r.get("cfl_used")
                for a_, xx in ((ax, x), (ax2, cour)):
                    if finite(xx):
                        a_.scatter([xx], [y], marker="*", s=170, zorder=4, edgecolors="k",
                                   color=colour.get(r["status"], "k"), linewidths=0.8)
            else:
                xmax = max(xmax, r["cfl"])
                ax.scatter([r["cfl"]], [y], marker="s", s=60,
                           color=colour.get(r["status"], "k"), zorder=3)
                if finite(cour):
                    ax2.scatter([cour], [y], marker="s", s=60,
                                color=colour.get(r["status"], "k"), zorder=3)
        if c.get("stable_max") is not None and c.get("unstable_min") is not None:
            ax.plot([c["stable_max"], c["unstable_min"]], [y, y], color="k", lw=0.8, zorder=2)
        if c.get("skipped"):
            ax.text(0.05, y, "skipped: " + c["skipped"][:60], va="center", fontsize=7)
    ax.set_yticks(range(len(cases)))
    ax.set_yticklabels([c["key"] for c in reversed(cases)], fontsize=8)
    ax.set_xlabel("[time] cfl (the setting)")
    ax.set_xlim(0, xmax + 0.1)
    ax.set_ylim(-0.7, len(cases) - 0.3)
    ax.grid(axis="x", alpha=0.3)
    ax2.set_xlabel("Courant number dt c / dx, c = sqrt((lambda + 2 mu)/rho0) (tlsph check)")
    ax2.set_xlim(left=0)
    ax2.grid(axis="x", alpha=0.3)
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], marker="s", ls="", color=colour["stable"], label="stable"),
               Line2D([], [], marker="s", ls="", color=colour["unstable"],
                      label="unstable (exit 4)"),
               Line2D([], [], marker="s", ls="", color=colour["error"], label="error/timeout"),
               Line2D([], [], marker="*", ls="", color="w", markeredgecolor="k", ms=12,
                      label="default rule")]
    fig.suptitle("Stability map: measured runs per case")
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 1.0 - 0.45 / height),
               ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 1.0 - 0.75 / height))
    path = REPORT / "stability_map.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    files.append(path)

    # 2. drift against cfl, one panel per group
    groups = [g for g in GROUPS if any(c["group"] == g for c in cases)]
    if groups:
        ncol = 3
        nrow = (len(groups) + ncol - 1) // ncol
        fig, axes = plt.subplots(nrow, ncol, figsize=(13, 3.6 * nrow), squeeze=False)
        for k, g in enumerate(groups):
            ax = axes[k // ncol][k % ncol]
            for c in cases:
                if c["group"] != g:
                    continue
                pts = sorted((r["cfl"], r["drift"], r["status"]) for r in by_case.get(c["key"], [])
                             if r["cfl"] is not None and finite(r.get("drift")))
                if not pts:
                    continue
                line, = ax.plot([p[0] for p in pts], [max(p[1], 1e-12) for p in pts], "-",
                                lw=1, label=c["key"])
                for p in pts:
                    ax.plot(p[0], max(p[1], 1e-12), "o" if p[2] == "stable" else "x",
                            color=line.get_color(), ms=5)
                d = next((r for r in by_case.get(c["key"], []) if r["cfl"] is None), None)
                if d and finite(d.get("drift")) and finite(d.get("cfl_used")):
                    ax.plot(d["cfl_used"], max(d["drift"], 1e-12), "*", color=line.get_color(),
                            ms=11, markeredgecolor="k")
            ax.set_yscale("log")
            ax.set_xlabel("[time] cfl")
            ax.set_ylabel("energy drift / max(E_kin + E_strain)")
            ax.set_title("%s. %s" % (g, GROUPS[g]), fontsize=9)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=6)
        for k in range(len(groups), nrow * ncol):
            axes[k // ncol][k % ncol].axis("off")
        fig.suptitle("Energy drift against CFL (o stable, x unstable, * default rule)")
        fig.tight_layout()
        path = REPORT / "stability_drift.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        files.append(path)

    # 3. wall time
    fig, ax = plt.subplots(figsize=(10, 0.3 * len(cases) + 1.5))
    total = [sum(r["wall_runner"] for r in by_case.get(c["key"], [])) for c in cases]
    default = [next((r["wall_runner"] for r in by_case.get(c["key"], []) if r["cfl"] is None), 0)
               for c in cases]
    ys = list(range(len(cases)))[::-1]
    ax.barh(ys, total, color="#9ecae1", label="all runs of the case")
    ax.barh(ys, default, color="#3182bd", label="run at the default rule")
    ax.set_yticks(ys)
    ax.set_yticklabels([c["key"] for c in cases], fontsize=8)
    ax.set_xlabel("wall time [s]")
    ax.legend(fontsize=8)
    ax.set_title("Wall time per case (%.0f s in all)" % sum(total))
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    path = REPORT / "stability_wall_time.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    files.append(path)

    # 4. energy histories of the cases unstable at the default rule
    bad = [r for r in recs if r["cfl"] is None and r["status"] != "stable" and r.get("history")]
    if bad:
        ncol = 2
        nrow = (len(bad) + 1) // 2
        fig, axes = plt.subplots(nrow, ncol, figsize=(12, 3.4 * nrow), squeeze=False)
        for k, r in enumerate(bad):
            ax = axes[k // ncol][k % ncol]
            h = r["history"]
            for name in ("kinetic", "strain", "hourglass", "total"):
                if name in h:
                    ax.plot(h["time"], [v if v is not None else float("nan") for v in h[name]],
                            label=name)
            ax.set_title("%s at the default rule: %s (exit %s)" % (r["case"], r["status"],
                                                                 r["exit"]), fontsize=9)
            ax.set_xlabel("time [s]")
            ax.set_ylabel("energy [J]")
            ax.set_yscale("symlog", linthresh=1e-6)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        for k in range(len(bad), nrow * ncol):
            axes[k // ncol][k % ncol].axis("off")
        fig.tight_layout()
        path = REPORT / "stability_unstable_default.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        files.append(path)

    # 5. the struck bar: velocity and stress profiles
    impact = [r for r in recs if r["cfl"] is None and r["case"].startswith("f_")
              and (r.get("quantities") or {}).get("profiles")]
    if impact:
        fig, axes = plt.subplots(2, 1, figsize=(10, 7.5), sharex=True)
        styles = ["-", "--", ":", "-."]
        for k, r in enumerate(impact):
            for j, (tp, prof) in enumerate(sorted(r["quantities"]["profiles"].items())):
                col = "C%d" % j
                lab = "%s, t = %.1f ms" % (r["case"], 1e3 * prof["time"])
                axes[0].plot(prof["x"], prof["v"], styles[k % 4], color=col, lw=1.2, label=lab)
                axes[1].plot(prof["x_stress"], [s / 1e3 for s in prof["stress"]], styles[k % 4],
                             color=col, lw=1.2, label=lab)
        for j, tp in enumerate(IMPACT_TIMES):
            xf = IMPACT_C * tp
            axes[0].plot([0, xf, xf, 0.5], [IMPACT_V0, IMPACT_V0, 0, 0], color="k", lw=0.6,
                         alpha=0.5)
            axes[1].plot([0, xf, xf, 0.5], [-IMPACT_RHO * IMPACT_C * IMPACT_V0 / 1e3] * 2 + [0, 0],
                         color="k", lw=0.6, alpha=0.5)
        axes[0].set_ylabel("v_x [m/s]")
        axes[1].set_ylabel("sigma_xx = E du/dx [kPa]")
        axes[1].set_xlabel("x [m]")
        axes[0].set_title("Bar struck at x = 0 with v0 = 1 m/s: profiles at 1, 2, 3 ms "
                          "(thin black: 1D theory)")
        axes[0].legend(fontsize=7, ncol=2)
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.tight_layout()
        path = REPORT / "stability_impact.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        files.append(path)
    return files


def write_report(res, plots):
    meta = res.get("meta", {})
    cases = [res["cases"][c.key] for c in CASES if c.key in res["cases"]]
    recs = res["records"]
    by_case = {}
    for r in recs:
        by_case.setdefault(r["case"], []).append(r)
    L = []
    w = L.append
    w("# Stability map")
    w("")
    w("Where the explicit step stops being stable, case by case: one run at the default "
      "time-step rule (no `[time] cfl` given), then `--time.cfl` swept over %s in increasing "
      "order until the first unstable value, and one bisection between the last stable and the "
      "first unstable value. *Unstable* is exit status 4: a `[guard]` check failed (non-finite "
      "state, inverted material, or energy books off by more than `[guard] energy_error`, 5 %% "
      "by default). Made by `validation/stability.py` from `stability.json`; the scenes, each "
      "saying what it is, are in `validation/stability/`." % ", ".join(fmt_cfl(c) for c in
                                                                      CFL_VALUES))
    w("")
    w("```sh")
    w("bash scripts/setup.sh stability                    # install, build, run the whole map")
    w("/usr/bin/python3 validation/stability.py --plan    # what would run")
    w("/usr/bin/python3 validation/stability.py --only c_twist,f   # some cases")
    w("/usr/bin/python3 validation/stability.py --report-only      # this page from the JSON")
    w("```")
    w("")
    if meta:
        w("Runs: %s; commit `%s`; %s, %s threads (%s cores); `%s`; %s." % (
            meta.get("date", "?"), meta.get("git", "?"), meta.get("cpu", "?"),
            meta.get("threads", "?"), meta.get("cores", "?"), meta.get("tlsph_version", "?"),
            meta.get("wall_total") and "%.0f s of runs in all" % meta["wall_total"] or ""))
        if meta.get("partial"):
            w("")
            w("**Partial map**: " + meta["partial"])
        w("")
    w("**Energy drift** = max over the run of |total(t) - total(0)| divided by the largest "
      "kinetic + strain energy of the run, from `energies.csv` (`total` is the balance of the "
      "books: kinetic + strain + hourglass - work of loads and boundaries + what damping took "
      "out). **dt c / dx**: the measured limit as a Courant number of the material's "
      "dilatational wave speed c = sqrt((lambda + 2 mu)/rho0) (from `tlsph check`), whatever "
      "the rule does with cfl. **dt margin** = the largest stable dt measured / dt of the "
      "default rule. "
      "**Predicted step**: the `summary.json` fields about the step rule at run time "
      "(whatever their names: %s), reported as found. **Wall times** are per run with "
      "`OMP_NUM_THREADS` = the threads above, one run at a time; `(load)` is the 1-minute load "
      "average when the run started: on a shared machine (load above the core count) wall "
      "times are not comparable. A sweep value equal to the default's cfl with the same dt is "
      "the default run itself (`= default`)." % ", ".join("`%s`" % h for h in PREDICTED_HINTS))
    w("")
    # headline table
    w("## Summary")
    w("")
    w("| case | particles | default rule: cfl, dt | status | steps | wall [s] | energy drift "
      "| measured limit (cfl: last stable - first unstable) | same as dt c / dx | dt margin "
      "| predicted step (summary.json) |")
    w("|---|---|---|---|---|---|---|---|---|---|---|")
    for c in cases:
        d = c.get("default") or {}
        pred = c.get("predicted") or {}
        pred_txt = ", ".join("%s = %s" % (k, fnum(v, "%.4g") if isinstance(v, (int, float))
                                          else v) for k, v in pred.items()
                             if k not in ("dt", "cfl"))
        if c.get("skipped"):
            w("| %s | - | - | skipped | - | - | - | - | - | - | %s |" % (c["key"], c["skipped"]))
            continue
        cdx = (c["wave_speed"] / c["dx"]) if finite(c.get("wave_speed")) and \
            finite(c.get("dx")) and c["dx"] > 0 else None
        courant = "-"
        if cdx:
            lo = c.get("dt_stable_max")
            hi = c.get("dt_unstable_min")
            if finite(lo) and finite(hi):
                courant = "%.3g - %.3g" % (lo * cdx, hi * cdx)
            elif finite(lo):
                courant = ">= %.3g" % (lo * cdx)
            elif finite(hi):
                courant = "< %.3g" % (hi * cdx)
        w("| %s | %s | %s, %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            c["key"], d.get("particles", "-"), fnum(d.get("cfl_used"), "%.3g"),
            fnum(d.get("dt"), "%.4g"), status_mark(d.get("status")), d.get("steps", "-"),
            fnum(d.get("wall_runner"), "%.1f"), fnum(d.get("drift"), "%.2e"), limit_text(c),
            courant, fnum(c.get("dt_margin"), "%.2f"), pred_txt or "-"))
    w("")
    bad = [c for c in cases if (c.get("default") or {}).get("status") not in (None, "stable")]
    w("## Unstable at the default rule")
    w("")
    if not bad:
        w("None: every case ran to its end at the default rule.")
        w("")
    else:
        w("These cases fail **at the default time-step rule**; this is a result, not a "
          "setting to tune away. Energy histories: `stability_unstable_default.png`.")
        w("")
        for c in bad:
            r = next(x for x in by_case[c["key"]] if x["cfl"] is None)
            w("### %s: %s (exit %s)" % (c["key"], c["title"], r["exit"]))
            w("")
            w("`%s`" % r["command"])
            w("")
            en = r.get("energy") or {}
            w("Stopped at step %s, t = %s s, dt %s; energy drift up to the stop %s (%s of %s "
              "energies.csv rows finite)." % (
                  r.get("steps", "-"), fnum(r.get("simulated_time"), "%.4g"),
                  fnum(r.get("dt"), "%.4g"), fnum(r.get("drift"), "%.2e"),
                  en.get("finite_rows", "-"), en.get("rows", "-")))
            w("")
            w("```")
            w(r.get("stderr", "").strip() or "(nothing on stderr)")
            w("```")
            w("")
    if any(p.name == "stability_unstable_default.png" for p in plots) or bad:
        w("![energy histories of the cases unstable at the default rule]"
          "(stability_unstable_default.png)")
        w("")
    w("## Plots")
    w("")
    w("![stability map](stability_map.png)")
    w("")
    w("![energy drift against cfl](stability_drift.png)")
    w("")
    w("![wall time](stability_wall_time.png)")
    w("")
    # per group
    for g, gtitle in GROUPS.items():
        gc = [c for c in cases if c["group"] == g]
        if not gc:
            continue
        w("## %s. %s" % (g, gtitle))
        w("")
        for c in gc:
            w("**%s** (%s): %s; scene `validation/stability/%s`%s." % (
                c["key"], limit_text(c), c["title"], c["scene"],
                (", overrides " + " ".join("`--%s=%s`" % kv for kv in c["overrides"].items()))
                if c["overrides"] else ""))
            chk = [l for l in (c.get("check") or []) if l.startswith("time")]
            if chk:
                w("")
                w("`tlsph check` at the default rule: " + "; ".join(
                    "`%s`" % " ".join(l.split()) for l in chk))
            note = BY_KEY[c["key"]].note if c["key"] in BY_KEY else c.get("note")
            if note:
                w("")
                w(note)
            if c.get("skipped"):
                w("")
                w("Skipped: %s" % c["skipped"])
                w("")
                continue
            w("")
            w("| cfl | status | exit | dt | steps | wall [s] (load) | drift | drift at end | max "
              "hourglass / scale | quantities |")
            w("|---|---|---|---|---|---|---|---|---|---|")
            rows = sorted(by_case.get(c["key"], []), key=lambda r: (r["cfl"] is not None,
                                                                    r["cfl"] or 0))
            for r in rows:
                en = r.get("energy") or {}
                w("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                    "default (%s)" % fnum(r.get("cfl_used"), "%.3g") if r["cfl"] is None
                    else fmt_cfl(r["cfl"]), status_mark(r["status"]), r["exit"],
                    fnum(r.get("dt"), "%.4g"), r.get("steps", "-"),
                    "= default" if r.get("reused") else "%s (%s)" % (
                        fnum(r["wall_runner"], "%.1f"), fnum(r.get("loadavg"), "%.1f")),
                    fnum(r.get("drift"), "%.2e"),
                    fnum(en.get("drift_end"), "%+.2e"), fnum(en.get("hourglass_max"), "%.2e"),
                    quantity_text(c["key"], r.get("quantities"))))
            w("")
            first_bad = next((r for r in rows if r["cfl"] is not None and
                              r["status"] != "stable"), None)
            if first_bad and first_bad.get("stderr"):
                msg = [l for l in first_bad["stderr"].splitlines() if l.strip()]
                w("First unstable run (cfl %s), the guard's message:" % fmt_cfl(first_bad["cfl"]))
                w("")
                w("```")
                w("\n".join(msg[-8:]))
                w("```")
                w("")
        if g == "f":
            w("1D theory: front speed c = sqrt(E/rho0) = %g m/s, behind it v = %g m/s and "
              "sigma_xx = -rho0 c v0 = %g Pa. Measured at the default rule (front speed from "
              "the arrival of v0/2 at the probes, least squares; velocity and stress averaged "
              "over the probes more than 0.05 m behind the front at 3 ms; stress from the "
              "displacement difference of probes 10 mm apart):" % (
                  IMPACT_C, IMPACT_V0, -IMPACT_RHO * IMPACT_C * IMPACT_V0))
            w("")
            w("| case | front speed [m/s] | error | v behind [m/s] | overshoot | stress behind "
              "[Pa] | error | max speed anywhere [m/s] |")
            w("|---|---|---|---|---|---|---|---|")
            for c in gc:
                r = next((x for x in by_case.get(c["key"], []) if x["cfl"] is None), None)
                if not r:
                    continue
                q = r.get("quantities") or {}
                w("| %s | %s | %s %% | %s | %s %% | %s | %s %% | %s |" % (
                    c["key"], fnum(q.get("front_speed"), "%.2f"),
                    fnum(q.get("front_speed_error_pct"), "%+.2f"),
                    fnum(q.get("v_behind_mean"), "%.4f"), fnum(q.get("v_overshoot_pct"), "%+.1f"),
                    fnum(q.get("stress_behind_mean"), "%.5g"),
                    fnum(q.get("stress_error_pct"), "%+.2f"), fnum(q.get("v_max_any"), "%.3f")))
            w("")
            if any(p.name == "stability_impact.png" for p in plots):
                w("![struck bar profiles](stability_impact.png)")
                w("")
    w("## Records")
    w("")
    w("Every run's record (command, exit status, outcome, wall time, steps, dt, energy drift, "
      "all of summary.json, the end of stderr, the quantities) is in `stability.json`; the run "
      "directories are `validation/runs/stability/<id>/` (not committed).")
    w("")
    MD_PATH.write_text("\n".join(L) + "\n")


def report(res, log):
    plots = make_plots(res, log)
    write_report(res, plots)
    log("wrote %s%s" % (rel(MD_PATH), "".join(", " + rel(p) for p in plots)))


# --------------------------------------------------------------------------------------------


def plan(selected, build_dir, cfl_values):
    exe = Path(build_dir) / "tlsph"
    print("Stability map: %d cases; per case the default rule, then --time.cfl in %s until the "
          "first unstable value, plus one bisection (0.1 first if 0.2 is unstable)." % (
              len(selected), " ".join(fmt_cfl(c) for c in cfl_values)))
    print("Runs go to %s/<case>__default, <case>__cfl<value>." % rel(RUNS))
    total = 0.0
    for c in selected:
        line = "%-22s %s. %s\n    %s" % (c.key, c.group, c.title,
                                         shown(argv_for(c, None, build_dir), os.cpu_count()))
        if c.requires:
            line += "\n    needs the scene key %s (checked with `tlsph check`; skipped if absent)" \
                    % c.requires
        if exe.exists():
            chk = check_text(c, build_dir)
            if chk.get("rc") == 0:
                tl = [l for l in chk["lines"] if l.startswith("time")]
                pl = [l for l in chk["lines"] if l.startswith("particles")]
                if tl and pl:
                    try:
                        steps = float(tl[0].split(",")[-1].split()[0])
                        n = float(pl[0].split()[1])
                        total += n * steps
                        line += "\n    %d particles; %s; %.2g particle-steps at the default " \
                                "rule" % (n, tl[0].split(None, 1)[1], n * steps)
                    except (ValueError, IndexError):
                        line += "\n    " + "; ".join(chk["lines"])
            else:
                line += "\n    tlsph check failed: %s" % chk.get("error", "")[-200:]
        print(line)
    if total:
        print("Default-rule runs: %.3g particle-steps in all; a sweep costs about 5x that "
              "(runs at cfl 0.2 ... the limit)." % total)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", action="store_true", help="list the cases and runs, run nothing")
    ap.add_argument("--only", nargs="+", help="cases: group letters (a..f), case keys or "
                    "patterns, comma or space separated")
    ap.add_argument("--build-dir", default=str(ROOT / "build"), help="where tlsph is (build)")
    ap.add_argument("--report-only", action="store_true",
                    help="rebuild stability.md and the plots from stability.json")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1,
                    help="OMP_NUM_THREADS of each run (default: all cores)")
    ap.add_argument("--cfl", help="comma-separated sweep values (default %s)" %
                    ",".join(fmt_cfl(c) for c in CFL_VALUES))
    ap.add_argument("--timeout", type=float, default=1200.0, help="seconds per run (1200)")
    ap.add_argument("--wait-policy", choices=["active", "passive"],
                    help="OMP_WAIT_POLICY of the runs (default: OpenMP's); passive keeps wall "
                         "times sane on a machine shared with other jobs")
    args = ap.parse_args()
    build_dir = Path(args.build_dir)
    if not build_dir.is_absolute():
        build_dir = (Path.cwd() / build_dir).resolve()
    cfl_values = sorted(float(x) for x in args.cfl.split(",")) if args.cfl else CFL_VALUES
    global WAIT_POLICY
    WAIT_POLICY = args.wait_policy or os.environ.get("OMP_WAIT_POLICY") or None
    selected = select(args.only)

    def log(msg):
        print(msg, flush=True)

    if args.plan:
        plan(selected, build_dir, cfl_values)
        return 0
    if args.report_only:
        res = load_results()
        if not res.get("records"):
            sys.exit("stability.py: no records in %s; run the map first" % rel(JSON_PATH))
        report(res, log)
        return 0
    exe = build_dir / "tlsph"
    if not exe.exists():
        sys.exit("stability.py: %s not found; build first (bash scripts/setup.sh build) or give "
                 "--build-dir" % exe)
    git = git_state()
    res = load_results()
    keys = {c.key for c in selected}
    res["records"] = [r for r in res.get("records", []) if r["case"] not in keys]
    res["cases"] = {k: v for k, v in res.get("cases", {}).items() if k not in keys}
    meta = machine_info(args.threads, build_dir)
    meta.update(git=git["commit"], date=time.strftime("%Y-%m-%d %H:%M:%S"),
                cfl_values=cfl_values, changed=git["changed"], wait_policy=WAIT_POLICY)
    start = time.monotonic()
    for c in selected:
        log("== %s: %s" % (c.key, c.title))
        ok, why = feature_available(c, build_dir)
        if not ok:
            note = ("the scene key %s is not accepted by this build of tlsph (tlsph check: %s)"
                    % (c.requires, why))
            log("   skipped: " + note)
            res["cases"][c.key] = case_summary(c, [], None, skipped=note)
            save_results(res)
            continue
        chk = check_text(c, build_dir)
        recs, limits = sweep(c, build_dir, args.threads, args.timeout, git, cfl_values, log)
        for r in recs:
            r["check"] = chk.get("lines") if r["cfl"] is None else None
        res["records"] += recs
        res["cases"][c.key] = case_summary(c, recs, limits)
        res["cases"][c.key]["check"] = chk.get("lines")
        res["cases"][c.key]["dx"] = chk.get("dx")
        res["cases"][c.key]["wave_speed"] = chk.get("wave_speed")
        log("   limit: %s" % limit_text(res["cases"][c.key]))
        meta["wall_total"] = sum(r["wall_runner"] for r in res["records"])
        all_keys = {k.key for k in CASES}
        missing = sorted(all_keys - set(res["cases"]))
        meta["partial"] = ("%d of %d cases have no records: %s" % (len(missing), len(all_keys),
                                                                   ", ".join(missing))
                           if missing else "")
        res["meta"] = meta
        save_results(res)
    log("map: %.0f s" % (time.monotonic() - start))
    report(res, log)
    return 0


if __name__ == "__main__":
    sys.exit(main())
