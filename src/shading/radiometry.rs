//! Radiometry: angles, solid angles and the irradiance each light gives a surface.
//!
//! Units: angles in radians unless a name says degrees; solid angles in steradians \[sr\]; radiance `L` in
//! W/(m²·sr); irradiance `E` in W/m². `shaders/radiometry.glsl` mirrors these functions name for name.
//!
//! Definitions (e.g. Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., §4.1):
//! - irradiance at `x` with normal `n`: `E = ∫ L(x, l) (n·l) dΩ` over the hemisphere;
//! - solid angle of a cone of half-angle `a`: `Ω = 2π(1 − cos a)`.

use std::f64::consts::PI;

use glam::DVec3;

pub use crate::scene::light::SUN_ANGULAR_DIAMETER_DEGREES;

/// Default irradiance on a surface facing the sun, `E⊥` [W/m²].
pub const DEFAULT_SUN_IRRADIANCE: f64 = 1000.0;

pub fn degrees_to_radians(degrees: f64) -> f64 {
    degrees * (PI / 180.0)
}

pub fn radians_to_degrees(radians: f64) -> f64 {
    radians * (180.0 / PI)
}

/// Exact solid angle \[sr\] of a cone of half-angle `half_angle` \[rad\]: `2π(1 − cos a)`.
///
/// Precision: for small cones `1 − cos a` cancels catastrophically (for the sun, `cos a = 1 − 1.07·10⁻⁵`, losing
/// five digits). The identity `1 − cos a = 2 sin²(a/2)` gives the same value without any subtraction.
pub fn cone_solid_angle(half_angle: f64) -> f64 {
    let s = (0.5 * half_angle).sin();
    4.0 * PI * s * s
}

/// Small-cone estimate of a solid angle \[sr\]: `area of the base / height²` (base area \[m²\], height \[m\]).
///
/// For a sphere of radius `r` seen from distance `d` (the sun) the base is its cross-section `π r²` and the
/// estimate is `π sin²a`, low by ≈ `a²/4` relative (5.3·10⁻⁶ for the sun). For a flat disk of radius `r` at
/// height `d` it is `π tan²a`, high by ≈ `3a²/4`.
pub fn small_cone_solid_angle(base_area: f64, height: f64) -> f64 {
    base_area / (height * height)
}

/// The sun's solid angle `Ω_sun` \[sr\] from its angular diameter `δ` \[rad\]: `2π(1 − cos(δ/2))`.
pub fn sun_solid_angle(angular_diameter: f64) -> f64 {
    cone_solid_angle(0.5 * angular_diameter)
}

/// Projected solid angle \[sr\] of the sun's cone at normal incidence: `∫ cosθ dΩ = π sin²(δ/2)`.
///
/// This is the exact ratio `E⊥ / L_sun`; it equals `Ω_sun (1 + cos(δ/2))/2`, i.e. `Ω_sun` to within
/// `sin²(δ/4)` relative (5.3·10⁻⁶ at 0.53°).
pub fn sun_projected_solid_angle(angular_diameter: f64) -> f64 {
    let s = (0.5 * angular_diameter).sin();
    PI * s * s
}

/// `E⊥` [W/m²] from the sun's radiance `L_sun` [W/(m²·sr)]: `E⊥ = L_sun · π sin²(δ/2)` (≈ `L_sun · Ω_sun`).
pub fn sun_irradiance_from_radiance(radiance: f64, angular_diameter: f64) -> f64 {
    radiance * sun_projected_solid_angle(angular_diameter)
}

/// `L_sun` [W/(m²·sr)] from `E⊥` [W/m²]; the inverse of [`sun_irradiance_from_radiance`].
pub fn sun_radiance_from_irradiance(irradiance: f64, angular_diameter: f64) -> f64 {
    irradiance / sun_projected_solid_angle(angular_diameter)
}

/// Irradiance [W/m²] from the sun treated as a direction (a delta light): `E = E⊥ · max(0, n·l)`.
///
/// `n_dot_l` is the cosine between the unit surface normal and the unit direction towards the sun.
pub fn sun_irradiance_delta(irradiance_normal: f64, n_dot_l: f64) -> f64 {
    irradiance_normal * n_dot_l.max(0.0)
}

