#!/usr/bin/env python3
"""CalculiX reference for the L-bracket of examples/bracket.geo (linear elasticity, static).

The problem: the solid of examples/bracket.geo (metres), E = 70e9 Pa, nu = 0.33; every node of
the physical surface "bore" (the bolt hole) clamped, u = 0; a uniform pressure p = 1e6 Pa on the
physical surface "arm_face" (the arm's inner face x = 0.01, z 0.015..0.06, area 0.0018 m^2),
pushing into the solid (force along -x, 1800 N in all); no gravity. Wanted: u at the probe
points P = (0, 0, 0.06) (the arm's top outer corner, a mesh node) and Q = (0.005, 0.02, 0.06)
(the centre of the arm's top face, inside a flat face of a tetrahedron: evaluated with the
element's quadratic shape functions) and the total reaction at the bore (must be +1800 N in x).

Three sets of meshes, each run the same way:
  * uniform (the ladder asked for): the unchanged .geo, element size h = 4, 2.83, 2, 1.41, 1 mm,
      gmsh examples/bracket.geo -3 -order 2 -clmax H -clmin H/2 -format msh2 -o OUT/...msh
  * graded (cross-check): a copy of the .geo with a size field appended (GRADED_FIELD; the
    geometry is unchanged): size H/8 on the bore growing linearly to H at 4 mm from it,
    H = 5.66, 4, 2.83, 2, 1.41 mm (every size scales with H: a proper ladder);
  * bore study: H = 2 mm, bore size H/f for f = 1, 2, 4, 8, 16 (f = 1 and 8 reuse the runs above).
For each mesh: read the msh2 file (10-node tetrahedra, gmsh type 11, and the 6-node triangles,
type 9, of the two physical surfaces), write a CalculiX model on C3D10 and run `ccx`:
  * node order: gmsh's 10-node tet is corners 0-3, then the edges 0-1, 1-2, 2-0, 3-0, 3-2, 3-1;
    CalculiX C3D10 wants corners 1-4, then 1-2, 2-3, 3-1, 1-4, 2-4, 3-4: the last two swap
    (GMSH_TO_C3D10). Checked on every element (each mid node lies near the midpoint of its
    edge, positive corner volume) and by a patch test (below); with the order unconverted ccx
    stops with "nonpositive jacobian";
  * the pressure as consistent nodal loads (*CLOAD) of the flat 6-node triangles: 0 at the
    corners, p A / 3 at each mid-edge node, along -x; the total is asserted to be p x 0.0018 m^2
    to 1e-9 relative; every face node is checked to lie on x = 0.01;
  * the clamp: *BOUNDARY 1-3 on every node (corners and mid-edges) of the bore's triangles;
  * *STATIC with the SPOOLES direct solver (ccx's ITERATIVE CHOLESKY stops at a residual of
    1e-4: at h = 2 mm its reaction was off by 1e-4 and u_y(P) by a factor ~3, so not used);
    u at P and at the nodes of the elements around Q and the reaction at the bore (per node
    and total) via *NODE PRINT into the .dat (7 significant digits; the .frd's DISP block, 6
    digits, is a cross-check); the reaction must balance (1800, 0, 0) N to 1e-6 relative;
  * limits: a watchdog kills ccx past --max-seconds (360) or --max-rss-gb (8 GB resident) and
    the ladder stops there; a run whose SPOOLES memory, extrapolated from the previous mesh as
    nodes^(4/3), would exceed the limit is not started (--no-predict starts it anyway).
    Such runs: the uniform h = 1 mm mesh (349252 nodes; predicted 21 GB; started anyway it was
    killed at 8.0 GB after 222 s) and the graded H = 1.41 mm mesh (234269 nodes; predicted
    8.6 GB; started anyway it was killed at 8.0 GB after 166 s).
Before the ladders a patch test: the cube [0, 0.01]^3 meshed the same way (gmsh, -order 2,
h = 3.5 mm), symmetry planes x = 0, y = 0, z = 0 on rollers, uniform tension 1e6 Pa on x = 0.01
(consistent loads as above); every node must reproduce the exact uniform strain
u = sigma / E (x, -nu y, -nu z) to 1e-5 of the largest displacement.

Convergence, per series: from the last three meshes (unstructured, not nested, h ratio about
sqrt 2) the observed order p and the Richardson value v_inf of v = v_inf + C h^p through the
three points, with the nominal h and with the effective h = (V / nodes)^(1/3); a least-squares
fit v_inf + C h^p over every mesh (only when all successive differences are of one sign and
contracting); error of the finest = |Richardson (nominal h) - finest|.
The reference (combined()) is the graded series' Richardson value; its uncertainty the largest
distance to any other estimate (both series, both h measures, the fits; a series without a
Richardson value contributes its finest value). u_y(Q) is zero by
symmetry (the model is symmetric about y = 0.02; the meshes are not exactly): only its size
means something (mesh asymmetry).

Why two series: the clamped bore's edges (the circles where the clamped bore meets the free
faces z = 0 and z = 0.01) are clamped/free 90-degree edges, stress ~ r^(lambda - 1) with
lambda ~ 0.69 (Williams, plane strain, nu = 0.33); a point displacement then converges as
(element size at the bore)^(2 lambda ~ 1.4). The bore study shows it (differences of u_x(P)
shrinking 2.6x per halving of the bore size, down to the noise of the unstructured meshes,
~5e-8 m at H = 2 mm); the uniform series, whose bore elements are h, converges at that slow
rate and its extrapolation is the less certain; the graded series reduces that error ~17x at
the same H.

Run (stdlib + numpy; Debian's python for numpy; ccx and gmsh on PATH or CCX=/path):
  /usr/bin/python3 validation/bracket_fem.py                  # everything (~6 min, 2 cores)
  /usr/bin/python3 validation/bracket_fem.py --sizes 4 2.83 2 --graded-sizes --no-bore-study \
      --json /tmp/bracket_quick.json                          # a quick subset (mm), ~30 s
  /usr/bin/python3 validation/bracket_fem.py --patch-only     # the patch test alone
Options: --threads N (ccx OpenMP/SPOOLES threads, default 2), --max-seconds, --max-rss-gb,
--no-predict, --out (default validation/fem/out/bracket/, git-ignored), --json (default
validation/bracket_fem.json).

Results: the .geo copy, .msh, .inp, .frd, .dat and logs of each mesh go to
OUT/{uniform,graded}/h<H>/ and OUT/bore/h2_f<f>/, the patch test to OUT/patch/; the tables,
convergence, reference values, run times, peak memory and the ccx/gmsh versions to
validation/bracket_fem.json.

Last full run (`/usr/bin/python3 validation/bracket_fem.py`, 2 threads, ccx 2.20, gmsh 4.8.4),
as printed (lengths in m):

  patch test: cube h = 3.5 mm, 2050 nodes, 1107 C3D10, max |u - exact| / max |u| = 3.48e-07 (pass), 0.5 s

  uniform series (the .geo as it is):
   h mm  bore   nodes         ux(P)         uy(P)         uz(P)         ux(Q)         uy(Q)         uz(Q)  RFx-1800  ccx s    GB
      4     4    8042 -7.481285e-04 -3.902151e-07 -3.653202e-04 -7.493239e-04  6.344395e-08 -2.919852e-04  0.00e+00    1.5  0.11
   2.83  2.83   21699 -7.518810e-04 -4.327935e-07 -3.667786e-04 -7.530846e-04  2.289814e-08 -2.930874e-04  0.00e+00    5.3  0.46
      2     2   50596 -7.529060e-04 -4.648521e-07 -3.672925e-04 -7.541117e-04 -8.115489e-09 -2.934964e-04  0.00e+00   20.8  1.53
   1.41  1.41  134719 -7.534606e-04 -4.572484e-07 -3.676116e-04 -7.546650e-04 -6.315451e-10 -2.937680e-04  0.00e+00  115.0  5.86
      1     1  349252  ccx skipped: predicted 21 GB (SPOOLES, nodes^4/3 from the previous mesh) > 8 GB: the ladder stops here
  convergence from h = 2.83, 2, 1.41 mm (effective h (V/nodes)^(1/3) = 1.334, 1.006, 0.725 mm):
                 finest  p nom    Richardson  p eff    Richardson  p fit     fit v_inf err finest      rel    spread
    ux_P  -7.534606e-04   1.78 -7.541013e-04   2.52 -7.538952e-04   3.37 -7.536618e-04   6.41e-07  8.5e-04  4.40e-07
    uy_P  -4.572484e-07      -  not monotone      -  not monotone      -             -   7.60e-09  1.7e-02         -
    uz_P  -3.676116e-04   1.39 -3.681224e-04   2.06 -3.679445e-04   2.61 -3.678151e-04   5.11e-07  1.4e-03  3.07e-07
    ux_Q  -7.546650e-04   1.80 -7.552983e-04   2.53 -7.550950e-04   3.37 -7.548662e-04   6.33e-07  8.4e-04  4.32e-07
    uy_Q  -6.315451e-10      -  not monotone      -  not monotone      -             -   7.48e-09  1.2e+01         -
    uz_Q  -2.937680e-04   1.20 -2.942915e-04   1.84 -2.940990e-04   2.42 -2.939629e-04   5.23e-07  1.8e-03  3.29e-07
    (uy_Q is zero by symmetry about y = 0.02: its values measure the mesh asymmetry)

  graded series (bore refined: H/8 at the bore, H at 4 mm):
   h mm  bore   nodes         ux(P)         uy(P)         uz(P)         ux(Q)         uy(Q)         uz(Q)  RFx-1800  ccx s    GB
   5.66 0.708    7344 -7.482775e-04 -4.415217e-07 -3.660796e-04 -7.494796e-04  1.475238e-08 -2.927032e-04  0.00e+00    1.2  0.07
      4   0.5   15772 -7.501328e-04 -3.121755e-07 -3.669119e-04 -7.512800e-04  1.293837e-07 -2.934276e-04  0.00e+00    2.8  0.19
   2.83 0.354   37221 -7.527397e-04 -4.423460e-07 -3.676306e-04 -7.539409e-04  1.279475e-08 -2.938587e-04  0.00e+00    9.5  0.70
      2  0.25   91506 -7.534774e-04 -4.514983e-07 -3.678452e-04 -7.546804e-04  4.568564e-09 -2.940026e-04  0.00e+00   41.2  2.49
   1.41 0.176  234269  ccx skipped: predicted 9 GB (SPOOLES, nodes^4/3 from the previous mesh) > 8 GB: the ladder stops here
  convergence from h = 4, 2.83, 2 mm (effective h (V/nodes)^(1/3) = 1.484, 1.114, 0.825 mm):
                 finest  p nom    Richardson  p eff    Richardson  p fit     fit v_inf err finest      rel    spread
    ux_P  -7.534774e-04   3.65 -7.537663e-04   4.48 -7.537376e-04      -             -   2.89e-07  3.8e-04  2.87e-08
    uy_P  -4.514983e-07   7.67 -4.521837e-07   9.30 -4.520987e-07      -             -   6.85e-10  1.5e-03  8.50e-11
    uz_P  -3.678452e-04   3.50 -3.679358e-04   4.30 -3.679268e-04   2.08 -3.682633e-04   9.06e-08  2.5e-04  3.36e-07
    ux_Q  -7.546804e-04   3.71 -7.549627e-04   4.54 -7.549347e-04      -             -   2.82e-07  3.7e-04  2.80e-08
    uy_Q   4.568564e-09   7.66  3.950213e-09   9.28  4.026835e-09      -             -   6.18e-10  1.6e-01  7.66e-11
    uz_Q  -2.940026e-04   3.18 -2.940742e-04   3.91 -2.940670e-04   2.81 -2.941509e-04   7.16e-08  2.4e-04  8.38e-08
    (uy_Q is zero by symmetry about y = 0.02: its values measure the mesh asymmetry)

  bore study: H = 2 mm, bore element size H / factor (H at 4 mm):
   h mm  bore   nodes         ux(P)         uy(P)         uz(P)         ux(Q)         uy(Q)         uz(Q)  RFx-1800  ccx s    GB
      2     2   50596 -7.529060e-04 -4.648521e-07 -3.672925e-04 -7.541117e-04 -8.115489e-09 -2.934964e-04  0.00e+00   20.8  1.53
      2     1   54116 -7.532787e-04 -4.581069e-07 -3.676294e-04 -7.544841e-04 -1.484119e-09 -2.938021e-04  0.00e+00   24.1  1.62
      2   0.5   63907 -7.534216e-04 -4.573929e-07 -3.677826e-04 -7.546254e-04 -1.164294e-09 -2.939428e-04  0.00e+00   28.9  1.85
      2  0.25   91506 -7.534774e-04 -4.514983e-07 -3.678452e-04 -7.546804e-04  4.568564e-09 -2.940026e-04  0.00e+00   41.2  2.49
      2 0.125  159846 -7.535366e-04 -4.457265e-07 -3.678804e-04 -7.547367e-04  9.506622e-09 -2.940348e-04  0.00e+00   73.2  4.10
    ux_P: differences -3.73e-07 -1.43e-07 -5.58e-08 -5.92e-08; rate per halving 1.38 1.36 -0.09
    uz_P: differences -3.37e-07 -1.53e-07 -6.26e-08 -3.52e-08; rate per halving 1.14 1.29 0.83
    ux_Q: differences -3.72e-07 -1.41e-07 -5.50e-08 -5.63e-08; rate per halving 1.40 1.36 -0.03
    uz_Q: differences -3.06e-07 -1.41e-07 -5.98e-08 -3.22e-08; rate per halving 1.12 1.23 0.89

  reference (graded Richardson; uncertainty = largest distance to any other estimate):
    ux_P: -7.53766e-04 +- 3.4e-07   finest uniform: error 3.1e-07 (4.1e-04 rel)   finest graded: error 2.9e-07 (3.8e-04 rel)
    uy_P: -4.52184e-07 +- 5.1e-09   finest uniform: error 5.1e-09 (1.1e-02 rel)   finest graded: error 6.9e-10 (1.5e-03 rel)
    uz_P: -3.67936e-04 +- 3.3e-07   finest uniform: error 3.2e-07 (8.8e-04 rel)   finest graded: error 9.1e-08 (2.5e-04 rel)
    ux_Q: -7.54963e-04 +- 3.4e-07   finest uniform: error 3.0e-07 (3.9e-04 rel)   finest graded: error 2.8e-07 (3.7e-04 rel)
    uy_Q:  3.95021e-09 +- 4.6e-09   finest uniform: error 4.6e-09 (1.2e+00 rel)   finest graded: error 6.2e-10 (1.6e-01 rel)
    uz_Q: -2.94074e-04 +- 2.2e-07   finest uniform: error 3.1e-07 (1.0e-03 rel)   finest graded: error 7.2e-08 (2.4e-04 rel)
    (uy_Q: zero by symmetry)
  reaction at the bore: max |RF - (1800, 0, 0)| / 1800 over the runs = 6.2e-12

  total 402 s
  wrote validation/bracket_fem.json

Summary of that run: the uniform ladder stops at h = 1.41 mm (134719 nodes, 115 s, 5.9 GB; the
1 mm mesh would need ~21 GB with SPOOLES); its observed order from 2.83/2/1.41 mm is 1.2-1.8
(nominal h), the bore-edge rate ~1.4; the reference values (graded Richardson, m) are
  u(P) = (-7.5377e-4 +- 3.4e-7, -4.52e-7 +- 5e-9, -3.6794e-4 +- 3.3e-7)
  u(Q) = (-7.5496e-4 +- 3.4e-7, 0 (symmetry; computed |u_y| < 1e-8), -2.9407e-4 +- 2.2e-7)
and the finest uniform mesh (1.41 mm) is off by 4e-4 (u_x) to 1e-3 (u_z) relative, the finest
graded mesh (H = 2 mm, 0.25 mm at the bore) by 4e-4 (u_x) and 2.5e-4 (u_z). The reaction at
the bore balances the 1800 N load to 6e-12 relative in every run.
"""

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from fem import FemError, _rel, ccx_path, ccx_version, read_frd_blocks  # noqa: E402

