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

// atan2(y, x) in (-pi, pi] from atan_accurate; 0 for (0, 0).
float atan2_accurate(float y, float x) {
    if (x == 0.0 && y == 0.0) {
        return 0.0;
    }
    if (abs(x) >= abs(y)) {
        float r = atan_accurate(y / x);
        return x > 0.0 ? r : (y >= 0.0 ? r + PI : r - PI);
    }
    float r = atan_accurate(x / y);
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

// log1p(x) by Goldberg's trick from log (0-1 ulp on lavapipe).
float log1p_accurate(float x) {
    float u = 1.0 + x;
    return u == 1.0 ? x : log(u) * x / (u - 1.0);
}

#endif
