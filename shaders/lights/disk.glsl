// Disk lights in f32: the projected solid angle (the small-source estimate, and the exact value by Stokes' theorem,
// the disk cut by the horizon included), the visible fraction, and its two terms in a shading point's sum
// (disk_term, disk_specular_visible). Mirrors src/shading/lights/disk.rs name for name
// (the Rust is the specification; its doc comments derive the formulas and say where precision is at stake).
// Units: radians, steradians, W/m^2 (irradiance), W/(m^2 sr) (radiance).
#ifndef SUNSHADE_LIGHTS_DISK_GLSL
#define SUNSHADE_LIGHTS_DISK_GLSL

#include "math.glsl"
#include "visibility.glsl"
#include "shadow_map.glsl"
#include "lobe.glsl"

// A partly visible disk's segment is integrated directly when it is thin (rim arc half-angle below this) or the
// receiver is at least a radius from every point of the disk; the contour form is used otherwise (see the Rust).
const float THIN_SEGMENT_ALPHA = 0.3;
// 16-point Gauss-Legendre, the positive half (nodes, weights); the rule is symmetric.
const float GL16_X[8] = float[8](0.095012509837637441, 0.28160355077925892, 0.45801677765722737, 0.61787624440264377, 0.755404408355003, 0.86563120238783176, 0.9445750230732326, 0.98940093499164994);
const float GL16_W[8] = float[8](0.18945061045506864, 0.18260341504492364, 0.16915651939500265, 0.14959598881657671, 0.12462897125553407, 0.095158511682492605, 0.062253523938647456, 0.027152459411754176);

// The small-source estimate of a disk's projected solid angle [sr]: A cos_r cos_d / d^2.
float disk_projected_solid_angle_small_source(vec3 x, vec3 n, vec3 center, vec3 direction, float radius) {
    vec3 to_disk = center - x;
    float d2 = dot(to_disk, to_disk);
    if (d2 == 0.0) {
        return 0.0;
    }
    float d = sqrt(d2);
    float cos_receiver = max(dot(n, to_disk) / d, 0.0);
    float cos_disk = max(-dot(direction, to_disk) / d, 0.0);
    return PI * radius * radius * cos_receiver * cos_disk / d2;
}

// n.Phi for a disk entirely above the horizon (closed-form vector irradiance without cancellation).
float full_disk_projected_solid_angle(vec3 n, vec3 d, vec3 r_perp, float h, float rho2, float radius) {
    float h2 = h * h;
    float r2 = radius * radius;
    float a = rho2 + h2 + r2;
    float rho = sqrt(rho2);
    float diff = (rho - radius) * (rho + radius);
    float s = sqrt(diff * diff + 2.0 * h2 * (rho2 + r2) + h2 * h2);
    float b = rho2 + h2 - r2;
    float axial = b >= 0.0 ? 2.0 * PI * r2 * h2 / (s * (s + b)) : 0.5 * PI * (1.0 - b / s);
    float radial = 2.0 * PI * h * r2 / (s * (a + s));
    return -axial * dot(n, d) - radial * dot(n, r_perp);
}

// tan(phi/2) for phi in [-pi, pi]; +-pi map to +-1e30 (f32's pi/2 lies above the true pi/2, where tan flips sign).
float tan_half(float phi) {
    if (phi >= PI) {
        return 1e30;
    }
    if (phi <= -PI) {
        return -1e30;
    }
    return tan(0.5 * phi);
}

// log1p(x)/x, 1 at 0, by Goldberg's trick: u = 1 + x rounded, ln(u)/(u - 1). `precise` keeps the compiler from
// folding (1 + x) - 1 into x (NIR does that to inexact arithmetic on lavapipe), which would undo the trick.
float log1p_over_x(float x) {
    precise float u = 1.0 + x;
    precise float um1 = u - 1.0;
    if (u == 1.0) {
        return 1.0;
    }
    return log_accurate(u) / um1;
}