GEO = ROOT / "examples" / "bracket.geo"
DEFAULT_OUT = HERE / "fem" / "out" / "bracket"
DEFAULT_JSON = HERE / "bracket_fem.json"

E = 70e9
NU = 0.33
PRESSURE = 1e6
LOAD_AREA = 0.045 * 0.04          # arm_face: x = 0.01, y 0..0.04, z 0.015..0.06
LOAD_X = 0.01
P_POINT = np.array([0.0, 0.0, 0.06])
Q_POINT = np.array([0.005, 0.02, 0.06])
SIZES_MM = [4.0, 2.83, 2.0, 1.41, 1.0]
GRADED_SIZES_MM = [5.66, 4.0, 2.83, 2.0, 1.41]
GRADED_FACTOR = 8.0          # element size at the bore: H / 8
GRADED_DISTANCE_MM = 4.0     # growing linearly to H at 4 mm from the bore
BORE_STUDY_H_MM = 2.0
BORE_STUDY_FACTORS = [1.0, 2.0, 4.0, 8.0, 16.0]

# A copy of examples/bracket.geo with this appended (the geometry unchanged): the element size
# H / factor on the bore, growing linearly with the distance d from it to H at d = distance.
GRADED_FIELD = """
// appended by validation/bracket_fem.py: mesh refinement at the bore (geometry unchanged)
Field[1] = Distance;
Field[1].SurfacesList = {{bore()}};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = {smin!r};
Field[2].SizeMax = {smax!r};
Field[2].DistMin = 0.0;
Field[2].DistMax = {dist!r};
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
"""

