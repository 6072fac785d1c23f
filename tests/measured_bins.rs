//! Where a MERL sample stands in its bin, and what a missing one does: a table made as the database's were, by
//! averaging the measurements that fall in each bin (here an analytic Ward evaluated at 3 × 3 × 3 points spread
//! evenly over each bin's coordinates; a bin none of whose points is above the horizon is missing, written
//! negative, MERL's pattern), read by sunshade's lookup against the formula.
//!
//! - Read with its samples at the bins' centres (sunshade's convention) the table is within a fraction of the
//!   error it has read at the bins' lower edges (the convention sunshade's lookup and `tabulate-brdf` used before).
//! - Up to grazing light and view, the lookup over the valid samples only is as close to the formula as in the
//!   table's interior, where taking the missing samples as 0 darkens a band beyond which nothing is left.
//! - `sunshade tabulate-brdf` writes each sample at its bin's centre: the lookup at a centre's directions returns
//!   the formula's value there.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

use glam::DVec3;
use sunshade::scene::measured::{
    merl_bin_angles, merl_index, MeasuredBrdf, MERL_SAMPLES, PHI_D_BINS, THETA_D_BINS, THETA_H_BINS,
};
use sunshade::scene::Brdf;
use sunshade::shading::measured::{
    brdf_about_z, half_diff_angles, half_diff_directions, measured_brdf, measured_coordinates, measured_lookup_at,
    MeasuredLookup,
};

/// The analytic Ward of the tables: kd 0.3/0.25/0.2, ks 0.2, α 0.2.
fn ward() -> Brdf {
    Brdf::Ward { kd: [0.3, 0.25, 0.2], ks: [0.2; 3], alpha_x: 0.2, alpha_y: 0.2 }
}

/// Points per axis of a bin that the averaged table averages over.
const POINTS: usize = 3;

/// The bin-averaged Ward's planes (`rho[c][i]`, negative where no point of the bin is above the horizon), made
/// once per test process on every thread.
fn averaged_planes() -> &'static [Vec<f64>; 3] {
    static PLANES: OnceLock<[Vec<f64>; 3]> = OnceLock::new();
    PLANES.get_or_init(|| {
        let brdf = ward();
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let rows: Vec<Vec<[f64; 3]>> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads)
                .map(|t| {
                    let brdf = &brdf;
                    s.spawn(move || {
                        (t..THETA_H_BINS).step_by(threads).map(|i| (i, bin_averages(brdf, i))).collect::<Vec<_>>()
                    })
                })
                .collect();
            let mut rows = vec![Vec::new(); THETA_H_BINS];
            for h in handles {
                for (i, row) in h.join().unwrap() {
                    rows[i] = row;
                }
            }
            rows
        });
        let mut planes: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; MERL_SAMPLES]);
        for (i, row) in rows.iter().enumerate() {
            for (jk, value) in row.iter().enumerate() {
                for c in 0..3 {
                    planes[c][merl_index(i, 0, 0) + jk] = value[c];
                }
            }
        }
        planes
    })
}

/// The averages over the bins of θ_h bin `i`, in table order (θ_d, then φ_d); −1 where no point is above the horizon.
fn bin_averages(brdf: &Brdf, i: usize) -> Vec<[f64; 3]> {
    let offset = |n: usize, s: usize| n as f64 + (s as f64 + 0.5) / POINTS as f64;
    let mut out = Vec::with_capacity(THETA_D_BINS * PHI_D_BINS);
    for j in 0..THETA_D_BINS {
        for k in 0..PHI_D_BINS {
            let (mut sum, mut count) = ([0.0; 3], 0);
            for a in 0..POINTS {
                let u_h = offset(i, a) / THETA_H_BINS as f64;
                for b in 0..POINTS {
                    let theta_d = offset(j, b) / THETA_D_BINS as f64 * FRAC_PI_2;
                    for c in 0..POINTS {
                        let phi_d = offset(k, c) / PHI_D_BINS as f64 * PI;
                        let (l, v) = half_diff_directions(u_h * u_h * FRAC_PI_2, theta_d, phi_d);
                        if l.z > 0.0 && v.z > 0.0 {
                            let rho = brdf_about_z(brdf, l, v);
                            for x in 0..3 {
                                sum[x] += rho[x];
                            }
                            count += 1;
                        }
                    }
                }
            }
            out.push(if count == 0 { [-1.0; 3] } else { sum.map(|s| s / count as f64) });
        }
    }
    out
}

