//! `sunshade albedo`: the energy check of the BRDFs and the accuracy of the sampled light integrals, as tables.
//!
//! - Directional albedo `a(θ) = ∫ ρ(ω, v) (n·ω)+ dω` of each specular lobe (ks = 1) at 0°, 30°, 60°, 85° and 89.9°
//!   incidence, by converged quadrature (`shading::albedo`): at most 1 for an energy-conserving BRDF.
//! - With a scene: the same for each of its materials, per channel, diffuse part included.
//! - Without one: also the relative error of the deterministic sample grids that integrate specular lobes over
//!   the sun's disk, a disk skylight and the sky, against converged values, per grid size.
//!
//! `--update FILE` writes the tables into the regions "albedo" and "convergence" of a Markdown file.

use std::path::PathBuf;

use clap::Args;
use glam::DVec3;
use rayon::prelude::*;

use super::generated::{check_region, machine, print_output, today, update_region};
use super::CliError;
use crate::scene::{self, Brdf, LoadOptions};
use crate::shading::albedo::lobe_albedo;
use crate::shading::lights::disk::DiskGeometry;
use std::f64::consts::PI;

use crate::shading::measured::measured_albedo;
use crate::shading::sky_lune::{sky_lobe_in_lune, Lune};
use crate::shading::{disk_lobe_integral, sky_lobe_integral, sun_lobe_integral, SurfacePoint};

#[derive(Args, Debug)]
pub struct AlbedoArgs {
    /// A glTF scene: tabulate its materials instead of the standard lobes.
    pub scene: Option<PathBuf>,
    /// Replace the generated regions "albedo" and "convergence" of this Markdown file (repeatable).
    #[arg(long, value_name = "MARKDOWN")]
    pub update: Vec<PathBuf>,
    /// Print the tables as JSON (rows by column title) instead of Markdown; --update still writes Markdown.
    #[arg(long)]
    pub json: bool,
}

/// Grid side of a measured table's albedo quadrature (`shading::measured::measured_albedo`): 512² lookups, cells
/// of about 0.35° near the normal.
const MEASURED_ALBEDO_GRID: u32 = 512;

/// Incidence angles [degrees] of the albedo tables.
const INCIDENCES_DEGREES: [f64; 5] = [0.0, 30.0, 60.0, 85.0, 89.9];

/// The quadrature's target: two successive orders agree to this (relative).
const QUADRATURE_TOLERANCE: f64 = 1e-9;

fn lobe(kind: &str, p: f64, q: f64) -> (String, Brdf) {
    let (kd, ks) = ([0.0; 3], [1.0; 3]);
    match kind {
        "phong" => (format!("Phong e={p}"), Brdf::Phong { kd, ks, exponent: p as f32 }),
        "blinn-phong" => (format!("Blinn-Phong e={p}"), Brdf::BlinnPhong { kd, ks, exponent: p as f32 }),
        // A white metal: the GGX lobe with Fresnel 1, whose albedo below 1 is what single scattering loses.
        "gltf" => {
            let specular = crate::scene::material::DielectricSpecular::DEFAULT;
            (format!("glTF metal α={p}"), Brdf::Gltf { base_color: [1.0; 3], metallic: 1.0, alpha: p as f32, specular })
        }
        _ if p == q => (format!("Ward α={p}"), Brdf::Ward { kd, ks, alpha_x: p as f32, alpha_y: q as f32 }),
        _ => (format!("Ward αx={p} αy={q}"), Brdf::Ward { kd, ks, alpha_x: p as f32, alpha_y: q as f32 }),
    }
}

fn standard_lobes() -> Vec<(String, Brdf)> {
    let mut v = Vec::new();
    for kind in ["phong", "blinn-phong"] {
        for e in [0.0, 1.0, 10.0, 100.0, 1e4, 1e6] {
            v.push(lobe(kind, e, e));
        }
    }
    for a in [0.01, 0.05, 0.1, 0.2, 0.5, 1.0] {
        v.push(lobe("ward", a, a));
    }
    v.push(lobe("ward", 0.02, 0.3));
    for a in [0.01, 0.04, 0.25, 0.5, 1.0] {
        v.push(lobe("gltf", a, a));
    }
    v
}

