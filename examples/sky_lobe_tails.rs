//! How the sky's lobe grid converges per lobe (the figures in docs/accuracy.md, "What prevents it, measured"):
//!
//!     cargo run --release --example sky_lobe_tails
//!
//! For brdfs.glb's four specular lobes, the sky's lobe integral (`shading::sky_lobe_integral`, unit radiance)
//! over the visible normals of a sphere seen along one direction (24 × 24 normals, those with n·v > 0.02), on
//! grids of 4², 8², 16², 24² against the same integral on 512²; the error of each normal relative to the larger of
//! its value and 1% of the lobe's peak over the normals (the diff's floor), the worst and the normal it is at;
//! then the worst over the normals facing the viewer more than halfway (n·v > 0.5), to show that the error is not
//! only the grazing views'; then the worst over a ring of grazing normals (n·v 0.001 to 0.05, a silhouette's),
//! relative to the same floor.

use glam::DVec3;
use sunshade::scene::Brdf;
use sunshade::shading::{sky_lobe_integral, SurfacePoint};

fn point(n: DVec3, v: DVec3) -> SurfacePoint {
    let t = sunshade::scene::tangent::default_tangent(n);
    SurfacePoint { position: DVec3::ZERO, normal: n, tangent: t, bitangent: n.cross(t), to_viewer: v }
}

fn main() {
    let v = DVec3::new(0.0, 0.3, 1.0).normalize();
    let (kd, ks) = ([0.0; 3], [1.0; 3]);
    let lobes = [
        ("Phong e=80", Brdf::Phong { kd, ks, exponent: 80.0 }),
        ("Blinn-Phong e=300", Brdf::BlinnPhong { kd, ks, exponent: 300.0 }),
        ("Ward α=0.15", Brdf::Ward { kd, ks, alpha_x: 0.15, alpha_y: 0.15 }),
        ("Ward αx=0.05 αy=0.3", Brdf::Ward { kd, ks, alpha_x: 0.05, alpha_y: 0.3 }),
    ];
    let n_side = 24;
    for (name, brdf) in &lobes {
        let mut normals = Vec::new();
        for i in 0..n_side {
            for j in 0..n_side {
                let th = (i as f64 + 0.5) / n_side as f64 * std::f64::consts::PI;
                let ph = (j as f64 + 0.5) / n_side as f64 * std::f64::consts::PI;
                let n = DVec3::new(th.cos(), ph.cos() * th.sin(), ph.sin() * th.sin());
                if n.dot(v) > 0.02 {
                    let p = point(n, v);
                    let truth = sky_lobe_integral(brdf, &p, 512);
                    normals.push((p, truth));
                }
            }
        }
        let peak = normals.iter().map(|(_, t)| *t).fold(0.0, f64::max);
        // The silhouette's grazing views: a ring of normals about the viewer at n·v from 0.001 to 0.05.
        let (t1, t2) = (DVec3::X, v.cross(DVec3::X).normalize());
        let mut ring = Vec::new();
        for nv in [0.001, 0.003, 0.01, 0.02, 0.05] {
            for j in 0..n_side {
                let ph = (j as f64 + 0.5) / n_side as f64 * std::f64::consts::TAU;
                let n = nv * v + (1.0f64 - nv * nv).sqrt() * (ph.cos() * t1 + ph.sin() * t2);
                let p = point(n, v);
                let truth = sky_lobe_integral(brdf, &p, 512);
                ring.push((p, truth));
            }
        }
        let mut line = format!("{name}:");
        let mut facing = String::from("  n·v > 0.5:");
        let mut grazing = String::from("  n·v ≤ 0.05:");
        for k in [4u32, 8, 16, 24] {
            let (mut worst, mut at, mut worst_facing) = (0.0, 0.0, 0.0f64);
            for (p, truth) in &normals {
                let e = (sky_lobe_integral(brdf, p, k) - truth).abs() / truth.abs().max(0.01 * peak);
                if e > worst {
                    (worst, at) = (e, p.normal.dot(v));
                }
                if p.normal.dot(v) > 0.5 {
                    worst_facing = worst_facing.max(e);
                }
            }
            let worst_grazing = ring
                .iter()
                .map(|(p, truth)| (sky_lobe_integral(brdf, p, k) - truth).abs() / truth.abs().max(0.01 * peak))
                .fold(0.0, f64::max);
            grazing += &format!("  {k}²: {worst_grazing:.1e}");
            line += &format!("  {k}²: {worst:.1e} (n·v {at:.2})");
            facing += &format!("  {k}²: {worst_facing:.1e}");
        }
        line += &format!("\n{facing}\n{grazing}");
        println!("{line}");
    }
}
