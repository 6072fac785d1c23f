//! Fitting an analytic BRDF to a measured table (`sunshade fit-brdf`).
//!
//! **Objective.** Over every sample of the table whose light and view are above the horizon and not missing, the
//! cosine-weighted squared difference, each sample weighted by the measure of its bin in the space of direction
//! pairs:
//!
//! `E_c = Σ_s w_s cos²θ_l (ρ_model,c(s) − ρ_c(s))²`, normalised as `√(E_c / Σ_s w_s cos²θ_l ρ_c(s)²)`,
//!
//! the relative RMS of the reflected radiance per unit irradiance, `ρ cos θ_l`, over all pairs of directions.
//! `w_s` is Rusinkiewicz's Jacobian `dω_l dω_v = 4 cos θ_d sin θ_d sin θ_h dθ_h dθ_d dφ_d dφ_h` at the bin's
//! centre times the bin's widths (φ_h integrates to 2π, a common factor). Ngan, Durand & Matusik (2005,
//! "Experimental Analysis of BRDF Models") fit this database with the same cosine-weighted difference; a plain
//! L² fit in ρ lets the specular peak dominate, as they note, and this objective keeps that property: it is the
//! error of rendered radiance under uniform light.
//!
//! **Method.** Every model is `kd/π + ks · lobe(shape)`: for a fixed shape (exponent or α) the objective is a
//! linear least-squares problem in (kd_c, ks_c) per channel, solved exactly from 2 × 2 normal equations with
//! kd, ks ≥ 0 (a negative coefficient is set to 0 and the other refitted). The shape is then a one-dimensional
//! search: a logarithmic grid over its range, then golden-section search on its logarithm in the bracket about the
//! grid's best (variable projection; Golub & Pereyra 1973). Ward is fitted isotropic (αx = αy): the table is
//! isotropic.
//!
//! **glTF** (`--model gltf`) is not `kd/π + ks · lobe`: its ρ is affine in the base colour for a fixed metallic
//! and α, so the base colour is solved exactly per channel and (metallic, ln α) searched (`fit_gltf`): a way to
//! turn a measured material into a glTF one.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;
use rayon::prelude::*;

use super::brdf::metallic_roughness::{
    ggx_distribution, one_minus_v_dot_h, schlick_weight, smith_visibility, GLTF_DIELECTRIC_F0,
};
use super::lobe::lobe_about_z;
use super::measured::{brdf_about_z, half_diff_directions};
use crate::scene::material::MIN_MAPPED_ALPHA;
use crate::scene::measured::{merl_index, MeasuredBrdf, PHI_D_BINS, THETA_D_BINS, THETA_H_BINS};
use crate::scene::{Brdf, BrdfKind};

/// One table sample in the fit: its directions about +z, its weight `w cos²θ_l` and its ρ per channel.
#[derive(Clone, Copy, Debug)]
pub struct FitSample {
    pub l: DVec3,
    pub v: DVec3,
    pub weight: f64,
    pub rho: [f64; 3],
}

/// The samples the objective runs over (see the module text).
pub fn fit_samples(table: &MeasuredBrdf) -> Vec<FitSample> {
    let mut out = Vec::new();
    let (dh_scale, dd, dp) =
        (FRAC_PI_2 / (THETA_H_BINS * THETA_H_BINS) as f64, FRAC_PI_2 / THETA_D_BINS as f64, PI / PHI_D_BINS as f64);
    for i in 0..THETA_H_BINS {
        // θ_h = (u/90)² π/2: the bin [i, i + 1) spans (2i + 1) π/2 / 90², centred at u = i + 1/2.
        let u = (i as f64 + 0.5) / THETA_H_BINS as f64;
        let theta_h_mid = u * u * FRAC_PI_2;
        let d_theta_h = (2 * i + 1) as f64 * dh_scale;
        for j in 0..THETA_D_BINS {
            let theta_d_mid = (j as f64 + 0.5) * dd;
            let jacobian = 4.0 * theta_d_mid.cos() * theta_d_mid.sin() * theta_h_mid.sin();
            for k in 0..PHI_D_BINS {
                let index = merl_index(i, j, k);
                if table.is_missing(index) {
                    continue;
                }
                let (theta_h, theta_d, phi_d) = crate::scene::measured::merl_bin_angles(i, j, k);
                let (l, v) = half_diff_directions(theta_h, theta_d, phi_d);
                if !(l.z > 0.0 && v.z > 0.0) {
                    continue;
                }
                let s = &table.values[3 * index..][..3];
                out.push(FitSample {
                    l,
                    v,
                    weight: jacobian * d_theta_h * dd * dp * l.z * l.z,
                    rho: [s[0] as f64, s[1] as f64, s[2] as f64],
                });
            }
        }
    }
    out
}

