#!/usr/bin/env python3
"""Computer-algebra proof of the image-motion derivation (see docs/derivation.md).

Builds the paper's nine homogeneous transforms (Li, Kong, Liu, Chinese Optics 6(5),
2013, Eqs. 7-12) literally, differentiates P(t) = M9 M8 M7 M6(t) M5 M4(t) M3 M2 M1 G
at t = 0 (Eq. 13) and proves, exactly:

  (a) v1, v2 of the chain equal the (g2, g3) closed forms;
  (b) the paper's Eq. 14 differs from the chain by exactly -f w g2 sin(i0) sin(g0)/D
      (its Earth-rotation cross term is doubled);
  (c) the stable forms in (eta, k, q, den) that core-math/src/sphere/closed_form.rs evaluates
      equal the (g2, g3) forms once g2, g3 come from Eqs. 1-6;
  (d) dP2/dt vanishes for i0 = 0, 180 deg and g0 = 90, 270 deg;
  (e) what survives of the garbled Eq. 15;
  (f) the conditioning formulas quoted in the doc;
and, in general.py (part II of the doc), the general real-Earth model.

"Exactly" means: every sin x, cos x is replaced by a symbol S_x, C_x; the difference of
the two sides is brought over a common denominator and its numerator is reduced modulo
the ideal {S_x^2 + C_x^2 - 1} (these generators have pairwise coprime leading monomials,
so they are a Groebner basis and remainder 0 <=> the identity holds for all angles).
A 50-digit random-point check ties the algebra to the literal asin route of Eqs. 1-6
(branch choices included), and 50-digit values for the paper's camera are printed for
comparison with the Rust reference.

Run:  pip install -r tools/derivation/requirements.txt
      python3 tools/derivation/derive.py
Exit status is non-zero if any check fails.
"""

import math
import random
import sys
import time

import mpmath as mp
import sympy as sp

T_START = time.time()
RESULTS = []


def check(label, ok, note=""):
    ok = bool(ok)
    RESULTS.append((label, ok))
    print(f"[{'PASS' if ok else 'FAIL'}] {label}" + (f"  ({note})" if note else ""))
    sys.stdout.flush()


def info(text):
    print(f"       {text}")


# --------------------------------------------------------------------------------------
# Exact zero test for expressions in sin/cos of a few angles.
# --------------------------------------------------------------------------------------

def _trig_symbols(x):
    name = str(x)
    return sp.Symbol(f"S_{name}"), sp.Symbol(f"C_{name}")


def is_identically_zero(expr, angles):
    """True iff expr == 0 for all values of the angles (and of the other symbols)."""
    expr = sp.expand_trig(sp.sympify(expr))
    reps, rels, trig_gens = {}, [], []
    for x in dict.fromkeys(angles):
        s, c = _trig_symbols(x)
        reps[sp.sin(x)] = s
        reps[sp.cos(x)] = c
        rels.append(s**2 + c**2 - 1)
        trig_gens += [s, c]
    e = expr.xreplace(reps)
    if e.has(sp.sin, sp.cos, sp.tan):
        raise RuntimeError(f"trig functions left after substitution: {e.atoms(sp.sin, sp.cos)}")
    num = sp.expand(sp.numer(sp.together(e)))
    if num == 0:
        return True
    others = sorted(num.free_symbols - set(trig_gens), key=str)
    _, rem = sp.reduced(num, rels, *trig_gens, *others, order="lex")
    return sp.expand(rem) == 0


# --------------------------------------------------------------------------------------
# Symbols and the nine matrices, as printed (two misprints mended, see below).
# --------------------------------------------------------------------------------------

t = sp.Symbol("t", real=True)
R, H, f = sp.symbols("R H f", positive=True)
w, W = sp.symbols("omega Omega", real=True)  # Earth rate, orbital rate
i0, g0, phi = sp.symbols("i0 gamma0 phi", real=True)
g1, g2, g3 = sp.symbols("g1 g2 g3", real=True)
sin, cos = sp.sin, sp.cos

