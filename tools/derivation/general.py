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
    n_fail = RESULTS.count(False)
    print(f"== {len(RESULTS) - n_fail}/{len(RESULTS)} checks passed in {time.time() - t_start:.1f} s")
    sys.exit(1 if n_fail else 0)
