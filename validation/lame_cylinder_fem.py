#!/usr/bin/env python3
"""CalculiX reference for the 3D thick-walled cylinder of validation/geometry/lame_cylinder.geo.

The problem: the tube a = 0.05 <= r <= b = 0.1 m, 0 <= z <= L = 0.05 m; steel E = 2e11 Pa,
nu = 0.3, linear elastic, static; the surface "outer" (r = b) clamped, u = 0 (all components);
a pressure p = 1e8 Pa on "bore" (r = a); the ends z = 0 and z = L free. The clamped outer
ring with free ends is not plane strain: there is no closed form, so the reference is a
converged CalculiX solution on the same geometry. Wanted:
  ur_mid   radial displacement at the bore at mid-length, u_r(a, L/2);
  ur_end   radial displacement at the bore at an end,     u_r(a, 0);
  stt_mid  hoop stress at the bore at mid-length, sigma_thetatheta(a, L/2);
  (srr_mid sigma_rr(a, L/2), a check: it must tend to -p.)

Method. The problem is axisymmetric, so the reference is CalculiX's 8-node axisymmetric
element CAX8 on the meridian rectangle (x = r in [a, b], y = z in [0, L]), a structured mesh
of n x n square elements, n = 4, 8, 16, 32, 64, 128:
  * the outer edge r = b fixed in r and z (both dofs of every node on it);
  * the pressure as *DLOAD P4 on the edge 4-1 (r = a) of the first column of elements (CAX8
    faces: P1 = 1-2, P2 = 2-3, P3 = 3-4, P4 = 4-1; positive pressure pushes into the element);
  * *STATIC with SPOOLES; u at the nodes from *NODE PRINT (the .dat, 7 digits); the stress
    from the .frd (*NODE FILE S: ccx extrapolates each element's integration-point stresses
    to its nodes and averages over the elements sharing the node). For CAX ccx's components
    are xx = rr, yy = zz, zz = thetatheta, xy = rz: sigma_thetatheta is the .frd's SZZ,
    nodal (extrapolated and averaged), at the corner node (a, L/2) (n even, so a node).
  * reactions: *NODE PRINT RF TOTALS on the outer edge. In ccx an axisymmetric model is a
    2-degree wedge of C3D20(R) internally; the *DLOAD pressure is a pressure (N/m^2). Measured
    here (checks 1, 2): *CLOAD forces on CAX nodes act as the total over the full circle (2 pi),
    not per radian (per-radian forces give 1/(2 pi) of the response), and the printed RF
    total is the reaction of the 2-degree wedge (0.03487 rad x sigma_rr(b) b L, 0.1 % from
    pi/90: not understood, not used).
Convergence: observed order and Richardson extrapolation from the last three meshes (ratio 2;
bracket_fem.richardson3), a least-squares fit v_inf + C h^p over every mesh
(bracket_fem.fit_all); converged value = Richardson of the last three; its uncertainty =
the spread of the estimates (Richardson, fit, and the finest mesh's distance to them).

Checks (each asserted):
  1. plane strain: the same CAX8 model with u_z = 0 on both end lines (rollers) must give the
     closed-form Lame solution u_r = A r + B / r, A = -B / b^2,
     B = p / (2 (lambda + mu) / b^2 + 2 mu / a^2): u_r(a) = 1.5000e-5 m, and
     sigma_thetatheta(a) = 2 lambda A + 2 mu (A + B / a^2) (to 1e-4 and 1e-3 at n = 32); its
     radial reaction total on r = b must be sigma_rr(b) b L times 2 degrees (to 1 %);
  2. the load convention: the plane-strain model again with the pressure as consistent nodal
     forces (*CLOAD p a h theta (1, 4, 1) / 6 on each edge's nodes) must reproduce the *DLOAD
     run with theta = 2 pi (to 1e-5) and give 1/(2 pi) of it with theta = 1 (per radian);
  3. the 3D cross-check: gmsh on the .geo (-order 2, C3D10, node order, mesh checks and the
     C3D10 patch test from validation/bracket_fem.py), outer clamped (every node of its
     triangles), the pressure as *DLOAD on the tetrahedron faces lying on the bore; u_r and
     sigma_thetatheta (the .frd's nodal stresses rotated to r, theta, z) at the bore from a
     least-squares quadratic in z through the bore's nodes near z = L/2 (the field is
     axisymmetric; gmsh's nodes do not sit exactly at (a, 0, L/2)) and the mean over the nodes
     of the circle r = a, z = 0; must agree with the CAX8 reference to 0.5 % (u) and 2 % (the
     nodal stress of a coarse tetrahedral mesh); the axial reaction must vanish.

Run (stdlib + numpy; Debian's python for numpy; ccx and gmsh on PATH or CCX=/path):
  /usr/bin/python3 validation/lame_cylinder_fem.py               # everything: 315 s measured (2 cores, shared)
  /usr/bin/python3 validation/lame_cylinder_fem.py --no-3d       # the CAX8 ladder alone
Options: --sizes (n per side of the CAX8 ladder), --h3d (3D element size, m; default 0.005),
--threads, --out (default validation/fem/out/lame_cylinder/, git-ignored), --json (default
validation/lame_cylinder_fem.json).
"""

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from fem import FemError, _rel, ccx_version, read_frd  # noqa: E402
from bracket_fem import (TetMesh, _write_ids, fit_all, fmt, gmsh_version,  # noqa: E402
                         patch_test, read_dat, richardson3, run_ccx_watched, run_gmsh)

