#!/usr/bin/env python3
"""The f32 sinc polynomial of core-math/src/mtf.rs (SINC_MINIMAX_F32).

sin(x)/x on |x| <= pi as a polynomial in z = x^2 of degree 6 (7 coefficients), fitted
for the least largest absolute error by Lawson's iteration (iteratively reweighted least
squares on 4 000 Chebyshev nodes), the coefficients rounded to f32, and the rounded
polynomial then evaluated in f32 by Horner's rule against f64 on 200 001 points.

Run: python3 tools/fit_sinc_f32.py   (needs numpy: pip install numpy)
Prints the coefficients and the f32 evaluation's largest error (1.7e-7; the Taylor
series needs 9 terms for the same, core-math/tests/mtf_period.rs checks it).
"""
import numpy as np

DEGREE = 6


def fit(degree, iters=200):
    x = np.sort(np.abs(np.cos(np.linspace(0, np.pi, 4000)) * np.pi))
    safe = np.where(x == 0, 1.0, x)
    f = np.where(x == 0, 1.0, np.sin(x) / safe)
    v = np.vander(x * x, degree + 1, increasing=True)
    w = np.ones_like(x) / len(x)
    for _ in range(iters):
        sw = np.sqrt(w)
        c, *_ = np.linalg.lstsq(v * sw[:, None], f * sw, rcond=None)
        e = np.abs(v @ c - f)
        w = w * e
        w /= w.sum()
    return [np.float32(c_k) for c_k in c]


def horner_f32(coefficients, x):
    x = x.astype(np.float32)
    z = (x * x).astype(np.float32)
    acc = np.zeros_like(z)
    for c_k in reversed(coefficients):
        acc = (acc * z + c_k).astype(np.float32)
    return acc


c = fit(DEGREE)
xs = np.linspace(0, np.pi, 200001).astype(np.float32)
x64 = xs.astype(np.float64)
exact = np.where(x64 == 0, 1.0, np.sin(x64) / np.where(x64 == 0, 1.0, x64))
err = np.abs(horner_f32(c, xs).astype(np.float64) - exact).max()
for k, c_k in enumerate(c):
    print(f"z^{k}: {float(c_k)!r}")
print(f"largest error of the f32 evaluation on [0, pi]: {err:.3e}")