# gmsh 10-node tet -> CalculiX C3D10: the mid nodes of the edges 3-2 and 3-1 swap places.
GMSH_TO_C3D10 = np.array([0, 1, 2, 3, 4, 5, 6, 7, 9, 8])
# C3D10 mid node k (4..9) sits on the edge between these corners
C3D10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
# gmsh 6-node triangle: corners 0-2, mid-edges 0-1, 1-2, 2-0
TRI6_EDGES = [(0, 1), (1, 2), (2, 0)]


def fmt(x):
    """A float in at most 20 characters (ccx's field width): exact when repr fits, else 14
    significant digits."""
    r = repr(float(x))
    return r if len(r) <= 20 else f"{x:.13e}"


# --------------------------------------------------------------------------------------------
# gmsh


def gmsh_version():
    out = subprocess.run(["gmsh", "--version"], capture_output=True, text=True)
    return (out.stdout + out.stderr).strip().splitlines()[-1].strip()


def run_gmsh(geo, msh, h, log_path, clmin=None):
    clmin = h / 2 if clmin is None else clmin
    cmd = ["gmsh", str(geo), "-3", "-order", "2", "-clmax", repr(h), "-clmin", repr(clmin),
           "-format", "msh2", "-o", str(msh)]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    Path(log_path).write_text(" ".join(cmd) + "\n" + proc.stdout + proc.stderr)
    if proc.returncode != 0 or not Path(msh).exists():
        raise FemError(f"gmsh failed on {geo} (h = {h}): see {log_path}")
    return cmd, wall


def read_msh2(path):
    """An ASCII msh2 file: node ids (n,), coordinates (n, 3), physical names {name: (dim, tag)}
    and the elements {type: (physical tags (e,), node ids (e, k))}."""
    names, elems = {}, {}
    with open(path) as f:
        lines = iter(f)
        for line in lines:
            s = line.strip()
            if s == "$MeshFormat":
                ver = next(lines).split()
                if not ver[0].startswith("2") or ver[1] != "0":
                    raise ValueError(f"{path}: not an ASCII msh2 file ({' '.join(ver)})")
            elif s == "$PhysicalNames":
                for _ in range(int(next(lines))):
                    d, t, name = next(lines).split(maxsplit=2)
                    names[name.strip().strip('"')] = (int(d), int(t))
            elif s == "$Nodes":
                n = int(next(lines))
                rows = [next(lines) for _ in range(n)]
                arr = np.array(" ".join(rows).split(), dtype=float).reshape(n, 4)
                ids = arr[:, 0].astype(np.int64)
                coords = arr[:, 1:4].copy()
            elif s == "$Elements":
                n = int(next(lines))
                by_type = {}
                for _ in range(n):
                    tok = next(lines).split()
                    et, nt = int(tok[1]), int(tok[2])
                    phys = int(tok[3]) if nt > 0 else 0
                    by_type.setdefault(et, ([], []))
                    by_type[et][0].append(phys)
                    by_type[et][1].append([int(v) for v in tok[3 + nt:]])
                for et, (ph, conn) in by_type.items():
                    elems[et] = (np.array(ph, dtype=np.int64), np.array(conn, dtype=np.int64))
    return ids, coords, names, elems