M1 = sp.Matrix([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, R], [0, 0, 0, 1]])
M2 = sp.Matrix([[cos(g0), 0, sin(g0), 0], [0, 1, 0, 0], [-sin(g0), 0, cos(g0), 0], [0, 0, 0, 1]])
M3 = sp.Matrix([[cos(i0), -sin(i0), 0, 0], [sin(i0), cos(i0), 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
wt = w * t
M4 = sp.Matrix([[cos(wt), 0, sin(wt), 0], [0, 1, 0, 0], [-sin(wt), 0, cos(wt), 0], [0, 0, 0, 1]])
# M5 as printed has only three rows; its third row [0 0 1 0] is missing.
M5_printed = [[cos(i0), sin(i0), 0, 0], [-sin(i0), cos(i0), 0, 0], [0, 0, 0, 1]]
M5 = sp.Matrix(M5_printed[:2] + [[0, 0, 1, 0]] + M5_printed[2:])
gam = g0 + W * t
M6 = sp.Matrix([[cos(gam), 0, -sin(gam), 0], [0, 1, 0, 0], [sin(gam), 0, cos(gam), 0], [0, 0, 0, 1]])
# M7 as printed has five rows: its second row [0 1 0 0] is repeated.
M7_printed = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, -(R + H)], [0, 0, 0, 1]]
M7 = sp.Matrix(M7_printed[:2] + M7_printed[3:])
M8 = sp.Matrix([[1, 0, 0, 0], [0, cos(phi), sin(phi), 0], [0, -sin(phi), cos(phi), 0], [0, 0, 0, 1]])
G = sp.Matrix([g1, g2, g3, 1])

Cvec = M8 * M7 * M6 * M5 * M4 * M3 * M2 * M1 * G  # camera frame, Eq. 10
C3 = Cvec[2]
M9 = sp.diag(-f / C3, -f / C3, f / C3, 1)  # Eq. 11, itself a function of t
P = M9 * Cvec  # Eq. 12

ANG = [i0, g0, phi]

print("== Frames and conventions")
check("M5 (mended) is the inverse of M3", sp.simplify(M5 * M3 - sp.eye(4)) == sp.zeros(4))
check("M7 (mended) is a translation by -(R+H) along axis 3",
      M7 == sp.Matrix([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -(R + H)], [0, 0, 0, 1]]))

# The relative rotation: Q(t) = M6(t) M5 M4(t) M3 M2 (upper-left 3x3).
Q = (M6 * M5 * M4 * M3 * M2)[:3, :3]
Q0 = Q.subs(t, 0)
Qdot0 = sp.diff(Q, t).subs(t, 0)
a_ = w * sin(i0) * cos(g0)
b_ = w * cos(i0) - W
c_ = w * sin(i0) * sin(g0)
Wx = sp.Matrix([[0, -c_, b_], [c_, 0, -a_], [-b_, a_, 0]])  # [W]_x, W = (a, b, c)
check("Q(0) = M6(0) M5 M4(0) M3 M2 = identity",
      all(is_identically_zero(e, ANG) for e in (Q0 - sp.eye(3))))
check("dQ/dt(0) = [W]x with W = w*(sin i0 cos g0, cos i0, sin i0 sin g0) - Omega*e2",
      all(is_identically_zero(e, ANG) for e in (Qdot0 - Wx)))

D = sin(phi) * g2 - cos(phi) * g3 + cos(phi) * H  # depth along the boresight
check("C3(0) = -D (D = sin(phi) g2 - cos(phi) g3 + cos(phi) H)",
      is_identically_zero(C3.subs(t, 0).subs(g1, 0) + D, ANG))

# --------------------------------------------------------------------------------------
# (a) v1, v2 of the chain.
# --------------------------------------------------------------------------------------
print("== (a) chain derivative = (g2, g3) forms")
t0 = time.time()
v1_chain = sp.diff(P[0], t).subs(t, 0).subs(g1, 0)
v2_chain = sp.diff(P[1], t).subs(t, 0).subs(g1, 0)
P1_0 = P[0].subs(t, 0).subs(g1, 0)
P2_0 = P[1].subs(t, 0).subs(g1, 0)

v1_form = f * (b_ * (g3 + R) - c_ * g2) / D
N2 = (g3 + R) * (g3 - H) + g2**2  # = Y . (Y - S): minus R * rho * cos(e)
v2_form = f * a_ * N2 / D**2
check("P1(0) = 0 when g1 = 0", is_identically_zero(P1_0, ANG))
check("v1 = dP1/dt(0) = f [ b (g3+R) - c g2 ] / D", is_identically_zero(v1_chain - v1_form, ANG))
check("v2 = dP2/dt(0) = f a [ (g3+R)(g3-H) + g2^2 ] / D^2", is_identically_zero(v2_chain - v2_form, ANG))
info(f"(a) took {time.time() - t0:.1f} s")

# --------------------------------------------------------------------------------------
# (b) the paper's Eq. 14.
# --------------------------------------------------------------------------------------
print("== (b) the paper's Eq. 14")
v1_eq14 = (f * (g3 + R) * (cos(i0) * w - W) + f * w * g2 * (cos(i0 + g0) - cos(i0 - g0))) / (
    sin(phi) * g2 - cos(phi) * g3 + cos(phi) * H)
check("Eq. 14 cross term f w g2 (cos(i0+g0) - cos(i0-g0)) = -2 f c g2",
      is_identically_zero(f * w * g2 * (cos(i0 + g0) - cos(i0 - g0)) + 2 * f * c_ * g2, ANG))
check("Eq. 14 - chain = -f w g2 sin(i0) sin(g0) / D  (cross term doubled)",
      is_identically_zero(v1_eq14 - v1_chain + f * w * g2 * sin(i0) * sin(g0) / D, ANG))