// (integral dphi/D, integral cos phi/D, integral sin phi/D) over [phi_a, phi_b], D = b0 + b cos phi.
vec3 rim_integrals(float phi_a, float phi_b, float b0, float b) {
    float shift = floor((phi_a + PI) / (2.0 * PI)) * 2.0 * PI;
    float a = max(phi_a - shift, -PI);
    float z = phi_b - shift;
    vec2 pieces[2];
    int count = 0;
    if (min(z, PI) > a) {
        pieces[count++] = vec2(a, min(z, PI));
    }
    if (min(z - 2.0 * PI, PI) > -PI) {
        pieces[count++] = vec2(-PI, min(z - 2.0 * PI, PI));
    }
    float eps = b / b0;
    float sq = sqrt((1.0 - eps) * (1.0 + eps));
    float lambda = sqrt((1.0 - eps) / (1.0 + eps));
    float one_minus_lambda = 2.0 * eps / (sqrt(1.0 + eps) * (sqrt(1.0 + eps) + sqrt(1.0 - eps)));
    float inv_sq_minus_one = eps * eps / (sq * (1.0 + sq));
    vec3 j = vec3(0.0);
    for (int i = 0; i < count; ++i) {
        float pa = pieces[i].x;
        float pb = pieces[i].y;
        float ta = tan_half(pa);
        float tb = tan_half(pb);
        float g_lambda = atan_accurate(lambda * tb) - atan_accurate(lambda * ta);
        j.x += 2.0 / (b0 * sq) * g_lambda;
        if (eps == 0.0) {
            j.y += (sin(pb) - sin(pa)) / b0;
        } else {
            float da = atan_accurate(one_minus_lambda / (1.0 / ta + lambda * ta));
            float db = atan_accurate(one_minus_lambda / (1.0 / tb + lambda * tb));
            j.y += 2.0 * ((db - da) - g_lambda * inv_sq_minus_one) / b;
        }
        float dcos = 2.0 * sin(0.5 * (pa + pb)) * sin(0.5 * (pb - pa));
        float denom = b0 + b * cos(pb);
        j.z += dcos / denom * log1p_over_x(b * dcos / denom);
    }
    return j;
}

// The projected solid angle of a visible segment by 16 x 16 Gauss-Legendre over beta in [0, alpha] and
// s in [-1, 1]: the integrand (n.y) h / |y|^4 R^2 sin^2(beta) is positive and smooth, so nothing cancels.
float segment_projected_solid_angle(vec3 n, vec3 d, vec3 q, float h, float radius, float alpha) {
    vec3 w = normalize(n - dot(n, d) * d);
    vec3 v = cross(d, w);
    float sum = 0.0;
    for (int i = 0; i < 16; ++i) {
        float xb = i < 8 ? -GL16_X[7 - i] : GL16_X[i - 8];
        float wb = i < 8 ? GL16_W[7 - i] : GL16_W[i - 8];
        float beta = 0.5 * alpha * (xb + 1.0);
        float sb = sin(beta);
        float cb = cos(beta);
        for (int j = 0; j < 16; ++j) {
            float xs = j < 8 ? -GL16_X[7 - j] : GL16_X[j - 8];
            float ws = j < 8 ? GL16_W[7 - j] : GL16_W[j - 8];
            vec3 y = q + radius * cb * w + radius * sb * xs * v;
            float d2 = dot(y, y);
            sum += wb * ws * max(dot(n, y), 0.0) * h / (d2 * d2) * radius * radius * sb * sb;
        }
    }
    return sum * 0.5 * alpha;
}

// The segment of a disk above the horizon: rim arc plus chord.
float partial_disk_projected_solid_angle(vec3 n, vec3 d, vec3 q, vec3 r_perp, float h, float rho, float radius) {
    vec3 e1 = rho > 0.0 ? -r_perp / rho : orthonormal_to(d);
    vec3 e2 = cross(d, e1);
    float n1 = dot(n, e1);
    float n2 = dot(n, e2);
    float n_d = dot(n, d);
    float m = sqrt(n1 * n1 + n2 * n2);
    float gamma = atan2_accurate(n2, n1);
    float kappa = clamp(-dot(n, q) / (radius * m), -1.0, 1.0);
    float alpha = atan2_accurate(sqrt((1.0 - kappa) * (1.0 + kappa)), kappa);
    float beyond_rim = max(rho - radius, 0.0);
    if (alpha < THIN_SEGMENT_ALPHA || h * h + beyond_rim * beyond_rim >= radius * radius) {
        return segment_projected_solid_angle(n, d, q, h, radius, alpha);
    }
    float b0 = h * h + rho * rho + radius * radius;
    float b = 2.0 * radius * rho;
    vec3 j = rim_integrals(gamma - alpha, gamma + alpha, b0, b);
    float rim = radius * (n_d * radius * j.x + (n_d * rho + h * n1) * j.y + h * n2 * j.z);
    vec3 pa = q + radius * (cos(gamma - alpha) * e1 + sin(gamma - alpha) * e2);
    vec3 pb = q + radius * (cos(gamma + alpha) * e1 + sin(gamma + alpha) * e2);
    vec3 c = cross(pb, pa);
    float theta = atan2_accurate(length(c), dot(pb, pa));
    float chord = dot(n, c) >= 0.0 ? theta : -theta;
    return -0.5 * (rim + chord);
}

