#!/usr/bin/env python3
"""FEM references from CalculiX (ccx) for the tlsph validation problems.

For each case this writes a CalculiX model of the same problem as the tlsph scene (geometry in
metres, material, clamps, loads), on quadratic hexahedra (C3D20R; the plane-strain cases as one
layer of C3D20R with u_z = 0 at every node), runs `ccx` on two to four meshes, reads the `.frd`
result (nodal displacement U and nodal stress S), evaluates the point values with the elements'
own shape functions, and writes for the finest mesh a VTK XML unstructured grid that
`tlsph compare RUN FEM.vtu` reads (docs/compare.md): undeformed mesh in metres, point data
`displacement` (3 components) and `cauchy_stress` (6, VTK order xx yy zz xy yz xz); 3D as VTK
quadratic hexahedra (type 25), 2D as quadratic quads (type 23) in the plane z = 0.

The modal cases (cantilever_modes, clamped_plate_modes: analysis="frequency") run a *FREQUENCY
step instead (no loads; ccx's eigenvalue table from the .dat, one DISP block per mode shape
from the .frd), name each mode from its shape (classify_beam_mode: bending_k / bending_kb for
the degenerate pair of the square section, torsion_k, axial_k; classify_plate_mode: the
fundamental is out-of-plane and symmetric, "SS") and keep the frequencies [Hz] as the point
values (f_bending_1, f_torsion_1, ..., f_1, f_2, ...), with the same ladders, Richardson
extrapolation and JSON records; validation/frequencies.py compares `tlsph modes` with them.

  /usr/bin/python3 validation/fem.py                       # every case, every mesh (~12 min)
  /usr/bin/python3 validation/fem.py --case cook_membrane  # one case (repeat --case for more)
  /usr/bin/python3 validation/fem.py --case cantilever_modes --case clamped_plate_modes --threads 1
                                                           # the natural frequencies (~15 min)
  /usr/bin/python3 validation/fem.py --quick               # the two coarsest meshes (smoke run)
  /usr/bin/python3 validation/fem.py --list                # the cases and their meshes
  /usr/bin/python3 validation/fem.py --self-test [--tlsph build/tlsph]
                                                           # node order / VTU read-back test

Large files (.inp, .frd, .vtu) go to --out (default validation/fem/out/, git-ignored); the point
values, mesh sizes, run times and convergence go to validation/fem/references.json (a full run;
a --quick run writes OUT/references_quick.json instead unless --json is given). With --case the
other cases' entries of the JSON file are kept.

Function API (for validation/run.py): `run_case(name, out_dir, meshes=None, quick=False)`
returns the case's record (the same dict as in references.json); `run_cases(names, out_dir,
quick, json_path)` runs several and merges them into the JSON file; `CASES` lists the cases;
`load_references(path)` reads the JSON; `write_vtu`, `read_frd`, `interpolate` are reusable.

Standard library + numpy only. Needs `ccx` (Debian package calculix-ccx) on PATH, or CCX=path.
"""

import argparse
import base64
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DEFAULT_OUT = HERE / "fem" / "out"
DEFAULT_JSON = HERE / "fem" / "references.json"
RHO0 = 1000.0


class FemError(RuntimeError):
    """A failure of a FEM run; the message names the case, the file and what went wrong."""


# --------------------------------------------------------------------------------------------
# Meshes: structured blocks of 8-node quadrilaterals (2D), extruded to 20-node hexahedra.
#
# CalculiX C3D20 node order (and VTK_QUADRATIC_HEXAHEDRON = 25, the same order): corners 1-4
# on the bottom face (counter-clockwise seen from +zeta), corners 5-8 above them, mid-edges
# 9-12 of the bottom edges (1-2, 2-3, 3-4, 4-1), 13-16 of the top edges (5-6, 6-7, 7-8, 8-5),
# 17-20 of the vertical edges (1-5, 2-6, 3-7, 4-8). The quad8 order (VTK_QUADRATIC_QUAD = 23,
# CalculiX CPE8) is the bottom face's: corners 1-4, then mid-edges 1-2, 2-3, 3-4, 4-1.