check("Eq. 14 != chain (the difference is not identically zero)",
      not is_identically_zero(v1_eq14 - v1_chain, ANG))

# --------------------------------------------------------------------------------------
# (c) stable forms = (g2, g3) forms with g2, g3 from Eqs. 1-6.
# --------------------------------------------------------------------------------------
print("== (c) stable forms (closed_form.rs) = (g2, g3) forms with Eqs. 1-6")
t0 = time.time()
alpha, e = sp.symbols("alpha e", real=True)  # field angle, incidence angle at G
a, b, c = sp.symbols("a b c", real=True)     # rates of the relative rotation
ANG_C = [phi, alpha, e]
eta = phi + alpha
s_eta, c_eta = sp.expand_trig(sin(eta)), sp.expand_trig(cos(eta))
beta = sp.pi - e                       # beta obtuse: the near intersection, e in (-90, 90) deg
k = sin(beta) / s_eta                  # Eq. 1: R / sin(alpha+phi) = (H+R) / sin(beta), k = (R+H)/R
H_c = R * (k - 1)
theta = sp.pi - phi - alpha - beta     # Eq. 3
g2_c = R * sin(theta)                  # Eq. 5
g3_c = R * (cos(theta) - 1)            # Eq. 6
q = cos(e)                             # cos of the incidence angle
c0 = k**2 - 1
den = k * c_eta + q
rho = c0 * R / den                     # slant range, stable root
cos_th_s = q * c_eta + k * s_eta**2
D_c = D.subs({g2: g2_c, g3: g3_c, H: H_c})

check("sin(e) = k sin(eta) and q^2 = (1 - k sin eta)(1 + k sin eta)",
      is_identically_zero(q**2 - (1 - k * s_eta) * (1 + k * s_eta), ANG_C))
check("rho = c0 R / den solves rho^2 - 2 k R cos(eta) rho + c0 R^2 = 0",
      is_identically_zero(rho**2 - 2 * k * R * c_eta * rho + c0 * R**2, ANG_C))
check("rho = R (k cos eta - q): the near root, rationalised",
      is_identically_zero(rho - R * (k * c_eta - q), ANG_C))
check("cos(theta) [Eq. 3] = q cos(eta) + k sin^2(eta)", is_identically_zero(cos(theta) - cos_th_s, ANG_C))
check("g2 = R sin(theta) = rho sin(eta)", is_identically_zero(g2_c - rho * s_eta, ANG_C))
check("g3 + R = R cos(theta) (so no cos(theta) - 1 is ever needed)",
      is_identically_zero(g3_c + R - R * cos_th_s, ANG_C))
check("D = rho cos(alpha)", is_identically_zero(D_c - rho * cos(alpha), ANG_C))
check("P2(0) = f tan(alpha) (pixel n sits at P2 = n A: sign convention)",
      is_identically_zero(P2_0.subs({g2: g2_c, g3: g3_c, H: H_c}) - f * sin(alpha) / cos(alpha),
                          ANG_C + [i0, g0]))

v1_gf = (f * (b * (g3 + R) - c * g2) / D).subs({g2: g2_c, g3: g3_c, H: H_c})
v2_gf = (f * a * N2 / D**2).subs({g2: g2_c, g3: g3_c, H: H_c})
v2_geom = -f * a * R * cos(e) / (D_c * cos(alpha))
v1_stable = f / cos(alpha) * ((b / c0) * cos_th_s * den - c * s_eta)
v2_stable = -(f / cos(alpha)**2) * (a / c0) * q * den
check("(g3+R)(g3-H) + g2^2 = -R rho cos(e)",
      is_identically_zero(N2.subs({g2: g2_c, g3: g3_c, H: H_c}) + R * rho * q, ANG_C))
check("v1: f[b(g3+R) - c g2]/D = (f/cos a)[(b/c0) cos(theta) den - c sin(eta)]",
      is_identically_zero(v1_gf - v1_stable, ANG_C))
check("v2: f a N/D^2 = -f a R cos(e) / (D cos(alpha))", is_identically_zero(v2_gf - v2_geom, ANG_C))
check("v2: f a N/D^2 = -(f/cos^2 a)(a/c0) q den", is_identically_zero(v2_gf - v2_stable, ANG_C))
hh = sp.Symbol("h", positive=True)
check("c0 = k^2 - 1 = h (2 + h) with k = 1 + h", sp.expand((1 + hh)**2 - 1 - hh * (2 + hh)) == 0)
info(f"(c) took {time.time() - t0:.1f} s")

# --------------------------------------------------------------------------------------
# (d) the along-track component vanishes with a.
# --------------------------------------------------------------------------------------
print("== (d) dP2/dt = 0 when a = w sin(i0) cos(g0) = 0")
for name, sub in [("i0 = 0", {i0: 0}), ("i0 = 180 deg", {i0: sp.pi}),
                  ("g0 = 90 deg", {g0: sp.pi / 2}), ("g0 = 270 deg", {g0: 3 * sp.pi / 2})]:
    check(f"dP2/dt(0) = 0 for {name}", is_identically_zero(v2_chain.subs(sub), ANG))

