#!/usr/bin/env python3
"""Computer-algebra proof of the general (real-Earth) model (docs/derivation.md, part II).

The construction of shared/EARTH-MODEL.md (frames L and B from the inertial state and the
attitude, a pixel's ray, its first intersection with the ground ellipsoid, the Earth's
rotation, the pinhole projection, one time derivative) is built literally with a symbolic
time t, differentiated by sympy, and compared with the general form that
core-math/src/earth/general.rs evaluates:

  (1) v1 = g1 + (p1/f) g3, v2 = g2 + (p2/f) g3,  g = c'(0)/s;
  (2) g = -W x u - V/s,  W = w_B - omega M^T z,  V = M^T (v - omega z x r);
  (3) the orbital frame L turns, in L, at (0, nu, 0), nu = |h|/|r|^2, for any central force;
  (4) A^T A' = [w_A]x for A = Rx(roll) Ry(pitch) Rz(yaw), and w_B = A^T (0, nu, 0) + w_A;
  (5) n, V_L, W_L in L and W_B = A^T W_L + w_A, V_B = A^T V_L;
  (6) the ray/ellipsoid quadratic alpha s^2 + 2 beta s + C = 0 and its near root;
  (7) the reduction to the round-Earth closed form already proven by derive.py.

"Exactly" means as in derive.py: sin x, cos x become symbols S_x, C_x; the square roots
|r| and |r x v| become symbols rn, hn; the numerator of the difference of the two sides is
reduced modulo {S_x^2 + C_x^2 - 1, rn^2 - |r|^2, hn^2 - |r x v|^2} (pairwise coprime leading
monomials: a Groebner basis), and remainder 0 proves the identity. On top of the symbolic
proofs, the literal construction (dual numbers in mpmath: the textbook root of the
quadratic, the two-body acceleration with GM, no formula of the general form) is compared
with the general form at random geometries with 60-digit arithmetic, and 50-digit values of
one general case are printed for the Rust tests.

Called by derive.py (one command runs everything); also runs on its own:
    python3 tools/derivation/general.py
"""

import math
import random
import sys
import time

import mpmath as mp
import sympy as sp

sin, cos = sp.sin, sp.cos


# --------------------------------------------------------------------------------------
# Exact zero test: trig symbols and square-root symbols, reduced by their squares.
# --------------------------------------------------------------------------------------