/// `atan(t) − t` without the cancellation of the direct difference for small `t` (≈ −t³/3): the Taylor series
/// for `|t| < 0.5` (error below 1e-17 with 28 terms), the difference itself beyond, where it loses at most a factor
/// 14 of relative precision.
pub fn atan_minus_identity(t: f64) -> f64 {
    if t.abs() >= 0.5 {
        return t.atan() - t;
    }
    let t2 = t * t;
    // Σ_{k≥1} (−1)^k t^{2k+1}/(2k+1), summed from the smallest term up.
    let mut sum = 0.0;
    for k in (1..=28).rev() {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        sum = sum * t2 + sign / (2 * k + 1) as f64;
    }
    sum * t2 * t
}

/// Irradiance [W/m²] from the sun as a disk (a cone of directions of half-angle δ/2 and uniform radiance) on a
/// surface whose normal makes angle θ with the sun's centre (`cos_theta = n·l`).
///
/// While the whole disk is above the horizon (`cos θ ≥ sin(δ/2)`) the result is exactly `E⊥ cos θ` (the cap's
/// projected solid angle is `π sin²(δ/2) cos θ`). Within δ/2 of the horizon only part of the disk is visible; by
/// the contour integral over its boundary (the cap's rim above the horizon and the horizon arc inside the cap;
/// the same result as Snyder's sphere-light formula, e.g. Lagarde & de Rousiers 2014, §4.7.2):
///
/// `E/L = s² cosθ (π − φ₀) − c s sinθ sin φ₀ + atan(t)`, with `s, c = sin, cos(δ/2)`,
/// `cos φ₀ = cot(δ/2) cot θ`, `t = s sinθ sinφ₀ / c`.
///
/// Precision: for the sun the last two terms are each about `1/σ ≈ 216` and cancel to ~1e-3. Since
/// `c s sinθ sinφ₀ = c² t`, the sum is rewritten `s² (cosθ (π − φ₀) + t) + (atan(t) − t)`, and `atan(t) − t` is
/// taken from its series: no term cancels. `acos` is avoided in favour of `atan2` (lavapipe's `acos` is off by up to
/// 4e-4). E goes to 0 continuously and monotonically as the sun sets.
pub fn sun_irradiance_disk(irradiance_normal: f64, cos_theta: f64, angular_diameter: f64) -> f64 {
    let (s, c) = (0.5 * angular_diameter).sin_cos();
    if cos_theta >= s {
        return irradiance_normal * cos_theta;
    }
    if cos_theta <= -s {
        return 0.0;
    }
    let sin_theta = ((1.0 - cos_theta) * (1.0 + cos_theta)).sqrt();
    let k = ((c * cos_theta) / (s * sin_theta)).clamp(-1.0, 1.0);
    let sin_phi0 = ((1.0 - k) * (1.0 + k)).sqrt();
    let pi_minus_phi0 = sin_phi0.atan2(-k);
    let t = s * sin_theta * sin_phi0 / c;
    let projected = s * s * (cos_theta * pi_minus_phi0 + t) + atan_minus_identity(t);
    irradiance_normal * projected / (PI * s * s)
}

/// Irradiance [W/m²] from a uniform overcast sky of radiance `L0` [W/(m²·sr)] over the whole sphere, unoccluded,
/// on a surface tilted by `t` from up (`n_dot_up = cos t`): `E = π L0 (1 + cos t)/2`.
pub fn sky_irradiance(radiance: f64, n_dot_up: f64) -> f64 {
    PI * radiance * 0.5 * (1.0 + n_dot_up)
}

/// A disk light's geometry in world space: centre \[m\], unit emission direction, radius \[m\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskGeometry {
    pub center: DVec3,
    pub direction: DVec3,
    pub radius: f64,
}

/// The lecture's small-source estimate of a disk's projected solid angle \[sr\] from `x` with normal `n`:
/// `A cosθ_receiver cosθ_disk / d²` (`A = πR²`, d the distance to the centre; each cosine clamped at 0). Under a
/// disk at height f facing down it is `A (n·l)⁴ / f²` on the floor. `E ≈ L0 ·` this.
pub fn disk_projected_solid_angle_small_source(x: DVec3, n: DVec3, disk: &DiskGeometry) -> f64 {
    let to_disk = disk.center - x;
    let d2 = to_disk.length_squared();
    if d2 == 0.0 {
        return 0.0;
    }
    let d = d2.sqrt();
    let cos_receiver = (n.dot(to_disk) / d).max(0.0);
    let cos_disk = (-disk.direction.dot(to_disk) / d).max(0.0);
    PI * disk.radius * disk.radius * cos_receiver * cos_disk / d2
}

