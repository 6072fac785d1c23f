//! Measured BRDFs in the MERL format (Matusik, Pfister, Brand & McMillan 2003, "A Data-Driven Reflectance
//! Model"): 90 × 90 × 180 samples of an isotropic BRDF over Rusinkiewicz's (1998) half/difference angles.
//!
//! The file: three little-endian int32 (90, 90, 180), then three planes (R, G, B) of little-endian f64, sample
//! `φ_d + 180 (θ_d + 90 θ_h)` (bins as `shading::measured` says), each value times its channel's scale
//! ([`MERL_CHANNEL_SCALE`]) a BRDF ρ [1/sr]; negative values mark samples the measurement missed. Checked
//! against the description distributed with the database (its README and the layout its C++ reader documents:
//! header, plane order, the index formula and the scales; nothing of it is copied here), and by reading back the
//! files [`merl_bytes`] writes.
//!
//! The table is kept as f32 (what the GPU reads: 17.5 MB per file), RGB interleaved per sample. A sample with a
//! missing channel is marked missing as a whole ([`MeasuredBrdf::is_missing`]): the lookup interpolates over the
//! valid samples only (`shading::measured`), and its stored value is the nearest valid sample's, for the cells
//! without any valid corner. Materials naming the same file share one table (`Arc`), on the CPU and in the GPU's
//! buffer.

use std::sync::Arc;

/// How the table is read between its samples (`--merl-lookup`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeasuredLookup {
    #[default]
    Linear,
    Nearest,
}

impl std::str::FromStr for MeasuredLookup {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "linear" => Ok(MeasuredLookup::Linear),
            "nearest" => Ok(MeasuredLookup::Nearest),
            _ => Err(format!("'{s}' is not a lookup (linear, nearest)")),
        }
    }
}

/// Bins of θ_h, θ_d and φ_d.
pub const THETA_H_BINS: usize = 90;
pub const THETA_D_BINS: usize = 90;
pub const PHI_D_BINS: usize = 180;
/// Samples per channel.
pub const MERL_SAMPLES: usize = THETA_H_BINS * THETA_D_BINS * PHI_D_BINS;
/// The size of a MERL file \[bytes\]: the header and three planes of f64.
pub const MERL_FILE_BYTES: usize = 12 + 3 * 8 * MERL_SAMPLES;
/// The factors from stored values to ρ [1/sr], per channel (the database's convention).
pub const MERL_CHANNEL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// A measured isotropic BRDF, tabulated as MERL tabulates it.
#[derive(Clone, PartialEq)]
pub struct MeasuredBrdf {
    /// The file it came from (for messages and metadata).
    pub name: String,
    /// ρ [1/sr] of sample `i` in channel `c` at `values[3 i + c]`, `i = φ_d + 180 (θ_d + 90 θ_h)`; a missing
    /// sample holds the value of the nearest valid one (fewest steps between neighbouring bins, φ_d wrapping).
    pub values: Vec<f32>,
    /// The smallest valid value per channel (≥ 0). Rendering takes `floor` as a Lambertian part, integrated exactly
    /// like any `kd/π`, and samples only the rest (`shading::measured`): a constant table renders exactly as
    /// Lambert, with or without missing samples.
    pub floor: [f32; 3],
    /// How many values were missing (negative in the file), over all channels.
    pub missing: usize,
    /// How many of the missing samples have their light and view above the horizon at their bin's centre
    /// ([`bin_centre_above_horizon`]): gaps in the measurement, where the rest are the directions it cannot have.
    pub missing_above_horizon: usize,
    /// Per sample, whether a channel of it was missing (empty where none was): such a sample is missing in every
    /// channel.
    pub missing_mask: Vec<bool>,
    /// The angular width \[rad\] of the specular peak about the mirror direction, for grading the sample grids:
    /// twice the θ_h at which the channels' mean, at θ_d = φ_d = 0 and above the floor, first falls to e^{-1/2}
    /// of its value at θ_h = 0 (ω turns twice as fast as the half vector); π where it never does (a table
    /// without a peak).
    pub lobe_width: f32,
}