HEX20_NATURAL = np.array([
    [-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1],
    [0, -1, -1], [1, 0, -1], [0, 1, -1], [-1, 0, -1],
    [0, -1, 1], [1, 0, 1], [0, 1, 1], [-1, 0, 1],
    [-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=float)
QUAD8_NATURAL = HEX20_NATURAL[[0, 1, 2, 3, 8, 9, 10, 11], :2]

# The six faces of a hex20, local node indices (4 corners then 4 mid-edges).
HEX20_FACES = [
    [0, 1, 2, 3, 8, 9, 10, 11],      # zeta = -1
    [4, 5, 6, 7, 12, 13, 14, 15],    # zeta = +1
    [0, 1, 5, 4, 8, 17, 12, 16],     # eta = -1
    [3, 2, 6, 7, 10, 18, 14, 19],    # eta = +1
    [0, 3, 7, 4, 11, 19, 15, 16],    # xi = -1
    [1, 2, 6, 5, 9, 18, 13, 17],     # xi = +1
]


def hex20_shape(nat):
    """Shape functions of the 20-node serendipity hexahedron at natural points (n, 3)."""
    nat = np.atleast_2d(nat)
    x, y, z = nat[:, 0:1], nat[:, 1:2], nat[:, 2:3]
    xi, yi, zi = HEX20_NATURAL[:, 0], HEX20_NATURAL[:, 1], HEX20_NATURAL[:, 2]
    N = np.empty((nat.shape[0], 20))
    c = slice(0, 8)
    N[:, c] = (0.125 * (1 + x * xi[c]) * (1 + y * yi[c]) * (1 + z * zi[c])
               * (x * xi[c] + y * yi[c] + z * zi[c] - 2))
    for k in range(8, 20):
        if xi[k] == 0:
            N[:, k] = (0.25 * (1 - x * x) * (1 + y * yi[k]) * (1 + z * zi[k]))[:, 0]
        elif yi[k] == 0:
            N[:, k] = (0.25 * (1 + x * xi[k]) * (1 - y * y) * (1 + z * zi[k]))[:, 0]
        else:
            N[:, k] = (0.25 * (1 + x * xi[k]) * (1 + y * yi[k]) * (1 - z * z))[:, 0]
    return N


def quad8_shape(nat):
    """Shape functions of the 8-node serendipity quadrilateral at natural points (n, 2)."""
    nat = np.atleast_2d(nat)
    x, y = nat[:, 0:1], nat[:, 1:2]
    xi, yi = QUAD8_NATURAL[:, 0], QUAD8_NATURAL[:, 1]
    N = np.empty((nat.shape[0], 8))
    c = slice(0, 4)
    N[:, c] = 0.25 * (1 + x * xi[c]) * (1 + y * yi[c]) * (x * xi[c] + y * yi[c] - 1)
    for k in range(4, 8):
        if xi[k] == 0:
            N[:, k] = (0.5 * (1 - x * x) * (1 + y * yi[k]))[:, 0]
        else:
            N[:, k] = (0.5 * (1 + x * xi[k]) * (1 - y * y))[:, 0]
    return N


class Mesh2D:
    """8-node quadrilaterals: points (n, 2), cells (e, 8) 0-based, corner flag per point."""

    def __init__(self):
        self.points = np.zeros((0, 2))
        self.cells = np.zeros((0, 8), dtype=np.int64)
        self._keys = {}
        self._pts = []
        self._cells = []

    def _node(self, p, scale):
        key = (round(p[0] / scale), round(p[1] / scale))
        idx = self._keys.get(key)
        if idx is None:
            idx = len(self._pts)
            self._keys[key] = idx
            self._pts.append((float(p[0]), float(p[1])))
        return idx

    def add_block(self, mapping, s_params, t_params):
        """A structured block: mapping(s, t) -> (x, y) on [0, 1]^2 (s, t right-handed in x, y);
        s_params, t_params: corner-node parameters (increasing, from 0 to 1). Mid-edge nodes are
        mapped at the mid parameter, so curved block edges are followed. Nodes that coincide
        with nodes of earlier blocks are merged (the blocks must match along shared edges)."""
        s = np.asarray(s_params, float)
        t = np.asarray(t_params, float)
        sf = np.empty(2 * len(s) - 1)
        tf = np.empty(2 * len(t) - 1)
        sf[0::2], sf[1::2] = s, 0.5 * (s[:-1] + s[1:])
        tf[0::2], tf[1::2] = t, 0.5 * (t[:-1] + t[1:])
        scale = 1e-9
        grid = {}
        for i, si in enumerate(sf):
            for j, tj in enumerate(tf):
                if i % 2 == 1 and j % 2 == 1:
                    continue
                grid[i, j] = self._node(mapping(si, tj), scale)
        for i in range(len(s) - 1):
            for j in range(len(t) - 1):
                a, b = 2 * i, 2 * j
                self._cells.append([grid[a, b], grid[a + 2, b], grid[a + 2, b + 2], grid[a, b + 2],
                                    grid[a + 1, b], grid[a + 2, b + 1], grid[a + 1, b + 2],
                                    grid[a, b + 1]])

    def finish(self):
        self.points = np.array(self._pts, float)
        self.cells = np.array(self._cells, dtype=np.int64)
        corner = np.zeros(len(self.points), bool)
        corner[self.cells[:, :4].ravel()] = True
        self.corner = corner
        # orientation check: every element counter-clockwise (positive Jacobian at the centre)
        p = self.points[self.cells[:, :4]]
        area = 0.5 * ((p[:, 2, 0] - p[:, 0, 0]) * (p[:, 3, 1] - p[:, 1, 1])
                      - (p[:, 3, 0] - p[:, 1, 0]) * (p[:, 2, 1] - p[:, 0, 1]))
        if np.any(area <= 0):
            raise ValueError("mesh generator: an element is not counter-clockwise")
        return self


class Mesh3D:
    """20-node hexahedra: points (n, 3), cells (e, 20) 0-based in CalculiX C3D20 order.
    For an extruded plane-strain model, `plane` holds the quad8 mesh of the plane z = z0 (its
    points are the hex points `plane_points`)."""

    def __init__(self, points, cells):
        self.points = points
        self.cells = cells
        self.plane = None
        self.plane_points = None


def extrude(m2, z_params):
    """Extrude a quad8 mesh along z through the corner levels z_params (increasing)."""
    z = np.asarray(z_params, float)
    nz = len(z) - 1
    levels = np.empty(2 * nz + 1)
    levels[0::2], levels[1::2] = z, 0.5 * (z[:-1] + z[1:])
    n2 = len(m2.points)
    ids = -np.ones((2 * nz + 1, n2), dtype=np.int64)
    pts = []
    count = 0
    for k, zk in enumerate(levels):
        sel = np.arange(n2) if k % 2 == 0 else np.nonzero(m2.corner)[0]
        ids[k, sel] = np.arange(count, count + len(sel))
        count += len(sel)
        pts.append(np.column_stack([m2.points[sel], np.full(len(sel), zk)]))
    points = np.vstack(pts)
    cells = []
    for k in range(nz):
        b, m, t = ids[2 * k], ids[2 * k + 1], ids[2 * k + 2]
        c = m2.cells
        cells.append(np.column_stack([b[c[:, :4]], t[c[:, :4]], b[c[:, 4:]], t[c[:, 4:]],
                                      m[c[:, :4]]]))
    mesh = Mesh3D(points, np.vstack(cells))
    mesh.plane = m2
    mesh.plane_points = ids[0]
    if np.any(mesh.cells < 0):
        raise ValueError("extrude: an element references a missing node")
    return mesh


def uniform(n):
    return np.linspace(0.0, 1.0, n + 1)


def rectangle_mesh(x0, x1, y0, y1, nx, ny):
    m = Mesh2D()
    m.add_block(lambda s, t: (x0 + s * (x1 - x0), y0 + t * (y1 - y0)), uniform(nx), uniform(ny))
    return m.finish()


def box_mesh(lower, upper, n):
    m2 = rectangle_mesh(lower[0], upper[0], lower[1], upper[1], n[0], n[1])
    mesh = extrude(m2, lower[2] + uniform(n[2]) * (upper[2] - lower[2]))
    mesh.plane = mesh.plane_points = None   # a 3D body, not a plane-strain layer
    return mesh


COOK_CORNERS = [(0.0, 0.0), (0.048, 0.044), (0.048, 0.060), (0.0, 0.044)]


def cook_mesh(n):
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = COOK_CORNERS

    def f(s, t):  # bilinear map of the quadrilateral (its edges are straight)
        return ((1 - s) * (1 - t) * x0 + s * (1 - t) * x1 + s * t * x2 + (1 - s) * t * x3,
                (1 - s) * (1 - t) * y0 + s * (1 - t) * y1 + s * t * y2 + (1 - s) * t * y3)

    m = Mesh2D()
    m.add_block(f, uniform(n), uniform(n))
    return m.finish()


HOLE = dict(length=0.4, width=0.1, centre=(0.2, 0.05), radius=0.01)


def plate_hole_mesh(nc, beta=1.65):
    """Plate 0.4 x 0.1 with a hole of radius 0.01 at (0.2, 0.05): a square ring
    [0.15, 0.25] x [0, 0.1] around the hole in four blocks (nc elements along each side and
    around each quarter of the hole, nc elements radially, graded towards the hole with
    g(v) = (exp(beta v) - 1)/(exp(beta) - 1)), and two rectangles with nc x 1.5 nc elements.
    Refining nc by 2 halves every element (the corner nodes are nested)."""
    L, W = HOLE["length"], HOLE["width"]
    cx, cy = HOLE["centre"]
    r = HOLE["radius"]
    a = W / 2.0
    m = Mesh2D()
    corners = [(cx + a, cy - a), (cx + a, cy + a), (cx - a, cy + a), (cx - a, cy - a)]
    radial = (np.exp(beta * uniform(nc)) - 1.0) / (np.exp(beta) - 1.0)
    for side in range(4):
        th0 = -0.25 * math.pi + side * 0.5 * math.pi
        p0, p1 = np.array(corners[side]), np.array(corners[(side + 1) % 4])

        def f(s, t, th0=th0, p0=p0, p1=p1):
            # s radial (graded through its node parameters), t along the side (anticlockwise)
            th = th0 + t * 0.5 * math.pi
            c = np.array([cx + r * math.cos(th), cy + r * math.sin(th)])
            q = p0 + t * (p1 - p0)
            g = s
            return tuple(c + g * (q - c))

        m.add_block(f, radial, uniform(nc))
    nl = int(round(1.5 * nc))
    if abs(1.5 * nc - nl) > 1e-9:
        raise ValueError("plate_hole: nc must be even")
    m.add_block(lambda s, t: (s * (cx - a), t * W), uniform(nl), uniform(nc))
    m.add_block(lambda s, t: (cx + a + s * (L - cx - a), t * W), uniform(nl), uniform(nc))
    return m.finish()


# --------------------------------------------------------------------------------------------
# Point location and interpolation with the element shape functions


def _locate(points, cells, shape, dim, p, tol=1e-7):
    """(element, natural coordinates) of point p, or None. Newton on the isoparametric map."""
    p = np.asarray(p, float)[:dim]
    X = points[cells][:, :, :dim]
    lo, hi = X.min(axis=1), X.max(axis=1)
    pad = 0.1 * (hi - lo).max(axis=1, keepdims=True) + 1e-12
    cand = np.nonzero(np.all((p >= lo - pad) & (p <= hi + pad), axis=1))[0]
    for e in cand:
        xe = X[e]
        nat = np.zeros(dim)
        for _ in range(30):
            N = shape(nat)[0]
            r = N @ xe - p
            J = np.empty((dim, dim))
            for a in range(dim):
                d = np.zeros(dim)
                d[a] = 1e-6
                J[:, a] = (shape(nat + d)[0] - shape(nat - d)[0]) @ xe / 2e-6
            step = np.linalg.solve(J, r)
            nat -= step
            if np.abs(step).max() < 1e-13:
                break
        if np.abs(nat).max() - 1.0 <= tol:
            return e, np.clip(nat, -1.0, 1.0)
    return None


def interpolate(mesh, field, p):
    """Field (per hex point, (n, k)) at point p: on the plane z = z0 of an extruded 2D mesh
    with the quad8 functions, else with the hex20 functions."""
    if mesh.plane is not None:
        pts = mesh.plane.points
        cells = mesh.plane.cells
        loc = _locate(pts, cells, quad8_shape, 2, p)
        if loc is None:
            raise ValueError(f"point {p} is not inside the mesh")
        e, nat = loc
        return quad8_shape(nat)[0] @ field[mesh.plane_points[cells[e]]]
    loc = _locate(mesh.points, mesh.cells, hex20_shape, 3, p)
    if loc is None:
        raise ValueError(f"point {p} is not inside the mesh")
    e, nat = loc
    return hex20_shape(nat)[0] @ field[mesh.cells[e]]


# --------------------------------------------------------------------------------------------
# Cases


def _box_label(n):
    return "x".join(str(k) for k in n)


def _cantilever_values(mesh, U, S, case):
    u = interpolate(mesh, U, (1.0, 0.0, 0.0))
    return {"tip_ux": u[0], "tip_uy": u[1], "tip_uz": u[2], "tip_deflection": -u[2]}


def _plate_values(mesh, U, S, case):
    u = interpolate(mesh, U, (0.25, 0.25, 0.025))
    return {"centre_uz": u[2], "centre_deflection": -u[2]}


def _principal_inplane(s):
    sxx, syy, sxy = s[0], s[1], s[3]
    c, r = 0.5 * (sxx + syy), math.hypot(0.5 * (sxx - syy), sxy)
    return c + r


def _cook_values(mesh, U, S, case):
    uc = interpolate(mesh, U, (0.048, 0.060))
    um = interpolate(mesh, U, (0.048, 0.052))
    s = interpolate(mesh, S, (0.024, 0.040))
    return {"corner_ux": uc[0], "corner_uy": uc[1], "edge_mid_ux": um[0], "edge_mid_uy": um[1],
            "interior_sxx": s[0], "interior_syy": s[1], "interior_szz": s[2],
            "interior_sxy": s[3], "interior_s1": _principal_inplane(s)}


def _hole_values(mesh, U, S, case):
    t = case["traction"][0]
    st = interpolate(mesh, S, (0.2, 0.06))
    sb = interpolate(mesh, S, (0.2, 0.04))
    u = interpolate(mesh, U, (0.4, 0.05))
    return {"hole_top_sxx": st[0], "hole_bottom_sxx": sb[0], "kt_top": st[0] / t,
            "kt_bottom": sb[0] / t, "end_ux": u[0], "end_uy": u[1]}


def _heywood_kt(d_over_w):
    """Finite-width plate with a central hole in tension: Kt on the net section (nominal
    stress P / ((W - d) t)) and on the gross section (P / (W t), = t_x here) from
    Roark (Young & Budynas, Roark's Formulas for Stress and Strain, 7th ed., 2002,
    table 17.1: 3 - 3.13 (d/W) + 3.66 (d/W)^2 - 1.53 (d/W)^3), Peterson (Pilkey & Pilkey,
    Peterson's Stress Concentration Factors, 3rd ed., 2008, chart 4.1, Howland's solution
    fitted: 3 - 3.14 (d/W) + 3.667 (d/W)^2 - 1.527 (d/W)^3) and Heywood (2 + (1 - d/W)^3)."""
    r = d_over_w
    net = {"roark": 3.0 - 3.13 * r + 3.66 * r**2 - 1.53 * r**3,
           "peterson": 3.0 - 3.14 * r + 3.667 * r**2 - 1.527 * r**3,
           "heywood": 2.0 + (1.0 - r) ** 3}
    out = {"d_over_w": r}
    for k, v in net.items():
        out[f"{k}_net"] = v
        out[f"{k}_gross"] = v / (1.0 - r)
    return out


def _timoshenko_cantilever():
    E, nu, b, L, q = 1.0e7, 0.3, 0.1, 1.0, RHO0 * 1.0 * 0.01
    I, A = b**4 / 12.0, b * b
    kappa = 10 * (1 + nu) / (12 + 11 * nu)
    G = E / (2 * (1 + nu))
    eb = q * L**4 / (8 * E * I)
    return {"euler_bernoulli": eb, "timoshenko": eb + q * L**2 / (2 * kappa * G * A)}


# --------------------------------------------------------------------------------------------
# Natural modes (*FREQUENCY): naming the modes by their shapes. The same functions name tlsph's
# modes (validation/frequencies.py), with the particles' reference positions for X.


def _sign_changes(v, rel=0.02):
    """Sign changes of a sequence, ignoring entries below rel of its largest magnitude."""
    v = np.asarray(v, float)
    big = v[np.abs(v) > rel * np.abs(v).max()] if len(v) and np.abs(v).max() > 0 else v[:0]
    return int(np.sum(np.sign(big[1:]) != np.sign(big[:-1])))


def classify_beam_mode(X, U, axis=0, centre=(0.0, 0.0), ends="clamped-free"):
    """Kind and order of a mode shape U (n, 3) of a straight beam along `axis` with its
    section centred at `centre` (the two other coordinates), nodes or particles at X (n, 3).

    Per cross-section (the points sharing one axial coordinate): the mean transverse
    displacement (bending), the mean axial displacement (extension) and the least-squares
    rotation about the axis times the largest radius (torsion); the kind is the largest of the
    three over the sections, the order 1 + the sign changes of that quantity along the beam
    (a clamped-free beam's k-th mode of a kind has k - 1 interior nodes). With
    ends="free-free" the k-th bending mode has k + 1 nodes and the k-th axial or torsion mode k,
    so the order is the sign changes - 1 (bending) or the sign changes. Returns
    (kind, order, shares) with shares = the three measures' largest values over the sections
    relative to max |U| (about 1 for the mode's own kind, 0 for the others)."""
    X = np.asarray(X, float)
    U = np.asarray(U, float)
    t = [a for a in range(3) if a != axis]
    key = np.round(X[:, axis] / 1e-9).astype(np.int64)
    levels = np.unique(key)
    dy = X[:, t[0]] - centre[0]
    dz = X[:, t[1]] - centre[1]
    r2 = dy * dy + dz * dz
    rmax = math.sqrt(r2.max())
    bend, ext, rot = [], [], []
    for lv in levels:
        sel = key == lv
        bend.append(U[sel][:, t].mean(axis=0))
        ext.append(U[sel, axis].mean())
        den = r2[sel].sum()
        rot.append(((dy[sel] * U[sel, t[1]] - dz[sel] * U[sel, t[0]]).sum() / den * rmax)
                   if den > 0 else 0.0)
    bend, ext, rot = np.array(bend), np.array(ext), np.array(rot)
    scale = np.linalg.norm(U, axis=1).max() or 1.0
    shares = {"bending": float(np.linalg.norm(bend, axis=1).max() / scale),
              "axial": float(np.abs(ext).max() / scale),
              "torsion": float(np.abs(rot).max() / scale)}
    kind = max(shares, key=shares.get)
    if kind == "bending":
        # the transverse displacement along its dominant direction
        k = np.argmax(np.linalg.norm(bend, axis=1))
        d = bend[k] / np.linalg.norm(bend[k])
        prof = bend @ d
    else:
        prof = ext if kind == "axial" else rot
    changes = _sign_changes(prof)
    if ends == "free-free":
        return kind, changes - 1 if kind == "bending" else changes, shares
    return kind, changes + 1, shares


def name_beam_modes(X, modes, **kw):
    """Names for a list of mode shapes of a beam: 'bending_1', 'bending_1b' (the second mode
    of a degenerate pair of a square section), 'torsion_1', 'axial_1', ... Returns a list of
    (name, kind, order, shares)."""
    seen = {}
    out = []
    for U in modes:
        kind, order, shares = classify_beam_mode(X, U, **kw)
        base = f"{kind}_{order}"
        n = seen.get(base, 0)
        seen[base] = n + 1
        name = base + ("" if n == 0 else "b" if n == 1 else f"_{n + 1}")
        out.append((name, kind, order, shares))
    return out


def classify_plate_mode(X, U, centre=(0.25, 0.25), normal=2):
    """Kind of a mode shape of a square plate normal to `normal`: 'out-of-plane' or 'in-plane'
    (which displacement dominates) and the parities of the out-of-plane displacement under the
    mirrors x -> 2 cx - x and y -> 2 cy - y ('S' symmetric, 'A' antisymmetric, '-' neither:
    a mixture of a degenerate pair), e.g. 'SS' for the first mode. Points without a mirror
    image in X are ignored."""
    X = np.asarray(X, float)
    U = np.asarray(U, float)
    t = [a for a in range(3) if a != normal]
    w = U[:, normal]
    inplane = np.linalg.norm(U[:, t], axis=1)
    kind = "out-of-plane" if np.abs(w).max() >= inplane.max() else "in-plane"
    f = w if kind == "out-of-plane" else U[:, t[0]]
    keys = {tuple(k): i for i, k in enumerate(np.round(X / 1e-7).astype(np.int64))}
    par = ""
    for a, c in zip(t, centre):
        Y = X.copy()
        Y[:, a] = 2 * c - X[:, a]
        idx = np.array([keys.get(tuple(k), -1) for k in np.round(Y / 1e-7).astype(np.int64)])
        ok = idx >= 0
        num = float(np.sum(f[ok] * f[idx[ok]]))
        den = float(np.sum(f[ok] ** 2)) or 1.0
        par += "S" if num / den > 0.9 else "A" if num / den < -0.9 else "-"
    return kind, par


def _beam_mode_values(mesh, modes, case):
    """Frequencies [Hz] by mode name (bending_1, bending_1b, torsion_1, ...), the modes being
    [(frequency, U)] in ascending order; only the modes below the highest complete family are
    kept (a pair cut off by the number of modes asked for would change names with the mesh).
    A free beam's (case["ends"] == "free-free") first `rigid` modes are its rigid-body motions
    (near-zero frequencies): skipped."""
    modes = modes[case.get("rigid", 0):]
    names = name_beam_modes(mesh.points, [U for _, U in modes], ends=case.get("ends",
                                                                              "clamped-free"))
    vals = {}
    for (f, _), (name, kind, order, shares) in zip(modes, names):
        vals[f"f_{name}"] = f
    return vals, [{"frequency": f, "name": n, "kind": k, "order": o,
                   "shares": {a: round(b, 4) for a, b in sh.items()}}
                  for (f, _), (n, k, o, sh) in zip(modes, names)]


def _plate_mode_values(mesh, modes, case):
    vals = {}
    info = []
    for k, (f, U) in enumerate(modes):
        kind, par = classify_plate_mode(mesh.points, U)
        vals[f"f_{k + 1}"] = f
        info.append({"frequency": f, "name": f"mode_{k + 1}", "kind": kind, "parity": par})
    return vals, info


def _beam_frequency_references():
    """Beam theory for the 1 x 0.1 x 0.1 m cantilever (E = 1e7, nu = 0.3, rho = 1000): first
    bending (Euler-Bernoulli, Timoshenko from validation/references.py), Saint-Venant torsion
    f = (1/(4L)) sqrt(G J / (rho I_p)) with J = 0.1406 b^4 (square section; warping free at the
    clamp) and the first axial mode sqrt(E/rho)/(4L)."""
    sys.path.insert(0, str(HERE))
    try:
        import references as R
    finally:
        sys.path.pop(0)
    E, nu, rho, b, L = 1.0e7, 0.3, RHO0, 0.1, 1.0
    A, I = b * b, b**4 / 12.0
    G = E / (2 * (1 + nu))
    J, Ip = 0.140577 * b**4, b**4 / 6.0
    return {"euler_bernoulli_bending_1": R.euler_bernoulli_frequency(E, I, rho, A, L),
            "timoshenko_bending_1": R.timoshenko_frequency(E, nu, rho, A, I, L),
            "euler_bernoulli_bending_2": R.euler_bernoulli_frequency(E, I, rho, A, L,
                                                                     beta_l=4.6940911330),
            "saint_venant_torsion_1": math.sqrt(G * J / (rho * Ip)) / (4 * L),
            "axial_1": math.sqrt(E / rho) / (4 * L)}


def _plate_frequency_references():
    """Kirchhoff (thin) clamped square plate, first mode: f = lambda^2/(2 pi a^2) sqrt(D/(rho
    t)), lambda^2 = 35.985 (Leissa, Vibration of Plates, NASA SP-160, 1969, table 4.23).
    a/t = 10: shear and rotary inertia lower the 3D value by several percent."""
    E, nu, rho, a, t = 1.0e7, 0.3, RHO0, 0.5, 0.05
    D = E * t**3 / (12 * (1 - nu * nu))
    return {"kirchhoff_mode_1": 35.985 / (2 * math.pi * a * a) * math.sqrt(D / (rho * t))}


# Mesh ladders. Cost on this 2-core machine (ccx 2.20, SPOOLES, 2 threads) in the README.
CASES = {
    "cantilever": dict(
        title="3D cantilever under self-weight (g = 1 m/s^2), linear",
        scene="validation/scenes/cantilever_static.ini", dim=3,
        lower=(0.0, -0.05, -0.05), upper=(1.0, 0.05, 0.05), E=1.0e7, nu=0.3,
        gravity=(0.0, 0.0, -1.0), clamp=[("x", 0.0)], values=_cantilever_values,
        main="tip_deflection",
        series={
            "linear": dict(nlgeom=False, vtu=True,
                           meshes=[(10, 1, 1), (20, 2, 2), (40, 4, 4), (80, 8, 8)]),
            "nlgeom_svk": dict(nlgeom=True, vtu=False, inc=(1.0, 1.0),
                               meshes=[(20, 2, 2), (40, 4, 4), (80, 8, 8)]),
        },
        note="Linear analysis: the reference. nlgeom_svk: NLGEOM with *ELASTIC (Saint Venant-"
             "Kirchhoff), the scene's neo-Hookean model differs from it only at large strain.",
        analytic=_timoshenko_cantilever()),
    "cantilever_large": dict(
        title="3D cantilever under self-weight (g = 30 m/s^2), Saint Venant-Kirchhoff, NLGEOM",
        scene="validation/scenes/cantilever_large.ini", dim=3,
        lower=(0.0, -0.05, -0.05), upper=(1.0, 0.05, 0.05), E=1.0e7, nu=0.3,
        gravity=(0.0, 0.0, -30.0), clamp=[("x", 0.0)], values=_cantilever_values,
        main="tip_deflection",
        series={
            "nlgeom_svk": dict(nlgeom=True, vtu=True, inc=(0.05, 0.1),
                               meshes=[(20, 2, 2), (40, 4, 4), (80, 8, 8)]),
        },
        note="Dead gravity load (reference configuration), ramped over the step in increments "
             "of at most 0.1."),
    "clamped_plate": dict(
        title="3D square plate clamped on its four sides, uniform pressure 1 kPa, linear",
        scene="validation/scenes/clamped_plate.ini", dim=3,
        lower=(0.0, 0.0, 0.0), upper=(0.5, 0.5, 0.05), E=1.0e7, nu=0.3,
        clamp=[("x", 0.0), ("x", 0.5), ("y", 0.0), ("y", 0.5)],
        traction=(0.0, 0.0, -1000.0), traction_face=("z", 0.05), values=_plate_values,
        main="centre_deflection",
        reference_note="Slow convergence through the thickness: the uniform ladder's Richardson "
                       "value (order 2.0) is 0.81436 mm, the thickness-only ladders extrapolate "
                       "to 0.81482 (20x20) and 0.81511 mm (40x40, order 0.7); take the "
                       "converged deflection as 0.8144-0.8151 mm (finest mesh 0.81403 mm).",
        series={
            "linear": dict(nlgeom=False, vtu=True,
                           meshes=[(10, 10, 4), (20, 20, 8), (40, 40, 16)]),
            "thickness": dict(nlgeom=False, vtu=False, ladder_axis=2,
                              meshes=[(20, 20, 2), (20, 20, 4), (20, 20, 8), (20, 20, 16)]),
            "thickness_40": dict(nlgeom=False, vtu=False, ladder_axis=2, quick=False,
                                 meshes=[(40, 40, 4), (40, 40, 8), (40, 40, 16)]),
            "inplane": dict(nlgeom=False, vtu=False, ladder_axis=(0, 1),
                            meshes=[(10, 10, 8), (20, 20, 8), (40, 40, 8)]),
            "nlgeom_svk": dict(nlgeom=True, vtu=False, inc=(1.0, 1.0),
                               meshes=[(20, 20, 4), (40, 40, 4)]),
        },
        note="The pressure is a dead load: consistent nodal forces (*CLOAD: corners -1/12, mid-"
             "edges +1/3 of each 8-node face's load), so the NLGEOM run has the scene's dead "
             "traction. Series: linear = uniform refinement (the reference); thickness, "
             "thickness_40 = 20x20 and 40x40 in-plane, 2..16 elements through (40x40x4 is "
             "the mesh of the earlier reference 0.8121 mm); inplane = 8 through, 10..40 "
             "in-plane. The deflection converges slowly through the thickness (order about "
             "1: the edge singularity where the clamped faces meet the top and bottom)."),
    "cantilever_modes": dict(
        title="3D cantilever 1 x 0.1 x 0.1 m, clamped at x = 0: lowest natural frequencies",
        scene="examples/cantilever.ini", dim=3, analysis="frequency", modes=12,
        lower=(0.0, -0.05, -0.05), upper=(1.0, 0.05, 0.05), E=1.0e7, nu=0.3,
        clamp=[("x", 0.0)], values=_beam_mode_values, main="f_bending_1",
        series={
            "linear": dict(nlgeom=False, vtu=False,
                           meshes=[(20, 2, 2), (40, 4, 4), (80, 8, 8)]),
        },
        note="*FREQUENCY (12 modes, consistent mass), linear elastic, face x = 0 clamped. "
             "The ladder starts at 20x2x2: 10x1x1 (one C3D20R through) has zero-energy "
             "(hourglass) modes of the reduced integration among its lowest 12. "
             "Modes named by their shapes (classify_beam_mode): bending_k / bending_kb the "
             "degenerate pair of the square section (k-th bending), torsion_k, axial_k. "
             "The tlsph scene's neo-Hookean model linearises to the same elasticity about the "
             "reference state.",
        analytic=_beam_frequency_references),
    "free_beam_modes": dict(
        title="3D free beam 1 x 0.1 x 0.1 m (no support): lowest flexible natural frequencies",
        scene="examples/cantilever.ini", dim=3, analysis="frequency", modes=20, rigid=6,
        ends="free-free", lower=(0.0, -0.05, -0.05), upper=(1.0, 0.05, 0.05), E=1.0e7, nu=0.3,
        clamp=[], values=_beam_mode_values, main="f_bending_1",
        series={
            "linear": dict(nlgeom=False, vtu=False,
                           meshes=[(20, 2, 2), (40, 4, 4), (80, 8, 8)]),
        },
        note="*FREQUENCY (20 modes, consistent mass), linear elastic, no boundary condition: "
             "the first 6 modes are the rigid-body motions (near-zero frequencies) and are "
             "skipped. The tlsph scene is examples/cantilever.ini without its clamp and "
             "gravity. Modes named by their shapes (classify_beam_mode, ends='free-free'): "
             "bending_k / bending_kb the degenerate pair of the square section (k-th "
             "free-free bending, k + 1 nodes), torsion_k, axial_k (k nodes)."),
    "clamped_plate_modes": dict(
        title="3D square plate 0.5 x 0.5 x 0.05 m clamped on its four sides: lowest natural "
              "frequencies",
        scene="validation/scenes/clamped_plate.ini", dim=3, analysis="frequency", modes=6,
        lower=(0.0, 0.0, 0.0), upper=(0.5, 0.5, 0.05), E=1.0e7, nu=0.3,
        clamp=[("x", 0.0), ("x", 0.5), ("y", 0.0), ("y", 0.5)],
        values=_plate_mode_values, main="f_1", reference_series="linear_16",
        reference_note="The reference is the linear_16 ladder (10x10x4, 20x20x8, 40x40x16, the "
                       "static case's): Richardson 31.534 Hz for f_1 (order 1.9), finest "
                       "31.541 Hz. The other ladders extrapolate to 31.541 (10x10x2..40x40x8, "
                       "order 2.1) and 31.528 Hz (20x20, 2..16 through, order 1.1: the edge "
                       "singularity where the clamped faces meet the top and bottom), so the "
                       "converged f_1 is 31.52-31.54 Hz (+-0.04 %).",
        series={
            "linear": dict(nlgeom=False, vtu=False,
                           meshes=[(10, 10, 2), (20, 20, 4), (40, 40, 8)]),
            "linear_16": dict(nlgeom=False, vtu=False,
                              meshes=[(10, 10, 4), (20, 20, 8), (40, 40, 16)]),
            "thickness": dict(nlgeom=False, vtu=False, ladder_axis=2,
                              meshes=[(20, 20, 2), (20, 20, 4), (20, 20, 8), (20, 20, 16)]),
        },
        note="*FREQUENCY (6 modes, consistent mass), linear elastic, the four side faces "
             "clamped in every direction (as the scene's mirrored clamps). mode_1 is the "
             "fundamental (out-of-plane, symmetric about both mid-planes: parity SS), "
             "modes 2-3 the degenerate (2,1)/(1,2) pair. Series: linear = uniform ladder from "
             "10x10x2, linear_16 = the static case's uniform ladder 10x10x4..40x40x16, "
             "thickness = 20x20 in-plane, 2..16 through.",
        analytic=_plate_frequency_references),
    "cook_membrane": dict(
        title="Cook's membrane, plane strain, nu = 0.3, linear",
        scene="validation/scenes/cook_membrane.ini", dim=2, E=1.0e7, nu=0.3,
        clamp=[("x", 0.0)], traction=(0.0, 100.0 / 0.016, 0.0), traction_face=("x", 0.048),
        values=_cook_values, main="corner_uy",
        series={"linear": dict(nlgeom=False, vtu=True, meshes=[4, 8, 16, 32, 64, 128])},
        note="Shear traction 6250 Pa on the right edge (total 100 N per metre of thickness)."),
    "cook_membrane_incompressible": dict(
        title="Cook's membrane, plane strain, nu = 0.4999, linear",
        scene="validation/scenes/cook_membrane_incompressible.ini", dim=2, E=1.0e7, nu=0.4999,
        clamp=[("x", 0.0)], traction=(0.0, 100.0 / 0.016, 0.0), traction_face=("x", 0.048),
        values=_cook_values, main="corner_uy",
        series={"linear": dict(nlgeom=False, vtu=True, meshes=[4, 8, 16, 32, 64, 128])},
        note="C3D20R (reduced integration): the mesh ladder shows no locking."),
    "plate_hole": dict(
        title="Plane-strain plate with a central hole in tension, linear",
        scene="validation/scenes/plate_hole.ini", dim=2, E=1.0e7, nu=0.3,
        clamp=[("x", 0.0)], traction=(1.0e5, 0.0, 0.0), traction_face=("x", 0.4),
        values=_hole_values, main="kt_top",
        series={"linear": dict(nlgeom=False, vtu=True, meshes=[4, 8, 16, 32, 64])},
        note="Mesh: nc elements along each quarter of the hole; d/W = 0.2.",
        analytic=_heywood_kt(0.2)),
}


def mesh_label(case, spec):
    if case["dim"] == 3:
        return _box_label(spec)
    return f"n{spec}"


def build_mesh(name, case, spec):
    if case["dim"] == 3:
        return box_mesh(case["lower"], case["upper"], spec), None
    if name.startswith("cook"):
        m2 = cook_mesh(spec)
        h = 0.048 / spec
    else:
        m2 = plate_hole_mesh(spec)
        h = 0.05 / spec
    return extrude(m2, [0.0, h]), h


# --------------------------------------------------------------------------------------------
# CalculiX input


def _fmt(x):
    # 13 significant digits: ccx reads at most 20 characters per field
    return f"{float(x):.12e}"


def _face_loads(mesh, axis, value, traction):
    """Consistent nodal forces of a uniform traction on every element face lying in the plane
    coordinate[axis] = value (8-node faces, planar parallelograms: corners -A t/12, mid-edges
    +A t/3). Returns {node index: force (3,)}."""
    a = "xyz".index(axis)
    pts = mesh.points
    tol = 1e-9 * max(1.0, abs(value))
    forces = {}
    on = np.abs(pts[:, a] - value) <= tol
    t = np.asarray(traction, float)
    for cell in mesh.cells:
        for face in HEX20_FACES:
            nodes = cell[face]
            if not on[nodes].all():
                continue
            c = pts[nodes[:4]]
            area = 0.5 * np.linalg.norm(np.cross(c[2] - c[0], c[3] - c[1]))
            for k, n in enumerate(nodes):
                w = -1.0 / 12.0 if k < 4 else 1.0 / 3.0
                forces[n] = forces.get(n, 0.0) + w * area * t
    if not forces:
        raise ValueError(f"no element face in the plane {axis} = {value}")
    return forces


def _write_ids(f, ids, per_line=16):
    ids = list(ids)
    for k in range(0, len(ids), per_line):
        f.write(", ".join(str(i) for i in ids[k:k + per_line]) + ",\n")


def write_inp(path, case, mesh, nlgeom, inc=(1.0, 1.0)):
    pts = mesh.points
    with open(path, "w") as f:
        f.write(f"** {case['title']}\n** written by validation/fem.py\n*NODE, NSET=NALL\n")
        for i, p in enumerate(pts):
            f.write(f"{i + 1}, {_fmt(p[0])}, {_fmt(p[1])}, {_fmt(p[2])}\n")
        f.write("*ELEMENT, TYPE=C3D20R, ELSET=EALL\n")
        for e, c in enumerate(mesh.cells):
            ids = [str(k + 1) for k in c]
            f.write(f"{e + 1}, " + ", ".join(ids[:15]) + ",\n" + ", ".join(ids[15:]) + "\n")
        clamped = np.zeros(len(pts), bool)
        for axis, value in case["clamp"]:
            a = "xyz".index(axis)
            clamped |= np.abs(pts[:, a] - value) <= 1e-9 * max(1.0, abs(value))
        if case["clamp"]:
            f.write("*NSET, NSET=NCLAMP\n")
            _write_ids(f, np.nonzero(clamped)[0] + 1)
        f.write(f"*MATERIAL, NAME=M\n*ELASTIC\n{_fmt(case['E'])}, {_fmt(case['nu'])}\n"
                f"*DENSITY\n{_fmt(RHO0)}\n*SOLID SECTION, ELSET=EALL, MATERIAL=M\n")
        # a free body (free_beam_modes) has no boundary condition at all
        if case["dim"] == 2:
            f.write("*BOUNDARY\nNALL, 3, 3\nNCLAMP, 1, 2\n")   # plane strain: u_z = 0
        elif case["clamp"]:
            f.write("*BOUNDARY\nNCLAMP, 1, 3\n")
        if case.get("analysis") == "frequency":
            # free vibration: no loads; the eigenvalues go to the .dat, the shapes to the .frd
            f.write(f"*STEP\n*FREQUENCY\n{int(case['modes'])}\n"
                    "*NODE FILE\nU\n*END STEP\n")
            return
        if nlgeom:
            f.write("*STEP, NLGEOM, INC=1000\n*STATIC\n"
                    f"{_fmt(inc[0])}, 1.0, 1e-5, {_fmt(inc[1])}\n")
        else:
            f.write("*STEP\n*STATIC\n")
        if "gravity" in case:
            g = np.asarray(case["gravity"], float)
            gm = np.linalg.norm(g)
            d = g / gm
            f.write(f"*DLOAD\nEALL, GRAV, {_fmt(gm)}, {_fmt(d[0])}, {_fmt(d[1])}, "
                    f"{_fmt(d[2])}\n")
        if "traction" in case:
            forces = _face_loads(mesh, *case["traction_face"], case["traction"])
            f.write("*CLOAD\n")
            for n in sorted(forces):
                for a in range(3):
                    if forces[n][a] != 0.0 and not clamped[n]:
                        f.write(f"{n + 1}, {a + 1}, {_fmt(forces[n][a])}\n")
        f.write("*NODE FILE, FREQUENCY=10000\nU\n*EL FILE, FREQUENCY=10000\nS\n*END STEP\n")


# --------------------------------------------------------------------------------------------
# CalculiX result (.frd)


def read_frd(path, n_nodes=None):
    """The last DISP and STRESS blocks of an ASCII .frd file: {'U': (n, 3), 'S': (n, 6)} by
    node number - 1 (S in ccx order xx yy zz xy yz zx), plus 'steps' (number of result
    blocks seen per kind). Raises ValueError when a block is missing."""
    blocks = {}
    counts = {}
    with open(path, "r", errors="replace") as f:
        name, rows, ncomp = None, None, 0
        for line in f:
            if line.startswith(" -4"):
                name = line.split()[1]
                rows = {}
                ncomp = int(line.split()[2])
            elif name is not None and line.startswith(" -1"):
                node = int(line[3:13])
                body = line[13:].rstrip("\n")
                vals = [float(body[k:k + 12]) for k in range(0, len(body) - 11, 12)]
                rows[node] = vals
            elif name is not None and line.startswith(" -3"):
                blocks[name] = (rows, ncomp)
                counts[name] = counts.get(name, 0) + 1
                name = None
    out = {"steps": counts}
    for key, block, width in (("U", "DISP", 3), ("S", "STRESS", 6)):
        if block not in blocks:
            raise ValueError(f"no {block} block ({key}) in the file")
        rows, _ = blocks[block]
        n = n_nodes or max(rows)
        arr = np.full((n, width), np.nan)
        for node, vals in rows.items():
            if node <= n:
                arr[node - 1] = vals[:width]
        out[key] = arr
    return out


def read_frd_blocks(path, block="DISP", width=3, n_nodes=None):
    """Every `block` result block of an ASCII .frd file in order (a *FREQUENCY step writes one
    DISP block per mode): a list of (n, width) arrays by node number - 1."""
    out = []
    with open(path, "r", errors="replace") as f:
        rows = None
        for line in f:
            if line.startswith(" -4"):
                rows = {} if line.split()[1] == block else None
            elif rows is not None and line.startswith(" -1"):
                body = line[13:].rstrip("\n")
                rows[int(line[3:13])] = [float(body[k:k + 12])
                                         for k in range(0, len(body) - 11, 12)]
            elif rows is not None and line.startswith(" -3"):
                n = n_nodes or max(rows)
                arr = np.full((n, width), np.nan)
                for node, vals in rows.items():
                    if node <= n:
                        arr[node - 1] = vals[:width]
                out.append(arr)
                rows = None
    return out


def read_dat_frequencies(path):
    """The eigenvalue table of a *FREQUENCY step in a ccx .dat file: a list of (mode,
    eigenvalue omega^2 [1/s^2], frequency [Hz])."""
    out = []
    lines = Path(path).read_text(errors="replace").splitlines()
    for k, line in enumerate(lines):
        if "E I G E N V A L U E   O U T P U T" in line:
            for row in lines[k + 1:]:
                tok = row.split()
                if not tok:
                    if out:
                        break
                    continue
                if tok[0].isdigit() and len(tok) >= 4:
                    out.append((int(tok[0]), float(tok[1]), float(tok[3])))
                elif out:
                    break
            break
    if not out:
        raise ValueError("no eigenvalue table (E I G E N V A L U E   O U T P U T)")
    return out


def ccx_path(case_name=None):
    where = f"case {case_name}: " if case_name else ""
    exe = os.environ.get("CCX") or shutil.which("ccx")
    if not exe:
        raise FemError(f"{where}ccx (CalculiX) not found on PATH: install the Debian package "
                       "calculix-ccx (apt-get install calculix-ccx) or set CCX=/path/to/ccx")
    if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        raise FemError(f"{where}{exe}: not an executable file (CCX={exe})")
    return exe


def ccx_version(case_name=None):
    exe = ccx_path(case_name)
    try:
        out = subprocess.run([exe, "-v"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise FemError(f"{'case ' + case_name + ': ' if case_name else ''}{exe} -v failed: {e}")
    for tok in out.stdout.split():
        if tok[:1].isdigit():
            return tok
    return out.stdout.strip()


def run_ccx(case_name, job_dir, job, threads):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
    inp = job_dir / f"{job}.inp"
    frd = job_dir / f"{job}.frd"
    if frd.exists():
        frd.unlink()
    t0 = time.perf_counter()
    try:
        proc = subprocess.run([ccx_path(case_name), "-i", job], cwd=job_dir, env=env,
                              capture_output=True, text=True)
    except OSError as e:
        raise FemError(f"case {case_name}: {inp}: could not start ccx: {e}")
    wall = time.perf_counter() - t0
    (job_dir / "ccx.log").write_text(proc.stdout + proc.stderr)
    errors = [l.strip() for l in (proc.stdout + proc.stderr).splitlines() if "*ERROR" in l]
    if proc.returncode != 0 or errors:
        detail = "; ".join(errors[:3]) or f"exit status {proc.returncode}"
        raise FemError(f"case {case_name}: {inp}: ccx failed: {detail} "
                       f"(log {job_dir / 'ccx.log'})")
    if not frd.exists():
        raise FemError(f"case {case_name}: {frd}: ccx wrote no result file "
                       f"(log {job_dir / 'ccx.log'})")
    return frd, wall


# --------------------------------------------------------------------------------------------
# VTK XML output


def _b64(arr):
    raw = np.ascontiguousarray(arr).tobytes()
    return base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")


def write_vtu(path, points, cells, cell_type, point_data, field_data=None):
    """VTK XML unstructured grid, inline base64 binary (header UInt64, little endian), written
    under a temporary name and renamed. points (n, 3) float64; cells (e, k) 0-based;
    point_data {name: (n, c) float64}."""
    path = Path(path)
    points = np.asarray(points, dtype="<f8")
    cells = np.asarray(cells, dtype="<i8")
    n, e = len(points), len(cells)
    k = cells.shape[1]
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
             'header_type="UInt64">', "<UnstructuredGrid>"]
    if field_data:
        lines.append("<FieldData>")
        for name, text in field_data.items():
            data = np.frombuffer(text.encode(), dtype=np.uint8)
            lines.append(f'<DataArray type="UInt8" Name="{name}" NumberOfTuples="{len(data)}" '
                         f'format="binary">{_b64(data)}</DataArray>')
        lines.append("</FieldData>")
    lines.append(f'<Piece NumberOfPoints="{n}" NumberOfCells="{e}">')
    lines.append("<PointData>")
    for name, arr in point_data.items():
        arr = np.asarray(arr, dtype="<f8")
        c = 1 if arr.ndim == 1 else arr.shape[1]
        lines.append(f'<DataArray type="Float64" Name="{name}" NumberOfComponents="{c}" '
                     f'format="binary">{_b64(arr)}</DataArray>')
    lines.append("</PointData>")
    lines.append('<Points><DataArray type="Float64" NumberOfComponents="3" format="binary">'
                 f"{_b64(points)}</DataArray></Points>")
    lines.append("<Cells>")
    lines.append(f'<DataArray type="Int64" Name="connectivity" format="binary">{_b64(cells)}'
                 "</DataArray>")
    lines.append(f'<DataArray type="Int64" Name="offsets" format="binary">'
                 f"{_b64(np.arange(1, e + 1, dtype='<i8') * k)}</DataArray>")
    lines.append(f'<DataArray type="UInt8" Name="types" format="binary">'
                 f"{_b64(np.full(e, cell_type, dtype=np.uint8))}</DataArray>")
    lines.append("</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as f:
            f.write("\n".join(lines))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)   # mkstemp makes it 0600
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read_vtu_point_data(path):
    """Points, cells (connectivity reshaped by the first offset) and point data of a VTU
    written by write_vtu (for the self-test)."""
    import xml.etree.ElementTree as ET
    root = ET.parse(path).getroot()
    types = {"Float64": "<f8", "Int64": "<i8", "UInt8": "u1"}

    def arr(da):
        raw = base64.b64decode(da.text.strip())
        n = int(np.frombuffer(raw[:8], "<u8")[0])
        data = np.frombuffer(raw[8:8 + n], types[da.get("type")])
        c = int(da.get("NumberOfComponents", "1"))
        return data.reshape(-1, c) if c > 1 else data

    piece = root.find(".//Piece")
    pts = arr(piece.find("Points/DataArray"))
    cd = {da.get("Name"): arr(da) for da in piece.find("Cells")}
    k = int(cd["offsets"][0])
    pd = {da.get("Name"): arr(da) for da in piece.find("PointData")}
    return pts, cd["connectivity"].reshape(-1, k), cd["types"], pd


def write_fem_vtu(path, mesh, U, S, meta):
    """The FEM solution in the undeformed configuration: 3D as hex20 (type 25), an extruded 2D
    mesh as its quad8 plane z = 0 (type 23). S (ccx: xx yy zz xy yz zx) is VTK's symmetric
    order xx yy zz xy yz xz as is."""
    fd = {"fem_source": json.dumps(meta, sort_keys=True)}
    if mesh.plane is not None:
        ids = mesh.plane_points
        pts = np.column_stack([mesh.plane.points, np.zeros(len(ids))])
        if np.abs(mesh.points[ids, 2]).max() > 0:
            raise ValueError("the 2D plane is not z = 0")
        u = U[ids].copy()
        u[:, 2] = 0.0
        write_vtu(path, pts, mesh.plane.cells, 23,
                  {"displacement": u, "cauchy_stress": S[ids]}, fd)
    else:
        write_vtu(path, mesh.points, mesh.cells, 25, {"displacement": U, "cauchy_stress": S}, fd)


# --------------------------------------------------------------------------------------------
# Running a case


def _plane_strain_check(mesh, U):
    """Largest difference of the in-plane displacement between the planes z = 0 and z = t
    relative to the largest displacement (the one-layer model must be z-independent)."""
    m2 = mesh.plane
    top = np.nonzero(np.abs(mesh.points[:, 2] - mesh.points[:, 2].max()) < 1e-12)[0]
    key = {(round(p[0] * 1e9), round(p[1] * 1e9)): i for i, p in zip(top, mesh.points[top])}
    other = np.array([key[(round(p[0] * 1e9), round(p[1] * 1e9))] for p in m2.points])
    base = mesh.plane_points
    return float(np.abs(U[base, :2] - U[other, :2]).max() / np.abs(U[:, :2]).max())


def convergence(specs, values, ratio=2.0):
    """Observed convergence of one quantity over a mesh ladder refined by `ratio`: successive
    differences, observed order from the last three, and a Richardson estimate when the last
    three are monotone."""
    v = [float(x) for x in values]
    out = {"values": v, "differences": [v[k + 1] - v[k] for k in range(len(v) - 1)],
           "finest": v[-1]}
    if len(v) >= 2 and v[-1] != 0:
        out["last_change_relative"] = abs(v[-1] - v[-2]) / abs(v[-1])
    if len(v) >= 3:
        d1, d2 = v[-2] - v[-3], v[-1] - v[-2]
        out["monotone"] = bool(d1 * d2 > 0 and abs(d2) < abs(d1))
        if out["monotone"]:
            p = math.log(d1 / d2) / math.log(ratio)
            out["observed_order"] = p
            out["richardson"] = v[-1] + d2 / (ratio**p - 1.0)
    return out


def _is_ladder(specs, axes=None):
    """Whether specs refine by 2: every mesh dimension doubles, or with `axes` the dimensions
    `axes` double and the others stay."""
    if len(specs) < 2:
        return False
    a = [np.atleast_1d(np.asarray(s, float)) for s in specs]
    mask = np.ones(len(a[0]), bool)
    if axes is not None:
        mask[:] = False
        mask[list(np.atleast_1d(axes))] = True
    return all(np.allclose(a[k + 1][mask], 2 * a[k][mask])
               and np.allclose(a[k + 1][~mask], a[k][~mask]) for k in range(len(a) - 1))


def run_case(name, out_dir=DEFAULT_OUT, meshes=None, quick=False, threads=2, log=print,
             series_names=None):
    """Run one case: every series' meshes (or `meshes` for every series; `quick`: the two
    coarsest of each series not marked quick=False), returning the case record (as in
    references.json). A mesh that an earlier series of the case ran with the same analysis is
    not run again (its record says same_run_as). Raises FemError."""
    if name not in CASES:
        raise FemError(f"unknown case '{name}' (known: {', '.join(CASES)})")
    case = CASES[name]
    out_dir = Path(out_dir)
    case_dir = out_dir / name
    case_dir.mkdir(parents=True, exist_ok=True)
    version = ccx_version(name)
    record = {"title": case["title"], "scene": case["scene"], "dimension": case["dim"],
              "material": {"E": case["E"], "nu": case["nu"], "rho0": RHO0,
                           "model": "*ELASTIC (linear; with NLGEOM Saint Venant-Kirchhoff)"},
              "element": "C3D20R" + (" (one layer, u_z = 0 at every node: plane strain)"
                                     if case["dim"] == 2 else ""),
              "ccx_version": version, "note": case.get("note", ""), "series": {}}
    if "analytic" in case:
        a = case["analytic"]
        record["analytic"] = a() if callable(a) else a
    if case.get("analysis") == "frequency":
        record["analysis"] = "frequency"
        record["material"]["model"] = "*ELASTIC (linear), *DENSITY"
        record["modes_requested"] = int(case["modes"])
        record["threads"] = threads
    done = {}
    for sname, series in case["series"].items():
        if series_names and sname not in series_names:
            continue
        specs = list(meshes) if meshes is not None else list(series["meshes"])
        if quick:
            if not series.get("quick", True):
                continue
            specs = specs[:2]
        runs = []
        for spec in specs:
            label = mesh_label(case, spec)
            key = (series["nlgeom"], tuple(np.atleast_1d(spec).tolist()),
                   tuple(series.get("inc", (1.0, 1.0))))
            if key in done:
                # the same model in an earlier series of this case: not run twice
                run = dict(done[key][1], same_run_as=done[key][0])
                run.pop("vtu", None)
                runs.append(run)
                log(f"{name:29s} {sname:11s} {label:9s} (= {done[key][0]})", flush=True)
                continue
            mesh, _ = build_mesh(name, case, spec)
            job_dir = case_dir / f"{sname}_{label}"
            job_dir.mkdir(parents=True, exist_ok=True)
            inp = job_dir / f"{name}.inp"
            write_inp(inp, case, mesh, series["nlgeom"], series.get("inc", (1.0, 1.0)))
            frd, wall = run_ccx(name, job_dir, name, threads)
            mode_info = None
            if case.get("analysis") == "frequency":
                dat = job_dir / f"{name}.dat"
                try:
                    eig = read_dat_frequencies(dat)
                    shapes = read_frd_blocks(frd, "DISP", 3, len(mesh.points))
                except (OSError, ValueError) as e:
                    raise FemError(f"case {name}: {dat} / {frd}: {e}")
                if len(shapes) != len(eig) or any(np.isnan(U).any() for U in shapes):
                    raise FemError(f"case {name}: {frd}: {len(shapes)} mode shapes for "
                                   f"{len(eig)} eigenvalues, or shapes missing at some nodes")
                vals, mode_info = case["values"](mesh, [(f, U) for (_, _, f), U
                                                        in zip(eig, shapes)], case)
                vals = {k: float(v) for k, v in vals.items()}
            else:
                try:
                    res = read_frd(frd, len(mesh.points))
                except (OSError, ValueError) as e:
                    raise FemError(f"case {name}: {frd}: {e}")
                U, S = res["U"], res["S"]
                if np.isnan(U).any() or np.isnan(S).any():
                    raise FemError(f"case {name}: {frd}: U or S missing at some nodes")
                vals = {k: float(v) for k, v in case["values"](mesh, U, S, case).items()}
            run = {"mesh": label, "spec": list(np.atleast_1d(spec).tolist()),
                   "nodes": int(len(mesh.points)), "elements": int(len(mesh.cells)),
                   "dofs": int(3 * len(mesh.points)), "wall_s": round(wall, 2),
                   "values": vals}
            if mode_info is not None:
                run["modes"] = mode_info
            if series["nlgeom"]:
                cvg = job_dir / f"{name}.cvg"
                if cvg.exists():
                    rows = [l for l in cvg.read_text().splitlines()[4:] if l.strip()]
                    run["increments"] = len({l.split()[1] for l in rows if len(l.split()) > 2})
                    run["iterations"] = len(rows)
            if case["dim"] == 2:
                run["plane_strain_z_variation"] = _plane_strain_check(mesh, U)
            runs.append(run)
            done[key] = (f"{sname} {label}", run)
            shown = "  ".join(f"{k}={v:.6g}" for k, v in vals.items())
            log(f"{name:29s} {sname:11s} {label:9s} dofs={run['dofs']:7d} "
                f"{wall:7.1f} s  {shown}", flush=True)
            if series["vtu"] and spec == specs[-1]:
                suffix = "" if sname in ("linear",) or len(case["series"]) == 1 else "_" + sname
                vtu = out_dir / f"{name}{suffix}.vtu"
                write_fem_vtu(vtu, mesh, U, S, {"case": name, "series": sname, "mesh": label,
                                                 "solver": f"CalculiX ccx {version}"})
                run["vtu"] = _rel(vtu)
        entry = {"nlgeom": series["nlgeom"], "runs": runs}
        if _is_ladder(specs, series.get("ladder_axis")):
            # the quantities every mesh has (a mode family cut off by the number of modes
            # asked for may be missing on some meshes)
            entry["convergence"] = {k: convergence(specs, [r["values"][k] for r in runs])
                                    for k in runs[0]["values"]
                                    if all(k in r["values"] for r in runs)}
        record["series"][sname] = entry
    reference_record(record, case)
    return record


def reference_record(record, case):
    """record["reference"]: the finest mesh of the case's `reference_series` (default the
    first series run), plus the Richardson values where that ladder converges monotonically."""
    sname = case.get("reference_series")
    if sname not in record["series"]:
        sname = next(iter(record["series"]), None)
    if sname is None:
        return
    series = record["series"][sname]
    finest = series["runs"][-1]
    ref = {"series": sname, "mesh": finest["mesh"], "values": finest["values"],
           "main": case["main"]}
    conv = series.get("convergence", {})
    rich = {k: c["richardson"] for k, c in conv.items() if "richardson" in c}
    if rich:
        ref["richardson"] = rich
    if case.get("reference_note"):
        ref["note"] = case["reference_note"]
    record["reference"] = ref


def _rel(path):
    path = Path(path).resolve()
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)


def load_references(path=DEFAULT_JSON):
    with open(path) as f:
        return json.load(f)


def _save_json(path, data):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=False) + "\n")
    os.replace(tmp, path)