pub fn run(a: &AlbedoArgs) -> Result<(), CliError> {
    for doc in &a.update {
        check_region(doc, "albedo")?;
        if a.scene.is_none() {
            check_region(doc, "convergence")?;
        }
    }
    let header = format!("Computed by `sunshade albedo` on {} ({}).\n\n", today(), machine());
    let albedo = match &a.scene {
        Some(path) => {
            let scene = scene::load_with_options(path, &LoadOptions::default())?;
            scene_table(&scene.materials.iter().map(|m| (m.name.clone(), m.brdf.clone())).collect::<Vec<_>>())
        }
        None => lobe_table(&standard_lobes()),
    };
    let albedo = format!("{header}{albedo}");
    if !a.json {
        print!("{albedo}");
    }
    let convergence = if a.scene.is_none() {
        let c = format!("{header}{}", convergence_tables());
        if !a.json {
            print!("\n{c}");
        }
        Some(c)
    } else {
        None
    };
    if a.json {
        print_output(&format!("{albedo}\n{}", convergence.as_deref().unwrap_or("")), true);
    }
    for doc in &a.update {
        update_region(doc, "albedo", &albedo)?;
        if let Some(c) = &convergence {
            update_region(doc, "convergence", c)?;
        }
        eprintln!("sunshade albedo: updated {}", doc.display());
    }
    Ok(())
}

/// A Markdown table header: the leading column titles, then one right-aligned column per label.
fn table_header(leading: &[&str], columns: impl ExactSizeIterator<Item = String>) -> String {
    let count = columns.len();
    let mut s = format!("| {} |", leading.join(" | "));
    for c in columns {
        s += &format!(" {c} |");
    }
    s += "\n|---|";
    s += &"---:|".repeat(leading.len() - 1 + count);
    s + "\n"
}

fn incidence_header(first: &str) -> String {
    table_header(&[first], INCIDENCES_DEGREES.iter().map(|d| format!("{d}°")))
}

/// Directional albedo of each lobe; anisotropic lobes at two view azimuths (along t, and 45° from it).
fn lobe_table(lobes: &[(String, Brdf)]) -> String {
    let mut s = incidence_header("lobe (ks = 1)");
    for (name, brdf) in lobes {
        let azimuths: &[f64] = match brdf {
            Brdf::Ward { alpha_x, alpha_y, .. } if alpha_x != alpha_y => &[0.0, 45.0],
            _ => &[0.0],
        };
        for &az in azimuths {
            let label = if azimuths.len() > 1 { format!("{name}, view azimuth {az}°") } else { name.clone() };
            s += &format!("| {label} |");
            for d in INCIDENCES_DEGREES {
                let (value, _) = lobe_albedo(brdf, d.to_radians(), az.to_radians(), QUADRATURE_TOLERANCE);
                s += &format!(" {value:.6} |");
            }
            s += "\n";
        }
    }
    s
}

/// Directional albedo of whole materials, per channel: `kd + ks a(θ)` (Lambert: the albedo).
fn scene_table(materials: &[(String, Brdf)]) -> String {
    let mut s = incidence_header("material: r, g, b");
    for (name, brdf) in materials {
        let (kd, ks) = match *brdf {
            Brdf::Lambert { albedo } => (albedo, [0.0; 3]),
            Brdf::Phong { kd, ks, .. } | Brdf::BlinnPhong { kd, ks, .. } | Brdf::Ward { kd, ks, .. } => (kd, ks),
            Brdf::Gltf { base_color, metallic, alpha, specular } => {
                // Per channel: the base colour enters the lobe (the metal's Fresnel, the dielectric's darkening),
                // and so does f0 (the dielectric's Fresnel).
                s += &format!("| {name} (glTF) |");
                for d in INCIDENCES_DEGREES {
                    // The directional albedo of a grey glTF BRDF (every channel alike).
                    let albedo = |b: f32, metallic: f32, f0: f32, f90: f32| {
                        let specular = crate::scene::material::DielectricSpecular { f0: [f0; 3], f90 };
                        let channel = Brdf::Gltf { base_color: [b; 3], metallic, alpha, specular };
                        channel.kd()[0] as f64 + lobe_albedo(&channel, d.to_radians(), 0.0, QUADRATURE_TOLERANCE).0
                    };
                    // The base keeps `1 − max F` of every channel, where the one-channel BRDF keeps its own: the
                    // difference is `(1 − m) b (f0_c − max f0) (1 − X)`, `X = ∫ (1 − v·h)⁵ cos/π dω`, which is
                    // `1 + A(0) − A(1)` for the albedos A of a dielectric with f0 0, f90 1, metallic 0 and base 0
                    // or 1 (computed once, and only for a tinted f0).
                    let tinted = specular.f0.iter().any(|&f| f != specular.f0_max());
                    let schlick =
                        if tinted { 1.0 + albedo(0.0, 0.0, 0.0, 1.0) - albedo(1.0, 0.0, 0.0, 1.0) } else { 0.0 };
                    let a: [f64; 3] = std::array::from_fn(|c| {
                        let own = albedo(base_color[c], metallic, specular.f0[c], specular.f90);
                        let gap = (specular.f0[c] - specular.f0_max()) as f64;
                        own + (1.0 - metallic as f64) * base_color[c] as f64 * gap * (1.0 - schlick)
                    });
                    s += &format!(" {:.4}, {:.4}, {:.4} |", a[0], a[1], a[2]);
                }
                s += "\n";
                continue;
            }
            Brdf::Measured { ref table, lookup } => {
                // The table's own albedo (no kd/ks split): quadrature over the light's hemisphere.
                s += &format!("| {name} (measured, {}) |", table.name);
                for d in INCIDENCES_DEGREES {
                    let a = measured_albedo(table, lookup, d.to_radians(), MEASURED_ALBEDO_GRID);
                    s += &format!(" {:.4}, {:.4}, {:.4} |", a[0], a[1], a[2]);
                }
                s += "\n";
                continue;
            }
        };
        s += &format!("| {name} |");
        for d in INCIDENCES_DEGREES {
            let a = if ks == [0.0; 3] { 0.0 } else { lobe_albedo(brdf, d.to_radians(), 0.0, QUADRATURE_TOLERANCE).0 };
            let c: Vec<String> = (0..3).map(|i| format!("{:.4}", kd[i] as f64 + ks[i] as f64 * a)).collect();
            s += &format!(" {} |", c.join(", "));
        }
        s += "\n";
    }
    s
}

