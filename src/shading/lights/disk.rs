//! Disk lights: a disk of radius `R` \[m\] and uniform radiance `L0` [W/(m²·sr)] emitting along `d`. Everything
//! sunshade computes of one in one place: its projected solid angle (the lecture's small-source estimate
//! `A (n·l)⁴ / f²` and the exact value by Stokes' theorem, the disk cut by the horizon included), its specular lobe
//! integrated over the disk, and its visible fraction. `shaders/lights/disk.glsl` mirrors it name for name.

use std::f64::consts::PI;

use glam::DVec3;

use crate::scene::{Brdf, DiskLight};
use crate::shading::lobe::{
    safe_normalize, segment_lobe_integral, segment_lobe_integral_visible, specular_lobe_rgb, SampleRays,
};
use crate::shading::options::{DiskModel, ShadingOptions};
use crate::shading::visibility::{grid_fraction, GridLight, Shadowing};
use crate::shading::{orthonormal_to, SurfacePoint};

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
    let e1 = if rho > 0.0 { -r_perp / rho } else { crate::shading::orthonormal_to(d) };
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
    let rule = crate::shading::quadrature::gauss_legendre(order);
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

/// A scene disk light's geometry in f64.
pub fn disk_geometry(d: &DiskLight) -> DiskGeometry {
    DiskGeometry { center: d.center.as_dvec3(), direction: d.direction.as_dvec3(), radius: d.radius as f64 }
}

/// `∫ lobe(ω) (n·ω)+ dω` over the part of a disk light above the horizon, per unit radiance.
/// The grid's sum is taken as it is: the ratio of [`normalized_lobe_integral`](crate::shading::normalized_lobe_integral) would bring the f32 error of the
/// disk's closed-form projected solid angle into every lobe on the GPU (measured: 3.3e-5 against the reference on
/// brdfs.glb's disks, over the 1e-5 of `render --check`).
/// Per channel, the first (an analytic lobe's three are equal).
pub fn disk_lobe_integral(brdf: &Brdf, p: &SurfacePoint, disk: &DiskGeometry, per_axis: u32) -> f64 {
    segment_lobe_integral(brdf, p, disk.center - p.position, disk.direction, disk.radius, per_axis).lobe[0]
}

/// The visible fraction of a disk light (centre \[m\], unit emission direction `d`, radius \[m\]), weighted by
/// projected solid angle, from the point `x` with unit normal `n`.
///
/// Where `s.slices` asks for it and the occluders are opaque triangles, the reference takes it by slices instead
/// (`disk_slices`; the GPU too, as the sun's).
pub fn disk_visible_fraction(s: &Shadowing, x: DVec3, n: DVec3, center: DVec3, d: DVec3, radius: f64) -> f64 {
    if let Some(v) =
        s.by_slices(|rows| crate::shading::disk_slices::disk_visible_fraction_sliced(s, n, center, d, radius, rows))
    {
        return v;
    }
    let a = orthonormal_to(d);
    let b = d.cross(a);
    grid_fraction(s, &GridLight::Disk { x, n, center, d, a, b, radius })
}

/// A disk light's irradiance [W/m²] per channel at `point` from its visible part, `L0 Ω⊥ v`, with `Ω⊥` the exact
/// or the small-source projected solid angle (`options.disk`) and `v` its visible fraction (`shadow`: the rays
/// that shadow this disk, if any; one ray to the centre for a small source), and `v`.
pub fn disk_irradiance_visible(
    disk: &DiskLight,
    point: &SurfacePoint,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> ([f64; 3], f64) {
    let g = disk_geometry(disk);
    let omega = match options.disk {
        DiskModel::Exact => disk_projected_solid_angle(point.position, point.normal, &g),
        DiskModel::SmallSource => disk_projected_solid_angle_small_source(point.position, point.normal, &g),
    };
    let v = match shadow {
        Some(s) if omega > 0.0 => match options.disk {
            DiskModel::Exact => disk_visible_fraction(s, point.position, point.normal, g.center, g.direction, g.radius),
            DiskModel::SmallSource => f64::from(u8::from(s.visible_to(g.center))),
        },
        _ => 1.0,
    };
    let omega = omega * v;
    (disk.radiance.map(|l0| l0 as f64 * omega), v)
}

/// A disk light's specular term at `point`: `∫ lobe(ω) L0 (n·ω)+ V(ω) dω` over the disk [W/(m²·sr)] per channel,
/// to be scaled by `ks`: the exact model's graded grid over the part above the horizon, each sample with its own
/// shadow ray (the grid's sum as it is, see [`disk_lobe_integral`]); the small source's lobe towards the centre
/// times its projected solid angle, shadowed by the ray to the centre.
pub fn disk_specular_visible(
    disk: &DiskLight,
    brdf: &Brdf,
    point: &SurfacePoint,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    let g = disk_geometry(disk);
    let integral = match options.disk {
        DiskModel::Exact => {
            let rays = shadow.map(SampleRays::ToPoint);
            let q = g.center - point.position;
            segment_lobe_integral_visible(brdf, point, q, g.direction, g.radius, options.samples_per_axis, rays).lobe
        }
        DiskModel::SmallSource => {
            let to_center = safe_normalize(g.center - point.position);
            let omega = disk_projected_solid_angle_small_source(point.position, point.normal, &g);
            let integral = specular_lobe_rgb(brdf, point, to_center).map(|lobe| lobe * omega);
            if integral.iter().any(|&x| x > 0.0) && shadow.is_some_and(|s| !s.visible_to(g.center)) {
                [0.0; 3]
            } else {
                integral
            }
        }
    };
    [0, 1, 2].map(|c| integral[c] * disk.radiance[c] as f64)
}

#[cfg(test)]
mod tests {
    use super::super::rel;
    use super::*;
    use crate::shading::quadrature::integrate_composite as composite;

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
}
