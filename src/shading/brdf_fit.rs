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

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;
use rayon::prelude::*;

use super::lobe::lobe_about_z;
use super::measured::{brdf_about_z, half_diff_directions};
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

/// Fits `kind` to the table (see the module text).
pub fn fit_brdf(table: &MeasuredBrdf, kind: BrdfKind) -> Fit {
    let samples = fit_samples(table);
    let fixed = fixed_sums(&samples);
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
        let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(GRID_POINTS - 1)]);
        // Golden-section search on ln(shape) in [a, b].
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
        let (mut fc, mut fd) = (at(c), at(d));
        for _ in 0..GOLDEN_STEPS {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - g * (b - a);
                fc = at(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + g * (b - a);
                fd = at(d);
            }
        }
        let t = if fc < fd { c } else { d };
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