# --------------------------------------------------------------------------------------
# (e) what can be recovered of Eq. 15.
# --------------------------------------------------------------------------------------
print("== (e) Eq. 15 as printed")
u_, w_ = g2, H - g3
A1, A3 = 3 * u_**3 + 3 * u_ * w_**2, -u_**3 + 3 * u_ * w_**2
B1, B3 = 3 * u_**2 * w_ + 3 * w_**3, w_**3 - 3 * u_**2 * w_
check("4 D^3 = A1 sin(phi) + A3 sin(3 phi) + B1 cos(phi) + B3 cos(3 phi)",
      is_identically_zero(4 * D**3 - (A1 * sin(phi) + A3 * sin(3 * phi) + B1 * cos(phi) + B3 * cos(3 * phi)),
                          ANG))
Gstray = sp.Symbol("G_stray")
p_cos1 = 3 * H**3 - 3 * g3**3 - 9 * g3 * H**2 - 3 * g2**2 * g3 + 3 * g2**2 * H + 9 * g3**2 * H
p_last = H**3 - g3**3 - 3 * g3 * H**2 + 3 * g2**2 * g3 - 3 * g2**2 * H + 3 * g3**2 * Gstray
p_sin3 = (3 * g2 * g3**2 - g2**2) - 6 * g3 * g2 * H    # printed sin(3 phi) terms
p_sin1 = (3 * g2**3 + 3 * g3**2 * g2) - 6 * g3 * g2 * H  # printed sin(phi) terms
check("Eq. 15 denominator: printed cos(phi) group = B1 exactly", sp.expand(p_cos1 - B1) == 0)
check("Eq. 15 denominator: last group with G -> H = B3 (so its 'cos phi' is cos 3phi)",
      sp.expand(p_last.subs(Gstray, H) - B3) == 0)
info(f"sin(3phi) group: A3 - printed = {sp.factor(sp.expand(A3 - p_sin3))}  (print has g2^2 for g2^3, drops 3 g2 H^2)")
info(f"sin(phi)  group: A1 - printed = {sp.factor(sp.expand(A1 - p_sin1))}")
brk1 = -cos(-g0 + phi + i0) + cos(g0 + phi - i0) + cos(-g0 + phi - i0) - cos(g0 + phi + i0)
brk2 = sin(g0 + phi + i0) + sin(-g0 + phi + i0) - sin(g0 + phi - i0) - sin(-g0 + phi - i0)
check("Eq. 15 numerator: cos bracket = 4 sin(phi) sin(i0) cos(g0)",
      is_identically_zero(brk1 - 4 * sin(phi) * sin(i0) * cos(g0), ANG))
check("Eq. 15 numerator: sin bracket = 4 cos(phi) sin(i0) cos(g0)",
      is_identically_zero(brk2 - 4 * cos(phi) * sin(i0) * cos(g0), ANG))
# Chain: v2 = 4 f a D N2 / (4 D^3), i.e. numerator 4 f a [g2 N2 sin(phi) + (H - g3) N2 cos(phi)].
need_s = sp.expand(g2 * N2)
need_c = sp.expand((H - g3) * N2)
have_s = sp.expand(g3 * R * g2 - g2 * R * H + g2**3)
have_c = sp.expand(g2**2 * H - R * H**2 + 2 * R * g3 * H)
info(f"numerator, coefficient of 4 f a sin(phi): chain - printed = {sp.factor(need_s - have_s)}")
info(f"numerator, coefficient of 4 f a cos(phi): chain - printed = {sp.expand(need_c - have_c)}")
info("plus a stray printed term -f g2 g3 w H cos(-g0+phi-i0), not proportional to a: Eq. 15 is not repairable")
check("corrected Eq. 15 in the paper's layout: 4 f a D N2 / (4 D^3) = chain v2",
      is_identically_zero(4 * f * a_ * D * N2 / (4 * D**3) - v2_chain, ANG))

# --------------------------------------------------------------------------------------
# (f) conditioning with respect to the nadir angle eta (alpha held fixed).
# --------------------------------------------------------------------------------------
print("== (f) conditioning in eta")
s_, cc_, qq, kk = sp.symbols("s_eta c_eta q k", real=True)
# Derivative along eta: s' = c, c' = -s, q' from q^2 = 1 - k^2 s^2.
dq = -kk**2 * s_ * cc_ / qq


def d_eta(F):
    return sp.diff(F, s_) * cc_ - sp.diff(F, cc_) * s_ + sp.diff(F, qq) * dq


def zero_mod_circle(F):
    num = sp.expand(sp.numer(sp.together(F)))
    if num == 0:
        return True
    _, rem = sp.reduced(num, [qq**2 - 1 + kk**2 * s_**2, s_**2 + cc_**2 - 1], qq, s_, cc_, kk, order="lex")
    return sp.expand(rem) == 0


