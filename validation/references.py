"""Reference values for the validation problems (Python standard library only).

Closed forms are evaluated here, and two references that have no closed form are computed:

* the first bending frequency of a clamped-free Timoshenko beam (shear deformation and rotary
  inertia), from its frequency equation: the 2x2 determinant of the free-end conditions of the
  two solutions that satisfy the clamped-end conditions, integrated with RK4 and bracketed by
  bisection on the sign of the determinant;
* the centre deflection of a clamped square Mindlin (first-order shear deformation) plate under
  uniform pressure, by a Ritz method on polynomial bases; the same code run on the Kirchhoff
  energy reproduces the classical coefficient 0.00126 (Timoshenko & Woinowsky-Krieger), which
  is the check that the Mindlin number is right.

`python3 validation/references.py` prints them all.
"""

import math

# --------------------------------------------------------------------------------------------
# Beams


def euler_bernoulli_frequency(E, I, rho, A, L, beta_l=1.8751040687):
    """First bending frequency [Hz] of a clamped-free Euler-Bernoulli beam."""
    return beta_l**2 / (2.0 * math.pi) * math.sqrt(E * I / (rho * A * L**4))


def rectangle_shear_coefficient(nu):
    """Cowper's shear coefficient of a rectangular section, kappa = 10(1+nu)/(12+11nu)."""
    return 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)