// The exact projected solid angle [sr] of the part of a disk above the receiver's horizon: E = L0 * this.
float disk_projected_solid_angle(vec3 x, vec3 n, vec3 center, vec3 direction, float radius) {
    vec3 r = x - center;
    float h = dot(r, direction);
    if (!(h > 0.0 && radius > 0.0)) {
        return 0.0;
    }
    vec3 r_perp = r - h * direction;
    float rho2 = dot(r_perp, r_perp);
    vec3 q = -r;
    float n_d = dot(n, direction);
    float n_perp_len = length(n - n_d * direction);
    float nq = dot(n, q);
    if (nq - radius * n_perp_len >= 0.0) {
        return full_disk_projected_solid_angle(n, direction, r_perp, h, rho2, radius);
    }
    if (nq + radius * n_perp_len <= 0.0) {
        return 0.0;
    }
    return partial_disk_projected_solid_angle(n, direction, q, r_perp, h, sqrt(rho2), radius);
}

// What the occluders do to the disk light's shadow rays from origin (moved off x, of normal n): the walk of
// disk_cone.glsl where the shader walks the occluders' tree (DISK_CONE_CLEAR: every ray of the grid and the lobe
// gets through; DISK_CONE_LIST: only the listed triangles can meet them); elsewhere unknown (the rays decide).
uint disk_rays_gather(vec3 origin, vec3 x, vec3 n, vec3 center, vec3 d, float radius) {
#if defined(SUNSHADE_WALK) && defined(SUNSHADE_SHADOW_RAYS)
    return disk_cone_gather(origin, x, n, center, d, radius);
#else
    return DISK_CONE_UNKNOWN;
#endif
}

// The visible fraction of a disk light, weighted by projected solid angle, from x with normal n: -1, the located
// grid over `grid` to find it (irradiance_visible); its rays test only the triangles the walk listed where `listed`
// (disk_rays_gather).
float disk_visible_fraction(vec3 x, vec3 n, vec3 center, vec3 d, float radius, bool listed,
                            out VisibilityLight grid) {
    vec3 a = orthonormal_to(d);
    grid = VisibilityLight(listed ? GRID_LIGHT_DISK_LISTED : GRID_LIGHT_DISK, x, n, center, d, a, cross(d, a),
                           radius, 0.0);
    return -1.0;
}

// The first disks' visible fractions from their maps, found by disk_term and reused by the specular term.
float disk_map_fraction[MAX_DISK_MAPS] = float[](1.0, 1.0, 1.0, 1.0);
// Bit i: the rays of disk light i (the first 32) proven clear by disk_term (disk_rays_gather): its
// lobe's samples then cast none, every one of them getting through.
uint disk_rays_clear = 0u;