/// A fitted model: the BRDF, and the objective's relative RMS per channel.
#[derive(Clone, Debug)]
pub struct Fit {
    pub brdf: Brdf,
    pub relative_rms: [f64; 3],
    /// How many samples the objective ran over.
    pub samples: usize,
}

/// Sums of the normal equations for one shape: `Σ w L²`, `Σ w L/π`, `Σ w L ρ_c`.
#[derive(Clone, Copy, Default)]
struct LobeSums {
    ll: f64,
    xl: f64,
    lr: [f64; 3],
}

/// Sums that do not depend on the shape: `Σ w/π²`, `Σ w ρ_c/π`, `Σ w ρ_c²`.
#[derive(Clone, Copy, Default)]
struct FixedSums {
    xx: f64,
    xr: [f64; 3],
    rr: [f64; 3],
}

fn fixed_sums(samples: &[FitSample]) -> FixedSums {
    let x = 1.0 / PI;
    let mut f = FixedSums::default();
    for s in samples {
        f.xx += s.weight * x * x;
        for c in 0..3 {
            f.xr[c] += s.weight * x * s.rho[c];
            f.rr[c] += s.weight * s.rho[c] * s.rho[c];
        }
    }
    f
}

fn lobe_sums(samples: &[FitSample], lobe: &Brdf) -> LobeSums {
    let x = 1.0 / PI;
    samples
        .par_chunks(8192)
        .map(|chunk| {
            let mut t = LobeSums::default();
            for s in chunk {
                let l = lobe_about_z(lobe, s.l, s.v);
                t.ll += s.weight * l * l;
                t.xl += s.weight * x * l;
                for c in 0..3 {
                    t.lr[c] += s.weight * l * s.rho[c];
                }
            }
            t
        })
        .reduce(LobeSums::default, |a, b| LobeSums {
            ll: a.ll + b.ll,
            xl: a.xl + b.xl,
            lr: [0, 1, 2].map(|c| a.lr[c] + b.lr[c]),
        })
}

/// The non-negative least-squares (kd_c, ks_c) for one channel and the objective's value there.
fn solve_channel(f: &FixedSums, l: &LobeSums, c: usize) -> (f64, f64, f64) {
    let objective = |a: f64, b: f64| {
        f.rr[c] - 2.0 * a * f.xr[c] - 2.0 * b * l.lr[c] + a * a * f.xx + 2.0 * a * b * l.xl + b * b * l.ll
    };
    let det = f.xx * l.ll - l.xl * l.xl;
    let mut candidates = Vec::with_capacity(3);
    if det > 1e-300 * f.xx * l.ll {
        let a = (f.xr[c] * l.ll - l.lr[c] * l.xl) / det;
        let b = (f.xx * l.lr[c] - l.xl * f.xr[c]) / det;
        if a >= 0.0 && b >= 0.0 {
            candidates.push((a, b));
        }
    }
    // On the boundary: kd alone, ks alone.
    candidates.push(((f.xr[c] / f.xx).max(0.0), 0.0));
    if l.ll > 0.0 {
        candidates.push((0.0, (l.lr[c] / l.ll).max(0.0)));
    }
    let (a, b) = candidates
        .into_iter()
        .min_by(|p, q| objective(p.0, p.1).total_cmp(&objective(q.0, q.1)))
        .expect("kd alone is always a candidate");
    (a, b, objective(a, b).max(0.0))
}

/// The model with shape parameter `shape` (exponent, or Ward's α) and unit reflectances, for the lobe alone.
fn lobe_of(kind: BrdfKind, shape: f64) -> Brdf {
    Brdf::of_kind(kind, [0.0; 3], [1.0; 3], shape as f32)
}

/// The shape's search range: exponents 0.1 to 1e5 (Phong, Blinn-Phong), Ward α 0.002 to 1.
fn shape_range(kind: BrdfKind) -> (f64, f64) {
    match kind {
        BrdfKind::Phong | BrdfKind::BlinnPhong => (0.1, 1e5),
        BrdfKind::Ward => (0.002, 1.0),
        BrdfKind::Gltf => (MIN_MAPPED_ALPHA as f64, 1.0),
        BrdfKind::Lambert => (0.0, 0.0),
    }
}

/// The fit of one shape: per channel (kd, ks), and the summed objective.
fn fit_shape(samples: &[FitSample], fixed: &FixedSums, kind: BrdfKind, shape: f64) -> ([(f64, f64, f64); 3], f64) {
    let sums = lobe_sums(samples, &lobe_of(kind, shape));
    let channels = [0, 1, 2].map(|c| solve_channel(fixed, &sums, c));
    (channels, channels.iter().map(|c| c.2).sum())
}