/// A surface point with normal +Y, tangent +X, viewed from `to_viewer`.
fn point(position: DVec3, to_viewer: DVec3) -> SurfacePoint {
    SurfacePoint { position, normal: DVec3::Y, tangent: DVec3::X, bitangent: DVec3::Z, to_viewer }
}

fn mirror_about_y(w: DVec3) -> DVec3 {
    DVec3::new(-w.x, w.y, -w.z)
}

/// Grid sizes (per axis) of the convergence tables; the defaults are 8 (sun) and 16 (disk lights, sky).
const GRIDS: [u32; 6] = [2, 4, 8, 16, 32, 64];

/// Converged values use this grid (the midpoint rule's error falls as 1/k²: ~1e-3 of the 16 × 16 error).
const CONVERGED_GRID: u32 = 512;

/// A deterministic uniform sequence in [0, 1) (a 64-bit LCG): the same configurations on every run.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn header(first: &str, second: &str) -> String {
    table_header(&[first, second], GRIDS.iter().map(|k| format!("{k}×{k}")))
}

/// A row of "median / max" relative errors over configurations, each given as the integral as a function of the
/// grid size (`None`: the converged value); cases whose converged value is at most `min_value` are left out.
fn statistics_row<F: Fn(Option<u32>) -> f64 + Sync>(label: &str, cases: &[F], min_value: f64) -> String {
    let errors: Vec<Vec<f64>> = cases
        .par_iter()
        .filter_map(|f| {
            let exact = f(None);
            (exact > min_value).then(|| GRIDS.iter().map(|&k| ((f(Some(k)) - exact) / exact).abs()).collect())
        })
        .collect();
    let mut s = format!("| {label} | {} |", errors.len());
    for g in 0..GRIDS.len() {
        let mut e: Vec<f64> = errors.iter().map(|row| row[g]).collect();
        e.sort_by(f64::total_cmp);
        s += &format!(" {:.1e} / {:.1e} |", e[e.len() / 2], e[e.len() - 1]);
    }
    s + "\n"
}

fn convergence_lobes() -> Vec<(String, Brdf)> {
    vec![
        lobe("phong", 1.0, 0.0),
        lobe("phong", 100.0, 0.0),
        lobe("phong", 1e4, 0.0),
        lobe("phong", 1e6, 0.0),
        lobe("blinn-phong", 100.0, 0.0),
        lobe("blinn-phong", 1e4, 0.0),
        lobe("ward", 0.01, 0.01),
        lobe("ward", 0.2, 0.2),
        lobe("ward", 0.02, 0.3),
        lobe("gltf", 0.01, 0.01),
        lobe("gltf", 0.0625, 0.0625),
        lobe("gltf", 0.25, 0.25),
        lobe("gltf", 1.0, 1.0),
    ]
}