def timoshenko_frequency(E, nu, rho, A, I, L, kappa=None, rotary_inertia=True, G=None,
                         beta_l=1.8751040687):
    """Bending frequency [Hz] of a clamped-free Timoshenko beam, found by bisection on the
    frequency determinant in a bracket around the Euler-Bernoulli value of the mode with
    beta_l (1.8751040687: the first; 4.6940911330: the second)."""
    if kappa is None:
        kappa = rectangle_shear_coefficient(nu)
    if G is None:
        G = E / (2.0 * (1.0 + nu))
    I_rot = I if rotary_inertia else 0.0
    w_eb = 2.0 * math.pi * euler_bernoulli_frequency(E, I, rho, A, L, beta_l)

    def det(omega):
        # rotary inertia enters through rho*I_rot; the bending stiffness keeps I
        return _timoshenko_determinant(omega, E, kappa * G * A, rho, A, I, I_rot, L)

    # scan upwards from 0.5 w_eb for the first sign change
    lo = 0.5 * w_eb
    f_lo = det(lo)
    step = 0.01 * w_eb
    hi = lo
    while True:
        hi = lo + step
        f_hi = det(hi)
        if f_lo == 0.0 or (f_lo < 0) != (f_hi < 0):
            break
        lo, f_lo = hi, f_hi
        if lo > 1.5 * w_eb:
            raise RuntimeError("no Timoshenko root near the Euler-Bernoulli frequency")
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        f_mid = det(mid)
        if (f_mid < 0) == (f_lo < 0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return 0.5 * (lo + hi) / (2.0 * math.pi)


def _timoshenko_determinant(omega, E, kGA, rho, A, I, I_rot, L, n=400):
    """Determinant of the free-end conditions (moment, shear) of the clamped-free Timoshenko
    beam at circular frequency omega. State y = (w, w', psi, psi');
        kappa G A (w'' - psi') + rho A omega^2 w = 0
        E I psi'' + kappa G A (w' - psi) + rho I omega^2 psi = 0
    clamped at x = 0 (w = psi = 0); free at x = L: psi' = 0 (moment) and w' - psi = 0
    (shear). The two columns are the solutions started with w' = 1 and psi' = 1."""
    def rhs(y):
        w, dw, psi, dpsi = y
        d2w = dpsi - rho * A * omega**2 * w / kGA
        d2psi = -(kGA * (dw - psi) + rho * I_rot * omega**2 * psi) / (E * I)
        return (dw, d2w, dpsi, d2psi)

    def integrate(y):
        h = L / n
        for _ in range(n):
            k1 = rhs(y)
            k2 = rhs(tuple(a + 0.5 * h * b for a, b in zip(y, k1)))
            k3 = rhs(tuple(a + 0.5 * h * b for a, b in zip(y, k2)))
            k4 = rhs(tuple(a + h * b for a, b in zip(y, k3)))
            y = tuple(a + h / 6.0 * (b + 2 * c + 2 * d + e)
                      for a, b, c, d, e in zip(y, k1, k2, k3, k4))
        return y

    ya = integrate((0.0, 1.0, 0.0, 0.0))
    yb = integrate((0.0, 0.0, 0.0, 1.0))
    return ya[3] * (yb[1] - yb[2]) - yb[3] * (ya[1] - ya[2])


def timoshenko_static_tip(q, E, nu, A, I, L, kappa=None):
    """Tip deflection of a clamped-free Timoshenko beam under a uniform load q [N/m]:
    bending q L^4/(8 E I) plus shear q L^2/(2 kappa G A)."""
    if kappa is None:
        kappa = rectangle_shear_coefficient(nu)
    G = E / (2.0 * (1.0 + nu))
    return q * L**4 / (8.0 * E * I) + q * L**2 / (2.0 * kappa * G * A)


def thin_plate_period(E, nu, rho, H, L, kL=1.875):
    """Gray, Monaghan & Swift (2001) thin-plate period [s], plane strain:
    omega^2 = E H^2 k^4 / (12 rho (1 - nu^2)), k = kL / L."""
    k = kL / L
    omega = math.sqrt(E * H**2 * k**4 / (12.0 * rho * (1.0 - nu**2)))
    return 2.0 * math.pi / omega


# --------------------------------------------------------------------------------------------
# Clamped square plate: Ritz solutions (Kirchhoff and Mindlin) on [-1, 1]^2 scaled to a x a.
#
# One-dimensional factors are polynomials stored as coefficient lists (index = power). Basis
# functions are products f(x) g(y) of such factors, so every energy integral over the square is
# a product of two one-dimensional integrals of polynomials, which are exact.


def _pmul(p, q):
    r = [0.0] * (len(p) + len(q) - 1)
    for i, a in enumerate(p):
        if a:
            for j, b in enumerate(q):
                r[i + j] += a * b
    return r


def _pder(p):
    return [i * p[i] for i in range(1, len(p))] or [0.0]


def _pint(p):
    """Integral over [-1, 1]."""
    return sum(2.0 * c / (i + 1) for i, c in enumerate(p) if i % 2 == 0)


def _legendre(n):
    """Legendre polynomial P_n as a coefficient list."""
    p0, p1 = [1.0], [0.0, 1.0]
    if n == 0:
        return p0
    for k in range(1, n):
        # (k+1) P_{k+1} = (2k+1) x P_k - k P_{k-1}
        a = _pmul([0.0, 1.0], p1)
        a = [(2 * k + 1) * c for c in a]
        b = [k * c for c in p0] + [0.0] * (len(a) - len(p0))
        p0, p1 = p1, [(x - y) / (k + 1) for x, y in zip(a, b)]
    return p1


def _solve(K, f):
    """Gaussian elimination with partial pivoting (K is modified)."""
    n = len(f)
    M = [row[:] + [f[i]] for i, row in enumerate(K)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(M[r][c]))
        M[c], M[p] = M[p], M[c]
        piv = M[c][c]
        for r in range(c + 1, n):
            m = M[r][c] / piv
            if m:
                row_r, row_c = M[r], M[c]
                for k in range(c, n + 1):
                    row_r[k] -= m * row_c[k]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        s = M[r][n] - sum(M[r][k] * x[k] for k in range(r + 1, n))
        x[r] = s / M[r][r]
    return x


def _factors(kind, count, parity):
    """1D factors (1-x^2)^kind P_m(x) for the first `count` Legendre P_m of the given parity."""
    bubble = [1.0]
    for _ in range(kind):
        bubble = _pmul(bubble, [1.0, 0.0, -1.0])
    ms = [m for m in range(2 * count + 2) if m % 2 == parity][:count]
    return [_pmul(bubble, _legendre(m)) for m in ms]


def _table(fs, gs, df, dg):
    return [[_pint(_pmul(_pder(f) if df else f, _pder(g) if dg else g)) for g in gs] for f in fs]


def kirchhoff_clamped_square(nu, n=6):
    """Centre deflection coefficient c in w = c q a^4 / D of a clamped square Kirchhoff plate
    (Ritz, w = sum (1-x^2)^2 (1-y^2)^2 P_i(x) P_j(y), i, j even). The clamped boundary makes the
    Gaussian-curvature term vanish, so U = D/2 int (lap w)^2 - q int w."""
    fs = _factors(2, n, 0)
    m = len(fs)
    d0 = [[_pint(_pmul(f, g)) for g in fs] for f in fs]
    d2 = [[_pint(_pmul(_pder(_pder(f)), g)) for g in fs] for f in fs]
    d22 = [[_pint(_pmul(_pder(_pder(f)), _pder(_pder(g)))) for g in fs] for f in fs]
    s = [_pint(f) for f in fs]
    idx = [(i, j) for i in range(m) for j in range(m)]
    # on [-1,1]^2 with a = 2 (half-width 1): lap w = w_xx + w_yy
    K = [[0.0] * len(idx) for _ in idx]
    for a, (i, j) in enumerate(idx):
        for b, (k, l) in enumerate(idx):
            K[a][b] = (d22[i][k] * d0[j][l] + d0[i][k] * d22[j][l] + d2[i][k] * d2[l][j] +
                       d2[k][i] * d2[j][l])
    f = [s[i] * s[j] for (i, j) in idx]
    x = _solve(K, f)  # D = 1, q = 1
    w0 = sum(x[a] * _peval(fs[i], 0.0) * _peval(fs[j], 0.0) for a, (i, j) in enumerate(idx))
    return w0 / 2.0**4  # w = c q a^4 / D with a = 2


def _peval(p, x):
    return sum(c * x**i for i, c in enumerate(p))


def mindlin_clamped_square(E, nu, t, a, q, kappa=5.0 / 6.0, n=6):
    """Centre deflection [m] of a clamped square Mindlin plate (side a, thickness t) under
    uniform pressure q, by Ritz: w, psi_x, psi_y all vanish on the edges;
        U = int D/2 [psi_x,x^2 + psi_y,y^2 + 2 nu psi_x,x psi_y,y + (1-nu)/2 (psi_x,y+psi_y,x)^2]
              + kappa G t/2 [(w,x + psi_x)^2 + (w,y + psi_y)^2] - q w.
    Bases: (1-x^2)(1-y^2) P_i(x) P_j(y) with the symmetry of each field (w even-even,
    psi_x odd-even, psi_y even-odd)."""
    D = E * t**3 / (12.0 * (1.0 - nu**2))
    S = kappa * E / (2.0 * (1.0 + nu)) * t
    c = a / 2.0  # half-width: X = c x
    ev = _factors(1, n, 0)
    od = _factors(1, n, 1)
    fam = {"e": ev, "o": od}
    # 1D integral tables T[(p, q, dp, dq)][i][k] = int p_i^(dp) q_k^(dq)
    tables = {}

    def T(p, qq, dp, dq):
        key = (p, qq, dp, dq)
        if key not in tables:
            tables[key] = _table(fam[p], fam[qq], dp, dq)
        return tables[key]

    # unknown list: (field, i, j) with field parities (px, py)
    fields = {"w": ("e", "e"), "px": ("o", "e"), "py": ("e", "o")}
    unknowns = [(fld, i, j) for fld in ("w", "px", "py") for i in range(n) for j in range(n)]
    N = len(unknowns)

    def integral(u, v, du, dv):
        """int over the square (physical) of D_u(phi_u) D_v(phi_v), du/dv in {"", "x", "y"}."""
        (fu, i, j), (fv, k, l) = u, v
        pux, puy = fields[fu]
        pvx, pvy = fields[fv]
        ix = T(pux, pvx, du == "x", dv == "x")[i][k]
        iy = T(puy, pvy, du == "y", dv == "y")[j][l]
        scale = c * c / (c ** ((du != "") + (dv != "")))
        return ix * iy * scale

    K = [[0.0] * N for _ in range(N)]
    # Energy density terms as (coefficient, [(field, deriv), (field, deriv)]) for the quadratic
    # form 1/2 sum coef * A * B.
    terms = [
        (D, ("px", "x"), ("px", "x")),
        (D, ("py", "y"), ("py", "y")),
        (D * nu, ("px", "x"), ("py", "y")),
        (D * nu, ("py", "y"), ("px", "x")),
        (D * (1 - nu) / 2, ("px", "y"), ("px", "y")),
        (D * (1 - nu) / 2, ("py", "x"), ("py", "x")),
        (D * (1 - nu) / 2, ("px", "y"), ("py", "x")),
        (D * (1 - nu) / 2, ("py", "x"), ("px", "y")),
        (S, ("w", "x"), ("w", "x")),
        (S, ("px", ""), ("px", "")),
        (S, ("w", "x"), ("px", "")),
        (S, ("px", ""), ("w", "x")),
        (S, ("w", "y"), ("w", "y")),
        (S, ("py", ""), ("py", "")),
        (S, ("w", "y"), ("py", "")),
        (S, ("py", ""), ("w", "y")),
    ]
    for A_, u in enumerate(unknowns):
        for B_, v in enumerate(unknowns):
            s = 0.0
            for coef, (fa, da), (fb, db) in terms:
                if u[0] == fa and v[0] == fb:
                    s += coef * integral(u, v, da, db)
            K[A_][B_] = s
    f = [0.0] * N
    for A_, (fld, i, j) in enumerate(unknowns):
        if fld == "w":
            f[A_] = q * _pint(ev[i]) * _pint(ev[j]) * c * c
    x = _solve(K, f)
    return sum(x[A_] * _peval(ev[i], 0.0) * _peval(ev[j], 0.0)
               for A_, (fld, i, j) in enumerate(unknowns) if fld == "w")


def kirchhoff_plate_deflection(E, nu, t, a, q, coefficient=0.00126):
    D = E * t**3 / (12.0 * (1.0 - nu**2))
    return coefficient * q * a**4 / D


# --------------------------------------------------------------------------------------------
# Thick-walled cylinder (Lame): plane strain with the outer surface clamped; the textbook case
# with it free (plane strain, and plane stress: the open-ended cylinder)


def lame_ring(E, nu, a, b, p):
    """Ring a <= r <= b under internal pressure p with u(b) = 0 (the outer surface clamped),
    plane strain: u_r = A r + B / r, A = -B / b^2, B from sigma_rr(a) = -p. Returns a function
    r -> (u_r, sigma_rr, sigma_tt)."""
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    B = p / (2.0 * (lam + mu) / b**2 + 2.0 * mu / a**2)
    A = -B / b**2

    def at(r):
        return (A * r + B / r, 2.0 * (lam + mu) * A - 2.0 * mu * B / r**2,
                2.0 * (lam + mu) * A + 2.0 * mu * B / r**2)
    return at


def lame_free(E, nu, a, b, p, plane_strain=True):
    """The textbook Lame problem: a <= r <= b under internal pressure p, the outer surface free
    (sigma_rr(a) = -p, sigma_rr(b) = 0). With k = p a^2 / (b^2 - a^2): sigma_rr = k (1 - b^2/r^2),
    sigma_tt = k (1 + b^2/r^2) in both cases; plane strain: u_r = (1 + nu)/E k ((1 - 2 nu) r +
    b^2/r); plane stress (sigma_zz = 0: the open-ended cylinder of any length, exact in 3D, its
    axial strain -2 nu k / E uniform): u_r = k/E ((1 - nu) r + (1 + nu) b^2/r). Returns a
    function r -> (u_r, sigma_rr, sigma_tt)."""
    k = p * a**2 / (b**2 - a**2)

    def at(r):
        if plane_strain:
            u = (1.0 + nu) / E * k * ((1.0 - 2.0 * nu) * r + b**2 / r)
        else:
            u = k / E * ((1.0 - nu) * r + (1.0 + nu) * b**2 / r)
        return u, k * (1.0 - b**2 / r**2), k * (1.0 + b**2 / r**2)
    return at


def lame_free_axial_strain(E, nu, a, b, p):
    """The open-ended cylinder's uniform axial strain (plane stress Lame): -2 nu k / E."""
    return -2.0 * nu * p * a**2 / (b**2 - a**2) / E


if __name__ == "__main__":
    E, nu, rho = 1.0e7, 0.3, 1000.0
    b = h = 0.1
    A, I, L = b * h, b * h**3 / 12.0, 1.0
    print("cantilever: EB f1 = %.5f Hz" % euler_bernoulli_frequency(E, I, rho, A, L))
    for rot in (False, True):
        print("cantilever: Timoshenko f1 (kappa %.4f, rotary inertia %s) = %.5f Hz" % (
            rectangle_shear_coefficient(nu), rot,
            timoshenko_frequency(E, nu, rho, A, I, L, rotary_inertia=rot)))
    print("cantilever: Timoshenko f1 (kappa 5/6) = %.5f Hz" %
          timoshenko_frequency(E, nu, rho, A, I, L, kappa=5.0 / 6.0))
    print("cantilever: static tip (Cowper kappa) = %.6f m, (kappa 5/6) = %.6f m" % (
        timoshenko_static_tip(10.0, E, nu, A, I, L),
        timoshenko_static_tip(10.0, E, nu, A, I, L, kappa=5.0 / 6.0)))
    Ep, nup, H, Lp = 2.0e6, 0.3975, 0.02, 0.2
    print("plate: thin-plate period = %.5f s" % thin_plate_period(Ep, nup, 1000.0, H, Lp))
    # plane strain Timoshenko: E' = E/(1-nu^2), G unchanged
    fT = timoshenko_frequency(Ep / (1 - nup**2), nup, 1000.0, H, H**3 / 12.0, Lp,
                              G=Ep / (2 * (1 + nup)))
    print("plate: Timoshenko (plane strain) period = %.5f s" % (1.0 / fT))
    for n in (3, 4, 5, 6, 7):
        print("Kirchhoff Ritz n=%d: %.6f" % (n, kirchhoff_clamped_square(0.3, n)))
    wk = kirchhoff_plate_deflection(1e7, 0.3, 0.05, 0.5, 1000.0)
    for n in (3, 4, 5, 6, 7):
        wm = mindlin_clamped_square(1e7, 0.3, 0.05, 0.5, 1000.0, n=n)
        print("Mindlin Ritz n=%d: %.6e m  (Kirchhoff 0.00126: %.6e, ratio %.4f)" % (
            n, wm, wk, wm / wk))
    ring = lame_ring(2.0e11, 0.3, 0.05, 0.1, 1.0e8)
    print("Lame ring: u(a) = %.5e m, u(0.075) = %.5e m, sigma_rr(a) = %.5e Pa, "
          "sigma_tt(a) = %.5e Pa" % (ring(0.05)[0], ring(0.075)[0], ring(0.05)[1],
                                     ring(0.05)[2]))
    for ps in (True, False):
        free = lame_free(2.0e11, 0.3, 0.05, 0.1, 1.0e8, plane_strain=ps)
        print("Lame free (%s): u(a) = %.6e m, sigma_rr(a) = %.6e Pa, sigma_tt(a) = %.6e Pa, "
              "sigma_tt(b) = %.6e Pa" % ("plane strain" if ps else "plane stress, open ends",
                                         free(0.05)[0], free(0.05)[1], free(0.05)[2],
                                         free(0.1)[2]))