class TetMesh:
    """C3D10 mesh: node ids (n,) (the gmsh ids, used as the ccx node numbers), coordinates
    (n, 3), tets (e, 10) as row indices in C3D10 order, and the 6-node triangles (as row
    indices) of each physical surface by name."""

    def __init__(self, path):
        ids, coords, names, elems = read_msh2(path)
        self.ids, self.coords = ids, coords
        row = np.full(ids.max() + 1, -1, dtype=np.int64)
        row[ids] = np.arange(len(ids))
        if 11 not in elems:
            raise ValueError(f"{path}: no 10-node tetrahedra (gmsh type 11): was it -order 2?")
        self.tets = row[elems[11][1]][:, GMSH_TO_C3D10]
        self.surfaces = {}
        for name, (dim, tag) in names.items():
            if dim == 2:
                ph, conn = elems.get(9, (np.zeros(0, np.int64), np.zeros((0, 6), np.int64)))
                self.surfaces[name] = row[conn[ph == tag]]
        if np.any(self.tets < 0) or any(np.any(t < 0) for t in self.surfaces.values()):
            raise ValueError(f"{path}: an element references a missing node")
        self.check()

    def check(self):
        """Every element: positive corner volume, each mid node near its edge's midpoint (the
        wrong order puts it half an edge away)."""
        X = self.coords[self.tets]
        v = np.einsum("ij,ij->i", X[:, 1] - X[:, 0],
                      np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 0])) / 6.0
        if np.any(v <= 0):
            raise ValueError(f"{np.sum(v <= 0)} tetrahedra with non-positive volume")
        worst = 0.0
        for k, (a, b) in enumerate(C3D10_EDGES):
            length = np.linalg.norm(X[:, b] - X[:, a], axis=1)
            dev = np.linalg.norm(X[:, 4 + k] - 0.5 * (X[:, a] + X[:, b]), axis=1) / length
            worst = max(worst, float(dev.max()))
        if worst > 0.2:
            raise ValueError(f"a mid-edge node lies {worst:.3f} edge lengths off its edge's "
                             "midpoint: wrong node order")
        self.volume = float(v.sum())
        self.worst_mid_offset = worst
        for name, tri in self.surfaces.items():
            Y = self.coords[tri]
            for k, (a, b) in enumerate(TRI6_EDGES):
                length = np.linalg.norm(Y[:, b] - Y[:, a], axis=1)
                dev = np.linalg.norm(Y[:, 3 + k] - 0.5 * (Y[:, a] + Y[:, b]), axis=1) / length
                if dev.max() > 0.2:
                    raise ValueError(f"surface {name}: triangle node order")


def flat_face_loads(mesh, tri, axis, value, traction):
    """Consistent nodal forces of a uniform traction (3-vector) on flat 6-node triangles lying
    on the plane x_axis = value: corners 0, each mid-edge node A/3 t. {row: force (3,)}."""
    Y = mesh.coords[tri]
    off = np.abs(Y[:, :, axis] - value).max()
    if off > 1e-9:
        raise ValueError(f"a loaded face node lies {off:.3e} m off the plane x{axis} = {value}")
    area = 0.5 * np.linalg.norm(np.cross(Y[:, 1] - Y[:, 0], Y[:, 2] - Y[:, 0]), axis=1)
    forces = {}
    for e in range(len(tri)):
        for k in range(3, 6):
            n = int(tri[e, k])
            forces[n] = forces.get(n, 0.0) + area[e] / 3.0 * np.asarray(traction, float)
    return forces, float(area.sum())


def tet10_shape(lam):
    """C3D10 shape functions at barycentric coordinates lam (4,) (lam_i of corner i)."""
    N = np.empty(10)
    N[:4] = lam * (2.0 * lam - 1.0)
    for k, (a, b) in enumerate(C3D10_EDGES):
        N[4 + k] = 4.0 * lam[a] * lam[b]
    return N


def locate(mesh, p, tol=1e-9):
    """Every tetrahedron containing p (on a face or an edge: several) with p's barycentric
    coordinates; the elements must be straight-sided there (checked), so the corner map is the
    element's own."""
    X = mesh.coords[mesh.tets]
    lo, hi = X.min(axis=1), X.max(axis=1)
    cand = np.nonzero(np.all((p >= lo - 1e-9) & (p <= hi + 1e-9), axis=1))[0]
    out = []
    for e in cand:
        x = X[e]
        T = np.column_stack([x[1] - x[0], x[2] - x[0], x[3] - x[0]])
        l123 = np.linalg.solve(T, p - x[0])
        lam = np.concatenate([[1.0 - l123.sum()], l123])
        if lam.min() >= -tol:
            for k, (a, b) in enumerate(C3D10_EDGES):
                if np.linalg.norm(x[4 + k] - 0.5 * (x[a] + x[b])) > 1e-12:
                    raise ValueError(f"element around {p} has a curved edge")
            out.append((int(e), np.clip(lam, 0.0, 1.0)))
    if not out:
        raise ValueError(f"point {p} is not in the mesh")
    return out


# --------------------------------------------------------------------------------------------
# CalculiX


def _write_ids(f, ids, per_line=16):
    ids = [int(i) for i in ids]
    for k in range(0, len(ids), per_line):
        f.write(", ".join(str(i) for i in ids[k:k + per_line]) + ",\n")


def write_inp(path, mesh, title, boundary, forces, print_nodes, print_rf_set):
    """boundary: [(name, rows, first dof, last dof)]; forces: {row: (3,)} (*CLOAD);
    print_nodes: rows whose U go to the .dat; print_rf_set: the name of a boundary set whose
    reactions (per node and total) go to the .dat."""
    ids = mesh.ids
    with open(path, "w") as f:
        f.write(f"** {title}\n** written by validation/bracket_fem.py\n*NODE, NSET=NALL\n")
        f.write("".join(f"{i}, {fmt(x)}, {fmt(y)}, {fmt(z)}\n"
                        for i, (x, y, z) in zip(ids, mesh.coords)))
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        f.write("".join(f"{e + 1}, " + ", ".join(str(v) for v in ids[c]) + "\n"
                        for e, c in enumerate(mesh.tets)))
        for name, rows, _, _ in boundary:
            f.write(f"*NSET, NSET={name}\n")
            _write_ids(f, ids[np.unique(rows)])
        f.write("*NSET, NSET=NPROBE\n")
        _write_ids(f, ids[np.unique(print_nodes)])
        f.write(f"*MATERIAL, NAME=M\n*ELASTIC\n{fmt(E)}, {fmt(NU)}\n"
                "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n*BOUNDARY\n")
        for name, _, d0, d1 in boundary:
            f.write(f"{name}, {d0}, {d1}\n")
        f.write("*STEP\n*STATIC, SOLVER=SPOOLES\n*CLOAD\n")
        for n in sorted(forces):
            for a in range(3):
                if forces[n][a] != 0.0:
                    f.write(f"{ids[n]}, {a + 1}, {fmt(forces[n][a])}\n")
        f.write("*NODE PRINT, NSET=NPROBE\nU\n")
        if print_rf_set:
            f.write(f"*NODE PRINT, NSET={print_rf_set}, TOTALS=YES\nRF\n")
        f.write("*NODE FILE\nU\n*END STEP\n")