/// What `--tolerance` claims for the sun's grid (`accuracy::bounds`): the delta sun's bound and the k × k grid's, per
/// lobe, for any camera, under the 0.53° sun.
fn sun_bound_table() -> String {
    use crate::accuracy::bounds::{sun_delta_bound, sun_grid_bound, SunViewAngles};
    let r = 0.5 * 0.53f64.to_radians();
    let mut s = "\n**The sun's bounds** that `--tolerance` chooses by (`src/accuracy/bounds.rs`; docs/accuracy.md, \
                 \"Error bounds\"), for any camera, under the 0.53° sun: the delta sun's relative error bound against \
                 the disk, and the graded grid's per size (1: no claim, a grid under 4² or cells wider than a quarter \
                 of the lobe). The table above measures the same grids:\n\n"
        .to_string();
    s += &table_header(&["lobe (ks = 1)", "delta"], GRIDS.iter().map(|k| format!("{k}×{k}")));
    for (name, brdf) in convergence_lobes() {
        s += &format!("| {name} | {:.1e} |", sun_delta_bound(&brdf, r, SunViewAngles::ALL));
        for &k in &GRIDS {
            s += &format!(" {:.1e} |", sun_grid_bound(&brdf, r, k, SunViewAngles::ALL));
        }
        s += "\n";
    }
    s
}

/// Relative errors of the sampled integrals `∫ lobe (n·ω)+ dω` over each light, per grid size.
fn convergence_tables() -> String {
    let mut s = String::new();
    // The sun: views up to 80° from the normal, the sun's centre within 1.5 of its radii of the mirror direction.
    let sun_diameter = 0.53f64.to_radians();
    let mut rng = Lcg(1);
    let sun_cases: Vec<(SurfacePoint, DVec3)> = (0..40)
        .map(|_| {
            let (tv, pv) = (rng.next() * 80f64.to_radians(), rng.next() * 2.0 * PI);
            let v = DVec3::new(tv.sin() * pv.cos(), tv.cos(), tv.sin() * pv.sin());
            let r = mirror_about_y(v);
            let (off, turn) = (rng.next() * 0.75 * sun_diameter, rng.next() * 2.0 * PI);
            let t = r.cross(DVec3::Y).try_normalize().unwrap_or(DVec3::X);
            let axis = (turn.cos() * t + turn.sin() * r.cross(t)).normalize();
            (point(DVec3::ZERO, v), glam::DQuat::from_axis_angle(axis, off) * r)
        })
        .filter(|(_, sun)| sun.y > 0.01)
        .collect();
    s += &format!(
        "**Sun** (a disk 0.53° wide: its cap as a disk one unit away), {} random views up to 80° from the normal with the sun's centre within 1.5 \
         of its radii of the lobe's peak. Relative error of the graded segment grid against a {CONVERGED_GRID}² grid, \
         median / max, per grid size (default 8 × 8, `--sun-samples`):\n\n",
        sun_cases.len()
    );
    s += &header("lobe (ks = 1)", "cases");
    for (name, brdf) in convergence_lobes() {
        let cases: Vec<_> = sun_cases
            .iter()
            .map(|(p, sun)| {
                let brdf = brdf.clone();
                move |k: Option<u32>| sun_lobe_integral(&brdf, p, *sun, sun_diameter, k.unwrap_or(CONVERGED_GRID))
            })
            .collect();
        s += &statistics_row(&name, &cases, 0.0);
    }
    s += &sun_bound_table();
    // Disk skylights: the lecture's disk (R = 0.6 m at f = 2.5 m, facing down) over receivers on the floor within
    // 3 m of its axis, tilted up to ~35°, viewed from the mirror of a point within 1 m of the disk's centre (the
    // lobe's peak on the disk, near its rim or off it).
    let disk = DiskGeometry { center: DVec3::new(0.0, 2.5, 0.0), direction: -DVec3::Y, radius: 0.6 };
    let mut rng = Lcg(2);
    let disk_cases: Vec<SurfacePoint> = (0..60)
        .filter_map(|_| {
            let x = DVec3::new(rng.next() * 6.0 - 3.0, 0.0, rng.next() * 6.0 - 3.0);
            let n = DVec3::new(rng.next() - 0.5, 1.5, rng.next() - 0.5).normalize();
            let target = disk.center + DVec3::new((rng.next() - 0.5) * 2.0, 0.0, (rng.next() - 0.5) * 2.0);
            let l = (target - x).normalize();
            let v = 2.0 * n.dot(l) * n - l;
            let t = n.cross(DVec3::X).normalize();
            (v.dot(n) > 0.05).then_some(SurfacePoint {
                position: x,
                normal: n,
                tangent: t,
                bitangent: n.cross(t),
                to_viewer: v,
            })
        })
        .collect();
    s += &format!(
        "\n**Disk skylight** (R = 0.6 m, 2.5 m above the floor), {} random receivers on the floor within 3 m of its \
         axis, tilted up to 35°, each viewed from the mirror of a point within 1 m of the disk's centre (the lobe's \
         peak on the disk, near its rim or off it; cases where the lobe gives less than 1e-6 are left out). \
         Relative error of the graded segment grid against a {CONVERGED_GRID}² grid, median / max, per grid size \
         (default 16 × 16, `--samples`):\n\n",
        disk_cases.len()
    );
    s += &header("lobe (ks = 1)", "cases");
    for (name, brdf) in convergence_lobes() {
        let cases: Vec<_> = disk_cases
            .iter()
            .map(|p| {
                let brdf = brdf.clone();
                move |k: Option<u32>| disk_lobe_integral(&brdf, p, &disk, k.unwrap_or(CONVERGED_GRID))
            })
            .collect();
        s += &statistics_row(&name, &cases, 1e-6);
    }
    // The sky: the sampled hemisphere integral against the directional albedo by converged quadrature.
    s += "\n**Overcast sky** (uniform radiance over the hemisphere), views at 0°, 30°, 60° and 85° from the normal \
          (azimuths 0° and 45° for the anisotropic lobe). Relative error of the stratified grid through the lobe's \
          inverse CDF against the directional albedo by quadrature, median / max, per grid size (default 16 × 16, \
          `--samples`):\n\n";
    s += &header("lobe (ks = 1)", "cases");
    for (name, brdf) in convergence_lobes() {
        let mut cases = Vec::new();
        for deg in [0.0f64, 30.0, 60.0, 85.0] {
            for az in [0.0f64, 45.0] {
                let (t, a) = (deg.to_radians(), az.to_radians());
                let p = point(DVec3::ZERO, DVec3::new(t.sin() * a.cos(), t.cos(), t.sin() * a.sin()));
                let brdf = brdf.clone();
                // The converged value is the directional albedo by quadrature.
                cases.push(move |k: Option<u32>| match k {
                    None => lobe_albedo(&brdf, t, a, QUADRATURE_TOLERANCE).0,
                    Some(k) => sky_lobe_integral(&brdf, &p, k),
                });
            }
        }
        s += &statistics_row(&name, &cases, 0.0);
    }
    s += &tilted_sky_table();
    s
}