impl std::fmt::Debug for MeasuredBrdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeasuredBrdf")
            .field("name", &self.name)
            .field("floor", &self.floor)
            .field("missing", &self.missing)
            .field("lobe_width", &self.lobe_width)
            .finish_non_exhaustive()
    }
}

/// The sample index of bins (θ_h, θ_d, φ_d).
pub fn merl_index(theta_h: usize, theta_d: usize, phi_d: usize) -> usize {
    phi_d + PHI_D_BINS * (theta_d + THETA_D_BINS * theta_h)
}

/// The bins (θ_h, θ_d, φ_d) of sample `index`: the inverse of [`merl_index`].
pub fn merl_bins(index: usize) -> (usize, usize, usize) {
    (index / (PHI_D_BINS * THETA_D_BINS), (index / PHI_D_BINS) % THETA_D_BINS, index % PHI_D_BINS)
}

/// The angles \[rad\] at the centre of each bin, where a sample stands (`shading::measured`, docs/measured.md):
/// `θ_h = ((i + ½)/90)² π/2` (the square-root scale), `θ_d = (j + ½) π/180`, `φ_d = (k + ½) π/180`.
pub fn merl_bin_angles(i: usize, j: usize, k: usize) -> (f64, f64, f64) {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let u = (i as f64 + 0.5) / THETA_H_BINS as f64;
    let theta_d = (j as f64 + 0.5) / THETA_D_BINS as f64 * half_pi;
    (u * u * half_pi, theta_d, (k as f64 + 0.5) / PHI_D_BINS as f64 * std::f64::consts::PI)
}

/// Whether light and view are both above the horizon at the centre of bin (i, j, k): with h at θ_h from the
/// normal and l at (θ_d, φ_d) about h (`shading::measured::half_diff_directions`), `cos θ_l = cos θ_d cos θ_h −
/// sin θ_d cos φ_d sin θ_h` and `cos θ_v = cos θ_d cos θ_h + sin θ_d cos φ_d sin θ_h`, both positive where
/// `cos θ_d cos θ_h > |sin θ_d cos φ_d sin θ_h|`.
pub fn bin_centre_above_horizon(i: usize, j: usize, k: usize) -> bool {
    let (theta_h, theta_d, phi_d) = merl_bin_angles(i, j, k);
    theta_d.cos() * theta_h.cos() > (theta_d.sin() * phi_d.cos() * theta_h.sin()).abs()
}

impl MeasuredBrdf {
    /// A table from ρ values [1/sr] per sample and channel (`rho[c][i]`; negative: missing). Refused when every
    /// sample is missing.
    pub fn from_planes(name: &str, rho: &[Vec<f64>; 3]) -> Result<Self, String> {
        let mut values = vec![0f32; 3 * MERL_SAMPLES];
        let mut missing = 0;
        let mut missing_mask = Vec::new();
        for (c, plane) in rho.iter().enumerate() {
            if plane.len() != MERL_SAMPLES {
                return Err(format!("{name}: channel {c} holds {} samples, not {MERL_SAMPLES}", plane.len()));
            }
            for (i, &v) in plane.iter().enumerate() {
                if !v.is_finite() || v > f32::MAX as f64 {
                    return Err(format!("{name}: sample {i} of channel {c} is {v}, not a finite reflectance"));
                }
                if v < 0.0 {
                    missing += 1;
                    missing_mask.resize(MERL_SAMPLES, false);
                    missing_mask[i] = true;
                } else {
                    values[3 * i + c] = v as f32;
                }
            }
        }
        if missing > 0 {
            fill_from_nearest_valid(name, &mut values, &missing_mask)?;
        }
        let missing_above_horizon = (missing_mask.iter().enumerate())
            .filter(|&(index, &m)| {
                let (i, j, k) = merl_bins(index);
                m && bin_centre_above_horizon(i, j, k)
            })
            .count();
        let mut floor = [f32::INFINITY; 3];
        for (i, s) in values.chunks_exact(3).enumerate() {
            if !missing_mask.get(i).copied().unwrap_or(false) {
                for c in 0..3 {
                    floor[c] = floor[c].min(s[c]);
                }
            }
        }
        let lobe_width = peak_width(&values, floor);
        Ok(Self { name: name.into(), values, floor, missing, missing_above_horizon, missing_mask, lobe_width })
    }