den_s = kk * cc_ + qq
c0_s = kk**2 - 1
costh_s = qq * cc_ + kk * s_**2
check("d ln q / d eta = -k^2 sin(eta) cos(eta) / q^2", zero_mod_circle(dq / qq + kk**2 * s_ * cc_ / qq**2))
check("d ln den / d eta = -k sin(eta) / q", zero_mod_circle(d_eta(den_s) / den_s + kk * s_ / qq))
check("d ln(q den) / d eta = -k sin(eta) den / q^2   (governs v2)",
      zero_mod_circle(d_eta(qq * den_s) / (qq * den_s) + kk * s_ * den_s / qq**2))
check("d (cos(theta) den) / d eta = -(sin eta / q) [c0^2/den + k den cos(theta)]   (governs v1)",
      zero_mod_circle(d_eta(costh_s * den_s) + (s_ / qq) * (c0_s**2 / den_s + kk * den_s * costh_s)))
check("d theta / d eta = rho / (R q) = c0 / (q den)  [d cos(theta) = -sin(theta) d theta]",
      zero_mod_circle(d_eta(costh_s) + (s_ * c0_s / den_s) * c0_s / (qq * den_s)))

# Near the limb: distance delta = L - eta to the limb, L = asin(1/k) (sin L = 1/k, cos L = sqrt(c0)/k).
Ls, d2 = sp.symbols("L d2", real=True)  # d2 = delta / 2
k_L, sqc0_L = 1 / sin(Ls), cos(Ls) / sin(Ls)
check("near-limb form: 1 - k sin(L - delta) = 2 s (s + sqrt(c0) c), s, c = sin, cos(delta/2)",
      is_identically_zero(1 - k_L * sin(Ls - 2 * d2) - 2 * sin(d2) * (sin(d2) + sqc0_L * cos(d2)), [Ls, d2]))
mm = sp.Symbol("m")
check("q^2 = m (2 - m) with m = 1 - k sin(eta)", sp.expand((1 - (1 - mm)) * (1 + (1 - mm)) - mm * (2 - mm)) == 0)
dl, s0 = sp.symbols("delta s0", positive=True)  # s0 = sqrt(c0)
m_d = 2 * sin(dl / 2) * (sin(dl / 2) + s0 * cos(dl / 2))
q_d = sp.sqrt(m_d * (2 - m_d))
den_d = s0 * cos(dl) + sin(dl) + q_d  # k cos(L - delta) = sqrt(c0) cos(delta) + sin(delta)
check("in delta the conditioning is benign: delta d ln q / d delta -> 1/2 as delta -> 0",
      sp.limit(dl * sp.diff(sp.log(q_d), dl), dl, 0, "+") == sp.Rational(1, 2))
check("and delta d ln(q den) / d delta -> 1/2 (v2) as delta -> 0",
      sp.limit(dl * sp.diff(sp.log(q_d * den_d), dl), dl, 0, "+") == sp.Rational(1, 2))

# --------------------------------------------------------------------------------------
# 50-digit numerics: random points (literal asin route vs stable forms) and the paper's camera.
# --------------------------------------------------------------------------------------
mp.mp.dps = 50
ARGS = (g2, g3, R, H, f, w, W, i0, g0, phi)
v1_chain_fn = sp.lambdify(ARGS, v1_chain, modules="mpmath")
v2_chain_fn = sp.lambdify(ARGS, v2_chain, modules="mpmath")
v1_eq14_fn = sp.lambdify(ARGS, v1_eq14, modules="mpmath")


def ground_eqs_1_6(Rm, Hm, alpha_r, phi_r):
    """Eqs. 1-6 literally: law of sines, beta obtuse, theta = pi - phi - alpha - beta."""
    sb = (Hm + Rm) * mp.sin(alpha_r + phi_r) / Rm
    beta_r = mp.pi - mp.asin(sb)
    th = mp.pi - phi_r - alpha_r - beta_r
    return Rm * mp.sin(th), Rm * (mp.cos(th) - 1)


def chain_mp(Rm, Hm, fm, wr, Wr, i0r, g0r, phi_r, alpha_r):
    G2, G3 = ground_eqs_1_6(Rm, Hm, alpha_r, phi_r)
    args = (G2, G3, Rm, Hm, fm, wr, Wr, i0r, g0r, phi_r)
    return v1_chain_fn(*args), v2_chain_fn(*args), v1_eq14_fn(*args)


