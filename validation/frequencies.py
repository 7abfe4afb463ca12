#!/usr/bin/env python3
"""Natural frequencies of tlsph (`tlsph modes`, docs/modes.md) against CalculiX and beam theory.

Runs `tlsph modes` on

* the 3D cantilever examples/cantilever.ini (1 x 0.1 x 0.1 m, E = 1e7 Pa, nu = 0.3,
  rho = 1000 kg/m^3, clamped at x = 0 by mirrored ghosts) at 4, 6, 8, 10 particles through the
  0.1 m side (--scene.dx = 0.1/n), 8 modes: the first bending pair, the second bending pair,
  the first torsion mode, the first axial mode and the third bending pair;
* the same beam free (validation/scenes/free_beam.ini: no clamp, no load) at 4, 6, 8, 10
  through, 14 modes: the six rigid-body modes (zero modes by the inertia count, skipped), then
  the first free-free bending pair, the second bending pair, the first torsion mode and the
  third bending pair (the first six flexible frequencies and the pair partner of the sixth) and
  the first axial mode;
* the clamped plate validation/scenes/clamped_plate.ini (0.5 x 0.5 x 0.05 m, the four side
  faces clamped) at 4 and 6 particles through the 0.05 m thickness, 3 modes: the fundamental
  and the degenerate (2,1)/(1,2) pair. (8 through would factorise a matrix of ~5 GB and take
  well over the few minutes each run here is kept to.)

Each mode is named from its shape (the frames of NAME_modes.pvd, ghosts left out) with the
functions that name the FEM modes (validation/fem.py: classify_beam_mode, classify_plate_mode),
so tlsph's and CalculiX's "bending_2" or "torsion_1" are the same mode even where the order of
close frequencies differs. References: the FEM frequencies of validation/fem/references.json
(cases cantilever_modes, free_beam_modes and clamped_plate_modes: C3D20R mesh ladders,
Richardson extrapolation; `/usr/bin/python3 validation/fem.py --case cantilever_modes --case
free_beam_modes --case clamped_plate_modes` recomputes them, ~15 min on one thread), the
Timoshenko beam
(validation/references.py; the second bending frequency from the same determinant, bracketed
near the Euler-Bernoulli value) and Saint-Venant torsion.

Writes validation/report/frequencies.md (the tables: frequency, error against the converged
FEM value and against Timoshenko per resolution, the observed order, the penalty share and
hourglass content of each mode, wall time and peak memory of each run, and the inertia
check of each run: zero modes counted by inertia, the list shown complete) and
validation/report/frequencies.png (relative error against particles through, log-log); the
runs go to validation/runs/frequencies/ (git-ignored), with summary.json (each run's record
from tlsph's modes.json included).

  /usr/bin/python3 validation/frequencies.py [--build-dir DIR]   # DIR/tlsph, default build/
  /usr/bin/python3 validation/frequencies.py --tlsph PATH        # a tlsph binary
  /usr/bin/python3 validation/frequencies.py --reuse             # rewrite the report from the
                                                                 # runs already made
  /usr/bin/python3 validation/frequencies.py --only cantilever   # one problem (or free_beam,
                                                                 # clamped_plate)

Every run has OMP_NUM_THREADS=1 (--threads to change). Measured cost on this machine: the
cantilever at 10 through 30 s and 0.7 GB, the plate at 6 through a few minutes and ~3 GB
(frequencies.md has the numbers of the last run). Standard library + numpy (+ matplotlib for
the plot, skipped if missing).
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import fem  # noqa: E402
import references as R  # noqa: E402

RUNS = HERE / "runs" / "frequencies"
REPORT_MD = HERE / "report" / "frequencies.md"
REPORT_PNG = HERE / "report" / "frequencies.png"
FEM_JSON = HERE / "fem" / "references.json"

# E, nu, rho and the beam's section
E, NU, RHO = 1.0e7, 0.3, 1000.0
BEAM_B, BEAM_L = 0.1, 1.0

PROBLEMS = {
    "cantilever": dict(
        scene="examples/cantilever.ini", side=BEAM_B, through=[4, 6, 8, 10], count=8,
        fem_case="cantilever_modes", kind="beam",
        modes=["bending_1", "bending_1b", "bending_2", "torsion_1", "axial_1", "bending_3"],
        title="3D cantilever 1 x 0.1 x 0.1 m (examples/cantilever.ini)"),
    "free_beam": dict(
        scene="validation/scenes/free_beam.ini", side=BEAM_B, through=[4, 6, 8, 10], count=14,
        fem_case="free_beam_modes", kind="beam", ends="free-free", rigid=6,
        modes=["bending_1", "bending_1b", "bending_2", "bending_2b", "torsion_1", "bending_3",
               "bending_3b", "axial_1"],
        title="3D free beam 1 x 0.1 x 0.1 m (validation/scenes/free_beam.ini: "
              "examples/cantilever.ini without clamp and load)"),
    "clamped_plate": dict(
        scene="validation/scenes/clamped_plate.ini", side=0.05, through=[4, 6], count=3,
        fem_case="clamped_plate_modes", kind="plate", modes=["mode_1", "mode_2"],
        title="square plate 0.5 x 0.5 x 0.05 m clamped on its four sides "
              "(validation/scenes/clamped_plate.ini)"),
}


# --------------------------------------------------------------------------------------------
# Analytic references


def timoshenko_bending(k):
    """k-th (1 or 2) bending frequency [Hz] of the clamped-free Timoshenko beam
    (validation/references.py)."""
    A, I = BEAM_B**2, BEAM_B**4 / 12.0
    beta = {1: 1.8751040687, 2: 4.6940911330}[k]
    return R.timoshenko_frequency(E, NU, RHO, A, I, BEAM_L, beta_l=beta)


def beam_theory():
    A, I = BEAM_B**2, BEAM_B**4 / 12.0
    G = E / (2 * (1 + NU))
    return {
        "bending_1": {"Timoshenko": timoshenko_bending(1),
                      "Euler-Bernoulli": R.euler_bernoulli_frequency(E, I, RHO, A, BEAM_L)},
        "bending_2": {"Timoshenko": timoshenko_bending(2),
                      "Euler-Bernoulli": R.euler_bernoulli_frequency(E, I, RHO, A, BEAM_L,
                                                                     beta_l=4.6940911330)},
        "torsion_1": {"Saint-Venant": math.sqrt(G * 0.140577 * BEAM_B**4
                                                / (RHO * BEAM_B**4 / 6.0)) / (4 * BEAM_L)},
        "axial_1": {"bar": math.sqrt(E / RHO) / (4 * BEAM_L)},
    }


# --------------------------------------------------------------------------------------------
# tlsph output: modes.csv and the VTU frames (appended raw, zlib-compressed, UInt64 headers)


def read_modes_csv(path):
    rows = []
    header = None
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        if header is None:
            header = line.split(",")
            continue
        vals = line.split(",")
        rows.append({k: (int(v) if k in ("mode", "zero") else float(v))
                     for k, v in zip(header, vals)})
    return rows


def read_tlsph_vtu(path):
    """Points and point data of a VTU written by tlsph (appended raw data, UInt64 headers,
    zlib-compressed blocks when the VTKFile names a compressor)."""
    data = Path(path).read_bytes()
    start = data.index(b"<AppendedData")
    us = data.index(b"_", start) + 1
    head = data[:start].decode("utf-8", "replace")
    top = re.search(r"<VTKFile([^>]*)>", head).group(1)
    compressed = "compressor=" in top
    if 'header_type="UInt64"' not in top:
        raise ValueError(f"{path}: only header_type UInt64 is supported")
    types = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4",
             "UInt8": "u1"}

    def array(attrs):
        off = us + int(attrs["offset"])
        if compressed:
            nb = int(np.frombuffer(data[off:off + 8], "<u8")[0])
            sizes = np.frombuffer(data[off + 24:off + 24 + 8 * nb], "<u8")
            pos = off + 24 + 8 * nb
            raw = b""
            for s in sizes:
                raw += zlib.decompress(data[pos:pos + int(s)])
                pos += int(s)
        else:
            n = int(np.frombuffer(data[off:off + 8], "<u8")[0])
            raw = data[off + 8:off + 8 + n]
        arr = np.frombuffer(raw, types[attrs["type"]])
        c = int(attrs.get("NumberOfComponents", "1"))
        return arr.reshape(-1, c) if c > 1 else arr

    pd, pts = {}, None
    section = None
    for m in re.finditer(r"<(/?)(PointData|Points|Cells|CellData|FieldData)\b|<DataArray([^>]*)>",
                         head):
        if m.group(2):
            section = None if m.group(1) else m.group(2)
        elif section in ("PointData", "Points"):
            attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(3)))
            if section == "Points":
                pts = array(attrs)
            else:
                pd[attrs["Name"]] = array(attrs)
    return pts, pd


def read_mode_shapes(run_dir):
    pvd = sorted(Path(run_dir).glob("*_modes.pvd"))
    if not pvd:
        raise FileNotFoundError(f"{run_dir}: no *_modes.pvd")
    root = ET.parse(pvd[0]).getroot()
    shapes = []
    X = None
    for ds in root.iter("DataSet"):
        pts, pd = read_tlsph_vtu(Path(run_dir) / ds.get("file"))
        real = pd["ghost"] == 0 if "ghost" in pd else np.ones(len(pts), bool)
        X = pts[real]
        shapes.append(np.asarray(pd["mode_shape"])[real])
    return X, shapes


# --------------------------------------------------------------------------------------------
# Running


def run_modes(tlsph, problem, n, threads, reuse):
    p = PROBLEMS[problem]
    dx = p["side"] / n
    out = RUNS / f"{problem}_n{n}"
    meta_path = out / "run.json"
    if reuse and meta_path.exists() and (out / "modes.csv").exists():
        meta = json.loads(meta_path.read_text())
    else:
        out.mkdir(parents=True, exist_ok=True)
        cmd = [str(tlsph), "modes", str(ROOT / p["scene"]), f"--count={p['count']}",
               f"--scene.dx={dx!r}", f"--output.directory={out}"]
        env = dict(os.environ, OMP_NUM_THREADS=str(threads))
        log = out / "tlsph.log"
        print(f"  {problem} n={n} dx={dx:.6g}: {' '.join(cmd[1:])}", flush=True)
        t0 = time.perf_counter()
        with open(log, "w") as f:
            proc = subprocess.Popen(cmd, stdout=f, stderr=subprocess.STDOUT, env=env,
                                    cwd=ROOT)
            _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - t0
        text = log.read_text()
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)}: exit status {proc.returncode}; log {log}:\n"
                               + text[-2000:])
        meta = {"command": " ".join(["tlsph"] + cmd[1:]), "dx": dx, "through": n,
                "wall_s": round(wall, 2), "max_rss_mb": round(usage.ru_maxrss / 1024.0, 1),
                "threads": threads}
        m = re.search(r"(\d+) unknowns; .*?(\d+) solves by conjugate gradients \((\d+) "
                      r"iterations\)", text)
        if m:
            meta.update(unknowns=int(m.group(1)), solves=int(m.group(2)),
                        cg_iterations=int(m.group(3)))
        meta_path.write_text(json.dumps(meta, indent=1) + "\n")
    rows = read_modes_csv(out / "modes.csv")
    X, shapes = read_mode_shapes(out)
    meta["particles"] = int(len(X))
    record = out / "modes.json"
    if record.exists():
        meta["tlsph_record"] = json.loads(record.read_text())
    rigid = p.get("rigid", 0)
    if rigid:
        # the rigid-body modes (zero modes) are not named; the flexible ones are
        zero = [r["zero"] for r in rows[:rigid]]
        if zero != [1] * rigid or any(r["zero"] for r in rows[rigid:]):
            raise RuntimeError(f"{out}: expected exactly {rigid} zero modes first, got "
                               f"{[r['zero'] for r in rows]}")
        rows, shapes = rows[rigid:], shapes[rigid:]
    if p["kind"] == "beam":
        names = fem.name_beam_modes(X, shapes, ends=p.get("ends", "clamped-free"))
        for row, (name, kind, order, shares) in zip(rows, names):
            row.update(name=name, kind=kind, order=order,
                       shares={k: round(v, 4) for k, v in shares.items()})
    else:
        lo, hi = X.min(axis=0), X.max(axis=0)
        centre = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))
        for row, U in zip(rows, shapes):
            kind, par = fem.classify_plate_mode(X, U, centre=centre)
            row.update(name=f"mode_{row['mode']}", kind=kind, parity=par)
    meta["modes"] = rows
    return meta


# --------------------------------------------------------------------------------------------
# References from the FEM JSON


def fem_reference(case_name):
    """{mode name: {"converged": f, "finest": f, "order": p, "mesh": label, "how": text}} from
    the FEM JSON's reference series (a uniform ladder: record["reference"]["series"])."""
    data = fem.load_references(FEM_JSON)
    if case_name not in data.get("cases", {}):
        raise SystemExit(f"frequencies.py: {FEM_JSON} has no case {case_name}: run "
                         f"/usr/bin/python3 validation/fem.py --case {case_name}")
    rec = data["cases"][case_name]
    sname = rec.get("reference", {}).get("series") or next(iter(rec["series"]))
    series = rec["series"][sname]
    finest = series["runs"][-1]
    out = {}
    for key, conv in series.get("convergence", {}).items():
        name = key[2:]  # f_bending_1 -> bending_1; the plate's f_1 -> mode_1
        if name.isdigit():
            name = f"mode_{name}"
        ref = {"finest": conv["finest"], "mesh": finest["mesh"], "series": sname}
        if "richardson" in conv:
            ref.update(converged=conv["richardson"], order=conv["observed_order"],
                       how="Richardson")
        else:
            ref.update(converged=conv["finest"], how="finest mesh")
        out[name] = ref
    return out, rec