    /// The warning a table with missing samples above the horizon deserves, naming it; `None` without (samples
    /// missing beyond the horizon are the database's pattern, not a gap).
    pub fn missing_warning(&self) -> Option<String> {
        (self.missing_above_horizon > 0).then(|| {
            format!(
                "{}: {} samples above the horizon are missing (negative in the file); the lookup interpolates the \
                 valid samples around them",
                self.name, self.missing_above_horizon
            )
        })
    }

    /// Whether a channel of sample `i` was missing.
    pub fn is_missing(&self, i: usize) -> bool {
        self.missing_mask.get(i).copied().unwrap_or(false)
    }

    /// The value ρ [1/sr] of sample `i`, channel `c`.
    pub fn value(&self, i: usize, c: usize) -> f32 {
        self.values[3 * i + c]
    }
}

/// Gives each missing sample (`missing[i]`) the value of the nearest valid one: a breadth-first search from every
/// valid sample at once over the bins' grid (six neighbours, φ_d wrapping, the θ axes not), so that the distance
/// is the number of steps between bins and ties go to the first valid sample in index order. Err where no sample
/// is valid.
fn fill_from_nearest_valid(name: &str, values: &mut [f32], missing: &[bool]) -> Result<(), String> {
    let mut queue: std::collections::VecDeque<usize> = (0..MERL_SAMPLES).filter(|&i| !missing[i]).collect();
    if queue.is_empty() {
        return Err(format!("{name}: every sample is missing (negative); there is nothing to render"));
    }
    let mut reached: Vec<bool> = missing.iter().map(|m| !m).collect();
    while let Some(at) = queue.pop_front() {
        let (i, j, k) = merl_bins(at);
        let mut neighbours = [None; 6];
        neighbours[0] = Some(merl_index(i, j, (k + 1) % PHI_D_BINS));
        neighbours[1] = Some(merl_index(i, j, (k + PHI_D_BINS - 1) % PHI_D_BINS));
        neighbours[2] = (j + 1 < THETA_D_BINS).then(|| merl_index(i, j + 1, k));
        neighbours[3] = j.checked_sub(1).map(|j| merl_index(i, j, k));
        neighbours[4] = (i + 1 < THETA_H_BINS).then(|| merl_index(i + 1, j, k));
        neighbours[5] = i.checked_sub(1).map(|i| merl_index(i, j, k));
        for next in neighbours.into_iter().flatten() {
            if !reached[next] {
                reached[next] = true;
                values.copy_within(3 * at..3 * at + 3, 3 * next);
                queue.push_back(next);
            }
        }
    }
    Ok(())
}

/// [`MeasuredBrdf::lobe_width`] of a table.
fn peak_width(values: &[f32], floor: [f32; 3]) -> f32 {
    let above = |i: usize| {
        let s = &values[3 * merl_index(i, 0, 0)..][..3];
        (0..3).map(|c| (s[c] - floor[c]) as f64).sum::<f64>() / 3.0
    };
    let peak = above(0);
    if peak > 0.0 {
        for i in 1..THETA_H_BINS {
            if above(i) <= (-0.5f64).exp() * peak {
                return (2.0 * merl_bin_angles(i, 0, 0).0) as f32;
            }
        }
    }
    std::f32::consts::PI
}