/// The exact projected solid angle \[sr\] of the part of a disk that lies above the horizon of a receiver at `x`
/// with unit normal `n` (0 behind the disk's emitting face): `E = L0 ·` this.
///
/// By Stokes' theorem the projected solid angle of a region is `−½ ∮ n·(p × dp)/|p|²` around its boundary (the
/// contour form of the irradiance integral; Lambert's polygon formula is its special case). For a disk
/// entirely above the horizon the integral has a closed form, the vector irradiance
/// `Φ = −2πR²h²/(S(S + ρ² + h² − R²)) d − 2πhR²/(S(a + S)) r⊥`, with h the receiver's height above the disk plane,
/// r⊥ its offset from the axis in that plane (ρ = |r⊥|), `a = ρ² + h² + R²`, `S² = a² − 4ρ²R²`; on the axis it
/// gives `πR²/(R² + h²)` and its d-component is the parallel-plane view factor
/// `(π/2)(1 − (h² + ρ² − R²)/S)`. Written this way nothing cancels (the textbook `1 − (…)/S` loses four digits
/// for R/h = 0.05 in f32) and nothing divides by ρ.
///
/// A disk cut by the horizon leaves a circular segment, bounded by an arc of the rim and a chord in the horizon
/// plane. The chord contributes half the angle it subtends; the arc, `½∫(A0 + A1 cosφ + A2 sinφ)/(B0 + B cosφ)`,
/// is integrated in closed form with tangent half-angles ([`rim_integrals`]).
pub fn disk_projected_solid_angle(x: DVec3, n: DVec3, disk: &DiskGeometry) -> f64 {
    let (d, radius) = (disk.direction, disk.radius);
    let r = x - disk.center;
    let h = r.dot(d);
    if !(h > 0.0 && radius > 0.0) {
        return 0.0;
    }
    let r_perp = r - h * d;
    let rho2 = r_perp.length_squared();
    // Rim points relative to x: p(φ) = q + R (cos φ e1 + sin φ e2), q = C − x. Their height above the horizon is
    // n·q + R (n_perp · u(φ)), between n·q − R|n_perp| and n·q + R|n_perp|.
    let q = -r;
    let n_d = n.dot(d);
    let n_perp_len = (n - n_d * d).length();
    let nq = n.dot(q);
    if nq - radius * n_perp_len >= 0.0 {
        return full_disk_projected_solid_angle(n, d, r_perp, h, rho2, radius);
    }
    if nq + radius * n_perp_len <= 0.0 {
        return 0.0;
    }
    partial_disk_projected_solid_angle(n, d, q, r_perp, h, rho2.sqrt(), radius)
}

/// `n·Φ` for a disk entirely above the horizon (see [`disk_projected_solid_angle`]).
fn full_disk_projected_solid_angle(n: DVec3, d: DVec3, r_perp: DVec3, h: f64, rho2: f64, radius: f64) -> f64 {
    let (h2, r2) = (h * h, radius * radius);
    let a = rho2 + h2 + r2;
    // S² = a² − 4ρ²R² = (ρ² − R²)² + 2h²(ρ² + R²) + h⁴, a sum of non-negative terms.
    let rho = rho2.sqrt();
    let diff = (rho - radius) * (rho + radius);
    let s = (diff * diff + 2.0 * h2 * (rho2 + r2) + h2 * h2).sqrt();
    let b = rho2 + h2 - r2;
    // (π/2)(1 − b/S): when b ≥ 0 the difference cancels, and 1 − b/S = 4R²h²/(S(S + b)) instead.
    let axial = if b >= 0.0 { 2.0 * PI * r2 * h2 / (s * (s + b)) } else { 0.5 * PI * (1.0 - b / s) };
    let radial = 2.0 * PI * h * r2 / (s * (a + s));
    -axial * n.dot(d) - radial * n.dot(r_perp)
}