def stable_mp(Rm, Hm, fm, wr, Wr, i0r, g0r, phi_r, alpha_r):
    h = Hm / Rm
    kx = 1 + h
    c0x = h * (2 + h)
    A = wr * mp.sin(i0r) * mp.cos(g0r)
    B = wr * mp.cos(i0r) - Wr
    Cc = wr * mp.sin(i0r) * mp.sin(g0r)
    se, ce = mp.sin(phi_r + alpha_r), mp.cos(phi_r + alpha_r)
    ks = kx * se
    qx = mp.sqrt((1 - ks) * (1 + ks))
    denx = kx * ce + qx
    cth = qx * ce + ks * se
    ca = mp.cos(alpha_r)
    v1 = fm / ca * ((B / c0x) * cth * denx - Cc * se)
    v2 = -(fm / ca**2) * (A / c0x) * qx * denx
    return v1, v2, dict(k=kx, c0=c0x, A=A, B=B, C=Cc, se=se, ce=ce, q=qx, den=denx, cth=cth, ca=ca)


print("== 50-digit checks")
rng = random.Random(20131005)
n_pts, worst = 0, mp.mpf(0)
while n_pts < 300:
    Rm = mp.mpf(rng.uniform(1e6, 1e7))
    Hm = Rm * mp.mpf(rng.choice([10 ** rng.uniform(-4, 0.5)]))
    ph = mp.mpf(rng.uniform(-1.3, 1.3))
    al = mp.mpf(rng.uniform(-1.3, 1.3))
    kx = 1 + Hm / Rm
    if not (mp.cos(ph + al) > 0 and kx * abs(mp.sin(ph + al)) < 1 - mp.mpf("1e-6")):
        continue
    pars = (Rm, Hm, mp.mpf(rng.uniform(0.1, 3)), mp.mpf(rng.uniform(-1e-3, 1e-3)),
            mp.mpf(rng.uniform(-2e-3, 2e-3)), mp.mpf(rng.uniform(0, 2 * math.pi)),
            mp.mpf(rng.uniform(0, 2 * math.pi)), ph, al)
    c1, c2, _ = chain_mp(*pars)
    s1, s2, _ = stable_mp(*pars)
    scale = abs(c1) + abs(c2)
    worst = max(worst, abs(c1 - s1) / scale, abs(c2 - s2) / scale)
    n_pts += 1
check(f"chain (asin route of Eqs. 1-6) = stable forms at {n_pts} random points, 50 digits",
      worst < mp.mpf("1e-30"), f"max |diff| / (|v1|+|v2|) = {mp.nstr(worst, 3)}")

# The paper's camera.
Rm, Hm, fm, Am = mp.mpf(6370e3), mp.mpf(645e3), mp.mpf("0.555"), mp.mpf("13e-6")
GM = mp.mpf("3.986004418e14")
wr = mp.mpf("7.2921159e-5")
Wr = mp.sqrt(GM / (Rm + Hm)**3)
i0r = mp.radians(mp.mpf("97.98"))
kx = 1 + Hm / Rm
eta_limb = mp.asin(1 / kx)
print("== The paper's camera: H 645 km, R 6370 km, f 0.555 m, A 13 um, i0 97.98 deg, 50 digits")
info(f"Omega = sqrt(GM/(R+H)^3) = {mp.nstr(Wr, 50)} rad/s")
info(f"k = 1 + H/R = {mp.nstr(kx, 20)},  c0 = k^2 - 1 = {mp.nstr(kx**2 - 1, 20)}")
info(f"limb nadir angle asin(1/k) = {mp.nstr(mp.degrees(eta_limb), 12)} deg")
info(f"|w cos i0| / Omega = {mp.nstr(abs(wr * mp.cos(i0r)) / Wr, 6)}  (b = w cos i0 - Omega: same sign, no cancellation)")
rows, worst_rel, max_cross, max_eq14 = [], mp.mpf(0), mp.mpf(0), mp.mpf(0)
for n in (-30000, 0, 30000):
    al = mp.atan(n * Am / fm)
    for phd in (0, 25):
        for g0d in (0, 45):
            pars = (Rm, Hm, fm, wr, Wr, i0r, mp.radians(g0d), mp.radians(phd), al)
            c1, c2, e14 = chain_mp(*pars)
            s1, s2, X = stable_mp(*pars)
            worst_rel = max(worst_rel, abs(c1 - s1) / abs(c1), abs(c2 - s2) / abs(c2) if c2 != 0 else 0)
            max_cross = max(max_cross, abs(X["C"] * X["se"]) / abs((X["B"] / X["c0"]) * X["cth"] * X["den"]))
            max_eq14 = max(max_eq14, abs(e14 - c1) / abs(c1))
            rows.append((n, phd, g0d, mp.degrees(al), c1, c2, e14))
print(f"       {'n':>6} {'phi':>3} {'g0':>3}  {'v1 = dP1/dt (m/s)':<58} {'v2 = dP2/dt (m/s)':<58}")
for n, phd, g0d, ald, c1, c2, _ in rows:
    print(f"       {n:>6} {phd:>3} {g0d:>3}  {mp.nstr(c1, 50, min_fixed=-10, max_fixed=-10):<58} "
          f"{mp.nstr(c2, 50, min_fixed=-10, max_fixed=-10):<58}")