def run_cases(names=None, out_dir=DEFAULT_OUT, quick=False, json_path=None, threads=2,
              log=print):
    """Run the named cases (default all) and merge their records into json_path (default:
    validation/fem/references.json, or OUT/references_quick.json for a quick run)."""
    names = list(names or CASES)
    out_dir = Path(out_dir)
    if json_path is None:
        json_path = out_dir / "references_quick.json" if quick else DEFAULT_JSON
    data = {}
    if Path(json_path).exists():
        try:
            data = load_references(json_path)
        except (OSError, ValueError):
            data = {}
    data.setdefault("cases", {})
    data["generator"] = "validation/fem.py"
    if "machine" not in data or set(names) >= set(CASES):
        # a partial run keeps the full run's record (the case records hold their threads)
        data["machine"] = {"platform": platform.platform(), "cpus": os.cpu_count(),
                           "threads": threads}
    t0 = time.perf_counter()
    for name in names:
        t1 = time.perf_counter()
        rec = run_case(name, out_dir, quick=quick, threads=threads, log=log)
        rec["case_wall_s"] = round(time.perf_counter() - t1, 1)
        data["cases"][name] = rec
        data["ccx_version"] = rec["ccx_version"]
        data["cases"] = {k: data["cases"][k] for k in CASES if k in data["cases"]}
        _save_json(json_path, data)
    log(f"total {time.perf_counter() - t0:.1f} s; wrote {json_path}")
    return data