/// The segment of a disk above the horizon: rim arc plus chord (see [`disk_projected_solid_angle`]).
fn partial_disk_projected_solid_angle(
    n: DVec3,
    d: DVec3,
    q: DVec3,
    r_perp: DVec3,
    h: f64,
    rho: f64,
    radius: f64,
) -> f64 {
    // Frame in the disk plane: e1 from the receiver's axis foot towards the axis (any direction on the axis).
    let e1 = if rho > 0.0 { -r_perp / rho } else { super::orthonormal_to(d) };
    let e2 = d.cross(e1);
    let (n1, n2, n_d) = (n.dot(e1), n.dot(e2), n.dot(d));
    // Visible arc: n·q + R m cos(φ − γ) ≥ 0.
    let m = (n1 * n1 + n2 * n2).sqrt();
    let gamma = n2.atan2(n1);
    let kappa = (-n.dot(q) / (radius * m)).clamp(-1.0, 1.0);
    let alpha = ((1.0 - kappa) * (1.0 + kappa)).sqrt().atan2(kappa);
    let beyond_rim = (rho - radius).max(0.0);
    if alpha < THIN_SEGMENT_ALPHA || h * h + beyond_rim * beyond_rim >= radius * radius {
        return segment_projected_solid_angle(n, d, q, h, radius, alpha, SEGMENT_ORDER);
    }
    let (b0, b) = (h * h + rho * rho + radius * radius, 2.0 * radius * rho);
    let (j0, jc, js) = rim_integrals(gamma - alpha, gamma + alpha, b0, b);
    // The integrand's numerator, R [n_d R + (n_d ρ + h n1) cos φ + h n2 sin φ].
    let rim = radius * (n_d * radius * j0 + (n_d * rho + h * n1) * jc + h * n2 * js);
    // The chord from the arc's end back to its start, in the horizon plane: half the angle it subtends, signed.
    let rim_point = |phi: f64| q + radius * (phi.cos() * e1 + phi.sin() * e2);
    let (pa, pb) = (rim_point(gamma - alpha), rim_point(gamma + alpha));
    let cross = pb.cross(pa);
    let theta = cross.length().atan2(pb.dot(pa));
    let chord = theta * n.dot(cross).signum();
    -0.5 * (rim + chord)
}

/// When a disk is cut by the receiver's horizon, the visible segment's contour integral (rim arc + chord) is
/// badly conditioned in two cases, and the segment is then integrated directly
/// ([`segment_projected_solid_angle`]):
/// - a thin segment (rim arc half-angle α < 0.3): arc and chord each contribute O(α) and cancel to the O(α³)
///   result (relative error ≈ u/α²: 1.5e-5 at α = 0.01 in f64, 1e-6 at α = 0.25 in f32);
/// - a receiver at least a radius away from every point of the disk (`√(h² + max(ρ − R, 0)²) ≥ R`): arc and chord
///   are of the order of the angle the disk subtends, and the result can be smaller by thousands (0.3% error in
///   f32 on the teapot's lid seeing a disk of R/h = 0.16 near its horizon; 8e-5 on its side seeing a disk nearly
///   edge-on). There the integrand's singularity (the receiver) is at least R from the disk, and 16-point
///   Gauss–Legendre per axis is measured within 8e-9 of converged quadrature (test `segment_quadrature_accuracy`).
///
/// In the near field of a segment that is not thin, the contour form is well conditioned and exact.
pub const THIN_SEGMENT_ALPHA: f64 = 0.3;
pub const SEGMENT_ORDER: usize = 16;

/// The projected solid angle of a visible segment of a disk (rim arc of half-angle `alpha` about the horizon
/// cut), integrated directly: with w the in-plane direction in which points rise above the horizon and v across
/// it, the segment is `a = R cos β ≥ R cos α`, `b = R sin β · s`, `β ∈ [0, α]`, `s ∈ [−1, 1]`,
/// `dA = R² sin²β dβ ds`, and the integrand `(n·y) h / |y|⁴` is positive and smooth there. `order`-point
/// Gauss–Legendre in each variable.
pub fn segment_projected_solid_angle(
    n: DVec3,
    d: DVec3,
    q: DVec3,
    h: f64,
    radius: f64,
    alpha: f64,
    order: usize,
) -> f64 {
    let n_perp = n - n.dot(d) * d;
    let w = n_perp.normalize();
    let v = d.cross(w);
    let rule = super::quadrature::gauss_legendre(order);
    let mut sum = 0.0;
    for &(xb, wb) in &rule {
        let beta = 0.5 * alpha * (xb + 1.0);
        let (sb, cb) = beta.sin_cos();
        for &(xs, ws) in &rule {
            let y = q + radius * cb * w + radius * sb * xs * v;
            let d2 = y.length_squared();
            sum += wb * ws * n.dot(y).max(0.0) * h / (d2 * d2) * radius * radius * sb * sb;
        }
    }
    sum * 0.5 * alpha
}