info(f"field angle at |n| = 30000: {mp.nstr(mp.degrees(mp.atan(30000 * Am / fm)), 12)} deg")
check("paper's camera: stable forms = chain at all 12 points", worst_rel < mp.mpf("1e-40"),
      f"max relative difference {mp.nstr(worst_rel, 3)}")
info(f"largest |c sin(eta)| / |(b/c0) cos(theta) den| over these points = {mp.nstr(max_cross, 6)}"
     " (the v1 bracket never cancels)")
# Eq. 14's error at the worst place: far pixel, roll 25 deg, g0 = 90 deg.
for n, phd, g0d in ((30000, 25, 90), (-30000, 0, 90)):
    pars = (Rm, Hm, fm, wr, Wr, i0r, mp.radians(g0d), mp.radians(phd), mp.atan(n * Am / fm))
    c1, _, e14 = chain_mp(*pars)
    info(f"Eq. 14 vs chain at n = {n}, phi = {phd}, g0 = {g0d} deg: v1 {mp.nstr(e14, 12)} vs "
         f"{mp.nstr(c1, 12)} m/s, relative error {mp.nstr((e14 - c1) / c1, 4)}")

# Conditioning numbers at the camera's extreme pixels.
print("== Conditioning in eta at the paper's camera (alpha fixed, g0 = 45 deg)")
print(f"       {'n':>6} {'phi':>3} {'eta deg':>10} {'k sin eta':>10} {'q':>10} "
      f"{'dln v1/deta':>12} {'dln v2/deta':>12} {'kappa_v1':>9} {'kappa_v2':>9} {'amp_v1':>7} {'amp_v2':>7} "
      f"{'delta deg':>9} {'kd_v2':>6}")
worst_dl2 = mp.mpf(0)
for n, phd in ((-30000, 0), (0, 0), (30000, 0), (-30000, 25), (0, 25), (30000, 25)):
    al = mp.atan(n * Am / fm)
    ph = mp.radians(phd)

    def v_of_eta(et, which):
        return stable_mp(Rm, Hm, fm, wr, Wr, i0r, mp.radians(45), et - al, al)[which]

    et = ph + al
    s1, s2, X = stable_mp(Rm, Hm, fm, wr, Wr, i0r, mp.radians(45), ph, al)
    dl1 = mp.diff(lambda x: v_of_eta(x, 0), et) / s1
    dl2 = mp.diff(lambda x: v_of_eta(x, 1), et) / s2
    dl2_formula = -X["k"] * X["se"] * X["den"] / X["q"]**2
    worst_dl2 = max(worst_dl2, abs(dl2 - dl2_formula) / (1 + abs(dl2)))
    print(f"       {n:>6} {phd:>3} {mp.nstr(mp.degrees(et), 6):>10} {mp.nstr(X['k'] * X['se'], 5):>10} "
          f"{mp.nstr(X['q'], 5):>10} {mp.nstr(dl1, 4):>12} {mp.nstr(dl2, 4):>12} "
          f"{mp.nstr(abs(et * dl1), 3):>9} {mp.nstr(abs(et * dl2), 3):>9} "
          f"{mp.nstr(abs(mp.tan(et) * dl1), 3):>7} {mp.nstr(abs(mp.tan(et) * dl2), 3):>7} "
          f"{mp.nstr(mp.degrees(eta_limb - abs(et)), 5):>9} {mp.nstr(abs((eta_limb - abs(et)) * dl2), 3):>6}")
info("kappa = |eta d ln v/d eta| (relative condition number in eta); amp = |tan(eta) d ln v/d eta|:")
info("relative error of v caused by a relative error of 1 in sin(eta) (multiply by the error of sin(eta));")
info("delta = L - |eta| the angular distance to the limb, kd_v2 = |delta d ln v2 / d delta| (-> 1/2 at the limb)")
check("numerical d ln v2/d eta matches -k sin(eta) den / q^2 at the camera's pixels",
      worst_dl2 < mp.mpf("1e-30"), f"max deviation {mp.nstr(worst_dl2, 3)}")

# --------------------------------------------------------------------------------------
# f64 illustration: the literal route (asin, cos(theta) - 1) vs the stable forms.
# --------------------------------------------------------------------------------------
print("== f64 illustration (Python floats = IEEE binary64) against 50 digits, g0 = 45 deg")


def naive_f64(Rm_, Hm_, fm_, wr_, Wr_, i0r_, g0r_, ph_, al_):
    sb = (Hm_ + Rm_) * math.sin(al_ + ph_) / Rm_
    th = math.pi - ph_ - al_ - (math.pi - math.asin(sb))
    G2, G3 = Rm_ * math.sin(th), Rm_ * (math.cos(th) - 1)
    A = wr_ * math.sin(i0r_) * math.cos(g0r_)
    B = wr_ * math.cos(i0r_) - Wr_
    Cc = wr_ * math.sin(i0r_) * math.sin(g0r_)
    Dd = math.sin(ph_) * G2 - math.cos(ph_) * G3 + math.cos(ph_) * Hm_
    return (fm_ * (B * (G3 + Rm_) - Cc * G2) / Dd,
            fm_ * A * ((G3 + Rm_) * (G3 - Hm_) + G2 * G2) / Dd**2)