GEO = HERE / "geometry" / "lame_cylinder.geo"
DEFAULT_OUT = HERE / "fem" / "out" / "lame_cylinder"
DEFAULT_JSON = HERE / "lame_cylinder_fem.json"

E, NU = 2e11, 0.3
P = 1e8
A_IN, B_OUT, LEN = 0.05, 0.1, 0.05
SIZES = [4, 8, 16, 32, 64, 128]
QUANTITIES = ["ur_mid", "ur_end", "stt_mid", "srr_mid"]

LAM = E * NU / ((1 + NU) * (1 - 2 * NU))
MU = E / (2 * (1 + NU))


def lame_plane_strain():
    """Closed-form plane-strain Lame solution for the clamped outer radius: u_r(a),
    sigma_thetatheta(a), sigma_rr(b)."""
    B = P / (2 * (LAM + MU) / B_OUT**2 + 2 * MU / A_IN**2)
    A = -B / B_OUT**2

    def stress(r):
        err, ett = A - B / r**2, A + B / r**2
        return (LAM * (err + ett) + 2 * MU * err, LAM * (err + ett) + 2 * MU * ett)

    return {"A": A, "B": B, "ur_a": A * A_IN + B / A_IN, "stt_a": stress(A_IN)[1],
            "srr_a": stress(A_IN)[0], "srr_b": stress(B_OUT)[0]}


# --------------------------------------------------------------------------------------------
# CAX8