# --------------------------------------------------------------------------------------------
# Report


def _pct(x):
    return "" if x is None else f"{100 * x:+.2f} %"


def _orders(ns, errs):
    """Observed order between successive resolutions from the errors against a reference,
    p = ln(e_{i-1}/e_i) / ln(n_i/n_{i-1}); None where the sign changes."""
    out = [None]
    for k in range(1, len(ns)):
        a, b = errs[k - 1], errs[k]
        if a is None or b is None or a * b <= 0:
            out.append(None)
        else:
            out.append(math.log(abs(a) / abs(b)) / math.log(ns[k] / ns[k - 1]))
    return out


def _fit_order(ns, errs):
    pts = [(math.log(n), math.log(abs(e))) for n, e in zip(ns, errs) if e]
    if len(pts) < 2 or len({math.copysign(1, e) for e in errs if e}) > 1:
        return None
    x, y = np.array(pts).T
    return -float(np.polyfit(x, y, 1)[0])


def _mode(meta, name):
    for row in meta["modes"]:
        if row["name"] == name:
            return row
    return None


def build_report(results, beam, fem_refs, fem_recs):
    L = []
    L.append("# Natural frequencies: `tlsph modes` against CalculiX and beam theory\n")
    L.append("Written by `/usr/bin/python3 validation/frequencies.py` (runs in "
             "validation/runs/frequencies/, each on one thread: `OMP_NUM_THREADS=1`). "
             "tlsph at the defaults of the scenes (quadratic correction, energy-form hourglass "
             "penalty alpha = 10, mirrored clamp, Taylor quadrature), modes about the reference state "
             "(docs/modes.md); the scenes' material linearises there to linear elasticity "
             "with E = 1e7 Pa, nu = 0.3, rho = 1000 kg/m^3. Modes are named from their shapes "
             "(validation/fem.py `classify_beam_mode`, `classify_plate_mode`: the same "
             "functions name the FEM modes). FEM: CalculiX C3D20R, `*FREQUENCY`, consistent "
             "mass (validation/fem.py, validation/fem/README.md); \"converged\" is the "
             "Richardson value of the uniform mesh ladder. Errors are (tlsph - reference) / "
             "reference. Order: observed between successive resolutions from the error "
             "against the converged FEM value, p = ln(e1/e2)/ln(n2/n1), n = particles through; "
             "\"fit\" is the least-squares slope over all resolutions.\n")
    # summary
    L.append("## Summary\n")
    for problem, runs in results.items():
        p = PROBLEMS[problem]
        refs = fem_refs[problem]
        main = p["modes"][0]
        ns = [m["through"] for m in runs]
        errs = [(_mode(m, main)["frequency"] / refs[main]["converged"] - 1) for m in runs]
        fit = _fit_order(ns, errs)
        last = runs[-1]
        f = _mode(last, main)["frequency"]
        txt = (f"* {problem}, {main}: {f:.5f} Hz at {last['through']} through, "
               f"{_pct(errs[-1])} against the converged FEM ({refs[main]['converged']:.5f} Hz)"
               + (f", {_pct(f / beam['bending_1']['Timoshenko'] - 1)} against Timoshenko "
                  f"({beam['bending_1']['Timoshenko']:.5f} Hz)" if problem == "cantilever"
                  else "")
               + f"; from {_pct(errs[0])} at {ns[0]} through, observed order "
               + (f"{fit:.2f}" if fit is not None else "-")
               + ". Every mode of every run below: penalty share at most "
               f"{max(r['penalty_share'] for m in runs for r in m['modes']):.3f} "
               f"({max(r['penalty_share'] for r in last['modes']):.4f} at {last['through']} "
               "through), hourglass content at most "
               f"{max(r['hourglass_content'] for m in runs for r in m['modes']):.4f}; "
               f"the costliest run {max(m['wall_s'] for m in runs):.0f} s, "
               f"{max(m['max_rss_mb'] for m in runs) / 1024:.1f} GB.")
        L.append(txt)
    L.append("")
    for problem, runs in results.items():
        p = PROBLEMS[problem]
        refs = fem_refs[problem]
        rec = fem_recs[problem]
        L.append(f"## {p['title']}\n")
        ns = [m["through"] for m in runs]
        main = p["modes"][0]
        ref = refs.get(main)
        L.append(f"FEM ({rec['series'][ref['series']]['runs'][-1]['mesh']} finest, "
                 f"{ref['series']} ladder "
                 + ", ".join(r["mesh"] for r in rec["series"][ref["series"]]["runs"])
                 + "): " + ", ".join(
                     f"{name} {refs[name]['converged']:.5f} Hz"
                     + (f" (Richardson, order {refs[name]['order']:.2f}; finest "
                        f"{refs[name]['finest']:.5f})" if refs[name]["how"] == "Richardson"
                        else " (finest mesh)")
                     for name in p["modes"] if name in refs) + ".\n")
        if rec.get("reference", {}).get("note"):
            L.append("FEM reference note (validation/fem/references.json): "
                     + rec["reference"]["note"] + "\n")
        if problem == "clamped_plate":
            k = rec.get("analytic", {}).get("kirchhoff_mode_1")
            if k:
                L.append(f"Thin-plate (Kirchhoff) fundamental: {k:.3f} Hz (Leissa, lambda^2 = "
                         "35.985); at a/t = 10 shear and rotary inertia lower the 3D value to "
                         f"{ref['converged']:.2f} Hz ({_pct(ref['converged'] / k - 1)}), so "
                         "only the FEM is a reference here.\n")
        if problem == "cantilever":
            L.append("Beam theory: " + "; ".join(
                f"{m}: " + ", ".join(f"{k} {v:.5f} Hz" for k, v in d.items())
                for m, d in beam.items()) + ".\n")
        # first mode table
        errs = []
        L.append(f"### {main} (the fundamental" + (", first of the bending pair)"
                                                     if problem == "cantilever" else ")") + "\n")
        head = ["through", "dx [m]", "particles", "unknowns", "f tlsph [Hz]", "vs FEM conv.",
                "vs FEM finest"]
        if problem == "cantilever":
            head += ["vs Timoshenko", "pair split"]
        head += ["order", "penalty share", "hourglass content", "wall [s]", "peak RSS [MB]"]
        L.append("| " + " | ".join(head) + " |")
        L.append("|" + "---:|" * len(head))
        rows_txt = []
        for m in runs:
            row = _mode(m, main)
            f = row["frequency"] if row else None
            e = f / ref["converged"] - 1 if f else None
            errs.append(e)
            rows_txt.append((m, row, f, e))
        orders = _orders(ns, errs)
        for (m, row, f, e), o in zip(rows_txt, orders):
            cells = [str(m["through"]), f"{m['dx']:.6g}", str(m["particles"]),
                     str(m.get("unknowns", "")), f"{f:.5f}" if f else "-", _pct(e),
                     _pct(f / ref["finest"] - 1) if f else ""]
            if problem == "cantilever":
                pair = _mode(m, main + "b")
                cells += [_pct(f / beam["bending_1"]["Timoshenko"] - 1) if f else "",
                          f"{abs(pair['frequency'] / f - 1):.0e}" if pair and f else "-"]
            cells += [f"{o:.2f}" if o is not None else "", f"{row['penalty_share']:.4f}",
                      f"{row['hourglass_content']:.5f}", f"{m['wall_s']:.1f}",
                      f"{m['max_rss_mb']:.0f}"]
            L.append("| " + " | ".join(cells) + " |")
        fit = _fit_order(ns, errs)
        if fit is not None:
            L.append("| fit | | | | | | | " + ("| | " if problem == "cantilever" else "")
                     + f"{fit:.2f} | | | | |")
        L.append("")
        # the other modes
        others = [n for n in p["modes"][1:] if not n.endswith("b")]
        if others:
            L.append("### Higher modes\n")
            head = ["mode", "reference [Hz]"] + [f"{n} through" for n in ns] + ["order (fit)"]
            L.append("| " + " | ".join(head) + " |")
            L.append("|---|---|" + "---:|" * (len(ns) + 1))
            for name in others:
                if name not in refs:
                    continue
                errs_m = []
                cells = []
                for m in runs:
                    row = _mode(m, name)
                    if row is None:
                        cells.append("not among the modes")
                        errs_m.append(None)
                        continue
                    e = row["frequency"] / refs[name]["converged"] - 1
                    errs_m.append(e)
                    cells.append(f"{row['frequency']:.4f} Hz ({_pct(e)}; mode {row['mode']}, "
                                 f"penalty {row['penalty_share']:.3f}, content "
                                 f"{row['hourglass_content']:.4f})")
                fit = _fit_order(ns, [e for e in errs_m if e is not None]) \
                    if None not in errs_m else None
                refcell = f"FEM {refs[name]['converged']:.4f}"
                th = beam.get(name, {}) if problem == "cantilever" else {}
                if th:
                    refcell += "; " + ", ".join(f"{k} {v:.4f}" for k, v in th.items())
                L.append(f"| {name} | {refcell} | " + " | ".join(cells)
                         + f" | {'' if fit is None else f'{fit:.2f}'} |")
            L.append("")
        # every mode of every run
        L.append("<details><summary>every mode of every run</summary>\n")
        L.append("| through | mode | name | f [Hz] | FEM conv. [Hz] | error | penalty share | "
                 "hourglass content |")
        L.append("|---:|---:|---|---:|---:|---:|---:|---:|")
        for m in runs:
            for row in m["modes"]:
                base = row["name"][:-1] if row["name"].endswith("b") else row["name"]
                r = refs.get(row["name"]) or refs.get(base)
                fc = r["converged"] if r else None
                name = row["name"] + (f" ({row['parity']})" if "parity" in row else "")
                L.append(f"| {m['through']} | {row['mode']} | {name} | {row['frequency']:.5f} | "
                         + (f"{fc:.5f} | {_pct(row['frequency'] / fc - 1)}" if fc else "- | -")
                         + f" | {row['penalty_share']:.4f} | {row['hourglass_content']:.5f} |")
        L.append("\n</details>\n")
        checks = []
        for m in runs:
            t = m.get("tlsph_record", {})
            if t.get("inertia_counted"):
                checks.append(f"{m['through']} through: {t['zero_modes']} zero modes by inertia "
                              f"({t['rigid_body_modes']} rigid-body), {t['eigenvalues_below_cut']} "
                              f"eigenvalues below the cut, {t['found_below_cut']} found "
                              f"({t['lanczos_runs']} Lanczos run(s)); exact K "
                              f"{t['exact_stiffness']}, L D L^T {t['ldlt_entries'] / 1e6:.1f} M "
                              f"entries, {t['inertia_seconds']:.0f} s")
            elif t:
                checks.append(f"{m['through']} through: no inertia count "
                              f"({t.get('inertia_not_counted_because', '')}); "
                              f"{t['zero_modes']} zero modes among the modes found")
        if checks:
            L.append("Inertia check (docs/modes.md): " + "; ".join(checks) + ".\n")
        L.append("Runs: " + "; ".join(
            f"{m['through']} through: `{m['command'].replace(str(ROOT) + '/', '')}` "
            f"({m.get('solves', '?')} solves, {m.get('cg_iterations', '?')} CG iterations, "
            f"{m['wall_s']:.1f} s, {m['max_rss_mb']:.0f} MB)" for m in runs) + ".\n")
    return "\n".join(L)