/// Reads a MERL file's bytes (`name` for messages): the header must be 90, 90, 180 and the size exactly
/// [`MERL_FILE_BYTES`]; a non-finite value is refused; negative values are missing samples.
pub fn parse_merl(name: &str, bytes: &[u8]) -> Result<MeasuredBrdf, String> {
    if bytes.len() < 12 {
        return Err(format!("{name}: {} bytes is too short for a MERL BRDF header (12 bytes)", bytes.len()));
    }
    let dims: Vec<i32> = bytes[..12].chunks_exact(4).map(|b| i32::from_le_bytes(b.try_into().unwrap())).collect();
    if dims != [THETA_H_BINS as i32, THETA_D_BINS as i32, PHI_D_BINS as i32] {
        return Err(format!(
            "{name}: the header says {} × {} × {} samples; a MERL BRDF has 90 × 90 × 180",
            dims[0], dims[1], dims[2]
        ));
    }
    if bytes.len() != MERL_FILE_BYTES {
        let what = if bytes.len() < MERL_FILE_BYTES { "truncated" } else { "too long" };
        return Err(format!("{name}: {what}: {} bytes, a MERL BRDF has {MERL_FILE_BYTES}", bytes.len()));
    }
    let planes: [Vec<f64>; 3] = std::array::from_fn(|c| {
        let plane = &bytes[12 + c * 8 * MERL_SAMPLES..][..8 * MERL_SAMPLES];
        plane
            .chunks_exact(8)
            .map(|b| {
                let stored = f64::from_le_bytes(b.try_into().unwrap());
                // Missing samples keep their sign (any negative value); the rest are scaled to ρ.
                if stored < 0.0 {
                    -1.0
                } else {
                    stored * MERL_CHANNEL_SCALE[c]
                }
            })
            .collect()
    });
    MeasuredBrdf::from_planes(name, &planes)
}

/// A MERL file's bytes for ρ values [1/sr] per channel and sample (`rho[c][i]`; negative: missing): the inverse
/// of [`parse_merl`], for tests and synthetic tables.
pub fn merl_bytes(rho: &[Vec<f64>; 3]) -> Vec<u8> {
    let mut out = Vec::with_capacity(MERL_FILE_BYTES);
    for d in [THETA_H_BINS, THETA_D_BINS, PHI_D_BINS] {
        out.extend_from_slice(&(d as i32).to_le_bytes());
    }
    for (c, plane) in rho.iter().enumerate() {
        for &v in plane {
            let stored = if v < 0.0 { -1.0 } else { v / MERL_CHANNEL_SCALE[c] };
            out.extend_from_slice(&stored.to_le_bytes());
        }
    }
    out
}

/// Reads a MERL file the user named (`--merl`, `sunshade fit-brdf`): a regular file, parsed by [`parse_merl`];
/// errors name the file.
pub fn read_merl_file(path: &std::path::Path) -> Result<MeasuredBrdf, String> {
    let name = path.display().to_string();
    let bytes = super::gltf::files::read_regular_file_at_most(path, MERL_FILE_BYTES as u64)
        .map_err(|e| format!("MERL BRDF '{name}': {e}"))?;
    parse_merl(&name, &bytes)
}