def markdown_tables(data, digits=6):
    """Markdown tables (one per case and series) of the point values per mesh, with the
    Richardson estimate and the observed order where the ladder shows monotone convergence."""
    out = []
    for name, rec in data.get("cases", {}).items():
        out.append(f"#### {name}: {rec['title']}\n")
        for sname, series in rec["series"].items():
            runs = series["runs"]
            keys = [k for k in runs[0]["values"]
                    if all(k in r["values"] for r in runs)
                    and not all(abs(r["values"][k]) < 1e-12 for r in runs)]
            out.append(f"{sname}" + (" (NLGEOM)" if series["nlgeom"] else "") + ":\n")
            out.append("| mesh | nodes | dofs | ccx s | " + " | ".join(keys) + " |")
            out.append("|---|---:|---:|---:|" + "---:|" * len(keys))
            for r in runs:
                out.append(f"| {r['mesh']} | {r['nodes']} | {r['dofs']} | {r['wall_s']:.1f} | "
                           + " | ".join(f"{r['values'][k]:.{digits}g}" for k in keys) + " |")
            conv = series.get("convergence")
            if conv:
                out.append("| Richardson | | | | " + " | ".join(
                    f"{conv[k]['richardson']:.{digits}g}" if "richardson" in conv[k] else "-"
                    for k in keys) + " |")
                out.append("| observed order | | | | " + " | ".join(
                    f"{conv[k]['observed_order']:.2f}" if "observed_order" in conv[k] else "-"
                    for k in keys) + " |")
            out.append("")
    return "\n".join(out)


