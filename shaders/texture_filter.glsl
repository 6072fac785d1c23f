// Texture lookups specified by sunshade, not by the device (docs/textures.md). Mirrors
// src/shading/texture_filter.rs name for name: coordinates, footprints and texel indices in REAL (f64 where the
// device has it), blend weights rounded to f32 and blends in f32 in the same order (`precise`: no fused
// multiply-adds), so that the GPU and the reference pick the same texels and levels and blend them bitwise alike.
#ifndef SUNSHADE_TEXTURE_FILTER_GLSL
#define SUNSHADE_TEXTURE_FILTER_GLSL

#include "bindings.glsl"

// Coordinates beyond +-2^40 texels (and NaN) are taken as 0 (MAX_TEXEL_COORDINATE in the Rust).
#define MAX_TEXEL_COORDINATE 1099511627776.0

// The level choice of a lookup (Rust: LevelChoice).
struct LevelChoice {
    uint filter_kind;
    uint level;
    float blend;
};

// A texel index in [0, n) for an integer-valued i, by the wrap mode.
uint wrap_texel(REAL i, uint n, uint wrap) {
    REAL nn = REAL(n);
    precise REAL w;
    if (wrap == WRAP_REPEAT) {
        w = i - nn * floor(i / nn);
    } else if (wrap == WRAP_CLAMP_TO_EDGE) {
        w = clamp(i, REAL(0.0), nn - REAL(1.0));
    } else {
        precise REAL p = i - REAL(2.0) * nn * floor(i / (REAL(2.0) * nn));
        w = p >= nn ? REAL(2.0) * nn - REAL(1.0) - p : p;
    }
    return uint(clamp(w, REAL(0.0), nn - REAL(1.0)));
}

// A coordinate in texels, NaN and far-off values taken as 0.
REAL texel_coordinate(REAL x) {
    return abs(x) < REAL(MAX_TEXEL_COORDINATE) ? x : REAL(0.0);
}

// The linear value of an 8-bit code from the code table at `table` (Rust: code_value).
float code_value(uint table, uint code) {
    return texelFetch(texels, int(table + code)).x;
}

// The texel (i, j) of a level entry (first texel, width, height, TEXELS_*): linear RGBA, an 8-bit level's codes
// read through the tables (colour channels in the level's colour space, alpha linear).
vec4 texel(uvec4 level, uint i, uint j) {
    int index = int(level.x + j * level.y + i);
    if (level.w == TEXELS_LINEAR) {
        return texelFetch(texels, index);
    }
    uvec4 c = texelFetch(texel_codes, index);
    uint colour = level.w == TEXELS_CODES_SRGB ? CODE_TABLE_SRGB : CODE_TABLE_LINEAR;
    return vec4(code_value(colour, c.r), code_value(colour, c.g), code_value(colour, c.b),
                code_value(CODE_TABLE_LINEAR, c.a));
}

// One level filtered at uv: nearest, or bilinear between the four texel centres around (u w - 1/2, v h - 1/2).
// The texels (one, or four corners k: x0 + (k & 1), y0 + (k >> 1)) are read by one call of texel in a loop, so
// that the driver, which inlines every call, compiles one texel read and two wraps a filter.
vec4 filter_level(uvec4 level, uint filter_kind, uint wrap_s, uint wrap_t, REAL2 uv) {
    uint w = level.y;
    uint h = level.z;
    bool nearest = filter_kind == FILTER_NEAREST;
    precise REAL x;
    precise REAL y;
    if (nearest) {
        x = floor(texel_coordinate(uv.x * REAL(w)));
        y = floor(texel_coordinate(uv.y * REAL(h)));
    } else {
        x = texel_coordinate(uv.x * REAL(w) - REAL(0.5));
        y = texel_coordinate(uv.y * REAL(h) - REAL(0.5));
    }
    REAL x0 = floor(x);
    REAL y0 = floor(y);
    vec4 t00 = vec4(0.0);
    vec4 t10 = vec4(0.0);
    vec4 t01 = vec4(0.0);
    vec4 t11 = vec4(0.0);
    uint corners = nearest ? 1u : 4u;
    for (uint k = 0u; k < corners; ++k) {
        // x0 + 0 is x0 (or +0 for -0, which wraps alike).
        vec4 t = texel(level, wrap_texel(x0 + REAL(k & 1u), w, wrap_s), wrap_texel(y0 + REAL(k >> 1u), h, wrap_t));
        if (k == 0u) {
            t00 = t;
        } else if (k == 1u) {
            t10 = t;
        } else if (k == 2u) {
            t01 = t;
        } else {
            t11 = t;
        }
    }
    if (nearest) {
        return t00;
    }
    precise float a = float(x - x0);
    precise float b = float(y - y0);
    precise float ra = 1.0 - a;
    precise float rb = 1.0 - b;
    precise vec4 top = t00 * ra + t10 * a;
    precise vec4 bottom = t01 * ra + t11 * a;
    precise vec4 result = top * rb + bottom * b;
    return result;
}