/// The sky on tilted surfaces: the horizontal cuts the lobe (`shading::sky_lune`).
fn tilted_sky_table() -> String {
    let mut s = format!(
        "\n**Overcast sky on tilted surfaces** (the sky is the upper hemisphere: the horizontal cuts the lobe), \
         surfaces tilted 45°, 90° and 135° from up, views at 30°, 60° and 85° from the normal, uphill, across and \
         downhill (azimuths 0°, 90°, 180°). Relative error of the renderer's sum against the upper lune's grid at \
         {CONVERGED_GRID}² (whose edge is the horizontal; cases where the sky holds under 1e-2 of the lobe are left \
         out), median / max, per grid size (default 16 × 16, `--samples`):\n\n"
    );
    s += &header("lobe (ks = 1)", "cases");
    for (name, brdf) in convergence_lobes() {
        let mut cases = Vec::new();
        for tilt in [45.0f64, 90.0, 135.0] {
            for theta in [30.0f64, 60.0, 85.0] {
                for phi in [0.0f64, 90.0, 180.0] {
                    let (t, th, ph) = (tilt.to_radians(), theta.to_radians(), phi.to_radians());
                    // n tilted about Z; uphill u = up's part across n; e = n × u.
                    let n = DVec3::new(t.sin(), t.cos(), 0.0);
                    let u = (DVec3::Y - n.y * n).normalize();
                    let e = n.cross(u);
                    let v = th.cos() * n + th.sin() * (ph.cos() * u + ph.sin() * e);
                    let p = SurfacePoint {
                        position: DVec3::ZERO,
                        normal: n,
                        tangent: u,
                        bitangent: n.cross(u),
                        to_viewer: v,
                    };
                    let brdf = brdf.clone();
                    cases.push(move |k: Option<u32>| match k {
                        None => sky_lobe_in_lune(&brdf, &p, CONVERGED_GRID, Lune::Above, None)[0],
                        Some(k) => sky_lobe_integral(&brdf, &p, k),
                    });
                }
            }
        }
        s += &statistics_row(&name, &cases, 1e-2);
    }
    s
}