def plot(results, fem_refs, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot")
        return False
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for problem, runs in results.items():
        refs = fem_refs[problem]
        for name in PROBLEMS[problem]["modes"]:
            if name.endswith("b") or name not in refs:
                continue
            pts = [(m["through"], abs(_mode(m, name)["frequency"] / refs[name]["converged"] - 1))
                   for m in runs if _mode(m, name)]
            if not pts:
                continue
            x, y = zip(*pts)
            ax.loglog(x, y, "o-", label=f"{problem} {name}")
    for p, ls in ((1, ":"), (2, "--")):
        x = np.array([4, 10])
        ax.loglog(x, 2e-2 * (x / 4.0) ** -p, "k" + ls, lw=0.8, label=f"order {p}")
    ax.set_xlabel("particles through the thickness")
    ax.set_ylabel("|f tlsph / f FEM (converged) - 1|")
    ax.set_xticks([4, 6, 8, 10])
    ax.set_xticklabels(["4", "6", "8", "10"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build-dir", default=str(ROOT / "build"),
                    help="directory holding the tlsph binary (default build/)")
    ap.add_argument("--tlsph", default=None, help="the tlsph binary (overrides --build-dir)")
    ap.add_argument("--threads", type=int, default=1, help="OMP_NUM_THREADS (default 1)")
    ap.add_argument("--only", action="append", choices=list(PROBLEMS),
                    help="a problem to run (repeatable; default both)")
    ap.add_argument("--reuse", action="store_true",
                    help="reuse runs already in validation/runs/frequencies/")
    args = ap.parse_args(argv)
    tlsph = Path(args.tlsph or Path(args.build_dir) / "tlsph").resolve()
    if not (tlsph.is_file() and os.access(tlsph, os.X_OK)):
        print(f"frequencies.py: {tlsph}: no tlsph binary (--build-dir / --tlsph)",
              file=sys.stderr)
        return 1
    RUNS.mkdir(parents=True, exist_ok=True)
    beam = beam_theory()
    results = {}
    summary_path = RUNS / "summary.json"
    old = json.loads(summary_path.read_text()) if summary_path.exists() else {}
    t0 = time.perf_counter()
    for problem in PROBLEMS:
        if args.only and problem not in args.only:
            if problem in old.get("results", {}):
                results[problem] = old["results"][problem]
            continue
        results[problem] = [run_modes(tlsph, problem, n, args.threads, args.reuse)
                            for n in PROBLEMS[problem]["through"]]
        for m in results[problem]:
            first = m["modes"][0]
            print(f"  {problem:14s} {m['through']:2d} through: mode 1 {first['name']} "
                  f"{first['frequency']:.5f} Hz, {m['wall_s']:.1f} s, {m['max_rss_mb']:.0f} MB")
    summary_path.write_text(json.dumps({"tlsph": str(tlsph), "results": results,
                                        "beam_theory": beam}, indent=1) + "\n")
    fem_refs, fem_recs = {}, {}
    for problem in results:
        fem_refs[problem], fem_recs[problem] = fem_reference(PROBLEMS[problem]["fem_case"])
    REPORT_MD.write_text(build_report(results, beam, fem_refs, fem_recs))
    plot(results, fem_refs, REPORT_PNG)
    print(f"total {time.perf_counter() - t0:.1f} s; wrote {REPORT_MD.relative_to(ROOT)}, "
          f"{REPORT_PNG.relative_to(ROOT)}, {summary_path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