// x = m 2^e with m in [1/2, 1) (frexp on the bits, as the Rust does it); (0, 0) for 0. Only finite positive
// x reach here (footprints past 2^80 and NaN are handled before).
#ifdef SUNSHADE_F64_BARYCENTRICS
double split_exponent(double x, out int e) {
    uvec2 bits = unpackDouble2x32(x);
    int biased = int((bits.y >> 20u) & 0x7ffu);
    if (x == 0.0 || biased == 0) {
        e = 0;
        return 0.0;
    }
    e = biased - 1022;
    return packDouble2x32(uvec2(bits.x, (bits.y & 0x800fffffu) | (1022u << 20u)));
}
#else
float split_exponent(float x, out int e) {
    uint bits = floatBitsToUint(x);
    int biased = int((bits >> 23u) & 0xffu);
    if (x == 0.0 || biased == 0) {
        e = 0;
        return 0.0;
    }
    e = biased - 126;
    return uintBitsToFloat((bits & 0x807fffffu) | (126u << 23u));
}
#endif

// The level (and the next level's blend weight) from the pixel's footprint in level-0 texels (see the Rust).
LevelChoice choose_level(uvec4 header, uvec4 level0, REAL2 uv, REAL2 uv_x, REAL2 uv_y) {
    uint bits = header.z;
    uint mag = (bits >> 4u) & 1u;
    uint min_filter = (bits >> 5u) & 1u;
    uint mip = (bits >> 6u) & 3u;
    REAL w = REAL(level0.y);
    REAL h = REAL(level0.z);
    precise REAL dxu = (uv_x.x - uv.x) * w;
    precise REAL dxv = (uv_x.y - uv.y) * h;
    precise REAL dyu = (uv_y.x - uv.x) * w;
    precise REAL dyv = (uv_y.y - uv.y) * h;
    precise REAL rho2 = max(dxu * dxu + dxv * dxv, dyu * dyu + dyv * dyv);
    LevelChoice c;
    c.filter_kind = min_filter;
    c.level = 0u;
    c.blend = 0.0;
    if (!(rho2 > REAL(1.0))) {
        c.filter_kind = mag;
        return c;
    }
    uint last = header.y - 1u;
    if (!(rho2 < REAL(MAX_TEXEL_COORDINATE) * REAL(MAX_TEXEL_COORDINATE))) {
        c.level = mip == MIP_NONE ? 0u : last;
        return c;
    }
    int e;
    precise REAL m = split_exponent(sqrt(rho2), e);
    uint d = uint(max(e - 1, 0));
    if (mip == MIP_NEAREST) {
        c.level = min(REAL(2.0) * m * m >= REAL(1.0) ? d + 1u : d, last);
    } else if (mip == MIP_LINEAR) {
        if (d >= last) {
            c.level = last;
        } else {
            c.level = d;
            c.blend = float(REAL(2.0) * m - REAL(1.0));
        }
    }
    return c;
}

// texture_lookup with no footprint (uv_x = uv_y = uv, a shadow ray's hit): level 0, the magnification filter.
vec4 texture_magnified(uint t, REAL2 uv) {
    uvec4 header = texture_table[t];
    uint wrap_s = header.z & 3u;
    uint wrap_t = (header.z >> 2u) & 3u;
    return filter_level(texture_table[header.x], (header.z >> 4u) & 1u, wrap_s, wrap_t, uv);
}

// Texture t looked up at uv with the footprint given by the UVs at the right and lower neighbouring pixel
// centres: choose_level, then filter_level on one level or two, blended r0 (1 - d) + r1 d in f32. The levels are
// filtered by one call in a loop, so that the driver, which inlines every call, compiles filter_level once a lookup.
vec4 texture_lookup(uint t, REAL2 uv, REAL2 uv_x, REAL2 uv_y) {
    uvec4 header = texture_table[t];
    LevelChoice c = choose_level(header, texture_table[header.x], uv, uv_x, uv_y);
    uint wrap_s = header.z & 3u;
    uint wrap_t = (header.z >> 2u) & 3u;
    // No local array: llvmpipe reads and writes one lane by lane.
    vec4 r0 = vec4(0.0);
    vec4 r1 = vec4(0.0);
    uint levels = c.blend == 0.0 ? 1u : 2u;
    for (uint l = 0u; l < levels; ++l) {
        vec4 r = filter_level(texture_table[header.x + c.level + l], c.filter_kind, wrap_s, wrap_t, uv);
        if (l == 0u) {
            r0 = r;
        } else {
            r1 = r;
        }
    }
    if (levels == 1u) {
        return r0;
    }
    precise float rd = 1.0 - c.blend;
    precise vec4 result = r0 * rd + r1 * c.blend;
    return result;
}

#endif