def _rss_kb(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


def run_ccx_watched(job_dir, job, threads, max_seconds, max_rss_gb):
    """Run `ccx -i job` in job_dir; kill it (by its own pid) past max_seconds of wall time or
    max_rss_gb of resident memory. Returns (frd path or None, wall s, peak RSS GB, status)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
    frd = job_dir / f"{job}.frd"
    for ext in (".frd", ".dat"):
        (job_dir / f"{job}{ext}").unlink(missing_ok=True)
    log = open(job_dir / "ccx.log", "w")
    t0 = time.perf_counter()
    proc = subprocess.Popen([ccx_path(), "-i", job], cwd=job_dir, env=env, stdout=log,
                            stderr=subprocess.STDOUT)
    peak, status = 0, "ok"
    while proc.poll() is None:
        peak = max(peak, _rss_kb(proc.pid))
        wall = time.perf_counter() - t0
        if wall > max_seconds or peak > max_rss_gb * 1024**2:
            status = (f"killed after {wall:.0f} s" if wall > max_seconds
                      else f"killed at {peak / 1024**2:.1f} GB resident")
            proc.kill()
            proc.wait()
            break
        time.sleep(0.25)
    wall = time.perf_counter() - t0
    log.close()
    text = (job_dir / "ccx.log").read_text(errors="replace")
    if status == "ok":
        errors = [l.strip() for l in text.splitlines() if "*ERROR" in l]
        if proc.returncode != 0 or errors or not frd.exists():
            detail = "; ".join(errors[:3]) or f"exit status {proc.returncode}"
            raise FemError(f"{job_dir / job}.inp: ccx failed: {detail} "
                           f"(log {job_dir / 'ccx.log'})")
    return (frd if status == "ok" else None), wall, peak / 1024**2, status


def read_dat(path):
    """The *NODE PRINT tables of a ccx .dat: {'U': {node: (3,)}, 'RF': {node: (3,)},
    'RF_total': (3,)}."""
    out = {"U": {}, "RF": {}, "RF_total": None}
    key = None
    for line in Path(path).read_text(errors="replace").splitlines():
        s = line.strip()
        if not s:
            continue
        low = s.lower()
        if low.startswith("displacements"):
            key = "U"
        elif low.startswith("forces"):
            key = "RF"
        elif low.startswith("total force"):
            key = "RF_total"
        elif low[0].isalpha():
            key = None
        elif key is not None:
            tok = s.split()
            if key == "RF_total":
                out["RF_total"] = np.array([float(t) for t in tok[:3]])
                key = None
            else:
                out[key][int(tok[0])] = np.array([float(t) for t in tok[1:4]])
    return out


# --------------------------------------------------------------------------------------------
# Patch test


CUBE_GEO = """SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.01, 0.01, 0.01};
Physical Volume("cube") = {1};
"""


def patch_test(out_dir, threads, log=print, h=0.0035):
    """The cube [0, 0.01]^3 on rollers on x = 0, y = 0, z = 0 under uniform tension sigma on
    x = 0.01: every node must carry u = sigma / E (x, -nu y, -nu z)."""
    d = out_dir / "patch"
    d.mkdir(parents=True, exist_ok=True)
    L, sigma = 0.01, 1e6
    names = ["x0", "x1", "y0", "y1", "z0", "z1"]
    geo = CUBE_GEO
    for k, name in enumerate(names):
        v = 0.0 if k % 2 == 0 else L
        lo = [-1e-6] * 3
        hi = [L + 1e-6] * 3
        lo[k // 2], hi[k // 2] = v - 1e-6, v + 1e-6
        geo += (f"s{name}() = Surface In BoundingBox{{{lo[0]}, {lo[1]}, {lo[2]}, "
                f"{hi[0]}, {hi[1]}, {hi[2]}}};\nPhysical Surface(\"{name}\") = {{s{name}()}};\n")
    (d / "cube.geo").write_text(geo)
    run_gmsh(d / "cube.geo", d / "cube.msh", h, d / "gmsh.log")
    mesh = TetMesh(d / "cube.msh")
    forces, area = flat_face_loads(mesh, mesh.surfaces["x1"], 0, L, [sigma, 0.0, 0.0])
    total = sum(forces.values())
    assert abs(total[0] - sigma * L * L) <= 1e-9 * sigma * L * L, total
    boundary = [("NX0", mesh.surfaces["x0"].ravel(), 1, 1),
                ("NY0", mesh.surfaces["y0"].ravel(), 2, 2),
                ("NZ0", mesh.surfaces["z0"].ravel(), 3, 3)]
    write_inp(d / "cube.inp", mesh, "patch test: cube in uniform tension", boundary, forces,
              np.arange(len(mesh.ids)), None)
    frd, wall, _, status = run_ccx_watched(d, "cube", threads, 120, 4)
    dat = read_dat(d / "cube.dat")
    X = mesh.coords
    exact = sigma / E * np.column_stack([X[:, 0], -NU * X[:, 1], -NU * X[:, 2]])
    U = np.array([dat["U"][int(i)] for i in mesh.ids])
    err = np.abs(U - exact).max() / np.abs(exact).max()
    ok = err < 1e-5
    log(f"patch test: cube h = {h * 1e3:g} mm, {len(mesh.ids)} nodes, {len(mesh.tets)} C3D10, "
        f"max |u - exact| / max |u| = {err:.2e} ({'pass' if ok else 'FAIL'}), {wall:.1f} s")
    if not ok:
        raise FemError(f"patch test failed: relative error {err:.3e} (see {d})")
    return {"h_m": h, "nodes": int(len(mesh.ids)), "elements": int(len(mesh.tets)),
            "max_rel_error": float(err), "passed": bool(ok)}


# --------------------------------------------------------------------------------------------
# The bracket


def run_bracket(h_mm, run_dir, threads, max_seconds, max_rss_gb, factor=1.0,
                distance_mm=GRADED_DISTANCE_MM, previous=None, predict=True):
    """One mesh: uniform (factor 1: the .geo as it is) or refined at the bore (factor > 1: a copy
    of the .geo with GRADED_FIELD). previous: (nodes, peak GB) of a smaller run of the series;
    with predict, a run whose SPOOLES memory, extrapolated as nodes^(4/3), would exceed
    max_rss_gb is skipped (status 'skipped ...') instead of being started."""
    h = h_mm * 1e-3
    d = Path(run_dir)
    d.mkdir(parents=True, exist_ok=True)
    t_all = time.perf_counter()
    if factor == 1.0:
        geo, clmin = GEO, h / 2
    else:
        geo = d / "bracket_graded.geo"
        geo.write_text(GEO.read_text() + GRADED_FIELD.format(
            smin=h / factor, smax=h, dist=distance_mm * 1e-3))
        clmin = h / factor / 2
    gmsh_cmd, gmsh_wall = run_gmsh(geo, d / "bracket.msh", h, d / "gmsh.log", clmin)
    mesh = TetMesh(d / "bracket.msh")
    bore, face = mesh.surfaces["bore"], mesh.surfaces["arm_face"]
    forces, area = flat_face_loads(mesh, face, 0, LOAD_X, [-PRESSURE, 0.0, 0.0])
    total = sum(forces.values())
    want = PRESSURE * LOAD_AREA
    if abs(total[0] + want) > 1e-9 * want or abs(area - LOAD_AREA) > 1e-9 * LOAD_AREA:
        raise FemError(f"h = {h_mm} mm: load total {total} (area {area}), want -{want} N in x")
    clamped = np.unique(bore.ravel())
    if np.intersect1d(clamped, np.array(sorted(forces))).size:
        raise FemError("a loaded node is clamped")
    # P: the node at the corner
    dist = np.linalg.norm(mesh.coords - P_POINT, axis=1)
    p_row = int(np.argmin(dist))
    if dist[p_row] > 1e-9:
        raise FemError(f"no node at P (nearest {dist[p_row]:.3e} m)")
    q_loc = locate(mesh, Q_POINT)
    q_rows = np.unique(np.concatenate([mesh.tets[e] for e, _ in q_loc]))
    write_inp(d / "bracket.inp", mesh, f"L-bracket, C3D10, h = {h_mm} mm",
              [("NBORE", clamped, 1, 3)], forces, np.concatenate([[p_row], q_rows]), "NBORE")
    rec = {"h_mm": h_mm, "bore_factor": factor, "bore_size_mm": h_mm / factor,
           "bore_distance_mm": distance_mm if factor != 1.0 else None,
           "run_dir": _rel(d), "nodes": int(len(mesh.ids)), "elements": int(len(mesh.tets)),
           "dofs": int(3 * len(mesh.ids)), "bore_nodes": int(len(clamped)),
           "load_nodes": int(len(forces)), "volume_m3": mesh.volume,
           "max_mid_node_offset": mesh.worst_mid_offset, "gmsh_s": round(gmsh_wall, 2),
           "gmsh_command": " ".join(_rel(c) if "/" in str(c) else str(c) for c in gmsh_cmd),
           "load_total_N": total.tolist()}
    if predict and previous is not None:
        guess = previous[1] * (len(mesh.ids) / previous[0]) ** (4.0 / 3.0)
        if guess > max_rss_gb:
            rec.update({"status": f"skipped: predicted {guess:.0f} GB (SPOOLES, nodes^4/3 from "
                                  f"the previous mesh) > {max_rss_gb:g} GB",
                        "ccx_s": None, "ccx_peak_rss_gb": None,
                        "total_s": round(time.perf_counter() - t_all, 2)})
            return rec
    frd, wall, rss, status = run_ccx_watched(d, "bracket", threads, max_seconds, max_rss_gb)
    rec.update({"ccx_s": round(wall, 2), "ccx_peak_rss_gb": round(rss, 3), "status": status})
    if frd is None:
        rec["total_s"] = round(time.perf_counter() - t_all, 2)
        return rec
    dat = read_dat(d / "bracket.dat")
    uP = dat["U"][int(mesh.ids[p_row])]
    uQs = [tet10_shape(lam) @ np.array([dat["U"][int(mesh.ids[r])] for r in mesh.tets[e]])
           for e, lam in q_loc]
    uQ = np.mean(uQs, axis=0)
    spread = float(np.abs(np.array(uQs) - uQ).max())
    # cross-check with the .frd (6 significant digits)
    U = read_frd_blocks(frd, "DISP", 3)[-1]
    uP_frd = U[mesh.ids[p_row] - 1]
    if np.abs(uP_frd - uP).max() > 1e-5 * np.abs(uP).max():
        raise FemError(f"u(P) from the .frd {uP_frd} differs from the .dat {uP}")
    rf_nodes = np.sum([v for v in dat["RF"].values()], axis=0)
    rf = dat["RF_total"]
    rf_rel = float(np.abs(rf - np.array([want, 0.0, 0.0])).max() / want)
    rec.update({
        "u_P": uP.tolist(), "u_Q": uQ.tolist(), "u_Q_element_spread": spread,
        "Q_elements": len(q_loc), "reaction_total_N": rf.tolist(),
        "reaction_sum_of_nodes_N": rf_nodes.tolist(), "reaction_rel_error": rf_rel,
        "total_s": round(time.perf_counter() - t_all, 2)})
    if rf_rel > 1e-6:
        raise FemError(f"h = {h_mm} mm: reaction {rf} does not balance {want} N "
                       f"(relative {rf_rel:.2e})")
    return rec


QUANTITIES = ["ux_P", "uy_P", "uz_P", "ux_Q", "uy_Q", "uz_Q"]


def values_of(rec):
    return dict(zip(QUANTITIES, list(rec["u_P"]) + list(rec["u_Q"])))


def richardson3(h, v):
    """Observed order and extrapolated value from three (h, v) (h decreasing, any ratios):
    v = v_inf + C h^p through the three points; None when the differences are not of one sign
    and contracting, or p is outside (0.05, 12)."""
    (h1, h2, h3), (v1, v2, v3) = h, v
    d1, d2 = v2 - v1, v3 - v2
    if not (d1 * d2 > 0 and abs(d2) < abs(d1)):
        return None
    r = d1 / d2

    def g(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - r

    lo, hi = 0.05, 12.0
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    C = d2 / (h3**p - h2**p)
    return p, v3 - C * h3**p


def fit_all(h, v):
    """Least squares v = v_inf + C h^p over every mesh (p scanned 0.5..6 by 0.001, v_inf and
    C linear): (p, v_inf, rms residual); needs four meshes or more, all successive differences
    of one sign and contracting (else a pre-asymptotic or noisy mesh would drive the fit)."""
    h, v = np.asarray(h, float), np.asarray(v, float)
    if len(v) < 4:
        return None
    d = np.diff(v)
    if not (np.all(d * d[0] > 0) and np.all(np.abs(d[1:]) < np.abs(d[:-1]))):
        return None
    best = None
    for p in np.arange(0.5, 6.0005, 0.001):
        A = np.column_stack([np.ones_like(h), h**p])
        coef, *_ = np.linalg.lstsq(A, v, rcond=None)
        res = float(np.sqrt(np.mean((A @ coef - v) ** 2)))
        if best is None or res < best[2]:
            best = (float(p), float(coef[0]), res)
    return best


def convergence(h_nominal, h_effective, values):
    """The observed order and Richardson value of one quantity from the last three meshes, with
    the nominal h and with the effective h = (V / nodes)^(1/3); a fit over all meshes; the best
    estimate (nominal Richardson) and the error of the finest mesh |best - finest| next to the
    spread of the extrapolations (max - min of the estimates)."""
    v = [float(x) for x in values]
    out = {"values": v, "finest": v[-1]}
    if len(v) >= 2:
        out["last_change"] = v[-1] - v[-2]
    if len(v) < 3:
        return out
    ests = []
    for key, h in (("nominal_h", h_nominal), ("effective_h", h_effective)):
        r = richardson3(h[-3:], v[-3:])
        out[key] = ({"observed_order": r[0], "richardson": r[1]} if r else
                    {"observed_order": None, "richardson": None,
                     "note": "last three not monotone and contracting"})
        if r:
            ests.append(r[1])
    f = fit_all(h_effective, v)
    if f:
        out["fit_all_effective_h"] = {"order": f[0], "v_inf": f[1], "rms_residual": f[2]}
        ests.append(f[1])
    if out["nominal_h"]["richardson"] is not None:
        out["best"] = out["nominal_h"]["richardson"]
        out["error_of_finest"] = abs(out["best"] - v[-1])
        out["extrapolation_spread"] = max(ests) - min(ests)
    else:
        out["best"] = v[-1]
        out["error_of_finest"] = abs(v[-1] - v[-2])
    return out


HEADER = (f"{'h mm':>5} {'bore':>5} {'nodes':>7} {'ux(P)':>13} {'uy(P)':>13} {'uz(P)':>13} "
          f"{'ux(Q)':>13} {'uy(Q)':>13} {'uz(Q)':>13} {'RFx-1800':>9} {'ccx s':>6} {'GB':>5}")


def print_run(rec):
    head = f"{rec['h_mm']:5g} {rec['bore_size_mm']:5.3g} {rec['nodes']:7d}"
    if rec["status"] != "ok":
        print(f"{head}  ccx {rec['status']}: the ladder stops here", flush=True)
        return
    v = list(rec["u_P"]) + list(rec["u_Q"])
    print(f"{head} " + " ".join(f"{x:13.6e}" for x in v)
          + f" {rec['reaction_total_N'][0] - PRESSURE * LOAD_AREA:9.2e}"
          f" {rec['ccx_s']:6.1f} {rec['ccx_peak_rss_gb']:5.2f}", flush=True)


def run_series(name, sizes, out_dir, args, factor=1.0):
    """A ladder of meshes; it stops at the first run killed or skipped (too big)."""
    print(f"\n{name} series" + (f" (bore refined: H/{factor:g} at the bore, H at "
                                 f"{GRADED_DISTANCE_MM:g} mm)" if factor != 1.0 else
                                 " (the .geo as it is)") + ":")
    print(HEADER)
    runs, previous = [], None
    for h_mm in sizes:
        rec = run_bracket(h_mm, out_dir / name / f"h{h_mm:g}", args.threads, args.max_seconds,
                          args.max_rss_gb, factor=factor, previous=previous,
                          predict=not args.no_predict)
        rec["series"] = name
        runs.append(rec)
        print_run(rec)
        if rec["status"] != "ok":
            break
        previous = (rec["nodes"], rec["ccx_peak_rss_gb"])
    done = [r for r in runs if r["status"] == "ok"]
    for r in done:
        r["h_effective_mm"] = 1e3 * (r["volume_m3"] / r["nodes"]) ** (1.0 / 3.0)
    hn = [r["h_mm"] for r in done]
    he = [r["h_effective_mm"] for r in done]
    conv = {q: convergence(hn, he, [values_of(r)[q] for r in done]) for q in QUANTITIES}
    if len(done) >= 3:
        print(f"convergence from h = {', '.join('%g' % x for x in hn[-3:])} mm (effective h "
              f"(V/nodes)^(1/3) = {', '.join('%.3f' % x for x in he[-3:])} mm):")
        print(f"  {'':5} {'finest':>13} {'p nom':>6} {'Richardson':>13} {'p eff':>6} "
              f"{'Richardson':>13} {'p fit':>6} {'fit v_inf':>13} {'err finest':>10} {'rel':>8}"
              f" {'spread':>9}")
        for q in QUANTITIES:
            c = conv[q]
            cells = [f"{c['finest']:13.6e}"]
            for key in ("nominal_h", "effective_h"):
                e = c[key]
                cells.append(f"{e['observed_order']:6.2f} {e['richardson']:13.6e}"
                             if e["richardson"] is not None else f"{'-':>6} {'not monotone':>13}")
            f = c.get("fit_all_effective_h")
            cells.append(f"{f['order']:6.2f} {f['v_inf']:13.6e}" if f else f"{'-':>6} {'-':>13}")
            cells.append(f"{c['error_of_finest']:10.2e} "
                         f"{c['error_of_finest'] / abs(c['best']):8.1e}")
            cells.append(f"{c['extrapolation_spread']:9.2e}" if "extrapolation_spread" in c
                         else f"{'-':>9}")
            print(f"  {q:5} " + " ".join(cells))
        print("  (uy_Q is zero by symmetry about y = 0.02: its values measure the mesh asymmetry)")
    return {"bore_factor": factor,
            "bore_distance_mm": GRADED_DISTANCE_MM if factor != 1.0 else None,
            "runs": runs, "convergence": conv}


def bore_study(series, out_dir, args):
    """u at fixed H = BORE_STUDY_H_MM with the element size at the bore H / factor: how fast the
    clamped bore's edges (a clamped/free 90-degree edge: stress ~ r^(lambda - 1), lambda ~ 0.69
    for nu = 0.33) converge. Runs of the series at the same H and factor are reused."""
    print(f"\nbore study: H = {BORE_STUDY_H_MM:g} mm, bore element size H / factor "
          f"(H at {GRADED_DISTANCE_MM:g} mm):")
    print(HEADER)
    have = {(r["h_mm"], r["bore_factor"]): r for s in series.values() for r in s["runs"]
            if r["status"] == "ok"}
    runs = []
    for fac in BORE_STUDY_FACTORS:
        rec = have.get((BORE_STUDY_H_MM, fac))
        if rec is None:
            rec = run_bracket(BORE_STUDY_H_MM, out_dir / "bore" / f"h{BORE_STUDY_H_MM:g}_f{fac:g}",
                              args.threads, args.max_seconds, args.max_rss_gb, factor=fac)
            rec["series"] = "bore"
        runs.append(rec)
        print_run(rec)
        if rec["status"] != "ok":
            break
    done = [r for r in runs if r["status"] == "ok"]
    rates = {}
    for q in QUANTITIES:
        v = [values_of(r)[q] for r in done]
        d = [v[k + 1] - v[k] for k in range(len(v) - 1)]
        rates[q] = {"values": v, "differences": d,
                    "rates": [math.log(abs(d[k] / d[k + 1])) / math.log(2.0)
                              if d[k + 1] != 0 and d[k] * d[k + 1] > 0 else None
                              for k in range(len(d) - 1)]}
    for q in ("ux_P", "uz_P", "ux_Q", "uz_Q"):
        print(f"  {q}: differences " + " ".join(f"{x: .2e}" for x in rates[q]["differences"])
              + "; rate per halving " + " ".join("-" if x is None else f"{x:.2f}"
                                                 for x in rates[q]["rates"]))
    return {"h_mm": BORE_STUDY_H_MM, "factors": [r["bore_factor"] for r in done],
            "runs": [r for r in runs if r.get("series") == "bore"],
            "reused": [f"{r['series']} h{r['h_mm']:g}" for r in runs if r.get("series") != "bore"],
            "analysis": rates}


def combined(series):
    """The reference: the graded series' Richardson value (nominal h) when it has one, else the
    uniform series'; its uncertainty: the largest distance to any other estimate (either
    series, nominal and effective h, the fit over all meshes; a series without a Richardson
    value contributes its finest value)."""
    out = {}
    for q in QUANTITIES:
        ests = {}
        for name, s in series.items():
            c = s["convergence"].get(q, {})
            for key in ("nominal_h", "effective_h"):
                if c.get(key, {}).get("richardson") is not None:
                    ests[f"{name}_{key}_richardson"] = c[key]["richardson"]
            if "fit_all_effective_h" in c:
                ests[f"{name}_fit_all"] = c["fit_all_effective_h"]["v_inf"]
            if c.get("nominal_h", {}).get("richardson") is None and "finest" in c:
                ests[f"{name}_finest"] = c["finest"]    # no extrapolation: its best value
        ref_key = next((k for k in ("graded_nominal_h_richardson", "uniform_nominal_h_richardson")
                        if k in ests), None)
        rec = {"estimates": ests}
        if ref_key:
            ref = ests[ref_key]
            rec.update({"reference": ref, "from": ref_key,
                        "uncertainty": max(abs(v - ref) for v in ests.values())})
            for name, s in series.items():
                ok = [r for r in s["runs"] if r["status"] == "ok"]
                if ok:
                    rec[f"error_of_finest_{name}"] = abs(values_of(ok[-1])[q] - ref)
        out[q] = rec
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=SIZES_MM,
                    help="uniform series: h in mm")
    ap.add_argument("--graded-sizes", type=float, nargs="*", default=GRADED_SIZES_MM,
                    help="bore-refined series: H in mm (none: skip the series)")
    ap.add_argument("--no-bore-study", action="store_true")
    ap.add_argument("--no-predict", action="store_true",
                    help="start every run (the watchdog still kills it past the limits)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--max-seconds", type=float, default=360.0)
    ap.add_argument("--max-rss-gb", type=float, default=8.0)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--json", type=Path, default=DEFAULT_JSON)
    ap.add_argument("--patch-only", action="store_true")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    patch = patch_test(args.out, args.threads)
    if args.patch_only:
        return 0
    series = {"uniform": run_series("uniform", args.sizes, args.out, args)}
    if args.graded_sizes:
        series["graded"] = run_series("graded", args.graded_sizes, args.out, args,
                                      factor=GRADED_FACTOR)
    bore = None if args.no_bore_study else bore_study(series, args.out, args)
    comb = combined(series)
    src = "graded" if any(c.get("from", "").startswith("graded") for c in comb.values()) \
        else "uniform"
    print(f"\nreference ({src} Richardson; uncertainty = largest distance to any other "
          "estimate):")
    for q in QUANTITIES:
        c = comb[q]
        if "reference" in c:
            print(f"  {q}: {c['reference']: .5e} +- {c['uncertainty']:.1e}"
                  + "".join(f"   finest {n}: error {c['error_of_finest_' + n]:.1e} "
                            f"({c['error_of_finest_' + n] / abs(c['reference']):.1e} rel)"
                            for n in series if "error_of_finest_" + n in c))
    print("  (uy_Q: zero by symmetry)")
    rf = [r["reaction_rel_error"] for s in series.values() for r in s["runs"]
          if r["status"] == "ok"]
    print(f"reaction at the bore: max |RF - (1800, 0, 0)| / 1800 over the runs = {max(rf):.1e}")
    total = time.perf_counter() - t0
    print(f"\ntotal {total:.0f} s")
    data = {
        "title": "L-bracket (examples/bracket.geo), linear static, CalculiX C3D10 reference",
        "problem": {"geometry": "examples/bracket.geo", "E_Pa": E, "nu": NU,
                    "pressure_Pa": PRESSURE, "load_face": "arm_face (x = 0.01, z 0.015..0.06)",
                    "load_area_m2": LOAD_AREA, "load_total_N": PRESSURE * LOAD_AREA,
                    "load_direction": "-x (into the solid)", "clamp": "bore: u = 0",
                    "P": P_POINT.tolist(), "Q": Q_POINT.tolist(), "units": "m, N, Pa"},
        "element": "C3D10 (gmsh -order 2, 10-node tetrahedra)",
        "solver": "ccx *STATIC, SPOOLES", "threads": args.threads,
        "limits": {"max_seconds": args.max_seconds, "max_rss_gb": args.max_rss_gb},
        "ccx_version": ccx_version(), "gmsh_version": gmsh_version(),
        "host": platform.node(), "patch_test": patch,
        "series": series, "bore_study": bore, "reference": comb,
        "convergence_note": ("per series: Richardson from the last three meshes (h ratio about "
                             "sqrt 2; unstructured, not nested) with the nominal h and with the "
                             "effective h = (V/nodes)^(1/3); fit_all: v_inf + C h^p over every "
                             "mesh; best = nominal Richardson (or the finest value when not "
                             "monotone), error_of_finest = |best - finest| (or the last change), "
                             "extrapolation_spread = max - min of the extrapolations. reference: "
                             "see combined(). uy_Q is zero by symmetry, its values are mesh "
                             "asymmetry. The uniform series converges slowly (order about 1.4 "
                             "asymptotically) because of the clamped bore's edges: see "
                             "bore_study."),
        "total_s": round(total, 1),
        "command": " ".join(["/usr/bin/python3 validation/bracket_fem.py"]
                            + list(argv if argv is not None else sys.argv[1:])),
    }
    tmp = args.json.with_name(args.json.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    os.replace(tmp, args.json)
    print(f"wrote {_rel(args.json)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