# --------------------------------------------------------------------------------------------
# Self-test: the VTU node order, read back by tlsph compare


def _quadratic_field(X):
    x, y, z = X[:, 0], X[:, 1], X[:, 2]
    return np.column_stack([1e-3 * (1 + 3 * x * x - 2 * x * y + y * z + z),
                            1e-3 * (2 * y * y + x * z - y + 0.5 * z * z),
                            1e-3 * (x * y + 4 * z * z - x)])


def _linear_field(X):
    x, y, z = X[:, 0], X[:, 1], X[:, 2]
    return np.column_stack([1e-3 * (1 + 3 * x - 2 * y + z), 1e-3 * (2 * y + x - 0.5 * z),
                            1e-3 * (x + 4 * z - y)])


def _fake_frame(path, X, u):
    """A tlsph-like frame: vertices at the current positions X + u, point data displacement."""
    write_vtu(path, X + u, np.arange(len(X)).reshape(-1, 1), 1, {"displacement": u})


def self_test(tlsph=None, out_dir=DEFAULT_OUT, log=print):
    """Checks the VTU writer and the element node order.

    (1) python: the hex20/quad8 shape functions, applied to the cells read back from the VTU,
    reproduce a linear field on every mesh (isoparametric) and a quadratic field on the box
    mesh (affine elements) at random points, and `interpolate` finds them;
    (2) with a tlsph binary: `tlsph compare` on a fake frame (particles at X + u(X)) against the
    VTU. VTK's quadratic cells find a point's parametric coordinates by a Newton iteration
    (vtkQuadraticHexahedron::EvaluatePosition) that scales its steps by 0.5 and stops at a
    step of 1e-4, so the read-back is exact only to about 1e-4 of the field's variation
    across one element: the test
    asks for max error / max |fem| < 3e-4, and checks that a wrong node order (top and vertical
    mid-edges swapped, or the quad's mid-edges rotated) fails it by far. Returns True if all
    pass."""
    out_dir = Path(out_dir) / "selftest"
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(1)
    ok = True
    meshes = {"hex20_box": box_mesh((0, -0.05, -0.05), (1, 0.05, 0.05), (10, 2, 2)),
              "quad8_cook": extrude(cook_mesh(4), [0, 0.01]),
              "quad8_hole": extrude(plate_hole_mesh(4), [0, 0.01])}
    for name, mesh in meshes.items():
        dim = 2 if mesh.plane is not None else 3
        fields = {"linear": _linear_field}
        if dim == 3:
            fields["quadratic"] = _quadratic_field
        for fname, field in fields.items():
            def f(X):
                u = field(X if dim == 3 else np.column_stack([X[:, :2], np.zeros(len(X))]))
                if dim == 2:
                    u[:, 2] = 0.0
                return u
            U = f(mesh.points)
            S = np.tile(np.arange(1.0, 7.0), (len(U), 1))
            vtu = out_dir / f"{name}_{fname}.vtu"
            write_fem_vtu(vtu, mesh, U, S, {"case": "selftest"})
            pts, cells, types, pd = read_vtu_point_data(vtu)
            shape = quad8_shape if dim == 2 else hex20_shape
            n = 300
            e = rng.integers(0, len(cells), n)
            nat = rng.uniform(-0.999, 0.999, (n, dim))
            X = np.array([shape(nat[i])[0] @ pts[cells[e[i]]] for i in range(n)])
            u_int = np.array([shape(nat[i])[0] @ pd["displacement"][cells[e[i]]]
                              for i in range(n)])
            exact = f(X)
            scale = np.abs(exact).max()
            err_py = np.abs(u_int - exact).max() / scale
            err_loc = max(np.abs(interpolate(mesh, U, X[i]) - exact[i]).max()
                          for i in range(10)) / scale
            good = err_py < 1e-12 and err_loc < 1e-9
            line = (f"selftest {name:10s} {fname:9s} {len(cells):4d} cells of VTK type "
                    f"{types[0]}: python read-back {err_py:.1e}, point location {err_loc:.1e}")
            if tlsph:
                frame = out_dir / f"{name}_{fname}_frame.vtu"
                _fake_frame(frame, X, exact)
                wrong = cells.copy()
                if dim == 3:
                    wrong[:, 12:16], wrong[:, 16:20] = cells[:, 16:20], cells[:, 12:16]
                else:
                    wrong[:, 4:8] = np.roll(cells[:, 4:8], 1, axis=1)
                bad = out_dir / f"{name}_{fname}_wrong_order.vtu"
                write_vtu(bad, pts, wrong, types[0], pd)
                res = {}
                for tag, target in (("right", vtu), ("wrong", bad)):
                    js = out_dir / f"{name}_{fname}_{tag}.json"
                    proc = subprocess.run([str(tlsph), "compare", str(frame), str(target),
                                           "--fields", "displacement", "--no-output", "--json",
                                           str(js)], capture_output=True, text=True)
                    if proc.returncode != 0:
                        res[tag] = None
                        if tag == "right":
                            line += f"; tlsph compare FAILED: {proc.stderr.strip()[:300]}"
                        continue
                    r = json.loads(js.read_text())
                    fd = r["fields"]["displacement"]
                    res[tag] = (r["compared_particles"], fd["max_relative"])
                if res.get("right"):
                    cmp_n, rel = res["right"]
                    line += f"; tlsph compare {cmp_n}/{n} compared, max err/max {rel:.1e}"
                    good = good and cmp_n == n and rel < 3e-4
                else:
                    good = False
                if res.get("wrong"):
                    cmp_w, rel_w = res["wrong"]
                    line += f" (wrong node order: {cmp_w} compared, {rel_w:.1e})"
                    good = good and (rel_w > 3e-3 or cmp_w < n)
                else:
                    line += " (wrong node order: rejected, no particle inside)"
            ok = ok and good
            log(line + ("  ok" if good else "  FAILED"))
    return ok