/// `(∫dφ/D, ∫cos φ dφ/D, ∫sin φ dφ/D)` over `[φa, φb]` (length ≤ 2π), `D = B0 + B cos φ`, `0 ≤ B < B0`.
///
/// The arc is cut at ±π so that each piece has finite tangent half-angles `t = tan(φ/2)`. With `ε = B/B0` and
/// `λ = √((1−ε)/(1+ε))`: `∫dφ/D = 2/(B0√(1−ε²)) [atan(λt)]`, and `∫cos φ/D = (Δφ − B0∫dφ/D)/B`, which cancels
/// as ε → 0 (near the disk's axis); it is computed from `atan(t) − atan(λt) = atan((1−λ)/(1/t + λt))` and
/// `1/√(1−ε²) − 1 = ε²/(√(1−ε²)(1 + √(1−ε²)))`, both O(ε), so the division by ε is harmless.
/// `∫sin φ/D = ln((B0 + B cos φa)/(B0 + B cos φb))/B` is taken as `Δcos/(…) · log1p(x)/x`.
pub fn rim_integrals(phi_a: f64, phi_b: f64, b0: f64, b: f64) -> (f64, f64, f64) {
    let mut pieces = [(0.0, 0.0); 3];
    let mut count = 0;
    let mut push = |a: f64, z: f64| {
        if z > a {
            pieces[count] = (a, z);
            count += 1;
        }
    };
    // Bring the arc's start into [−π, π) and cut at π (the arc may wrap once).
    let shift = ((phi_a + PI) / (2.0 * PI)).floor() * 2.0 * PI;
    let (a, z) = ((phi_a - shift).max(-PI), phi_b - shift);
    push(a, z.min(PI));
    push(-PI, (z - 2.0 * PI).min(PI));
    let eps = b / b0;
    let sq = ((1.0 - eps) * (1.0 + eps)).sqrt();
    let lambda = ((1.0 - eps) / (1.0 + eps)).sqrt();
    let one_minus_lambda = 2.0 * eps / ((1.0 + eps).sqrt() * ((1.0 + eps).sqrt() + (1.0 - eps).sqrt()));
    let inv_sq_minus_one = eps * eps / (sq * (1.0 + sq));
    let (mut j0, mut jc, mut js) = (0.0, 0.0, 0.0);
    for &(pa, pb) in &pieces[..count] {
        let (ta, tb) = (tan_half(pa), tan_half(pb));
        // atan(λt); at t = ±∞ (φ = ±π) the limits ±π/2.
        let g_lambda = (lambda * tb).atan() - (lambda * ta).atan();
        j0 += 2.0 / (b0 * sq) * g_lambda;
        if eps == 0.0 {
            jc += (pb.sin() - pa.sin()) / b0;
        } else {
            let diff = |t: f64| (one_minus_lambda / (1.0 / t + lambda * t)).atan();
            let g1_minus_glambda = diff(tb) - diff(ta);
            jc += 2.0 * (g1_minus_glambda - g_lambda * inv_sq_minus_one) / b;
        }
        let dcos = 2.0 * (0.5 * (pa + pb)).sin() * (0.5 * (pb - pa)).sin(); // cos φa − cos φb
        let denom = b0 + b * pb.cos();
        let x = b * dcos / denom;
        js += dcos / denom * log1p_over_x(x);
    }
    (j0, jc, js)
}

/// `tan(φ/2)` for φ in [−π, π], with ±π mapped to ±1e30 explicitly: in f32, π/2 rounds above the true π/2 and
/// its tangent comes out hugely *negative*, which would flip an `atan` by π.
fn tan_half(phi: f64) -> f64 {
    if phi >= PI {
        1e30
    } else if phi <= -PI {
        -1e30
    } else {
        (0.5 * phi).tan()
    }
}

