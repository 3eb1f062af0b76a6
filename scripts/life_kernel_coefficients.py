"""The coefficients of the photon life's kernels: sim/simd/life_trig.h's sine and
cosine for |x| <= pi/4 and sim/simd/life_log.h's logarithm.

In z = x^2, with 60-digit decimal arithmetic (Python's decimal module, no
other dependency):
  sin x = x + x z S(z),        S of degree 6 ~ (sin(sqrt z) / sqrt z - 1) / z
  cos x = 1 - z (1/2 - z C(z)), C of degree 5 ~ (cos(sqrt z) - 1 + z / 2) / z^2
S and C interpolate those functions at the Chebyshev nodes of [0, (pi/4)^2]
(near-minimax). The script prints the coefficients (as C99 hex floats,
rounded to double) and the largest error, relative to sin x or cos x, of the
polynomial with the rounded coefficients over 2000 points of z (exact
arithmetic otherwise): about 0.06 and 0.012 units of 2^-53.

The logarithm: log(1 + f) = f - f^2/2 + s (f^2/2 + z P(z)) for 1 + f in
[sqrt(2)/2, sqrt(2)), s = f / (2 + f), z = s^2, P of degree 6 interpolating
sum_k 2 z^(k-1) / (2k + 1) at the Chebyshev nodes of [0, s_max^2]; s z P(z)
is within about 0.04 units of 2^-53 of its target, relative to log(1 + f).

Run: /usr/bin/python3 scripts/life_kernel_coefficients.py
"""
from decimal import Decimal as D, getcontext
getcontext().prec = 60

def pi():
    # Machin: pi = 16 atan(1/5) - 4 atan(1/239)
    def atan_inv(n):
        x = D(1) / n; x2 = x * x; s = D(0); t = x; k = 1; sign = 1
        while abs(t) > D(10) ** -70:
            s += sign * t / k; t *= x2; k += 2; sign = -sign
        return s
    return 16 * atan_inv(5) - 4 * atan_inv(239)

PI = pi()

def g_sin(z):  # sum_{n>=1} (-1)^n z^(n-1) / (2n+1)!
    s = D(0); t = D(-1) / 6; n = 1
    while abs(t) > D(10) ** -70:
        s += t; t = -t * z / ((2 * n + 2) * (2 * n + 3)); n += 1
    return s

def g_cos(z):  # sum_{n>=2} (-1)^n z^(n-2) / (2n)!
    s = D(0); t = D(1) / 24; n = 2
    while abs(t) > D(10) ** -70:
        s += t; t = -t * z / ((2 * n + 1) * (2 * n + 2)); n += 1
    return s

def cos_d(x):
    s = D(0); t = D(1); n = 0
    while abs(t) > D(10) ** -70:
        s += t; t = -t * x * x / ((2 * n + 1) * (2 * n + 2)); n += 1
    return s

def solve(a, b):
    n = len(b); m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for i in range(n):
        p = max(range(i, n), key=lambda r: abs(m[r][i])); m[i], m[p] = m[p], m[i]
        for r in range(n):
            if r != i:
                f = m[r][i] / m[i][i]
                m[r] = [m[r][j] - f * m[i][j] for j in range(n + 1)]
    return [m[i][n] / m[i][i] for i in range(n)]

def interpolate(g, deg, a):
    # Chebyshev nodes of [0, a], then the interpolating polynomial's monomial coefficients.
    nodes = [a / 2 * (1 - cos_d((2 * k + 1) * PI / (2 * (deg + 1)))) for k in range(deg + 1)]
    return solve([[z ** j for j in range(deg + 1)] for z in nodes], [g(z) for z in nodes])

A = (PI / 4) ** 2
for name, g, deg in (("sin", g_sin, 6), ("cos", g_cos, 5)):
    c = interpolate(g, deg, A)
    print(name, [float(v).hex() for v in c])
    # Max error of the double-rounded polynomial against g over a fine grid, times the
    # factor that carries it into the function (x^3 for sin, x^4 for cos), relative to the function.
    worst = D(0)
    cd = [D(float(v)) for v in c]
    for i in range(1, 2001):
        z = A * i / 2000
        p = sum(cd[j] * z ** j for j in range(deg + 1))
        x = z.sqrt()
        if name == "sin":
            f = x * (1 + z * g_sin(z)); err = abs(x * z * (p - g(z))) / f
        else:
            f = 1 - z / 2 + z * z * g_cos(z); err = abs(z * z * (p - g(z))) / f
        worst = max(worst, err)
    print(name, "worst relative error of the polynomial (coefficients rounded):", float(worst), "=", float(worst / D(2) ** -53), "ulp-ish (2^-53)")

# The logarithm's kernel (sim/simd/life_log.h): log(1 + f) = f - f^2/2 + s (f^2/2 + z P(z)),
# s = f / (2 + f), z = s^2, for 1 + f in [sqrt(2)/2, sqrt(2)): |s| <= (sqrt 2 - 1) / (sqrt 2 + 1).
# P of degree 6 ~ sum_{k>=1} 2 z^(k-1) / (2k + 1) (the series of log((1+s)/(1-s)) = 2s + s z P(z)).
def g_log(z):
    s = D(0); k = 1; t = D(1)
    while True:
        term = 2 * t / (2 * k + 1)
        if abs(term) < D(10) ** -70: return s
        s += term; t *= z; k += 1

SQ2 = D(2).sqrt()
S_MAX = (SQ2 - 1) / (SQ2 + 1)
ZL = S_MAX * S_MAX
c = interpolate(g_log, 6, ZL)
print("log", [float(v).hex() for v in c])
cd = [D(float(v)) for v in c]
worst = D(0)
for i in range(1, 2001):
    z = ZL * i / 2000
    sz = z.sqrt()
    p = sum(cd[j] * z ** j for j in range(7))
    f = abs(2 * sz + sz * z * g_log(z))  # |log((1 + s) / (1 - s))|
    worst = max(worst, sz * z * abs(p - g_log(z)) / f)
print("log worst relative error of s z P(z) (coefficients rounded):", float(worst), "=", float(worst / D(2) ** -53), "units of 2^-53")