/// Pseudo-random pairs of directions about +z, both above the horizon, with polar angles up to `max_theta`
/// \[rad\] (uniform in cos θ, so grazing pairs are rare unless `min_theta` is near it).
fn pairs(count: usize, min_theta: f64, max_theta: f64) -> Vec<(DVec3, DVec3)> {
    // Marsaglia's xorshift64: the same pairs on every machine.
    let mut seed = 0x5eed_b105_u64;
    let mut uniform = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (c0, c1) = (min_theta.cos(), max_theta.cos());
    let mut dir = move || {
        let cos = c0 + (c1 - c0) * uniform();
        let phi = 2.0 * PI * uniform();
        let sin = (1.0 - cos * cos).sqrt();
        DVec3::new(sin * phi.cos(), sin * phi.sin(), cos)
    };
    (0..count).map(|_| (dir(), dir())).collect()
}

/// The relative error per channel (largest) of `lookup` against the formula.
fn rel(lookup: [f64; 3], formula: [f64; 3]) -> f64 {
    (0..3).map(|c| (lookup[c] - formula[c]).abs() / formula[c]).fold(0.0, f64::max)
}

/// The `q`-quantile of `xs` (sorted in place).
fn quantile(xs: &mut [f64], q: f64) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[((xs.len() - 1) as f64 * q).round() as usize]
}

#[test]
fn bin_averaged_tables_are_read_at_their_centres() {
    let table = MeasuredBrdf::from_planes("averaged", averaged_planes()).unwrap();
    let brdf = ward();
    let (mut centre, mut edge) = (Vec::new(), Vec::new());
    for (l, v) in pairs(100_000, 0.0, 80f64.to_radians()) {
        let formula = brdf_about_z(&brdf, l, v);
        let (th, td, pd) = half_diff_angles(DVec3::Z, l, v).unwrap();
        let u = measured_coordinates(th, td, pd);
        centre.push(rel(measured_lookup_at(&table, MeasuredLookup::Linear, u), formula));
        // Samples at the lower edges: sample i at u = i is what the centre lookup reads at u + ½.
        let shifted = (u.0 + 0.5, u.1 + 0.5, u.2 + 0.5);
        edge.push(rel(measured_lookup_at(&table, MeasuredLookup::Linear, shifted), formula));
    }
    let stats = |xs: &mut Vec<f64>| (quantile(xs, 0.5), quantile(xs, 0.99), quantile(xs, 1.0));
    let (c, e) = (stats(&mut centre), stats(&mut edge));
    println!("bin-averaged Ward α = 0.2 against the formula, 100 000 pairs up to 80°: median / 99% / max");
    println!("  samples at the centres: {:.2e} / {:.2e} / {:.2e}", c.0, c.1, c.2);
    println!("  samples at the edges:   {:.2e} / {:.2e} / {:.2e}", e.0, e.1, e.2);
    assert!(c.1 < e.1 / 5.0 && c.2 < e.2 / 3.0, "centres {c:?}, edges {e:?}");
}

/// sunshade's `tabulate` (what `tabulate-brdf` writes) against the bin-averaged table, sample by sample up to
/// 80° from the normal: the formula at the bins' centres is the bins' average to second order; at their lower edges it is off
/// by a first-order shift, most at the peak.
#[test]
fn tabulated_samples_are_the_bin_averages_to_second_order() {
    let averaged = averaged_planes();
    let brdf = ward();
    let centres = sunshade::shading::measured::tabulate(|l, v| brdf_about_z(&brdf, l, v));
    let (mut centre, mut edge) = (Vec::new(), Vec::new());
    let (mut centre_peak, mut edge_peak) = (0.0f64, 0.0f64);
    for i in 0..THETA_H_BINS {
        for j in 0..THETA_D_BINS {
            for k in 0..PHI_D_BINS {
                let index = merl_index(i, j, k);
                let (th, td, pd) = merl_bin_angles(i, j, k);
                let (l, v) = half_diff_directions(th, td, pd);
                // Up to 80° from the normal: nearer the horizon Ward's 1/√(cos θ_l cos θ_v) changes by orders
                // of magnitude within a bin, and a bin across it averages its upper part only.
                let above = 10f64.to_radians().sin();
                if averaged[0][index] < 0.0 || !(l.z > above && v.z > above) {
                    continue;
                }
                // The lower edges' angles: the centre's less half a bin on each axis.
                let u_h = i as f64 / THETA_H_BINS as f64;
                let edge_angles = (
                    u_h * u_h * FRAC_PI_2,
                    td - FRAC_PI_2 / (2 * THETA_D_BINS) as f64,
                    pd - PI / (2 * PHI_D_BINS) as f64,
                );
                let (le, ve) = half_diff_directions(edge_angles.0, edge_angles.1, edge_angles.2);
                let at_edge = brdf_about_z(&brdf, le, ve);
                let want: [f64; 3] = std::array::from_fn(|c| averaged[c][index]);
                let (c, e) = (rel([0, 1, 2].map(|c| centres[c][index]), want), rel(at_edge, want));
                centre.push(c);
                edge.push(e);
                if i < 10 {
                    centre_peak = centre_peak.max(c);
                    edge_peak = edge_peak.max(e);
                }
            }
        }
    }
    let (c99, e99) = (quantile(&mut centre, 0.99), quantile(&mut edge, 0.99));
    println!("the formula at the bins' centres against their averages: 99% {c99:.2e}, θ_h bins 0–9 {centre_peak:.2e}");
    println!("the formula at the bins' lower edges:                     99% {e99:.2e}, θ_h bins 0–9 {edge_peak:.2e}");
    assert!(c99 < e99 / 10.0 && centre_peak < edge_peak / 10.0);
}

