"""The portable noise generator (SPEC section 7), bit-for-bit equal to runtime/src/diffusion/noise.rs."""

import numpy as np

INITIAL_NOISE_STREAM = 0
HARMONIZE_STREAM_BASE = 1_000_000

_MASK = (1 << 64) - 1
_GOLDEN = 0x9E3779B97F4A7C15
_STREAM_MIX = 0xD1B54A32D192ED03


def _words(seed, stream, count):
    """Words 0..count-1 of a stream as uint64, with numpy's wrapping uint64 arithmetic."""
    base = np.uint64((seed ^ (stream * _STREAM_MIX)) & _MASK)
    index = np.arange(1, count + 1, dtype=np.uint64)
    with np.errstate(over="ignore"):
        z = base + index * np.uint64(_GOLDEN)
        z ^= z >> np.uint64(30)
        z *= np.uint64(0xBF58476D1CE4E5B9)
        z ^= z >> np.uint64(27)
        z *= np.uint64(0x94D049BB133111EB)
        z ^= z >> np.uint64(31)
    return z


def uniforms(seed, stream, count):
    """Uniform numbers in (0, 1]: ((word >> 11) + 1) * 2**-53, in float64."""
    words = _words(seed, stream, count)
    return ((words >> np.uint64(11)) + np.uint64(1)).astype(np.float64) * 2.0**-53


# Quarter turn pi/2 in three parts and the fdlibm kernel coefficients of sin and cos on
# [-pi/4, pi/4], as in the Rust runtime.
_TWO_OVER_PI = 0.6366197723675814
_HALF_PI_1 = 1.5707963267341256
_HALF_PI_2 = 6.077100506303966e-11
_HALF_PI_3 = 2.0222662487959506e-21
_SIN = (
    -0.16666666666666632,
    0.00833333333332249,
    -0.0001984126982985795,
    2.7557313707070068e-06,
    -2.5050760253406863e-08,
    1.58969099521155e-10,
)
_COS = (
    0.0416666666666666,
    -0.001388888888887411,
    2.480158728947673e-05,
    -2.7557314351390663e-07,
    2.087572321298175e-09,
    -1.1359647557788195e-11,
)


# ln 2 in two parts and the fdlibm coefficients of the logarithm's polynomial, as in the runtime.
_LN2_HI = 0.6931471803691238
_LN2_LO = 1.9082149292705877e-10
_LOG = (
    0.6666666666666735,
    0.3999999999940942,
    0.2857142874366239,
    0.22222198432149784,
    0.1818357216161805,
    0.15313837699209373,
    0.14798198605116586,
)


def ln_unit(u):
    """ln u for 0 < u <= 1: the runtime's mantissa/exponent split and polynomial, every float64
    operation in the same order."""
    bits = u.view(np.uint64)
    exponent = ((bits >> np.uint64(52)) & np.uint64(0x7FF)).astype(np.int64) - 1023
    mantissa = ((bits & np.uint64(0x000FFFFFFFFFFFFF)) | np.uint64(0x3FF0000000000000)).view(np.float64)
    big = mantissa > np.sqrt(2.0)
    m = np.where(big, mantissa * 0.5, mantissa)
    e = (exponent + big.astype(np.int64)).astype(np.float64)
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (_LOG[1] + w * (_LOG[3] + w * _LOG[5]))
    t2 = z * (_LOG[0] + w * (_LOG[2] + w * (_LOG[4] + w * _LOG[6])))
    r = t2 + t1
    half_f2 = 0.5 * f * f
    return e * _LN2_HI - ((half_f2 - (s * (half_f2 + r) + e * _LN2_LO)) - f)


def sin_cos_turn(x):
    """(sin x, cos x) for 0 <= x <= 2 pi: the runtime's quarter-turn reduction and kernel
    polynomials, every float64 operation in the same order, so the bits match without libm."""
    q = np.floor(x * _TWO_OVER_PI + 0.5)
    quadrant = q.astype(np.int64)
    y = ((x - q * _HALF_PI_1) - q * _HALF_PI_2) - q * _HALF_PI_3
    z = y * y
    s_tail = _SIN[1] + z * (_SIN[2] + z * (_SIN[3] + z * (_SIN[4] + z * _SIN[5])))
    s = y + z * y * (_SIN[0] + z * s_tail)
    c_tail = z * (_COS[0] + z * (_COS[1] + z * (_COS[2] + z * (_COS[3] + z * (_COS[4] + z * _COS[5])))))
    half_z = 0.5 * z
    w = 1.0 - half_z
    c = w + (((1.0 - w) - half_z) + z * c_tail)
    swap = (quadrant & 1) == 1
    sin = np.where(swap, c, s)
    cos = np.where(swap, s, c)
    sin = np.where(((quadrant >> 1) & 1) == 1, -sin, sin)
    cos = np.where((((quadrant + 1) >> 1) & 1) == 1, -cos, cos)
    return sin, cos


def normals(seed, stream, count):
    """The first `count` normals of a stream (Box-Muller in float64, then float32)."""
    pairs = (count + 1) // 2
    u = uniforms(seed, stream, 2 * pairs).reshape(pairs, 2)
    r = np.sqrt(-2.0 * ln_unit(np.ascontiguousarray(u[:, 0])))
    sin, cos = sin_cos_turn(2.0 * np.pi * u[:, 1])
    out = np.stack([r * cos, r * sin], axis=1).reshape(-1)
    return out[:count].astype(np.float32)