/// `log1p(x)/x`, 1 at x = 0.
pub fn log1p_over_x(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.ln_1p() / x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn degrees_round_trip() {
        assert_eq!(degrees_to_radians(180.0), PI);
        assert!((radians_to_degrees(degrees_to_radians(0.53)) - 0.53).abs() < 1e-15);
    }

    #[test]
    fn cone_solid_angle_matches_closed_forms() {
        // Hemisphere: 2π; full sphere: 4π; 60°: 2π(1 − 1/2) = π.
        assert!(rel(cone_solid_angle(PI / 2.0), 2.0 * PI) < 1e-15);
        assert!(rel(cone_solid_angle(PI), 4.0 * PI) < 1e-15);
        assert!(rel(cone_solid_angle(PI / 3.0), PI) < 1e-15);
        // Against the textbook form, whose own cancellation error is ulp(1)/(1 − cos a): 4e-14 at a = 0.1.
        for a in [0.5, 1.0, 2.0] {
            assert!(rel(cone_solid_angle(a), 2.0 * PI * (1.0 - f64::cos(a))) < 1e-14);
        }
        assert!(rel(cone_solid_angle(0.1), 2.0 * PI * (1.0 - f64::cos(0.1))) < 1e-13);
    }

    #[test]
    fn sun_solid_angle_and_radiance_give_1000_w_per_m2() {
        let delta = degrees_to_radians(0.53);
        let omega = sun_solid_angle(delta);
        // Hand value: a = 0.265° = 4.6251e-3 rad, Ω ≈ π a² (1 − a²/12) = 6.7204e-5 sr.
        assert!(rel(omega, 6.7204e-5) < 1e-4, "{omega}");
        // The brief's figure: L_sun ≈ 1.47e7 W/(m²·sr) gives ≈ 1000 W/m² (within its 2 significant digits).
        let e = sun_irradiance_from_radiance(1.47e7, delta);
        assert!((e - 1000.0).abs() < 20.0, "{e}");
        // E⊥ = L_sun Ω_sun to within sin²(δ/4) = 5.3e-6 relative.
        let l = 1.47e7;
        assert!((rel(l * omega, e) - 5.3e-6).abs() < 0.1e-6, "{}", rel(l * omega, e));
        assert!(rel(sun_radiance_from_irradiance(e, delta), l) < 1e-15);
    }

    #[test]
    fn small_cone_estimate_error_is_tiny_for_the_sun_and_large_at_60_degrees() {
        // Sphere seen at half-angle a (the sun): base = π r², height = d, r/d = sin a.
        let sphere = |a: f64| rel(small_cone_solid_angle(PI * a.sin().powi(2), 1.0), cone_solid_angle(a));
        let a_sun = degrees_to_radians(0.265);
        assert!((sphere(a_sun) - 5.35e-6).abs() < 0.05e-6, "{}", sphere(a_sun));
        // 60° half-angle: π sin²60° = 3π/4 against π: 25% low.
        assert!((sphere(PI / 3.0) - 0.25).abs() < 1e-12);
        // Flat disk of radius tan a at height 1: π tan² a; at 60°: 3π against π, 200% high.
        let disk = |a: f64| rel(small_cone_solid_angle(PI * a.tan().powi(2), 1.0), cone_solid_angle(a));
        assert!((disk(a_sun) - 0.75 * a_sun * a_sun).abs() < 1e-9);
        assert!((disk(PI / 3.0) - 2.0).abs() < 1e-12);
    }

    use crate::shading::quadrature::{integrate, integrate_composite as composite};

    fn down_disk(height: f64, radius: f64) -> DiskGeometry {
        DiskGeometry { center: DVec3::new(0.0, height, 0.0), direction: -DVec3::Y, radius }
    }

    #[test]
    fn disk_on_axis_and_off_axis_match_the_view_factor_formulas() {
        for (f, r) in [(2.0, 0.1), (2.0, 0.5), (2.0, 2.0), (2.0, 8.0), (1.0, 1e-3)] {
            let disk = down_disk(f, r);
            let on_axis = disk_projected_solid_angle(DVec3::ZERO, DVec3::Y, &disk);
            assert!(rel(on_axis, PI * r * r / (r * r + f * f)) < 1e-14, "{f} {r}: {on_axis}");
            for rho in [0.01, 0.3, 1.0, 1.999, 2.0, 2.001, 5.0, 40.0] {
                let x = DVec3::new(rho * 0.6, 0.0, rho * 0.8);
                let got = disk_projected_solid_angle(x, DVec3::Y, &disk);
                let (a, b) = (f * f + rho * rho + r * r, f * f + rho * rho - r * r);
                let s = (a * a - 4.0 * rho * rho * r * r).sqrt();
                let want = 0.5 * PI * (1.0 - b / s);
                // The textbook form itself cancels for small sources: compare to its own precision.
                let tol = 1e-13 * (a / (want * s)).max(1.0);
                assert!(rel(got, want) < tol.max(1e-12), "f {f} R {r} ρ {rho}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn receivers_behind_or_in_the_plane_of_the_disk_get_nothing() {
        let disk = down_disk(2.0, 1.0);
        assert_eq!(disk_projected_solid_angle(DVec3::new(0.0, 3.0, 0.0), -DVec3::Y, &disk), 0.0);
        assert_eq!(disk_projected_solid_angle(DVec3::new(3.0, 2.0, 0.0), DVec3::Y, &disk), 0.0);
        // Facing away from the disk: the whole disk is below the horizon.
        assert_eq!(disk_projected_solid_angle(DVec3::ZERO, -DVec3::Y, &disk), 0.0);
    }

    #[test]
    fn small_source_estimate_on_the_floor_is_l0_a_cos4_over_f2() {
        let disk = down_disk(2.0, 0.1);
        for x in [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.5), DVec3::new(-3.0, 0.0, 2.0)] {
            let cos = 2.0 / (disk.center - x).length();
            let want = PI * 0.01 * cos.powi(4) / 4.0;
            assert!(rel(disk_projected_solid_angle_small_source(x, DVec3::Y, &disk), want) < 1e-14);
        }
        // The estimate converges to the exact value as the disk shrinks, and differs for a big one.
        let exact = |r: f64| disk_projected_solid_angle(DVec3::ZERO, DVec3::Y, &down_disk(2.0, r));
        let small = |r: f64| disk_projected_solid_angle_small_source(DVec3::ZERO, DVec3::Y, &down_disk(2.0, r));
        assert!(rel(small(0.01), exact(0.01)) < 3e-5);
        assert!(rel(small(2.0), exact(2.0)) > 0.5);
    }

    #[test]
    fn rim_integrals_match_quadrature_on_and_off_the_axis() {
        for (b0, b) in [(2.0, 0.0), (2.0, 1e-9), (2.0, 1e-3), (2.0, 1.0), (2.0, 1.99)] {
            for (pa, pb) in [(-0.3, 1.2), (2.0, 4.0), (-3.5, -2.9), (-1.0, 5.0), (0.0, 2.0 * PI)] {
                let (j0, jc, js) = rim_integrals(pa, pb, b0, b);
                let w0 = composite(pa, pb, 200, 32, |p| 1.0 / (b0 + b * p.cos()));
                let wc = composite(pa, pb, 200, 32, |p| p.cos() / (b0 + b * p.cos()));
                let ws = composite(pa, pb, 200, 32, |p| p.sin() / (b0 + b * p.cos()));
                for (g, w) in [(j0, w0), (jc, wc), (js, ws)] {
                    assert!((g - w).abs() < 1e-11 * w0.abs(), "B0 {b0} B {b} [{pa}, {pb}]: {g} vs {w}");
                }
            }
        }
    }

    /// The sun's projected solid angle by quadrature over the cap's directions: polar angle β from the sun's
    /// centre, azimuth ψ, visible where n·ω > 0 (a ψ-interval for each β).
    fn sun_numerical(cos_theta: f64, sigma: f64, order: usize) -> f64 {
        let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
        let inner = |beta: f64| {
            // n·ω = cos β cos θ + sin β sin θ cos ψ > 0.
            let (sb, cb) = beta.sin_cos();
            let f = |psi: f64| (cb * cos_theta + sb * sin_theta * psi.cos()).max(0.0) * sb;
            let bound = if sb * sin_theta == 0.0 { 2.0 } else { -cb * cos_theta / (sb * sin_theta) };
            if bound <= -1.0 {
                integrate(0.0, 2.0 * PI, order, f)
            } else if bound >= 1.0 {
                0.0
            } else {
                2.0 * integrate(0.0, bound.acos(), order, f)
            }
        };
        // The ψ-interval changes form where the bound crosses ±1.
        let mut cuts = vec![0.0, sigma];
        let b = (cos_theta / sin_theta).abs().atan();
        if b > 0.0 && b < sigma {
            cuts.insert(1, b);
        }
        cuts.windows(2).map(|w| integrate(w[0], w[1], order, inner)).sum()
    }

    #[test]
    fn partly_set_sun_matches_numerical_integration_over_the_cap() {
        for diameter_degrees in [0.53, 5.0, 30.0] {
            let delta = degrees_to_radians(diameter_degrees);
            let sigma = 0.5 * delta;
            for frac in [-0.999, -0.7, -0.3, 0.0, 0.2, 0.6, 0.95, 0.999] {
                let theta = 0.5 * PI - frac * sigma;
                let e = sun_irradiance_disk(1.0, theta.cos(), delta);
                let want = sun_numerical(theta.cos(), sigma, 200) / sun_projected_solid_angle(delta);
                assert!(
                    (e - want).abs() < 1e-10 * want.max(1e-12) + 1e-14,
                    "δ {diameter_degrees}° frac {frac}: {e} vs {want}"
                );
            }
        }
    }

    #[test]
    fn sun_irradiance_is_continuous_and_monotone_through_sunset() {
        let delta = degrees_to_radians(0.53);
        let sigma = 0.5 * delta;
        let steps = 20_000;
        let mut prev = f64::INFINITY;
        let mut max_jump = 0.0f64;
        for i in 0..=steps {
            // Elevation of the centre from +2σ down to −2σ.
            let elevation = sigma * (2.0 - 4.0 * i as f64 / steps as f64);
            let e = sun_irradiance_disk(1000.0, elevation.sin(), delta);
            assert!(e <= prev + 1e-12, "not monotone at elevation {elevation}");
            if prev.is_finite() {
                max_jump = max_jump.max(prev - e);
            }
            prev = e;
        }
        // A step of 4σ/20000 in elevation moves E by at most E⊥ · step (the slope of E⊥ sin(elevation) ≤ E⊥).
        let step = 4.0 * sigma / steps as f64;
        assert!(max_jump <= 1000.0 * step * 1.0001, "jump {max_jump} > {}", 1000.0 * step);
        assert_eq!(sun_irradiance_disk(1000.0, (-1.01 * sigma).sin(), delta), 0.0);
        let above = (1.01 * sigma).sin();
        assert_eq!(sun_irradiance_disk(1000.0, above, delta), 1000.0 * above);
        // Half set: E/E⊥ = 2σ/(3π) to leading order (the visible half-disk's mean elevation is 4σ/(3π)).
        let half = sun_irradiance_disk(1.0, 0.0, delta);
        assert!(rel(half, 2.0 * sigma / (3.0 * PI)) < 1e-4, "{half}");
    }

    #[test]
    fn sky_irradiance_of_an_overcast_day() {
        assert!(rel(sky_irradiance(100.0, 1.0), PI * 100.0) < 1e-15);
        assert!(rel(sky_irradiance(100.0, 0.0), PI * 50.0) < 1e-15);
        assert_eq!(sky_irradiance(100.0, -1.0), 0.0);
    }

    #[test]
    fn atan_minus_identity_is_accurate_near_zero() {
        for t in [1e-8, 1e-4, 0.01, 0.3, 0.49, 0.5, 2.0, -0.2] {
            // Reference from the series in higher effective precision: compare with atan(t) − t where that is
            // well conditioned, and with −t³/3 + t⁵/5 for tiny t.
            let got = atan_minus_identity(t);
            let want = if t.abs() < 1e-3 { -t.powi(3) / 3.0 + t.powi(5) / 5.0 } else { t.atan() - t };
            let tol = if t.abs() < 1e-3 { 1e-15 } else { 1e-15 / (want / t).abs() };
            assert!(rel(got, want) < tol.max(1e-15), "{t}: {got} vs {want}");
        }
    }

    #[test]
    fn delta_sun_irradiance() {
        assert_eq!(sun_irradiance_delta(1000.0, 0.5), 500.0);
        assert_eq!(sun_irradiance_delta(1000.0, -0.5), 0.0);
        assert_eq!(sun_irradiance_delta(1000.0, 0.0), 0.0);
    }
}