def cax8_mesh(n):
    """n x n CAX8 on [a, b] x [0, L]: node grid (2n+1)^2 (the centre nodes unused), ids
    k = j (2n+1) + i + 1 at (r_i, z_j); elements (corner order counterclockwise, then the mid
    nodes of 1-2, 2-3, 3-4, 4-1)."""
    m = 2 * n + 1
    r = np.linspace(A_IN, B_OUT, m)
    z = np.linspace(0.0, LEN, m)

    def nid(i, j):
        return j * m + i + 1

    elems = []
    for ej in range(n):
        for ei in range(n):
            i, j = 2 * ei, 2 * ej
            elems.append([nid(i, j), nid(i + 2, j), nid(i + 2, j + 2), nid(i, j + 2),
                          nid(i + 1, j), nid(i + 2, j + 1), nid(i + 1, j + 2), nid(i, j + 1)])
    used = sorted({k for e in elems for k in e})
    coords = {k: (r[(k - 1) % m], z[(k - 1) // m]) for k in used}
    return {"n": n, "m": m, "r": r, "z": z, "nid": nid, "elems": elems, "coords": coords}


def write_cax8(path, mesh, plane_strain=False, cload=None):
    n, m, nid = mesh["n"], mesh["m"], mesh["nid"]
    outer = [nid(m - 1, j) for j in range(m)]
    ends = sorted({nid(i, 0) for i in range(m)} | {nid(i, m - 1) for i in range(m)}) \
        if plane_strain else []
    bore_nodes = [nid(0, j) for j in range(m)]
    probes = [nid(0, n), nid(0, 0), nid(0, m - 1)]
    with open(path, "w") as f:
        f.write("** thick-walled cylinder, CAX8 meridian (x = r, y = z); "
                "written by validation/lame_cylinder_fem.py\n*NODE, NSET=NALL\n")
        for k, (x, y) in sorted(mesh["coords"].items()):
            f.write(f"{k}, {fmt(x)}, {fmt(y)}, 0\n")
        f.write("*ELEMENT, TYPE=CAX8, ELSET=EALL\n")
        for e, c in enumerate(mesh["elems"]):
            f.write(f"{e + 1}, " + ", ".join(str(v) for v in c) + "\n")
        f.write("*NSET, NSET=NOUTER\n")
        _write_ids(f, np.array(outer))
        f.write("*NSET, NSET=NPROBE\n")
        _write_ids(f, np.array(probes))
        if ends:
            f.write("*NSET, NSET=NENDS\n")
            _write_ids(f, np.array(ends))
        f.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{fmt(E)}, {fmt(NU)}\n"
                "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*BOUNDARY\nNOUTER, 1, 2\n")
        if ends:
            f.write("NENDS, 2, 2\n")
        f.write("*STEP\n*STATIC, SOLVER=SPOOLES\n")
        total = 0.0
        if cload:
            # consistent forces of a uniform pressure on the straight edge r = a over the
            # angle `cload` (radians): the edge's force p a h cload split 1/6, 4/6, 1/6
            # (r constant along it)
            h = LEN / n
            force = {k: 0.0 for k in bore_nodes}
            for ej in range(n):
                j = 2 * ej
                for jj, w in ((j, 1 / 6), (j + 1, 4 / 6), (j + 2, 1 / 6)):
                    force[nid(0, jj)] += w * P * A_IN * h * cload
            f.write("*CLOAD\n")
            for k in bore_nodes:
                f.write(f"{k}, 1, {fmt(force[k])}\n")
                total += force[k]
        else:
            f.write("*DLOAD\n")
            for ej in range(n):
                f.write(f"{ej * n + 1}, P4, {fmt(P)}\n")
        f.write("*NODE PRINT, NSET=NPROBE\nU\n*NODE PRINT, NSET=NOUTER, TOTALS=YES\nRF\n"
                "*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n")
    return probes, total


def run_cax8(n, run_dir, threads, plane_strain=False, cload=None, tag=""):
    d = Path(run_dir) / f"cax8_n{n}{tag}"
    d.mkdir(parents=True, exist_ok=True)
    mesh = cax8_mesh(n)
    probes, cload_total = write_cax8(d / "cyl.inp", mesh, plane_strain, cload)
    frd, wall, gb, status = run_ccx_watched(d, "cyl", threads, 600, 8)
    if frd is None:
        raise FemError(f"{d}: ccx {status}")
    dat = read_dat(d / "cyl.dat")
    res = read_frd(frd)
    mid, end, top = probes
    S = res["S"]
    rec = {"n": n, "h_m": (B_OUT - A_IN) / n, "nodes": len(mesh["coords"]),
           "elements": len(mesh["elems"]), "ccx_s": round(wall, 2), "peak_gb": round(gb, 3),
           "ur_mid": float(dat["U"][mid][0]), "uz_mid": float(dat["U"][mid][1]),
           "ur_end": float(dat["U"][end][0]), "ur_top": float(dat["U"][top][0]),
           "stt_mid": float(S[mid - 1][2]), "srr_mid": float(S[mid - 1][0]),
           "szz_mid": float(S[mid - 1][1]),
           "RF_total_per_rad": [float(x) for x in dat["RF_total"][:2]]}
    if cload:
        rec["cload_total"] = cload_total
    return rec


# --------------------------------------------------------------------------------------------
# 3D C3D10 cross-check

# C3D10 faces (corner rows, 0-based) in ccx's numbering P1..P4
C3D10_FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


def run_3d(h, run_dir, threads, log=print):
    d = Path(run_dir) / f"c3d10_h{h * 1e3:g}mm"
    d.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    run_gmsh(GEO, d / "cyl.msh", h, d / "gmsh.log")
    mesh = TetMesh(d / "cyl.msh")
    X = mesh.coords
    ids = mesh.ids
    bore = set(np.unique(mesh.surfaces["bore"][:, :3]).tolist())
    outer_rows = np.unique(mesh.surfaces["outer"].ravel())
    r_all = np.hypot(X[:, 0], X[:, 1])
    if np.abs(r_all[outer_rows] - B_OUT).max() > 1e-6 * B_OUT:
        raise FemError("outer nodes off r = b")
    faces = []
    for e, t in enumerate(mesh.tets):
        for k, fc in enumerate(C3D10_FACES):
            if all(int(t[c]) in bore for c in fc):
                faces.append((e + 1, k + 1))
    bore_rows = np.unique(mesh.surfaces["bore"].ravel())
    if np.abs(r_all[bore_rows] - A_IN).max() > 1e-6 * A_IN:
        raise FemError("bore nodes off r = a")
    if len(faces) != len(mesh.surfaces["bore"]):
        raise FemError(f"{len(faces)} tet faces on the bore for "
                       f"{len(mesh.surfaces['bore'])} triangles")
    with open(d / "cyl.inp", "w") as f:
        f.write("** thick-walled cylinder, C3D10; written by validation/lame_cylinder_fem.py\n"
                "*NODE, NSET=NALL\n")
        f.write("".join(f"{i}, {fmt(x)}, {fmt(y)}, {fmt(z)}\n" for i, (x, y, z) in zip(ids, X)))
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        f.write("".join(f"{e + 1}, " + ", ".join(str(v) for v in ids[c]) + "\n"
                        for e, c in enumerate(mesh.tets)))
        f.write("*NSET, NSET=NOUTER\n")
        _write_ids(f, ids[outer_rows])
        f.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{fmt(E)}, {fmt(NU)}\n"
                "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*BOUNDARY\nNOUTER, 1, 3\n"
                "*STEP\n*STATIC, SOLVER=SPOOLES\n*DLOAD\n")
        f.write("".join(f"{e}, P{k}, {fmt(P)}\n" for e, k in faces))
        f.write("*NODE PRINT, NSET=NOUTER, TOTALS=YES\nRF\n*NODE FILE\nU\n*EL FILE\nS\n"
                "*END STEP\n")
    frd, wall, gb, status = run_ccx_watched(d, "cyl", threads, 600, 8)
    if frd is None:
        raise FemError(f"{d}: ccx {status}")
    res = read_frd(frd)
    dat = read_dat(d / "cyl.dat")
    U, S = res["U"][ids - 1], res["S"][ids - 1]
    Xb, Ub, Sb = X[bore_rows], U[bore_rows], S[bore_rows]
    rb = np.hypot(Xb[:, 0], Xb[:, 1])
    c, s = Xb[:, 0] / rb, Xb[:, 1] / rb
    ur = c * Ub[:, 0] + s * Ub[:, 1]
    # S order xx yy zz xy yz zx: sigma_tt = s^2 sxx + c^2 syy - 2 s c sxy
    stt = s * s * Sb[:, 0] + c * c * Sb[:, 1] - 2 * s * c * Sb[:, 3]
    srr = c * c * Sb[:, 0] + s * s * Sb[:, 1] + 2 * s * c * Sb[:, 3]
    z = Xb[:, 2]

    def at_mid(v):
        sel = np.abs(z - LEN / 2) < 1.5 * h
        coef = np.polyfit(z[sel] - LEN / 2, v[sel], 2)
        return float(coef[-1]), int(sel.sum())

    end = np.abs(z) < 1e-9
    rec = {"h_m": h, "nodes": int(len(ids)), "elements": int(len(mesh.tets)),
           "bore_faces": len(faces), "ccx_s": round(wall, 2), "peak_gb": round(gb, 3),
           "ur_mid": at_mid(ur)[0], "stt_mid": at_mid(stt)[0], "srr_mid": at_mid(srr)[0],
           "mid_fit_nodes": at_mid(ur)[1],
           "ur_end": float(ur[end].mean()), "ur_end_spread": float(np.ptp(ur[end])),
           "end_circle_nodes": int(end.sum()),
           "RF_total": [float(x) for x in dat["RF_total"]],
           "wall_s": round(time.perf_counter() - t0, 1)}
    log(f"3D C3D10 h = {h * 1e3:g} mm: {rec['nodes']} nodes, {rec['elements']} elements, "
        f"ur_mid {rec['ur_mid']:.6e}, ur_end {rec['ur_end']:.6e} (spread over the circle "
        f"{rec['ur_end_spread']:.1e}), stt_mid {rec['stt_mid']:.6e}, srr_mid "
        f"{rec['srr_mid']:.4e}, RF {np.array(rec['RF_total'])}, ccx {wall:.1f} s, "
        f"{gb:.2f} GB")
    return rec


# --------------------------------------------------------------------------------------------


def convergence(runs):
    h = [r["h_m"] for r in runs]
    out = {}
    for q in QUANTITIES:
        v = [r[q] for r in runs]
        c = {"values": v, "finest": v[-1]}
        rr = richardson3(h[-3:], v[-3:])
        if rr:
            c["observed_order"], c["richardson"] = rr
            ests = [rr[1], v[-1]]
            f = fit_all(h, v)
            if f:
                c["fit_all"] = {"order": f[0], "v_inf": f[1], "rms_residual": f[2]}
                ests.append(f[1])
            c["converged"] = rr[1]
            c["spread"] = max(ests) - min(ests)
        else:
            c["converged"] = v[-1]
            c["spread"] = abs(v[-1] - v[-2])
            c["note"] = "last three not monotone and contracting: finest value, last change"
        c["rel_spread"] = c["spread"] / abs(c["converged"])
        out[q] = c
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=SIZES)
    ap.add_argument("--h3d", type=float, default=0.005)
    ap.add_argument("--no-3d", action="store_true")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--json", type=Path, default=DEFAULT_JSON)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()

    # check 1 and 2: plane strain against the closed form, DLOAD and CLOAD
    ex = lame_plane_strain()
    ps = run_cax8(32, args.out, args.threads, plane_strain=True, tag="_planestrain")
    cl = {}
    for name, angle in (("per_radian", 1.0), ("full_circle", 2 * np.pi)):
        r = run_cax8(32, args.out, args.threads, plane_strain=True, cload=angle,
                     tag=f"_planestrain_cload_{name}")
        cl[name] = {"cload_total": r["cload_total"], "ur_a": r["ur_mid"],
                    "ratio_to_dload": r["ur_mid"] / ps["ur_mid"]}
    rf_rad = ex["srr_b"] * B_OUT * LEN       # reaction on the structure at r = b, per radian
    checks = {
        "plane_strain": {
            "n": 32, "closed_form": ex,
            "ur_a": ps["ur_mid"], "ur_a_rel_error": ps["ur_mid"] / ex["ur_a"] - 1,
            "ur_a_end_rel_error": ps["ur_end"] / ex["ur_a"] - 1,
            "stt_a": ps["stt_mid"], "stt_a_rel_error": ps["stt_mid"] / ex["stt_a"] - 1,
            "srr_a": ps["srr_mid"],
            "RF_r_total": ps["RF_total_per_rad"][0],
            "RF_r_closed_form_per_radian": rf_rad,
            "RF_r_ratio_radians": ps["RF_total_per_rad"][0] / rf_rad,
            "RF_note": "ccx's RF of a CAX model: the reaction of its internal 2-degree "
                       "(0.0349 rad) wedge, measured ratio RF / (sigma_rr(b) b L) in radians"},
        "cload": {
            "n": 32, "p_a_L": P * A_IN * LEN, **cl,
            "note": "*CLOAD on CAX nodes is the force over the full circumference (2 pi): "
                    "per-radian forces give 1/(2 pi) of the *DLOAD response"}}
    pc = checks["plane_strain"]
    print(f"plane strain (ends on rollers), CAX8 n = 32: u_r(a) = {ps['ur_mid']:.6e} "
          f"(Lame {ex['ur_a']:.6e}, {pc['ur_a_rel_error']:+.1e}); sigma_tt(a) = "
          f"{ps['stt_mid']:.6e} (Lame {ex['stt_a']:.6e}, {pc['stt_a_rel_error']:+.1e}); "
          f"sigma_rr(a) = {ps['srr_mid']:.5e}; RF_r on r = b {ps['RF_total_per_rad'][0]:.6e} "
          f"= {pc['RF_r_ratio_radians']:.5f} rad x sigma_rr(b) b L (2 deg = "
          f"{np.pi / 90:.5f} rad)")
    for name, c in cl.items():
        print(f"pressure as *CLOAD, total {c['cload_total']:.6e} N ({name}; p a L = "
              f"{P * A_IN * LEN:.4e}): u_r(a) = {c['ur_a']:.6e}, ratio to *DLOAD "
              f"{c['ratio_to_dload']:.6f} (1/(2 pi) = {1 / (2 * np.pi):.6f})")
    assert abs(pc["ur_a_rel_error"]) < 1e-4 and abs(pc["ur_a_end_rel_error"]) < 1e-4, pc
    assert abs(pc["stt_a_rel_error"]) < 1e-3, pc
    assert abs(pc["RF_r_ratio_radians"] / (np.pi / 90) - 1) < 1e-2, pc
    assert abs(cl["full_circle"]["ratio_to_dload"] - 1) < 1e-5, cl
    assert abs(cl["per_radian"]["ratio_to_dload"] * 2 * np.pi - 1) < 1e-5, cl

    # the ladder
    runs = []
    print(f"\n{'n':>4} {'h mm':>7} {'nodes':>6} {'ur_mid':>13} {'ur_end':>13} {'stt_mid':>13} "
          f"{'srr_mid':>13} {'RF_z/rad':>10} {'ccx s':>6}")
    for n in args.sizes:
        r = run_cax8(n, args.out, args.threads)
        runs.append(r)
        print(f"{n:4d} {r['h_m'] * 1e3:7.4g} {r['nodes']:6d} {r['ur_mid']:13.7e} "
              f"{r['ur_end']:13.7e} {r['stt_mid']:13.7e} {r['srr_mid']:13.6e} "
              f"{r['RF_total_per_rad'][1]:10.2e} {r['ccx_s']:6.2f}")
    conv = convergence(runs)
    print("\nconverged (Richardson of the last three, observed order p; spread = max - min of "
          "Richardson, fit over all, finest):")
    for q in QUANTITIES:
        c = conv[q]
        print(f"  {q:8s} {c['converged']: .7e}  p = {c.get('observed_order', float('nan')):.2f}"
              f"  spread {c['spread']:.1e} ({c['rel_spread']:.1e} rel)  finest {c['finest']:.7e}")

    three = None
    patch = None
    if not args.no_3d:
        print()
        patch = patch_test(args.out, args.threads)
        three = run_3d(args.h3d, args.out, args.threads)
        three["rel_diff"] = {q: three[q] / conv[q]["converged"] - 1
                             for q in ("ur_mid", "ur_end", "stt_mid")}
        print("3D vs CAX8 converged: " + ", ".join(f"{q} {v:+.2e}"
                                                    for q, v in three["rel_diff"].items()))
        assert abs(three["rel_diff"]["ur_mid"]) < 5e-3, three["rel_diff"]
        assert abs(three["rel_diff"]["ur_end"]) < 5e-3, three["rel_diff"]
        assert abs(three["rel_diff"]["stt_mid"]) < 2e-2, three["rel_diff"]

    total = time.perf_counter() - t0
    data = {
        "title": "thick-walled cylinder (validation/geometry/lame_cylinder.geo), outer clamped, "
                 "internal pressure, ends free: CalculiX reference",
        "problem": {"geometry": "validation/geometry/lame_cylinder.geo", "a_m": A_IN,
                    "b_m": B_OUT, "L_m": LEN, "E_Pa": E, "nu": NU, "pressure_Pa": P,
                    "clamp": "outer (r = b): u = 0", "load": "pressure on bore (r = a)",
                    "ends": "free", "units": "m, Pa"},
        "quantities": {"ur_mid": "u_r(a, z = L/2) [m]", "ur_end": "u_r(a, z = 0) [m]",
                       "stt_mid": "sigma_thetatheta(a, L/2) [Pa]: CAX8 nodal stress (ccx "
                                  "extrapolates integration points to nodes, averaged over "
                                  "the adjacent elements), .frd SZZ",
                       "srr_mid": "sigma_rr(a, L/2) [Pa], must tend to -p"},
        "element": "CAX8 structured n x n on [a, b] x [0, L]",
        "solver": "ccx *STATIC, SPOOLES", "threads": args.threads,
        "ccx_version": ccx_version(), "host": platform.node(),
        "checks": checks, "ladder": runs, "converged": conv,
        "reference": {q: {"value": conv[q]["converged"], "spread": conv[q]["spread"]}
                      for q in QUANTITIES},
        "patch_test_c3d10": patch, "cross_check_3d": three,
        "total_s": round(total, 1),
        "command": " ".join(["/usr/bin/python3 validation/lame_cylinder_fem.py"]
                            + list(argv if argv is not None else sys.argv[1:])),
    }
    if three is not None:
        data["gmsh_version"] = gmsh_version()
    tmp = args.json.with_name(args.json.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    os.replace(tmp, args.json)
    print(f"\ntotal {total:.0f} s; wrote {_rel(args.json)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