// Disk light i's term of the irradiance [W/m^2] per channel from its visible part, L0 (Omega v) (the exact or the
// small-source model, the pipeline variant's; disk_irradiance_visible in the Rust), v left to irradiance_visible's
// grid where the light needs one; keeps what its specular term reuses (disk_map_fraction, disk_rays_clear).
LightTerm disk_term(uint i, Frame p) {
    vec3 position = p.position;
    vec3 normal = p.normal;
    uint k = lights.sampling.y;
    DiskGpu d = lights.disks[i];
    float omega = VARIANT_DISKS == DISKS_SMALL_SOURCE
        ? disk_projected_solid_angle_small_source(position, normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w)
        : disk_projected_solid_angle(position, normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w);
    LightTerm term = LightTerm(d.radiance.rgb, omega, true, 1.0, k, NO_GRID_LIGHT);
    if (SHADOWS_ON && omega > 0.0) {
        if (VARIANT_DISKS == DISKS_SMALL_SOURCE) {
            term.v = visible_to(p.shadow_origin, d.center_radius.xyz) ? 1.0 : 0.0;
        } else {
            // By slices where asked and the shader walks the BVH itself, or by their passes, as the sun's.
            term.v = -1.0;
#ifdef SUNSHADE_SLICES
            if (VARIANT_VISIBILITY == VISIBILITY_SLICES) {
                term.v = (lights.light_rows.w & READ_DISKS) != 0u
                    ? PASSED_FRACTION(ROWS_OF_DISK + i)
                    : disk_visible_fraction_sliced(p.shadow_origin, normal, d.center_radius.xyz, d.direction.xyz,
                                                   d.center_radius.w, 4u * k * k);
            }
#endif
            if (term.v < 0.0) {
                uint gathered = disk_rays_gather(p.shadow_origin, position, normal, d.center_radius.xyz,
                                                 d.direction.xyz, d.center_radius.w);
                if (gathered == DISK_CONE_CLEAR) {
                    term.v = 1.0;
                    disk_rays_clear |= i < 32u ? 1u << i : 0u;
                } else {
                    term.v = disk_visible_fraction(position, normal, d.center_radius.xyz, d.direction.xyz,
                                                   d.center_radius.w, gathered == DISK_CONE_LIST, term.grid);
                }
            }
        }
    }
    if (SHADOWS_MAP_ON && i < MAX_DISK_MAPS && lights.disk_map[i].w > 0.0 && omega > 0.0) {
        bool pcss = VARIANT_DISKS != DISKS_SMALL_SOURCE && lights.sampling.z == 1u;
        term.v = disk_visible_fraction_map(i, p.shadow_origin, k, position, normal, p.face_normal,
            d.center_radius.xyz, d.direction.xyz, d.center_radius.w, pcss);
        disk_map_fraction[i] = term.v;
    }
    return term;
}

// The segment disk light i's specular term integrates the lobe over (the disk, exact model), for radiance_out's one
// call of segment_lobe_integral_visible; none for a small source.
SegmentAsk disk_specular_segment(uint i, Frame p) {
    if (VARIANT_DISKS == DISKS_SMALL_SOURCE) {
        return NO_SEGMENT;
    }
    DiskGpu d = lights.disks[i];
    // The grid's sum as it is (see disk_lobe_integral in the Rust); no rays where they are proven clear.
    bool clear = i < 32u && (disk_rays_clear & (1u << i)) != 0u;
    return SegmentAsk(true, d.center_radius.xyz - p.position, d.direction.xyz, d.center_radius.w, pc.lobe_samples,
                      SHADOWS_ON && !clear ? RAYS_TO_POINT : RAYS_NONE);
}

// Disk light i's specular term [W/(m^2 sr)] per channel, to be scaled by ks: the lobe over the disk (exact:
// `sums`, disk_specular_segment's) or towards its centre (small source), visible part only (see the Rust).
vec3 disk_specular_visible(uint i, MaterialGpu material, Frame p, SegmentSums sums) {
    DiskGpu d = lights.disks[i];
    vec3 integral;
    if (VARIANT_DISKS == DISKS_SMALL_SOURCE) {
        vec3 to_center = safe_normalize(d.center_radius.xyz - p.position);
        float omega = disk_projected_solid_angle_small_source(p.position, p.normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w);
        integral = specular_lobe_rgb(material, p, to_center) * omega;
        if (SHADOWS_ON && any(greaterThan(integral, vec3(0.0))) && !visible_to(p.shadow_origin, d.center_radius.xyz)) {
            integral = vec3(0.0);
        }
    } else {
        integral = sums.lobe;
    }
    if (SHADOWS_MAP_ON && i < MAX_DISK_MAPS) {
        integral *= disk_map_fraction[i];
    }
    return integral * d.radiance.rgb;
}

#endif