def _reduce_squares(num, rels):
    """Normal form of the polynomial num modulo {g^2 - P(g)}: every g^(2k+e) -> P^k g^e.

    The leading monomials g^2 (lex order with the g first, P free of the g's that come
    before it) are pairwise coprime, so the relations are a Groebner basis and this
    remainder is the unique normal form: zero iff num lies in the ideal."""
    for g, P in rels:
        if not num.has(g):
            continue
        poly = sp.Poly(num, g)
        num = sp.expand(sum(cf * P**(e // 2) * g**(e % 2) for (e,), cf in poly.terms()))
        if num == 0:
            return num
    return num


def zero_mod(expr, angles=(), roots=()):
    """True iff expr == 0 identically, given sin^2 + cos^2 = 1 for each angle and
    sym^2 = P for each (sym, P) in roots (sym standing for sqrt(P))."""
    reps, rels = {}, []
    for x in dict.fromkeys(angles):
        s, c = sp.Symbol(f"S_{x}"), sp.Symbol(f"C_{x}")
        reps[sin(x)] = s
        reps[cos(x)] = c
        rels.append((s, 1 - c**2))
    e = sp.expand_trig(sp.sympify(expr)).xreplace(reps)
    if e.has(sp.sin, sp.cos, sp.tan):
        raise RuntimeError(f"trig functions left: {e.atoms(sp.sin, sp.cos)}")
    num = sp.expand(sp.numer(sp.together(e)))
    if num == 0:
        return True
    # Square-root symbols first (their P hold no trig symbol), then the trig ones.
    return _reduce_squares(num, list(roots) + rels) == 0


def vec_zero(v, angles=(), roots=()):
    return all(zero_mod(x, angles, roots) for x in v)


def cross(a, b):
    return sp.Matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def skew(w):
    return sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def Rx(x):
    return sp.Matrix([[1, 0, 0], [0, cos(x), -sin(x)], [0, sin(x), cos(x)]])


def Ry(x):
    return sp.Matrix([[cos(x), 0, sin(x)], [0, 1, 0], [-sin(x), 0, cos(x)]])


def Rz(x):
    return sp.Matrix([[cos(x), -sin(x), 0], [sin(x), cos(x), 0], [0, 0, 1]])


# --------------------------------------------------------------------------------------
# Symbols.
# --------------------------------------------------------------------------------------
t = sp.Symbol("t", real=True)
x, y, z, vx, vy, vz = sp.symbols("x y z v_x v_y v_z", real=True)
lam = sp.Symbol("lambda", real=True)          # central acceleration a = lambda r (two-body: -GM/|r|^3)
rn, hn = sp.symbols("rn hn", positive=True)   # |r|, |r x v|
om = sp.Symbol("omega", real=True)            # Earth rate
ph, th, ps = sp.symbols("phi theta psi", real=True)        # roll, pitch, yaw
dph, dth, dps = sp.symbols("phidot thetadot psidot", real=True)
p1, p2 = sp.symbols("p1 p2", real=True)
f, s = sp.symbols("f s", positive=True)
EA, EB = sp.symbols("A_e B_e", positive=True)  # ground semi-axes A (equatorial), B (polar)

r0 = sp.Matrix([x, y, z])
v0 = sp.Matrix([vx, vy, vz])
zhat = sp.Matrix([0, 0, 1])
u = sp.Matrix([p1, p2, -f])
RR = x**2 + y**2 + z**2
h0 = cross(r0, v0)
HH = sp.expand(h0.dot(h0))
ROOTS = [(rn, RR), (hn, HH)]
ATT = [ph, th, ps]
b1, b2, b3 = sp.symbols("b1 b2 b3", real=True)   # angles of a generic rotation
BQ = [b1, b2, b3]


def _norms_to_symbols(e):
    """sqrt(|r|^2)^k -> rn^k and sqrt(|h|^2)^k -> hn^k (k odd) after t = 0."""
    def is_norm_pow(a):
        return a.is_Pow and a.exp.is_Rational and a.exp.q == 2 and (
            sp.expand(a.base - RR) == 0 or sp.expand(a.base - HH) == 0)

    def to_sym(a):
        sym = rn if sp.expand(a.base - RR) == 0 else hn
        return sym**(2 * a.exp)
    return e.replace(is_norm_pow, to_sym)


def run(check, info, full=False):
    T0 = time.time()

    # ----------------------------------------------------------------------------------
    print("== (G1) the projection: v = g1,2 + (p1,2/f) g3 with g = c'(0)/s  [claim 1]")
    cf = [sp.Function(f"c{i}")(t) for i in (1, 2, 3)]
    P1 = -f * cf[0] / cf[2]
    P2 = -f * cf[1] / cf[2]
    at0 = {cf[0]: s * p1, cf[1]: s * p2, cf[2]: -s * f}
    dc = sp.symbols("dc1 dc2 dc3")
    dsub = {sp.Derivative(cf[i], t): dc[i] for i in range(3)}

    def d0(e):
        return sp.diff(e, t).subs(dsub).subs(at0)
    g = [d / s for d in dc]
    check("P(0) = (p1, p2) when c(0) = s u, u = (p1, p2, -f)",
          sp.simplify(P1.subs(at0) - p1) == 0 and sp.simplify(P2.subs(at0) - p2) == 0)
    check("dP1/dt(0) = g1 + (p1/f) g3", zero_mod(d0(P1) - (g[0] + p1 / f * g[2])))
    check("dP2/dt(0) = g2 + (p2/f) g3", zero_mod(d0(P2) - (g[1] + p2 / f * g[2])))

    # ----------------------------------------------------------------------------------
    print("== (G2) the orbital frame L: literal r(t), v(t), normalisations  [claim 3]")
    t1 = time.time()
    rt = r0 + v0 * t
    vt = v0 + lam * r0 * t                      # any central force: v' = lambda r
    ht = cross(rt, vt)
    zL = rt / sp.sqrt(rt.dot(rt))
    yL = ht / sp.sqrt(ht.dot(ht))
    xL = cross(yL, zL)
    Et = sp.Matrix.hstack(xL, yL, zL)           # columns: L's axes in I
    E0 = _norms_to_symbols(Et.subs(t, 0))
    E1 = _norms_to_symbols(sp.diff(Et, t).subs(t, 0))
    nu = hn / rn**2
    check("E(0) is orthonormal (E^T E = I)", vec_zero(E0.T * E0 - sp.eye(3), roots=ROOTS))
    check("E(0) is right-handed (det E = 1)", zero_mod(E0.det() - 1, roots=ROOTS))
    check("(r x v)' = r x a = 0 for any central force, so y_L'(0) = 0",
          vec_zero(sp.diff(ht, t).subs(t, 0)) and vec_zero(E1[:, 1], roots=ROOTS))
    check("E^T E'(0) = [(0, nu, 0)]x, nu = |r x v| / |r|^2 (no lambda, i.e. no GM)",
          vec_zero(E0.T * E1 - skew([0, nu, 0]), roots=ROOTS))
    check("E'(0) does not depend on lambda", not E1.has(lam))
    info(f"(G2) took {time.time() - t1:.1f} s")

    # ----------------------------------------------------------------------------------
    print("== (G3) the attitude: A = Rx(roll) Ry(pitch) Rz(yaw), angles moving at their rates  [claim 4]")
    t1 = time.time()
    At = Rx(ph + dph * t) * Ry(th + dth * t) * Rz(ps + dps * t)
    A0 = At.subs(t, 0)
    A1 = sp.diff(At, t).subs(t, 0)
    cph, sph, cth, sth, cps, sps = cos(ph), sin(ph), cos(th), sin(th), cos(ps), sin(ps)
    wA = (dph * sp.Matrix([cps * cth, -sps * cth, sth]) + dth * sp.Matrix([sps, cps, 0])
          + dps * sp.Matrix([0, 0, 1]))
    # The columns of A exactly as general.rs writes them.
    cols_rs = sp.Matrix([[cth * cps, cph * sps + sph * sth * cps, sph * sps - cph * sth * cps],
                         [-cth * sps, cph * cps - sph * sth * sps, sph * cps + cph * sth * sps],
                         [sth, -sph * cth, cph * cth]]).T
    check("general.rs's columns of A = Rx(roll) Ry(pitch) Rz(yaw)", vec_zero(cols_rs - A0, ATT))
    check("A^T A'(0) = [w_A]x, w_A = roll'(c_psi c_theta, -s_psi c_theta, s_theta) + "
          "pitch'(s_psi, c_psi, 0) + yaw'(0, 0, 1)", vec_zero(A0.T * A1 - skew(wA), ATT))
    wv = sp.Matrix(sp.symbols("w1 w2 w3", real=True))
    check("A^T [w]x A = [A^T w]x (so M^T M' = [A^T w_L + w_A]x with M = E A)",
          vec_zero(A0.T * skew(wv) * A0 - skew(A0.T * wv), ATT))
    check("A is a rotation: A^T A = I", vec_zero(A0.T * A0 - sp.eye(3), ATT))
    M0 = E0 * A0
    M1 = E1 * A0 + E0 * A1                      # product rule
    wB = A0.T * sp.Matrix([0, nu, 0]) + wA
    if full:
        check("M^T M'(0) = [w_B]x, w_B = A^T (0, nu, 0) + w_A  (literal E(t) of (G2), M = E A)",
              vec_zero(M0.T * M1 - skew(wB), ATT, ROOTS))
    else:
        # M^T M' = A^T (E^T E') A + A^T (E^T E) A' by the product rule; E^T E = I and
        # E^T E' = [(0, nu, 0)]x by (G2):
        check("M^T M'(0) = A^T [(0, nu, 0)]x A + A^T A' = [w_B]x, w_B = A^T (0, nu, 0) + w_A  (M = E A)",
              vec_zero(A0.T * skew([0, nu, 0]) * A0 + A0.T * A1 - skew(wB), ATT))
    info(f"(G3) took {time.time() - t1:.1f} s")

    # ----------------------------------------------------------------------------------
    print("== (G4) the per-update quantities in L, as general.rs forms them  [claim 5]")
    t1 = time.time()
    n_L = E0.T * zhat
    hx, hy, hz = h0
    n_rs = sp.Matrix([(hx * y - hy * x) / (hn * rn), hz / hn, z / rn])   # general.rs's n_l
    check("n = E^T z = (x_L.z, y_L.z, z_L.z) = ((h x r)_z/(|h||r|), h_z/|h|, r_z/|r|)",
          vec_zero(n_L - n_rs, roots=ROOTS))
    check("E^T v = (|h|/|r|, 0, r.v/|r|)",
          vec_zero(E0.T * v0 - sp.Matrix([hn / rn, 0, r0.dot(v0) / rn]), roots=ROOTS))
    check("E^T r = (0, 0, |r|)", vec_zero(E0.T * r0 - sp.Matrix([0, 0, rn]), roots=ROOTS))
    V_L = sp.Matrix([hn / rn - om * rn * n_rs[1], om * rn * n_rs[0], r0.dot(v0) / rn])
    check("V_L = E^T (v - omega z x r) = (|h|/|r| - omega |r| n2, omega |r| n1, r.v/|r|)",
          vec_zero(E0.T * (v0 - om * cross(zhat, r0)) - V_L, roots=ROOTS))
    W_L = sp.Matrix([0, nu, 0]) - om * n_rs
    W_B = A0.T * W_L + wA
    V_B = A0.T * V_L
    check("W_B = A^T W_L + w_A equals w_B - omega M^T z  (W_L = (0, nu, 0) - omega n)",
          vec_zero(W_B - (wB - om * M0.T * zhat), ATT, ROOTS))
    check("V_B = A^T V_L equals M^T (v - omega z x r)",
          vec_zero(V_B - M0.T * (v0 - om * cross(zhat, r0)), ATT, ROOTS))
    info(f"(G4) took {time.time() - t1:.1f} s")

    # ----------------------------------------------------------------------------------
    print("== (G5) the camera coordinates: c'(0) = -s (W x u) - V  [claim 2]")
    t1 = time.time()
    claim = -s * cross(W_B, u) - V_B
    # Lemma: for any M(t) with M(0) = Q a rotation (three fresh angles) and M'(0) = Q [w]x,
    # r(t) = r + v t, the ground point G = r + s Q u at distance s along the ray (any s: the
    # intersection only fixes s) carried by the Earth's rotation Rz(omega t):
    wq = sp.Matrix(sp.symbols("wq1 wq2 wq3", real=True))
    Qm = Rx(b1) * Ry(b2) * Rz(b3)
    Gq = r0 + s * (Qm * u)
    cq = ((Qm + t * Qm * skew(wq)).T * (Rz(om * t) * Gq - rt))
    check("c(0) = s u (the ground point is on the pixel's ray)", vec_zero(cq.subs(t, 0) - s * u, BQ))
    check("c'(0) = -s ((w - omega Q^T z) x u) - Q^T (v - omega z x r) for any rotation Q = M(0), "
          "M^T M' = [w]x",
          vec_zero(sp.diff(cq, t).subs(t, 0) + s * cross(wq - om * Qm.T * zhat, u)
                   + Qm.T * (v0 - om * cross(zhat, r0)), BQ))
    info("with w = w_B of (G3) and (G4), -s (w_B - omega M^T z) x u - M^T (v - omega z x r) = -s (W_B x u) - V_B")
    if full:
        # The literal camera coordinates c(t); E(t) enters through E(0) and E'(0) of (G2),
        # the only things d/dt at t = 0 can see.
        Mt = (E0 + E1 * t) * At
        Gp = r0 + s * (M0 * u)
        ct = Mt.T * (Rz(om * t) * Gp - rt)
        c_dot = sp.diff(ct, t).subs(t, 0)
        check("literal: c(0) = s u", vec_zero(ct.subs(t, 0) - s * u, ATT, ROOTS))
        check("literal: c'(0) = -s (W_B x u) - V_B, W_B, V_B of (G4), for every attitude, rate, "
              "state and pixel", vec_zero(c_dot - claim, ATT, ROOTS))
    info(f"(G5) took {time.time() - t1:.1f} s")

    # ----------------------------------------------------------------------------------
    print("== (G6) the ray/ellipsoid quadratic and its near root  [claim 6]")
    t1 = time.time()
    kap2m1 = (EA - EB) * (EA + EB) / EB**2
    n_B = A0.T * n_rs
    alpha_q = u.dot(u) + kap2m1 * n_B.dot(u)**2
    rho_B = A0.T * (sp.Matrix([0, 0, rn]) + kap2m1 * z * n_rs)
    beta_q = rho_B.dot(u)
    C_q = ((x**2 + y**2) * EB**2 + z**2 * EA**2 - EA**2 * EB**2) / EB**2
    Xg = r0 + s * (M0 * u)
    ell = (Xg[0]**2 + Xg[1]**2) / EA**2 + Xg[2]**2 / EB**2 - 1
    check("kappa^2 - 1 = (A - B)(A + B)/B^2 with kappa = A/B", zero_mod((EA / EB)**2 - 1 - kap2m1))
    check("C = |K r|^2 - A^2 = ((x^2 + y^2) B^2 + z^2 A^2 - A^2 B^2)/B^2",
          zero_mod(x**2 + y**2 + (EA / EB)**2 * z**2 - EA**2 - C_q))
    # Fast route: the pixel's ray in L, ub = A u (any vector; |ub| = |u|, n.ub = n_B.u and
    # rho_L.ub = rho_B.u because A is a rotation, checked in (G3)).
    ub = sp.Matrix(sp.symbols("ub1 ub2 ub3", real=True))
    rho_L = sp.Matrix([0, 0, rn]) + kap2m1 * z * n_rs
    XL = r0 + s * (E0 * ub)
    ellL = (XL[0]**2 + XL[1]**2) / EA**2 + XL[2]**2 / EB**2 - 1
    check("alpha s^2 + 2 beta s + C = A^2 [ (X^2 + Y^2)/A^2 + Z^2/B^2 - 1 ] at X = r + s E (A u), with "
          "alpha = |u|^2 + (kappa^2 - 1)(n.Au)^2, beta = rho_L.Au",
          zero_mod((ub.dot(ub) + kap2m1 * n_rs.dot(ub)**2) * s**2 + 2 * rho_L.dot(ub) * s + C_q
                   - EA**2 * ellL, roots=ROOTS))
    check("n_B . u = n . (A u) and rho_B . u = rho_L . (A u)",
          vec_zero([n_B.dot(u) - n_rs.dot(A0 * u), beta_q - rho_L.dot(A0 * u)], ATT))
    if full:
        check("literal: alpha s^2 + 2 beta s + C = A^2 [ (X^2 + Y^2)/A^2 + Z^2/B^2 - 1 ] at X = r + s M u",
              zero_mod(alpha_q * s**2 + 2 * beta_q * s + C_q - EA**2 * ell, ATT, ROOTS))
    al_, be_, C_, sq_ = sp.symbols("alpha_q beta_q C_q sqrtdisc", real=True)
    s_near = (-be_ - sq_) / al_
    inv_s = (sq_ - be_) / C_
    rts = [(sq_, be_**2 - al_ * C_)]
    check("the near root (-beta - sqrt(beta^2 - alpha C))/alpha solves the quadratic",
          zero_mod(al_ * s_near**2 + 2 * be_ * s_near + C_, roots=rts))
    check("1/s_near = (sqrt(beta^2 - alpha C) - beta)/C  (rationalised: no cancellation for beta < 0)",
          zero_mod(s_near * inv_s - 1, roots=rts))
    check("roots' product C/alpha and sum -2 beta/alpha: with C > 0, both ahead iff beta < 0",
          zero_mod(s_near * ((-be_ + sq_) / al_) - C_ / al_, roots=rts)
          and zero_mod(s_near + (-be_ + sq_) / al_ + 2 * be_ / al_, roots=rts))
    info(f"(G6) took {time.time() - t1:.1f} s")

    # ----------------------------------------------------------------------------------
    print("== (G7) reduction to the round-Earth closed form (derive.py (c))  [claim 7]")
    t1 = time.time()
    # Sphere of radius R (flattening 0, h = 0), circular orbit of radius k R at rate Omega,
    # inclination i0, argument of latitude g0 (node on +x, as earth::circular_state), roll
    # phi only; pixel p1 = 0, p2 = f tan(alpha). As in derive.py (c), k = sin(e)/sin(eta)
    # with e the incidence angle at the ground, so q = cos(e) needs no square root.
    R, Om = sp.symbols("R Omega", positive=True)
    i0, g0, al, e = sp.symbols("i0 gamma0 alpha e", real=True)
    eta = ph + al
    s_eta, c_eta = sp.expand_trig(sin(eta)), sp.expand_trig(cos(eta))
    k = sin(e) / s_eta
    c0 = k**2 - 1
    q = cos(e)
    den = k * c_eta + q
    zL_c = sp.Matrix([cos(g0), sin(g0) * cos(i0), sin(g0) * sin(i0)])
    xL_c = sp.Matrix([-sin(g0), cos(g0) * cos(i0), cos(g0) * sin(i0)])
    yL_c = sp.Matrix([0, -sin(i0), cos(i0)])
    ANG7 = [ph, al, e, i0, g0]
    r_c = k * R * zL_c
    v_c = Om * k * R * xL_c
    h_c = cross(r_c, v_c)
    check("circular state: |r| = k R, |r x v| = Omega k^2 R^2, r x v along (0, -sin i0, cos i0)",
          zero_mod(r_c.dot(r_c) - (k * R)**2, ANG7) and zero_mod(h_c.dot(h_c) - (Om * k**2 * R**2)**2, ANG7)
          and vec_zero(h_c - Om * k**2 * R**2 * yL_c, ANG7))
    sub_c = {x: r_c[0], y: r_c[1], z: r_c[2], vx: v_c[0], vy: v_c[1], vz: v_c[2],
             rn: k * R, hn: Om * k**2 * R**2, th: 0, ps: 0, dph: 0, dth: 0, dps: 0,
             p1: 0, p2: f * sin(al) / cos(al), EA: R, EB: R}
    nL_c = n_rs.subs(sub_c)
    check("n in L = (sin i0 cos g0, cos i0, sin i0 sin g0) = the paper's spin axis w",
          vec_zero(nL_c - sp.Matrix([sin(i0) * cos(g0), cos(i0), sin(i0) * sin(g0)]), ANG7))
    uc = u.subs(sub_c)
    alpha_c = alpha_q.subs(sub_c)
    beta_c = beta_q.subs(sub_c)
    C_c = C_q.subs(sub_c)
    sqrt_c = f * R * q / cos(al)       # sqrt(beta^2 - alpha C), positive for |e|, |alpha| < 90 deg
    check("sqrt(beta^2 - alpha C) = f R cos(e) / cos(alpha)",
          zero_mod(sqrt_c**2 - (beta_c**2 - alpha_c * C_c), ANG7))
    inv_s_c = (sqrt_c - beta_c) / C_c
    check("1/s = f den / (R c0 cos(alpha))", zero_mod(inv_s_c - f * den / (R * c0 * cos(al)), ANG7))
    gv = -cross(W_B.subs(sub_c), uc) - V_B.subs(sub_c) * inv_s_c
    v1_g = gv[0]
    v2_g = gv[1] + (uc[1] / f) * gv[2]
    a_ = om * sin(i0) * cos(g0)
    b_ = om * cos(i0) - Om
    c_ = om * sin(i0) * sin(g0)
    v1_cf = f / cos(al) * ((b_ / c0) * (q * c_eta + k * s_eta**2) * den - c_ * s_eta)
    v2_cf = -(f / cos(al)**2) * (a_ / c0) * q * den
    check("v1 (general form, reduced) = (f/cos a)[(b/c0) cos(theta) den - c sin(eta)]",
          zero_mod(v1_g - v1_cf, ANG7))
    check("v2 (general form, reduced) = -(f/cos^2 a)(a/c0) q den",
          zero_mod(v2_g - v2_cf, ANG7))
    info(f"(G7) took {time.time() - t1:.1f} s")
    info(f"symbolic part of the general model took {time.time() - T0:.1f} s")


# --------------------------------------------------------------------------------------
# High precision: the literal construction on dual numbers vs the general form.
# --------------------------------------------------------------------------------------

class Dual:
    """a + b e, e^2 = 0 (mpmath parts): the value and the exact derivative in t."""
    __slots__ = ("a", "b")

    def __init__(self, a, b=0):
        self.a, self.b = mp.mpf(a), mp.mpf(b)

    @staticmethod
    def lift(o):
        return o if isinstance(o, Dual) else Dual(o)

    def __add__(self, o):
        o = Dual.lift(o)
        return Dual(self.a + o.a, self.b + o.b)
    __radd__ = __add__

    def __sub__(self, o):
        o = Dual.lift(o)
        return Dual(self.a - o.a, self.b - o.b)

    def __rsub__(self, o):
        return Dual.lift(o) - self

    def __neg__(self):
        return Dual(-self.a, -self.b)

    def __mul__(self, o):
        o = Dual.lift(o)
        return Dual(self.a * o.a, self.a * o.b + self.b * o.a)
    __rmul__ = __mul__

    def __truediv__(self, o):
        o = Dual.lift(o)
        return Dual(self.a / o.a, (self.b * o.a - self.a * o.b) / o.a**2)

    def __rtruediv__(self, o):
        return Dual.lift(o) / self


def d_sqrt(x):
    r = mp.sqrt(x.a)
    return Dual(r, x.b / (2 * r))


def d_sin(x):
    return Dual(mp.sin(x.a), mp.cos(x.a) * x.b)


def d_cos(x):
    return Dual(mp.cos(x.a), -mp.sin(x.a) * x.b)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _matmul(A, B):
    return [[sum((A[i][k] * B[k][j] for k in range(3)), Dual(0)) for j in range(3)] for i in range(3)]


def _rot(axis, ang):
    sn, cs, o, z0 = d_sin(ang), d_cos(ang), Dual(1), Dual(0)
    if axis == 0:
        return [[o, z0, z0], [z0, cs, -sn], [z0, sn, cs]]
    if axis == 1:
        return [[cs, z0, sn], [z0, o, z0], [-sn, z0, cs]]
    return [[cs, -sn, z0], [sn, cs, z0], [z0, z0, o]]


GM = mp.mpf("3.986004418e14")


def literal(c):
    """EARTH-MODEL.md's construction, literally: (v1, v2), P(0), slant range s |d|.

    r(t) = r + v t, v(t) = v + a t with the two-body a = -GM r/|r|^3; L(t) by normalising
    r and r x v; A(t) = Rx Ry Rz of the moving angles; the first intersection of
    r + s M(0) u with the ground ellipsoid by the textbook root; G(t) = Rz(omega t) G;
    c(t) = M(t)^T (G(t) - r(t)); P = -f (c1, c2)/c3; d/dt by the dual parts."""
    T = Dual(0, 1)
    rr, vv = c["r"], c["v"]
    rn0 = mp.sqrt(_dot(rr, rr))
    acc = [-GM * q / rn0**3 for q in rr]
    r = [Dual(rr[i]) + vv[i] * T for i in range(3)]
    v = [Dual(vv[i]) + acc[i] * T for i in range(3)]

    def unit(a):
        nrm = d_sqrt(_dot(a, a))
        return [q / nrm for q in a]
    zL = unit(r)
    yL = unit(_cross(r, v))
    xL = _cross(yL, zL)
    E = [[xL[i], yL[i], zL[i]] for i in range(3)]
    ang = [Dual(c["att"][i]) + c["rate"][i] * T for i in range(3)]
    A = _matmul(_matmul(_rot(0, ang[0]), _rot(1, ang[1])), _rot(2, ang[2]))
    M = _matmul(E, A)
    u = [c["p1"], c["p2"], -c["f"]]
    d = [sum(M[i][j].a * u[j] for j in range(3)) for i in range(3)]
    Ae = c["a"] + c["h"]
    Be = c["a"] * (1 - c["fl"]) + c["h"]
    qa = (d[0]**2 + d[1]**2) / Ae**2 + d[2]**2 / Be**2
    qb = 2 * ((rr[0] * d[0] + rr[1] * d[1]) / Ae**2 + rr[2] * d[2] / Be**2)
    qc = (rr[0]**2 + rr[1]**2) / Ae**2 + rr[2]**2 / Be**2 - 1
    disc = qb**2 - 4 * qa * qc
    if not (qc > 0 and disc >= 0 and qb < 0):
        return None
    sr = (-qb - mp.sqrt(disc)) / (2 * qa)
    G = [rr[i] + sr * d[i] for i in range(3)]
    wt = c["omega"] * T
    Gt = [d_cos(wt) * G[0] - d_sin(wt) * G[1], d_sin(wt) * G[0] + d_cos(wt) * G[1], Dual(G[2])]
    rel = [Gt[i] - r[i] for i in range(3)]
    cam = [sum((M[i][j] * rel[i] for i in range(3)), Dual(0)) for j in range(3)]
    P1 = -c["f"] * cam[0] / cam[2]
    P2 = -c["f"] * cam[1] / cam[2]
    return P1.b, P2.b, (P1.a, P2.a), sr * mp.sqrt(_dot(d, d))


def general_form(c):
    """core-math/src/earth/general.rs, step by step, in mpmath."""
    rr, vv, w = c["r"], c["v"], c["omega"]
    rn_ = mp.sqrt(_dot(rr, rr))
    h = _cross(rr, vv)
    hn_ = mp.sqrt(_dot(h, h))
    inv_hr = 1 / (hn_ * rn_)
    n_l = [(h[0] * rr[1] - h[1] * rr[0]) * inv_hr, h[2] * rn_ * inv_hr, rr[2] * hn_ * inv_hr]
    inv_r = hn_ * inv_hr
    v_fwd = hn_ * inv_r
    nu_ = v_fwd * inv_r
    rdot = _dot(rr, vv) * inv_r
    wr = w * rn_
    v_l = [v_fwd - wr * n_l[1], wr * n_l[0], rdot]
    w_l = [-w * n_l[0], nu_ - w * n_l[1], -w * n_l[2]]
    Ae = c["a"] + c["h"]
    Be = c["a"] * (1 - c["fl"]) + c["h"]
    k2m1 = c["a"] * c["fl"] * (Ae + Be) / Be**2
    rho_l = [k2m1 * rr[2] * n_l[0], k2m1 * rr[2] * n_l[1], rn_ + k2m1 * rr[2] * n_l[2]]
    sp_, cp_ = mp.sin(c["att"][0]), mp.cos(c["att"][0])
    st_, ct_ = mp.sin(c["att"][1]), mp.cos(c["att"][1])
    sy_, cy_ = mp.sin(c["att"][2]), mp.cos(c["att"][2])
    cols = [[ct_ * cy_, cp_ * sy_ + sp_ * st_ * cy_, sp_ * sy_ - cp_ * st_ * cy_],
            [-ct_ * sy_, cp_ * cy_ - sp_ * st_ * sy_, sp_ * cy_ + cp_ * st_ * sy_],
            [st_, -sp_ * ct_, cp_ * ct_]]
    dr, dp, dy = c["rate"]
    w_a = [dr * cy_ * ct_ + dp * sy_, -dr * sy_ * ct_ + dp * cy_, dr * st_ + dy]

    def at(xv):
        return [_dot(cols[0], xv), _dot(cols[1], xv), _dot(cols[2], xv)]
    w_b = [a + b for a, b in zip(at(w_l), w_a)]
    v_b = at(v_l)
    n_b = at(n_l)
    rho_b = at(rho_l)
    C = ((rr[0]**2 + rr[1]**2) * Be**2 + rr[2]**2 * Ae**2 - Ae**2 * Be**2) / Be**2
    u = [c["p1"], c["p2"], -c["f"]]
    nu_u = _dot(n_b, u)
    beta = _dot(rho_b, u)
    alpha = _dot(u, u) + k2m1 * nu_u**2
    disc = beta**2 - alpha * C
    if not (beta < 0 and disc >= 0):
        return None
    inv_s = (mp.sqrt(disc) - beta) / C
    g = [-(w_b[1] * u[2] - w_b[2] * u[1]) - v_b[0] * inv_s,
         -(w_b[2] * u[0] - w_b[0] * u[2]) - v_b[1] * inv_s,
         -(w_b[0] * u[1] - w_b[1] * u[0]) - v_b[2] * inv_s]
    return g[0] + c["p1"] / c["f"] * g[2], g[1] + c["p2"] / c["f"] * g[2]


def random_case(rng):
    a = mp.mpf(rng.uniform(6.0e6, 6.5e6))
    fl = mp.mpf(rng.choice([0, rng.uniform(0, 0.01), rng.uniform(0, 0.3)]))
    h = mp.mpf(rng.uniform(-500, 9000))
    # Position: any direction, 150 km to 3 radii above the ground.
    dirv = [rng.gauss(0, 1) for _ in range(3)]
    nd = math.sqrt(sum(q * q for q in dirv))
    rmag = float(a) * (1 + 10 ** rng.uniform(math.log10(0.025), math.log10(3)))
    r = [mp.mpf(rmag * q / nd) for q in dirv]
    # Velocity: circular speed times 0.8 .. 1.2 along a random tangent, plus a radial part.
    tv = [rng.gauss(0, 1) for _ in range(3)]
    dotp = sum(tv[i] * dirv[i] for i in range(3)) / nd
    tv = [tv[i] - dotp * dirv[i] / nd for i in range(3)]
    nt = math.sqrt(sum(q * q for q in tv))
    vc = math.sqrt(3.986004418e14 / rmag) * rng.uniform(0.8, 1.2)
    vr = vc * rng.uniform(-0.1, 0.1)
    v = [mp.mpf(vc * tv[i] / nt + vr * dirv[i] / nd) for i in range(3)]
    att = [mp.radians(rng.uniform(-45, 45)), mp.radians(rng.uniform(-30, 30)), mp.radians(rng.uniform(-180, 180))]
    rate = [mp.radians(rng.uniform(-2, 2)) for _ in range(3)]
    fm = mp.mpf(rng.uniform(0.1, 3))
    return dict(r=r, v=v, att=att, rate=rate, a=a, fl=fl, h=h, f=fm,
                p1=fm * mp.mpf(rng.uniform(-0.2, 0.2)), p2=fm * mp.mpf(rng.uniform(-0.5, 0.5)),
                omega=mp.mpf(rng.uniform(-1e-3, 1e-3)))


def run_numeric(check, info):
    T0 = time.time()
    dps_saved = mp.mp.dps
    mp.mp.dps = 60
    print("== (G8) literal construction (dual numbers, textbook root, GM) = general form, 60 digits")
    rng = random.Random(20261124)
    n_ok, n_miss, worst, worst_p = 0, 0, mp.mpf(0), mp.mpf(0)
    while n_ok < 300:
        c = random_case(rng)
        lit = literal(c)
        gen = general_form(c)
        if lit is None or gen is None:
            n_miss += 1
            if (lit is None) != (gen is None):
                worst = mp.inf
            continue
        scale = abs(lit[0]) + abs(lit[1])
        worst = max(worst, abs(lit[0] - gen[0]) / scale, abs(lit[1] - gen[1]) / scale)
        worst_p = max(worst_p, abs(lit[2][0] - c["p1"]) / c["f"], abs(lit[2][1] - c["p2"]) / c["f"])
        n_ok += 1
    check(f"literal = general form at {n_ok} random geometries (eccentric orbits, any attitude and rates, "
          f"flattening up to 0.3, terrain, p1 != 0)", worst < mp.mpf("1e-45"),
          f"max |diff| / (|v1|+|v2|) = {mp.nstr(worst, 3)}")
    check(f"both agree on which of {n_miss} further rays miss the ground", worst != mp.inf)
    check("the literal ground point projects on its pixel: P(0) = (p1, p2)", worst_p < mp.mpf("1e-45"),
          f"max |P(0) - p| / f = {mp.nstr(worst_p, 3)}")
    c = random_case(random.Random(7))
    v_a = literal(c)
    GM_saved = globals()["GM"]
    globals()["GM"] = GM_saved * 3
    v_b = literal(c)
    globals()["GM"] = GM_saved
    check("the literal construction does not depend on GM (tried GM and 3 GM)",
          abs(v_a[0] - v_b[0]) + abs(v_a[1] - v_b[1]) < mp.mpf("1e-50") * (abs(v_a[0]) + abs(v_a[1])))
    info(f"(G8) took {time.time() - T0:.1f} s")
    mp.mp.dps = dps_saved


# The general test case for the Rust tests (every input exact in binary64 except the
# decimal ones noted in docs/derivation.md).
CASE_INPUTS = dict(
    x_m=-2100000, y_m=4800000, z_m=4600000, vx_mps=3198, vy_mps=-3995, vz_mps=5689,
    roll_deg="20.5", pitch_deg="-7.25", yaw_deg="3.5",
    roll_rate_dps="0.05", pitch_rate_dps="-0.025", yaw_rate_dps="0.0125",
    ground_h_m=1500, f_m="0.75", pixel_m="0.0000152587890625", n_px=12000,
    p1_m="0.001953125", a_m=6378137, flattening="1/298.257223563", earth_rate_rad_s="7.2921159e-5")


def case_from_inputs(ci, to_rad):
    def num(x):
        if isinstance(x, str) and "/" in x:
            a_, b_ = x.split("/")
            return mp.mpf(a_) / mp.mpf(b_)
        return mp.mpf(x)
    return dict(r=[num(ci["x_m"]), num(ci["y_m"]), num(ci["z_m"])],
                v=[num(ci["vx_mps"]), num(ci["vy_mps"]), num(ci["vz_mps"])],
                att=[to_rad(ci[k]) for k in ("roll_deg", "pitch_deg", "yaw_deg")],
                rate=[to_rad(ci[k]) for k in ("roll_rate_dps", "pitch_rate_dps", "yaw_rate_dps")],
                a=num(ci["a_m"]), fl=num(ci["flattening"]), h=num(ci["ground_h_m"]), f=num(ci["f_m"]),
                p1=num(ci["p1_m"]), p2=num(ci["n_px"]) * num(ci["pixel_m"]), omega=num(ci["earth_rate_rad_s"]))


def sinc(xv):
    return mp.mpf(1) if xv == 0 else mp.sin(mp.pi * xv) / (mp.pi * xv)


def circular_case(Rm, Hm, i0d, g0d, phid, fm, p2m, omega):
    """earth::circular_state + from_sphere: the paper's round Earth as a general case."""
    rad = Rm + Hm
    si, ci = mp.sin(mp.radians(i0d)), mp.cos(mp.radians(i0d))
    su, cu = mp.sin(mp.radians(g0d)), mp.cos(mp.radians(g0d))
    spd = mp.sqrt(GM / rad)
    return dict(r=[rad * cu, rad * su * ci, rad * su * si], v=[-spd * su, spd * cu * ci, spd * cu * si],
                att=[mp.radians(phid), 0, 0], rate=[0, 0, 0], a=Rm, fl=mp.mpf(0), h=mp.mpf(0), f=fm,
                p1=mp.mpf(0), p2=p2m, omega=omega)


def run_case(check, info):
    T0 = time.time()
    dps_saved = mp.mp.dps
    mp.mp.dps = 80
    print("== (G9) the general test case, 50 digits (literal construction; general form agrees)")
    ci = CASE_INPUTS
    info("inputs: " + ", ".join(f"{k}={v}" for k, v in ci.items()))
    c = case_from_inputs(ci, lambda d: mp.radians(mp.mpf(d)))
    lit = literal(c)
    gen = general_form(c)
    v1, v2 = lit[0], lit[1]
    Ae = c["a"] + c["h"]
    rr = c["r"]
    hv = _cross(rr, c["v"])
    ecc = _cross(c["v"], hv)
    ecc = [ecc[i] / GM - rr[i] / mp.sqrt(_dot(rr, rr)) for i in range(3)]
    info(f"|r| = {mp.nstr(mp.sqrt(_dot(rr, rr)), 12)} m, r.v/|r| = {mp.nstr(_dot(rr, c['v']) / mp.sqrt(_dot(rr, rr)), 8)} m/s, "
         f"eccentricity {mp.nstr(mp.sqrt(_dot(ecc, ecc)), 6)}, inclination "
         f"{mp.nstr(mp.degrees(mp.acos(hv[2] / mp.sqrt(_dot(hv, hv)))), 8)} deg; "
         f"slant range {mp.nstr(lit[3], 12)} m; field angle atan(p2/f) = {mp.nstr(mp.degrees(mp.atan(c['p2'] / c['f'])), 8)} deg")
    info(f"v1 = {mp.nstr(v1, 50)} m/s")
    info(f"v2 = {mp.nstr(v2, 50)} m/s")
    drift = mp.atan(v2 / v1)
    info(f"v_mps = {mp.nstr(mp.hypot(v1, v2), 20)}, line_period_s = pixel/|v1| = "
         f"{mp.nstr(mp.mpf(ci['pixel_m']) / abs(v1), 20)}, drift_rad = {mp.nstr(drift, 20)}")
    check("test case: general form = literal construction", abs(gen[0] - v1) + abs(gen[1] - v2)
          < mp.mpf("1e-70") * (abs(v1) + abs(v2)), f"difference {mp.nstr(abs(gen[0] - v1) + abs(gen[1] - v2), 3)} m/s")
    # The same with the angles rounded to binary64 radians as Rust's f64::to_radians does.
    cb = case_from_inputs(ci, lambda d: mp.mpf(float(d) * (math.pi / 180)))
    cb["p1"], cb["omega"], cb["fl"], cb["f"] = (mp.mpf(float(cb["p1"])), mp.mpf(float(cb["omega"])),
                                                mp.mpf(1.0 / 298.257223563), mp.mpf(float(cb["f"])))
    lb = literal(cb)
    info("with every input rounded to binary64 first (angles and rates as f64 deg.to_radians(), "
         "flattening = 1.0/298.257223563, earth rate 7.2921159e-5 as f64):")
    info(f"v1 = {mp.nstr(lb[0], 50)} m/s")
    info(f"v2 = {mp.nstr(lb[1], 50)} m/s")
    info(f"relative change from the decimal inputs: v1 {mp.nstr((lb[0] - v1) / v1, 3)}, v2 {mp.nstr((lb[1] - v2) / v2, 3)}")

    print("== (G10) line period from v1, drift and its MTF")
    pairs = []
    for name, cc, Mst in [("test case", c, (16, 48))]:
        pairs.append((name, v1, v2))
    Rm, Hm = mp.mpf(6370e3), mp.mpf(645e3)
    fm, Am = mp.mpf("0.555"), mp.mpf("13e-6")
    wr = mp.mpf("7.2921159e-5")
    worst = None
    for g0d in (0, 45, 90):
        for n in (-30000, 0, 30000):
            for phd in (0, 25):
                cc = circular_case(Rm, Hm, mp.mpf("97.98"), g0d, phd, fm, n * Am, wr)
                a1, a2 = general_form(cc)
                dr = abs(mp.atan(a2 / a1))
                if worst is None or dr > worst[0]:
                    worst = (dr, g0d, n, phd, a1, a2)
    dr, g0d, n, phd, a1, a2 = worst
    pairs.append((f"paper's camera, largest drift (g0 {g0d} deg, n {n}, phi {phd} deg)", a1, a2))
    cc = circular_case(Rm, Hm, mp.mpf("97.98"), 0, 0, fm, 0, wr)
    a1, a2 = general_form(cc)
    pairs.append(("paper's camera, nadir pixel, g0 0 deg, phi 0", a1, a2))
    info(f"{'case':<58} {'drift deg':>10} {'1/cos-1':>10} {'drift^2/2':>10} {'MTFd M16':>9} {'M48':>7} "
         f"{'MTFm M16':>9} {'M48':>9} {'prod M16':>9} {'M48':>7}")
    for name, q1, q2 in pairs:
        dft = mp.atan(q2 / q1)
        rel = 1 / mp.cos(dft) - 1
        row = []
        for Mst in (16, 48):
            dpx = Mst * abs(mp.tan(dft))
            mtf_d = abs(sinc(dpx / 2))
            mtf_m = abs(sinc(Mst * rel / 2))      # = sin(x)/x, x = pi M (dv/v)/2
            row.append((mtf_d, mtf_m, mtf_d * mtf_m))
        info(f"{name:<58} {mp.nstr(mp.degrees(dft), 5):>10} {mp.nstr(rel, 4):>10} {mp.nstr(dft**2 / 2, 4):>10} "
             f"{mp.nstr(row[0][0], 4):>9} {mp.nstr(row[1][0], 4):>7} {mp.nstr(row[0][1], 6):>9} "
             f"{mp.nstr(row[1][1], 6):>9} {mp.nstr(row[0][2], 4):>9} {mp.nstr(row[1][2], 4):>7}")
    info("MTFd = |sinc(M |tan drift| / 2)| (drift smear across the line); MTFm = |sinc(M (1/cos(drift) - 1) / 2)|,")
    info("the mismatch a line period of pixel/|v_P| (Eq. 16) would add; prod = MTFd * MTFm; sinc(x) = sin(pi x)/(pi x)")
    x95 = mp.findroot(lambda xv: sinc(xv) - mp.mpf("0.95"), mp.mpf("0.14"))
    for Mst in (16, 48):
        info(f"M = {Mst}: MTFd >= 0.95 needs M |tan drift| <= {mp.nstr(2 * x95, 4)} px, |drift| <= "
             f"{mp.nstr(mp.degrees(mp.atan(2 * x95 / Mst)), 4)} deg; MTFd = 0 at 2 px, drift "
             f"{mp.nstr(mp.degrees(mp.atan(mp.mpf(2) / Mst)), 4)} deg")
    # Yaw steering: the yaw that makes v2 = 0 at the nadir pixel of the paper's camera.
    base = circular_case(Rm, Hm, mp.mpf("97.98"), 0, 0, fm, 0, wr)

    def v2_of_yaw(yw):
        cy = dict(base)
        cy["att"] = [0, 0, yw]
        return general_form(cy)[1]
    y0 = mp.findroot(v2_of_yaw, mp.atan(a2 / a1))
    cy = dict(base)
    cy["att"] = [0, 0, y0]
    s1, s2 = general_form(cy)
    info(f"yaw steering, paper's camera, nadir pixel, g0 0: yaw {mp.nstr(mp.degrees(y0), 8)} deg makes v2 = "
         f"{mp.nstr(s2, 3)}; then |v1| = {mp.nstr(abs(s1), 12)} m/s against the unsteered |v_P| = "
         f"{mp.nstr(mp.hypot(a1, a2), 12)} and |v1| = {mp.nstr(abs(a1), 12)}")
    check("yaw steering at the nadir pixel: yaw = drift gives v2 = 0 and |v1| = the unsteered |v_P|",
          abs(abs(s1) - mp.hypot(a1, a2)) < mp.mpf("1e-40") * abs(s1)
          and abs(y0 - mp.atan(a2 / a1)) < mp.mpf("1e-40"), f"yaw - drift = {mp.nstr(y0 - mp.atan(a2 / a1), 3)} rad")
    info(f"(G9, G10) took {time.time() - T0:.1f} s")
    mp.mp.dps = dps_saved


def run_bus(check, info):
    """(G11) Part II of the contract: the bus's quaternion and the DEM's ground."""
    T0 = time.time()
    print("== (G11) Part II: the quaternion's matrix, the DEM's ground point, the raised ellipsoid")
    # The matrix core-math's quaternion_matrix writes (scalar first, Hamilton) against the
    # rotation q v q* by Hamilton products, for any unit quaternion.
    w, x, y, z = sp.symbols("qw qx qy qz", real=True)
    v = sp.symbols("v0:3", real=True)

    def hmul(p, q):
        return (p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
                p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
                p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
                p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0])
    qv = hmul(hmul((w, x, y, z), (0, *v)), (w, -x, -y, -z))
    R = sp.Matrix([[1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                   [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
                   [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)]])
    unit = w**2 + x**2 + y**2 + z**2 - 1
    diff = [sp.expand(qv[1 + i] - (R * sp.Matrix(v))[i]) for i in range(3)]
    ok = all(sp.reduced(d, [unit], w, x, y, z, *v)[1] == 0 for d in diff) and sp.expand(qv[0]) == 0
    check("R(q) of quaternion_matrix = the rotation v -> q v q* (Hamilton products), for |q| = 1", ok)
    info("the DEM's ground point: (G5) proves c'(0) = -s W x u - V for any range s, so a ground point "
         "found on a DEM (any Earth-fixed point of the ray) gives g = -W x u - V/s unchanged")
    # A point of the ellipsoid raised by H (semi-axes a + H, b + H) against the geodetic
    # height H: its distance to the ellipsoid along the normal, found here by Newton on
    # the foot point's parametric angle at 40 digits (the crate uses Vermeille's closed
    # form, the goldens ERFA's Fukushima method).
    dps_saved = mp.mp.dps
    mp.mp.dps = 40
    a = mp.mpf(6378137)
    b = a * (1 - 1 / mp.mpf("298.257223563"))

    def height(rho, zz):
        f = lambda t: (a * mp.cos(t) - rho) * (-a * mp.sin(t)) + (b * mp.sin(t) - zz) * (b * mp.cos(t))
        t = mp.findroot(f, mp.atan2(zz * a, rho * b))
        foot = (a * mp.cos(t), b * mp.sin(t))
        dist = mp.sqrt((rho - foot[0])**2 + (zz - foot[1])**2)
        inside = (rho / a)**2 + (zz / b)**2 < 1
        return -dist if inside else dist
    worst = mp.mpf(0)
    for H in (-501, 4500, 9001, 20000):
        for k in range(0, 91, 3):
            th = mp.radians(k) if k < 90 else mp.radians(mp.mpf("89.9"))
            rho, zz = (a + H) * mp.cos(th), (b + H) * mp.sin(th)
            worst = max(worst, abs(height(rho, zz) - H) / abs(H))
    check("a point of the ellipsoid raised by H has geodetic height within 2e-6 |H| of H "
          "(H from -501 m to 20 km, every 3 deg of latitude)", worst < mp.mpf("2e-6"),
          f"max {mp.nstr(worst, 3)} |H|")
    mp.mp.dps = dps_saved
    info(f"(G11) took {time.time() - T0:.1f} s")


if __name__ == "__main__":
    RESULTS = []

    def check(label, ok, note=""):
        RESULTS.append(bool(ok))
        print(f"[{'PASS' if ok else 'FAIL'}] {label}" + (f"  ({note})" if note else ""))
        sys.stdout.flush()

    def info(text):
        print(f"       {text}")
        sys.stdout.flush()

    t_start = time.time()
    run(check, info, full="--full" in sys.argv)
    run_numeric(check, info)
    run_case(check, info)
    run_bus(check, info)
    n_fail = RESULTS.count(False)
    print(f"== {len(RESULTS) - n_fail}/{len(RESULTS)} checks passed in {time.time() - t_start:.1f} s")
    sys.exit(1 if n_fail else 0)