/// Pairs with the light up to 80° from the normal and the view from 80° to 89.9° (and the other way round).
fn grazing_pairs(count: usize) -> Vec<(DVec3, DVec3)> {
    let (steep, grazing) =
        (pairs(count, 0.0, 80f64.to_radians()), pairs(count, 80f64.to_radians(), 89.9f64.to_radians()));
    steep.iter().zip(&grazing).enumerate().map(|(n, (a, b))| if n % 2 == 0 { (a.0, b.1) } else { (b.0, a.1) }).collect()
}

#[test]
fn missing_samples_beyond_the_horizon_do_not_darken_grazing_views() {
    let planes = averaged_planes();
    let table = MeasuredBrdf::from_planes("averaged", planes).unwrap();
    assert!(table.missing > 0);
    // The same table with its missing samples taken as 0 (what the lookup did before it skipped them).
    let zeros: [Vec<f64>; 3] = std::array::from_fn(|c| planes[c].iter().map(|&x| x.max(0.0)).collect());
    let zeroed = MeasuredBrdf::from_planes("zeroed", &zeros).unwrap();
    // A constant with the same pattern.
    let constant: [Vec<f64>; 3] =
        std::array::from_fn(|c| planes[c].iter().map(|&x| if x < 0.0 { -1.0 } else { 0.1 * (c + 1) as f64 }).collect());
    let constant_zeroed: [Vec<f64>; 3] = std::array::from_fn(|c| constant[c].iter().map(|&x| x.max(0.0)).collect());
    let constant = MeasuredBrdf::from_planes("constant", &constant).unwrap();
    let constant_zeroed = MeasuredBrdf::from_planes("constant zeroed", &constant_zeroed).unwrap();
    let brdf = ward();
    let (mut valid, mut zero, mut worst_constant, mut worst_zeroed) = (Vec::new(), Vec::new(), 0.0f64, 0.0f64);
    for (l, v) in grazing_pairs(100_000) {
        let formula = brdf_about_z(&brdf, l, v);
        valid.push(rel(measured_brdf(&table, MeasuredLookup::Linear, DVec3::Z, l, v), formula));
        zero.push(rel(measured_brdf(&zeroed, MeasuredLookup::Linear, DVec3::Z, l, v), formula));
        let want = [0, 1, 2].map(|c| (0.1 * (c + 1) as f64) as f32 as f64);
        worst_constant =
            worst_constant.max(rel(measured_brdf(&constant, MeasuredLookup::Linear, DVec3::Z, l, v), want));
        let zeroed = measured_brdf(&constant_zeroed, MeasuredLookup::Linear, DVec3::Z, l, v);
        worst_zeroed = worst_zeroed.max(rel(zeroed, want));
    }
    let stats = |xs: &mut Vec<f64>| (quantile(xs, 0.5), quantile(xs, 0.99), quantile(xs, 1.0));
    let (a, b) = (stats(&mut valid), stats(&mut zero));
    println!("grazing pairs (one direction 80°–89.9°), against the formula: median / 99% / max");
    println!("  over the valid samples:     {:.2e} / {:.2e} / {:.2e}", a.0, a.1, a.2);
    println!("  missing samples taken as 0: {:.2e} / {:.2e} / {:.2e}", b.0, b.1, b.2);
    println!("  a constant table with the same pattern: {worst_constant:.2e} ({worst_zeroed:.2e} taken as 0)");
    assert!(worst_constant < 1e-12 && worst_zeroed > 0.3);
    assert!(a.1 < b.1 / 5.0 && a.2 < b.2 / 5.0, "{a:?} {b:?}");
}
