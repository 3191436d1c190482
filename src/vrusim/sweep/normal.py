"""The standard normal CDF Φ and its inverse Φ⁻¹ on arrays, for the Gaussian copula of a sweep design.

Both are Cephes' rational approximations (Stephen L. Moshier; `ndtr` and `ndtri` as SciPy ships them in
`scipy.special`, BSD-3-Clause), evaluated with the same coefficients in the same order, one IEEE-754 operation
at a time, with the C library's `exp` and `log` (through `math`, as SciPy calls them). The values therefore
equal SciPy's bit for bit, which keeps every correlated sweep design of earlier versions unchanged without the
140 MB SciPy install; `tests/test_sweep_normal.py` compares them over every branch. Relative error about 1e-15
(Cephes' figures: Φ 3.4e-14 peak on [-13, 0], Φ⁻¹ 7.2e-16 peak).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

_SQRT1_2 = 0.70710678118654752440
_SQRT2PI = 2.50662827463100050242
_MAXLOG = 7.09782712893383996843e2
_EXP_M2 = 0.13533528323661269189
"""exp(-2): below it (and above 1 - it) Φ⁻¹ uses its tail approximations."""

# erfc(x) = exp(-x²) P(x) / Q(x) for 1 <= x < 8, R(x) / S(x) beyond; erf(x) = x T(x²) / U(x²) for |x| < 1
_ERFC_P = (
    2.46196981473530512524e-10,
    5.64189564831068821977e-1,
    7.46321056442269912687e0,
    4.86371970985681366614e1,
    1.96520832956077098242e2,
    5.26445194995477358631e2,
    9.34528527171957607540e2,
    1.02755188689515710272e3,
    5.57535335369399327526e2,
)
_ERFC_Q = (
    1.32281951154744992508e1,
    8.67072140885989742329e1,
    3.54937778887819891062e2,
    9.75708501743205489753e2,
    1.82390916687909736289e3,
    2.24633760818710981792e3,
    1.65666309194161350182e3,
    5.57535340817727675546e2,
)
_ERFC_R = (
    5.64189583547755073984e-1,
    1.27536670759978104416e0,
    5.01905042251180477414e0,
    6.16021097993053585195e0,
    7.40974269950448939160e0,
    2.97886665372100240670e0,
)
_ERFC_S = (
    2.26052863220117276590e0,
    9.39603524938001434673e0,
    1.20489539808096656605e1,
    1.70814450747565897222e1,
    9.60896809063285878198e0,
    3.36907645100081516050e0,
)
_ERF_T = (
    9.60497373987051638749e0,
    9.00260197203842689217e1,
    2.23200534594684319226e3,
    7.00332514112805075473e3,
    5.55923013010394962768e4,
)
_ERF_U = (
    3.35617141647503099647e1,
    5.21357949780152679795e2,
    4.59432382970980127987e3,
    2.26290000613890934246e4,
    4.92673942608635921086e4,
)
# Φ⁻¹: |p - 0.5| <= 3/8 (0); tail z = sqrt(-2 log p) in [2, 8) (1) and [8, 64] (2)
_CENTRE_P = (
    -5.99633501014107895267e1,
    9.80010754185999661536e1,
    -5.66762857469070293439e1,
    1.39312609387279679503e1,
    -1.23916583867381258016e0,
)
_CENTRE_Q = (
    1.95448858338141759834e0,
    4.67627912898881538453e0,
    8.63602421390890590575e1,
    -2.25462687854119370527e2,
    2.00260212380060660359e2,
    -8.20372256168333339912e1,
    1.59056225126211695515e1,
    -1.18331621121330003142e0,
)
_TAIL_P = (
    (
        4.05544892305962419923e0,
        3.15251094599893866154e1,
        5.71628192246421288162e1,
        4.40805073893200834700e1,
        1.46849561928858024014e1,
        2.18663306850790267539e0,
        -1.40256079171354495875e-1,
        -3.50424626827848203418e-2,
        -8.57456785154685413611e-4,
    ),
    (
        3.23774891776946035970e0,
        6.91522889068984211695e0,
        3.93881025292474443415e0,
        1.33303460815807542389e0,
        2.01485389549179081538e-1,
        1.23716634817820021358e-2,
        3.01581553508235416007e-4,
        2.65806974686737550832e-6,
        6.23974539184983293730e-9,
    ),
)
_TAIL_Q = (
    (
        1.57799883256466749731e1,
        4.53907635128879210584e1,
        4.13172038254672030440e1,
        1.50425385692907503408e1,
        2.50464946208309415979e0,
        -1.42182922854787788574e-1,
        -3.80806407691578277194e-2,
        -9.33259480895457427372e-4,
    ),
    (
        6.02427039364742014255e0,
        3.67983563856160859403e0,
        1.37702099489081330271e0,
        2.16236993594496635890e-1,
        1.34204006088543189037e-2,
        3.28014464682127739104e-4,
        2.89247864745380683936e-6,
        6.79019408009981274425e-9,
    ),
)


def _poly(x: np.ndarray, coefficients: Sequence[float]) -> np.ndarray:
    """c[0] xⁿ + ... + c[n] by Horner's rule (Cephes' polevl)."""
    result = np.full_like(x, coefficients[0])
    for c in coefficients[1:]:
        result = result * x + c
    return result


def _monic(x: np.ndarray, coefficients: Sequence[float]) -> np.ndarray:
    """xⁿ + c[0] xⁿ⁻¹ + ... + c[n-1] by Horner's rule (Cephes' p1evl)."""
    result = x + coefficients[0]
    for c in coefficients[1:]:
        result = result * x + c
    return result


def _libm(function: Callable[[float], float], x: np.ndarray) -> np.ndarray:
    """`function` (math.exp or math.log: the C library's) of every element; NumPy's own SIMD versions may differ
    from it in the last bit."""
    return np.fromiter(map(function, x.tolist()), dtype=float, count=x.size)


def _result(out: np.ndarray) -> np.ndarray | np.float64:
    return out if out.ndim else out[()]


def normal_cdf(x: np.ndarray | float) -> np.ndarray | np.float64:
    """Φ(x), the standard normal CDF, elementwise (NaN stays NaN); equals `scipy.special.ndtr` bit for bit."""
    a = np.asarray(x, dtype=float)
    half = a * _SQRT1_2
    z = np.abs(half)
    out = np.full(a.shape, np.nan)
    centre = z < 1.0  # Φ = 1/2 + erf(x/√2)/2; erf is odd
    w = z[centre]
    ww = w * w
    erf = w * _poly(ww, _ERF_T) / _monic(ww, _ERF_U)
    out[centre] = 0.5 + 0.5 * np.where(half[centre] < 0.0, -erf, erf)
    tail = z >= 1.0  # Φ = erfc(|x|/√2)/2, or 1 - that above zero
    w = z[tail]
    erfc = np.zeros_like(w)
    finite = -w * w >= -_MAXLOG  # else exp(-w²) underflows: erfc = 0
    w = w[finite]
    near = w < 8.0
    numerator, denominator = np.empty_like(w), np.empty_like(w)
    numerator[near], denominator[near] = _poly(w[near], _ERFC_P), _monic(w[near], _ERFC_Q)
    numerator[~near], denominator[~near] = _poly(w[~near], _ERFC_R), _monic(w[~near], _ERFC_S)
    erfc[finite] = _libm(math.exp, -w * w) * numerator / denominator
    below = 0.5 * erfc
    out[tail] = np.where(half[tail] > 0.0, 1.0 - below, below)
    return _result(out)


def normal_quantile(p: np.ndarray | float) -> np.ndarray | np.float64:
    """Φ⁻¹(p), the standard normal quantile, elementwise: -inf at 0, inf at 1, NaN outside [0, 1] and for NaN;
    equals `scipy.special.ndtri` bit for bit."""
    p0 = np.asarray(p, dtype=float)
    out = np.full(p0.shape, np.nan)
    out[p0 == 0.0] = -np.inf
    out[p0 == 1.0] = np.inf
    inside = (p0 > 0.0) & (p0 < 1.0)
    upper = p0 > 1.0 - _EXP_M2  # mirrored into the lower tail
    y = np.where(upper, 1.0 - p0, p0)
    centre = inside & (y > _EXP_M2)
    w = y[centre] - 0.5
    ww = w * w
    x = w + w * (ww * _poly(ww, _CENTRE_P) / _monic(ww, _CENTRE_Q))
    out[centre] = x * _SQRT2PI
    tail = inside & ~(y > _EXP_M2)
    t = np.sqrt(-2.0 * _libm(math.log, y[tail]))
    t0 = t - _libm(math.log, t) / t
    z = 1.0 / t
    far = t >= 8.0  # p below exp(-32)
    x1 = np.empty_like(t)
    for rows, P, Q in ((~far, _TAIL_P[0], _TAIL_Q[0]), (far, _TAIL_P[1], _TAIL_Q[1])):
        x1[rows] = z[rows] * _poly(z[rows], P) / _monic(z[rows], Q)
    x = t0 - x1
    out[tail] = np.where(upper[tail], x, -x)
    return _result(out)
