//! Whether the lobe grids would gain from a grid per pixel class (the figures in docs/accuracy.md, "What prevents
//! it, measured"):
//!
//!     cargo run --release --example lobe_grid_pixel_classes
//!
//! The reference of brdfs.glb under the sun (1000 W/m², elevation 40°, azimuth 30°) and a sky of 100 W/(m²·sr),
//! unshadowed, at 128², rendered on the rungs 13² to 80² of `--tolerance`'s ladder of lobe grids. Each material's
//! pixels (`cpu::material_map`) are split into its silhouette ring (a pixel with a neighbour of another material
//! or of nothing) and the rest, and for each pair of consecutive rungs the largest relative difference of each
//! class is printed (`refinement::max_difference_where`, the diff's floor: 1% of the finer image's peak), as the
//! study measures a material.

use sunshade::accuracy::refinement::max_difference_where;
use sunshade::cpu::{self, ReferenceOptions};
use sunshade::settings::{self, CameraOptions, LightOptions, SunOptions};
use sunshade::shading::{ShadingOptions, Shadows};

fn main() {
    let scene = sunshade::scene::load(std::path::Path::new("models/brdfs.glb")).expect("models/brdfs.glb");
    let lights = LightOptions {
        sun: SunOptions {
            direction: Some(settings::sun_direction_from_angles(40.0, 30.0)),
            irradiance: Some(1000.0),
            ..Default::default()
        },
        sky: Some([100.0; 3]),
        shading: ShadingOptions { shadows: Shadows::None, ..Default::default() },
        ..Default::default()
    };
    let (w, h) = (128i64, 128i64);
    let base =
        settings::resolve_with(&scene, w as u32, h as u32, &CameraOptions::default(), &lights).expect("settings");
    let reference = ReferenceOptions::default();
    let map = cpu::material_map(&scene, &base, &reference);
    let at = |x: i64, y: i64| if x < 0 || y < 0 || x >= w || y >= h { None } else { map[(y * w + x) as usize] };
    let ring: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let m = at(x, y);
            m.is_some() && (-1..=1).any(|dx| (-1..=1).any(|dy| at(x + dx, y + dy) != m))
        })
        .collect();
    let mut previous: Option<(u32, sunshade::Image)> = None;
    for k in [13u32, 19, 27, 39, 56, 80] {
        let mut s = base.clone();
        s.shading.samples_per_axis = k;
        let image = cpu::render(&scene, &s, &reference);
        if let Some((j, prev)) = &previous {
            println!("{j}² to {k}²:");
            for (m, material) in scene.materials.iter().enumerate().filter(|(_, m)| !m.brdf.is_lambert()) {
                // The material's pixels on its ring or inside it, measured as the study measures a material.
                let class = |on_ring: bool| -> Vec<bool> {
                    map.iter().zip(&ring).map(|(&owner, &r)| owner == Some(m) && r == on_ring).collect()
                };
                let on_ring = max_difference_where(prev, &image, Some(&class(true)));
                let inside = max_difference_where(prev, &image, Some(&class(false)));
                println!("  {}: ring {on_ring:.1e}, inside {inside:.1e}", material.name);
            }
        }
        previous = Some((k, image));
    }
}