/// A shared table (materials naming one file hold the same `Arc`).
pub type SharedMeasuredBrdf = Arc<MeasuredBrdf>;

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(v: f64) -> [Vec<f64>; 3] {
        std::array::from_fn(|c| vec![v * (c + 1) as f64; MERL_SAMPLES])
    }

    #[test]
    fn reads_back_what_it_writes() {
        let mut rho = constant(0.1);
        rho[1][merl_index(3, 4, 5)] = -1.0;
        rho[0][merl_index(0, 0, 0)] = 2.5;
        let t = parse_merl("x.binary", &merl_bytes(&rho)).unwrap();
        assert_eq!(t.missing, 1);
        assert!(t.is_missing(merl_index(3, 4, 5)) && !t.is_missing(0));
        // A missing sample is missing in every channel and holds its nearest valid neighbour's values.
        assert_eq!(t.value(merl_index(3, 4, 5), 1), 0.2);
        assert_eq!(t.value(merl_index(3, 4, 5), 0), 0.1);
        assert!((t.value(merl_index(0, 0, 0), 0) - 2.5).abs() < 1e-6);
        assert!((t.value(7, 2) as f64 - 0.3).abs() < 1e-7);
        assert_eq!(t.floor, [0.1, 0.2, 0.3]);
        // The peak in red alone: the mean falls below e^{-1/2} of it at the next bin.
        assert!((t.lobe_width as f64 - 2.0 * merl_bin_angles(1, 0, 0).0).abs() < 1e-9);
        assert_eq!(parse_merl("c", &merl_bytes(&constant(0.2))).unwrap().lobe_width, std::f32::consts::PI);
    }

    #[test]
    fn bins_and_index_are_inverses() {
        for (i, j, k) in [(0, 0, 0), (89, 89, 179), (3, 40, 7), (45, 0, 179)] {
            assert_eq!(merl_bins(merl_index(i, j, k)), (i, j, k));
        }
    }

    #[test]
    fn missing_samples_take_the_nearest_valid_value_and_not_the_floor() {
        // Valid only at θ_h bin 0 (value 1 + j) and φ_d bin 3 of θ_h bin 5 (value 100): the rest missing.
        let mut rho: [Vec<f64>; 3] = std::array::from_fn(|_| vec![-1.0; MERL_SAMPLES]);
        for plane in rho.iter_mut() {
            for j in 0..THETA_D_BINS {
                for k in 0..PHI_D_BINS {
                    plane[merl_index(0, j, k)] = 1.0 + j as f64;
                }
            }
            plane[merl_index(5, 7, 3)] = 100.0;
        }
        let t = MeasuredBrdf::from_planes("m", &rho).unwrap();
        assert_eq!(t.missing, 3 * (MERL_SAMPLES - THETA_D_BINS * PHI_D_BINS - 1));
        // Straight up the θ_h axis from bin 0 (distance i), unless the lone sample is nearer.
        assert_eq!(t.value(merl_index(40, 20, 90), 1), 21.0);
        assert_eq!(t.value(merl_index(5, 7, 2), 0), 100.0);
        // φ_d wraps: 4 steps from the lone sample (3, 2, 1, 0, 179) against 5 from θ_h bin 0.
        assert_eq!(t.value(merl_index(5, 7, 179), 0), 100.0);
        assert_eq!(t.value(merl_index(5, 7, 176), 0), 8.0);
        assert_eq!(t.value(merl_index(4, 7, 3), 2), 100.0);
        assert_eq!(t.floor, [1.0; 3]);
        let none: [Vec<f64>; 3] = std::array::from_fn(|_| vec![-1.0; MERL_SAMPLES]);
        let e = MeasuredBrdf::from_planes("none.binary", &none).unwrap_err();
        assert!(e.contains("none.binary") && e.contains("every sample is missing"), "{e}");
    }

    #[test]
    fn refuses_bad_files_with_one_line() {
        let good = merl_bytes(&constant(0.1));
        let mut header = good.clone();
        header[0..4].copy_from_slice(&45i32.to_le_bytes());
        let e = parse_merl("h.binary", &header).unwrap_err();
        assert!(e.contains("h.binary") && e.contains("45 × 90 × 180"), "{e}");
        let e = parse_merl("t.binary", &good[..good.len() - 8]).unwrap_err();
        assert!(e.contains("t.binary: truncated"), "{e}");
        let mut long = good.clone();
        long.push(0);
        assert!(parse_merl("l", &long).unwrap_err().contains("too long"));
        assert!(parse_merl("s", &good[..5]).unwrap_err().contains("too short"));
        let mut nan = good.clone();
        nan[12 + 8 * 17..][..8].copy_from_slice(&f64::NAN.to_le_bytes());
        let e = parse_merl("n.binary", &nan).unwrap_err();
        assert!(e.contains("sample 17 of channel 0") && !e.contains('\n'), "{e}");
        let mut inf = good;
        inf[12 + 8 * MERL_SAMPLES..][..8].copy_from_slice(&f64::INFINITY.to_le_bytes());
        assert!(parse_merl("i", &inf).unwrap_err().contains("channel 1"));
    }
}