def stable_f64(Rm_, Hm_, fm_, wr_, Wr_, i0r_, g0r_, ph_, al_):
    h = Hm_ / Rm_
    kx_, c0x = 1 + h, h * (2 + h)
    A = wr_ * math.sin(i0r_) * math.cos(g0r_) / c0x
    B = (wr_ * math.cos(i0r_) - Wr_) / c0x
    Cc = wr_ * math.sin(i0r_) * math.sin(g0r_)
    ta = math.tan(al_)
    sec2 = 1 + ta * ta
    sec = math.sqrt(sec2)
    sa, ca = ta / sec, 1 / sec
    sp_, cp_ = math.sin(ph_), math.cos(ph_)
    se, ce = sp_ * ca + cp_ * sa, cp_ * ca - sp_ * sa
    ks = kx_ * se
    qx = math.sqrt((1 - ks) * (1 + ks))
    denx = kx_ * ce + qx
    cth = qx * ce + ks * se
    return fm_ * sec * (B * cth * denx - Cc * se), -(fm_ * sec2 * A * qx * denx)


U64 = 2.0**-53  # unit roundoff of binary64
print(f"       {'case':<36} {'naive v1':>9} {'v2':>9} {'stable v1':>10} {'v2':>9} {'u*cond v1':>10} {'v2':>9}")
cases = [("H 645 km, nadir pixel, phi 0", 645e3, 0.0, 0.0),
         ("H 645 km, n=30000, phi 25 deg", 645e3, math.radians(25), math.atan(30000 * 13e-6 / 0.555))]
for gap in (1e-4, 1e-8):  # rays with k sin(eta) = 1 - gap (near the limb)
    et_ = math.asin((1 - gap) / (1 + 645e3 / 6370e3))
    cases.append((f"H 645 km, k sin eta = 1 - {gap:g}", 645e3, et_ - 0.3, 0.3))
for hr in (1e-3, 1e-6):  # low altitude H/R: the cos(theta) - 1 and k cos eta - q cancellations
    cases.append((f"H/R = {hr:g}, phi 10 deg, alpha 5 deg", 6370e3 * hr, math.radians(10), math.radians(5)))
for label, Hm_, ph_, al_ in cases:
    pf = (6370e3, Hm_, 0.555, 7.2921159e-5, math.sqrt(3.986004418e14 / (6370e3 + Hm_)**3),
          math.radians(97.98), math.radians(45))
    pm = [mp.mpf(x) for x in pf] + [mp.mpf(ph_), mp.mpf(al_)]
    ref1, ref2, _ = stable_mp(*pm)
    n1, n2 = naive_f64(*pf, ph_, al_)
    s1, s2 = stable_f64(*pf, ph_, al_)
    e = [abs((mp.mpf(x) - r) / r) for x, r in ((n1, ref1), (n2, ref2), (s1, ref1), (s2, ref2))]
    # Conditioning bound: a relative error u in sin(eta) moves eta by u tan(eta).
    et = pm[7] + pm[8]
    dl1 = mp.diff(lambda x: stable_mp(*pm[:7], x - pm[8], pm[8])[0], et) / ref1
    dl2 = mp.diff(lambda x: stable_mp(*pm[:7], x - pm[8], pm[8])[1], et) / ref2
    b1, b2 = (U64 * abs(mp.tan(et) * d) for d in (dl1, dl2))
    print(f"       {label:<36} {mp.nstr(e[0], 2):>9} {mp.nstr(e[1], 2):>9} {mp.nstr(e[2], 2):>10} "
          f"{mp.nstr(e[3], 2):>9} {mp.nstr(b1, 2):>10} {mp.nstr(b2, 2):>9}")
info("relative errors; inputs are the same binary64 numbers for both routes and the reference is exact for them;")
info("u*cond = 2^-53 |tan(eta) d ln v/d eta|: the error that one rounding of sin(eta) alone causes")

# --------------------------------------------------------------------------------------
# Part II: the general (real-Earth) model, tools/derivation/general.py. `--full` adds the
# literal end-to-end symbolic checks (about two minutes more).
# --------------------------------------------------------------------------------------
import general  # noqa: E402  (same directory as this script)

general.run(check, info, full="--full" in sys.argv)
general.run_numeric(check, info)
general.run_case(check, info)
general.run_bus(check, info)

# --------------------------------------------------------------------------------------
n_fail = sum(1 for _, ok in RESULTS if not ok)
print(f"== {len(RESULTS) - n_fail}/{len(RESULTS)} checks passed in {time.time() - T_START:.1f} s")
sys.exit(1 if n_fail else 0)