# --------------------------------------------------------------------------------------------
# CLI


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", action="append", choices=list(CASES), metavar="NAME",
                    help="a case to run (repeat for several; default all): " + ", ".join(CASES))
    ap.add_argument("--out", default=str(DEFAULT_OUT),
                    help="directory for .inp/.frd/.vtu (default validation/fem/out)")
    ap.add_argument("--quick", action="store_true", help="the two coarsest meshes only")
    ap.add_argument("--json", default=None,
                    help="the JSON to write (default validation/fem/references.json; "
                         "--quick: OUT/references_quick.json)")
    ap.add_argument("--threads", type=int, default=2, help="ccx threads (default 2)")
    ap.add_argument("--list", action="store_true", help="list the cases and meshes")
    ap.add_argument("--table", action="store_true",
                    help="print Markdown tables from the JSON (--json or the default)")
    ap.add_argument("--self-test", action="store_true",
                    help="test the element node order and the VTU read-back")
    ap.add_argument("--tlsph", default=None, help="with --self-test: a tlsph binary for "
                                                  "`tlsph compare`")
    args = ap.parse_args(argv)
    if args.list:
        for name, case in CASES.items():
            print(f"{name}: {case['title']}")
            for sname, s in case["series"].items():
                print(f"  {sname}: " + ", ".join(mesh_label(case, m) for m in s["meshes"]))
        return 0
    if args.table:
        print(markdown_tables(load_references(args.json or DEFAULT_JSON)))
        return 0
    if args.self_test:
        return 0 if self_test(args.tlsph, args.out) else 1
    try:
        run_cases(args.case, args.out, args.quick, args.json, args.threads)
    except FemError as e:
        print(f"fem.py: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