/// Grid points of the shape search and golden-section steps after it.
const GRID_POINTS: usize = 36;
const GOLDEN_STEPS: usize = 30;

/// Golden-section search for the minimum of `f` on `[a, b]`, `GOLDEN_STEPS` steps; returns the abscissa.
fn golden_section(f: impl Fn(f64) -> f64, (mut a, mut b): (f64, f64)) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc < fd {
        c
    } else {
        d
    }
}

/// Metallic values of the glTF fit's first grid.
const GLTF_METALLIC_GRID: usize = 11;

/// The glTF BRDF's sums of the normal equations for one metallic m: ρ is affine in the base colour b,
/// `ρ = b P + Q` with `P = (1 − m)(1 − F_d)/π + m (1 − s) D V` and `Q = (1 − m) F_d D V + m s D V` (s Schlick's
/// weight, `F_d = 0.04 + 0.96 s`): `Σ w P²`, `Σ w P Q`, `Σ w Q²`, `Σ w P ρ_c`, `Σ w Q ρ_c`.
#[derive(Clone, Copy, Default)]
struct GltfSums {
    pp: f64,
    pq: f64,
    qq: f64,
    pr: [f64; 3],
    qr: [f64; 3],
}

impl GltfSums {
    fn add(self, o: GltfSums) -> GltfSums {
        GltfSums {
            pp: self.pp + o.pp,
            pq: self.pq + o.pq,
            qq: self.qq + o.qq,
            pr: [0, 1, 2].map(|c| self.pr[c] + o.pr[c]),
            qr: [0, 1, 2].map(|c| self.qr[c] + o.qr[c]),
        }
    }

    /// The least-squares base colour per channel, `Σ w P (ρ − Q) / Σ w P²` clamped to [0, 1] (the objective is
    /// a parabola in b), and the summed objective `Σ w (b P + Q − ρ)²` there.
    fn solve(&self, fixed: &FixedSums) -> ([f64; 3], f64) {
        let mut total = 0.0;
        let base = [0, 1, 2].map(|c| {
            let b = if self.pp > 0.0 { ((self.pr[c] - self.pq) / self.pp).clamp(0.0, 1.0) } else { 0.0 };
            total +=
                b * b * self.pp + 2.0 * b * self.pq + self.qq - 2.0 * b * self.pr[c] - 2.0 * self.qr[c] + fixed.rr[c];
            b
        });
        (base, total)
    }
}

/// [`GltfSums`] for each metallic of `metallics` at one α: D V and Schlick's weight are computed once per sample.
fn gltf_sums(samples: &[FitSample], alpha: f64, metallics: &[f64]) -> Vec<GltfSums> {
    let zero = || vec![GltfSums::default(); metallics.len()];
    samples
        .par_chunks(8192)
        .map(|chunk| {
            let mut t = zero();
            for s in chunk {
                let (dv, weight) = gltf_terms(s.l, s.v, alpha);
                let fd = GLTF_DIELECTRIC_F0 + (1.0 - GLTF_DIELECTRIC_F0) * weight;
                for (sums, &m) in t.iter_mut().zip(metallics) {
                    let p = (1.0 - m) * (1.0 - fd) / PI + m * (1.0 - weight) * dv;
                    let q = (1.0 - m) * fd * dv + m * weight * dv;
                    sums.pp += s.weight * p * p;
                    sums.pq += s.weight * p * q;
                    sums.qq += s.weight * q * q;
                    for c in 0..3 {
                        sums.pr[c] += s.weight * p * s.rho[c];
                        sums.qr[c] += s.weight * q * s.rho[c];
                    }
                }
            }
            t
        })
        .reduce(zero, |a, b| a.into_iter().zip(b).map(|(x, y)| x.add(y)).collect())
}

/// GGX's `D V` and Schlick's `(1 − v·h)⁵` for light l and viewer v about +z (`shading::brdf::metallic_roughness`).
fn gltf_terms(l: DVec3, v: DVec3, alpha: f64) -> (f64, f64) {
    let h = l + v;
    if h.length_squared() == 0.0 {
        return (0.0, 0.0);
    }
    let dv = ggx_distribution(DVec3::Z, h, alpha) * smith_visibility(l.z, v.z, alpha);
    (dv, schlick_weight(one_minus_v_dot_h(l, v)))
}

