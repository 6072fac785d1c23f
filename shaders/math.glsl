// Numerical helpers the shading needs in f32. The Rust specification uses the f64 standard library for these.
#ifndef SUNSHADE_MATH_GLSL
#define SUNSHADE_MATH_GLSL

const float PI = 3.14159265358979323846;
const float HALF_PI = 1.57079632679489661923;
const float QUARTER_PI = 0.78539816339744830962;
const float INV_PI = 0.31830988618379067154;

// atan(x) to about 1 ulp. lavapipe's atan is off by up to 2.5e-6 relative (and acos/asin by 4e-4), too much for
// the disk-light contour integrals. Range reduction to |z| <= tan(pi/8) (atan x = pi/2 - atan(1/x);
// atan y = pi/4 + atan((y-1)/(y+1))), then atan z = z + z^3 P(z^2) with P of degree 5, a least-squares
// Chebyshev fit made for sunshade (relative error 2.8e-10 on the reduced range, well below f32's 6e-8).
float atan_accurate(float x) {
    float a = abs(x);
    bool invert = a > 1.0;
    float y = invert ? 1.0 / a : a;
    bool shift = y > 0.41421356237;
    float z = shift ? (y - 1.0) / (y + 1.0) : y;
    float z2 = z * z;
    float p = -0.3333333329617285 + z2 * (0.19999982868780558 + z2 * (-0.14284443550020454
        + z2 * (0.11076619500893384 + z2 * (-0.08662781174751054 + z2 * 0.051439724212663566))));
    float r = z + z * z2 * p;
    if (shift) {
        r += QUARTER_PI;
    }
    if (invert) {
        r = HALF_PI - r;
    }
    return x < 0.0 ? -r : r;
}

// atan2(y, x) in (-pi, pi] from atan_accurate; 0 for (0, 0). atan_accurate is called once, on y/x or x/y (the
// smaller over the larger), as the driver inlines each call: a call in each branch would compile it twice.
float atan2_accurate(float y, float x) {
    if (x == 0.0 && y == 0.0) {
        return 0.0;
    }
    bool by_x = abs(x) >= abs(y);
    float r = atan_accurate(by_x ? y / x : x / y);
    if (by_x) {
        return x > 0.0 ? r : (y >= 0.0 ? r + PI : r - PI);
    }
    return y > 0.0 ? HALF_PI - r : -HALF_PI - r;
}

// A unit vector orthogonal to the unit vector v (Duff et al. 2017, "Building an Orthonormal Basis, Revisited");
// mirrors orthonormal_to in src/shading/shade.rs.
vec3 orthonormal_to(vec3 v) {
    float s = v.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + v.z);
    float b = v.x * v.y * a;
    return vec3(b, s + v.y * v.y * a, -v.y);
}

// ln(u) for u > 0 with a small relative error everywhere, 1 at u = 1 included. lavapipe's log has a small
// absolute error (~6e-8) but not a small relative one near u = 1: for u just below 1 it computes
// -1 + log2(1.99...) and cancels (measured: up to 2e-3 relative error for u in (0.999, 1); this function stays
// within 2e-7 from 2^-20 to 2^20; docs/platform.md). Here
// u = m 2^k with m in [sqrt(1/2), sqrt(2)), and ln m = 2 atanh(s), s = (m - 1)/(m + 1), |s| <= 0.172, summed as
// 2 s (1 + s^2/3 + ... + s^12/13): the truncation is below 1e-10 relative, m - 1 is exact (Sterbenz) and every
// other step rounds once, so the result carries a few ulp of relative error even where ln u is tiny.
float log_accurate(float u) {
#ifdef SUNSHADE_NAIVE_MATH
    return log(u);
#else
    int k;
    float m = frexp(u, k);
    if (m < 0.70710678118) {
        m *= 2.0;
        k -= 1;
    }
    float s = (m - 1.0) / (m + 1.0);
    float s2 = s * s;
    float series = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0
        + s2 * (1.0 / 11.0 + s2 * (1.0 / 13.0))))));
    return 2.0 * s * series + float(k) * 0.69314718055994530942;
#endif
}

// log1p(x) by Goldberg's trick: u = 1 + x rounded, ln(u) x / (u - 1), with the accurate ln above. `precise`
// keeps the compiler from folding (1 + x) - 1 into x (NIR does that to inexact arithmetic), which undoes the trick.
float log1p_accurate(float x) {
#ifdef SUNSHADE_NAIVE_MATH
    return log(1.0 + x);
#else
    precise float u = 1.0 + x;
    precise float um1 = u - 1.0;
    return u == 1.0 ? x : log_accurate(u) * x / um1;
#endif
}

// exp(x) - 1 without cancellation for small x (Kahan's trick): (u - 1) x / ln u with u = exp(x) rounded. `precise`
// keeps u - 1 as computed (see log1p_over_x) and log_accurate keeps ln u accurate near 1.
float exp_minus_one(float x) {
    precise float u = exp(x);
    if (u == 1.0) {
        return x;
    }
    precise float um1 = u - 1.0;
    if (um1 == -1.0) {
        return -1.0;
    }
    return um1 * x / log_accurate(u);
}

// asinh(x) without cancellation: sign(x) log1p(|x| + x^2 / (1 + sqrt(1 + x^2))) (the device's asinh goes through
// log(x + sqrt(x^2 + 1)), which loses the digits of small x); ln(2|x|) where x^2 would overflow. log1p_accurate's
// steps written out, so that both branches take their logarithm from one call of log_accurate (the driver inlines
// each call): the same operations on the same values.
float asinh_accurate(float x) {
    float a = abs(x);
    bool huge = a > 1e18;
    float t = a + a * a / (1.0 + sqrt(1.0 + a * a));
#ifdef SUNSHADE_NAIVE_MATH
    float r = huge ? log_accurate(a) + 0.69314718055994530942 : log1p_accurate(t);
#else
    precise float u = 1.0 + t;
    precise float um1 = u - 1.0;
    float ln = log_accurate(huge ? a : u);
    float r = huge ? ln + 0.69314718055994530942 : (u == 1.0 ? t : ln * t / um1);
#endif
    return x < 0.0 ? -r : r;
}

// sinh(z) without cancellation near 0: (expm1(z) - expm1(-z)) / 2.
float sinh_accurate(float z) {
    return 0.5 * (exp_minus_one(z) - exp_minus_one(-z));
}

#endif