/// Fits the glTF BRDF (base colour, metallic, roughness) to the table: the base colour exactly for each
/// (metallic, α) ([`GltfSums::solve`]); a grid over metallic × ln α, then golden-section search on ln α at the best
/// metallic and on metallic at that α.
fn fit_gltf(samples: &[FitSample], fixed: &FixedSums) -> Brdf {
    let (lo, hi) = shape_range(BrdfKind::Gltf);
    let (lo, hi) = (lo.ln(), hi.ln());
    let alphas: Vec<f64> = (0..GRID_POINTS).map(|i| lo + (hi - lo) * i as f64 / (GRID_POINTS - 1) as f64).collect();
    let metallics: Vec<f64> = (0..GLTF_METALLIC_GRID).map(|i| i as f64 / (GLTF_METALLIC_GRID - 1) as f64).collect();
    let mut best = (f64::INFINITY, 0, 0);
    for (ai, &t) in alphas.iter().enumerate() {
        for (mi, sums) in gltf_sums(samples, t.exp(), &metallics).iter().enumerate() {
            let value = sums.solve(fixed).1;
            if value < best.0 {
                best = (value, mi, ai);
            }
        }
    }
    let at = |m: f64, t: f64| gltf_sums(samples, t.exp(), &[m])[0].solve(fixed);
    let m0 = metallics[best.1];
    let bracket = (alphas[best.2.saturating_sub(1)], alphas[(best.2 + 1).min(GRID_POINTS - 1)]);
    let t = golden_section(|t| at(m0, t).1, bracket);
    let step = 1.0 / (GLTF_METALLIC_GRID - 1) as f64;
    let m = golden_section(|m| at(m, t).1, ((m0 - step).max(0.0), (m0 + step).min(1.0)));
    let base = at(m, t).0;
    Brdf::Gltf {
        base_color: base.map(|b| b as f32),
        metallic: m as f32,
        alpha: t.exp() as f32,
        specular: crate::scene::material::DielectricSpecular::DEFAULT,
    }
}

/// Fits `kind` to the table (see the module text).
pub fn fit_brdf(table: &MeasuredBrdf, kind: BrdfKind) -> Fit {
    let samples = fit_samples(table);
    let fixed = fixed_sums(&samples);
    if kind == BrdfKind::Gltf {
        let brdf = fit_gltf(&samples, &fixed);
        return Fit { relative_rms: relative_rms(&samples, &brdf), brdf, samples: samples.len() };
    }
    let (channels, shape) = if kind == BrdfKind::Lambert {
        let none = LobeSums::default();
        ([0, 1, 2].map(|c| solve_channel(&fixed, &none, c)), 0.0)
    } else {
        let (lo, hi) = shape_range(kind);
        let (lo, hi) = (lo.ln(), hi.ln());
        let at = |t: f64| fit_shape(&samples, &fixed, kind, t.exp()).1;
        let grid: Vec<f64> = (0..GRID_POINTS).map(|i| lo + (hi - lo) * i as f64 / (GRID_POINTS - 1) as f64).collect();
        let values: Vec<f64> = grid.iter().map(|&t| at(t)).collect();
        let best = (0..GRID_POINTS).min_by(|&a, &b| values[a].total_cmp(&values[b])).unwrap();
        // Golden-section search on ln(shape) in the bracket about the grid's best.
        let t = golden_section(at, (grid[best.saturating_sub(1)], grid[(best + 1).min(GRID_POINTS - 1)]));
        let shape = t.exp();
        (fit_shape(&samples, &fixed, kind, shape).0, shape)
    };
    let kd = channels.map(|c| c.0 as f32);
    let ks = channels.map(|c| c.1 as f32);
    let brdf = Brdf::of_kind(kind, kd, ks, shape as f32);
    Fit { relative_rms: relative_rms(&samples, &brdf), brdf, samples: samples.len() }
}

/// The objective's relative RMS per channel for `brdf` over `samples`, summed directly (the normal equations'
/// expansion cancels where the fit is close).
pub fn relative_rms(samples: &[FitSample], brdf: &Brdf) -> [f64; 3] {
    let (num, den) = samples
        .par_chunks(8192)
        .map(|chunk| {
            let (mut num, mut den) = ([0.0; 3], [0.0; 3]);
            for s in chunk {
                let model = brdf_about_z(brdf, s.l, s.v);
                for c in 0..3 {
                    let model = model[c];
                    num[c] += s.weight * (model - s.rho[c]).powi(2);
                    den[c] += s.weight * s.rho[c] * s.rho[c];
                }
            }
            (num, den)
        })
        .reduce(
            || ([0.0; 3], [0.0; 3]),
            |a, b| ([0, 1, 2].map(|c| a.0[c] + b.0[c]), [0, 1, 2].map(|c| a.1[c] + b.1[c])),
        );
    [0, 1, 2].map(|c| if den[c] > 0.0 { (num[c] / den[c]).sqrt() } else { 0.0 })
}
