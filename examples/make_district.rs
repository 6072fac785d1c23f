//! Writes a city block of about 100 000 triangles for timing daylight accumulations (docs/daylight.md):
//!
//!     cargo run --release --example make_district -- /tmp/district.glb
//!
//! A 120 m square of ground (a 100 × 100 grid, 20 000 triangles), 64 box buildings 6–30 m tall on a regular
//! plan, and 62 round trees (icospheres of 1 280 triangles) between them: 100 128 triangles, with shadows
//! falling on the ground, the facades and the trees. Too large to keep in `models/`; generated in a second.

use glam::Vec3;
use sunshade::authoring::shapes::{cube, grid, icosphere, MeshData};
use sunshade::authoring::{GltfBuilder, Node};

fn main() -> std::io::Result<()> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "district.glb".into());
    let mut b = GltfBuilder::new();
    let ground_m = b.add_material("ground", [0.25, 0.25, 0.25], false, None);
    let facade_m = b.add_material("facade", [0.6, 0.55, 0.5], false, None);
    let tree_m = b.add_material("tree", [0.1, 0.3, 0.1], false, None);
    let ground = grid(Vec3::ZERO, 120.0, 100);
    let mut buildings = MeshData::default();
    let mut trees = MeshData::default();
    // A deterministic spread of heights (no random generator needed).
    let height = |i: usize| 6.0 + ((i * 37 + 11) % 25) as f32;
    for i in 0..64 {
        let (gx, gz) = ((i % 8) as f32, (i / 8) as f32);
        let (x, z) = (-52.5 + gx * 15.0, -52.5 + gz * 15.0);
        let h = height(i);
        let mut c = cube(0.5);
        for p in &mut c.positions {
            *p = [x + p[0] * 8.0, (p[1] + 0.5) * h, z + p[2] * 8.0];
        }
        buildings.append(&c);
        if i < 62 {
            trees.append(&icosphere(Vec3::new(x + 7.5, 3.0, z + 7.5), 2.5, 3));
        }
    }
    let mesh = b.add_mesh(
        "district",
        &[ground.primitive(Some(ground_m)), buildings.primitive(Some(facade_m)), trees.primitive(Some(tree_m))],
    );
    let n = b.add_node(Node { name: Some("district".into()), mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    b.write(std::path::Path::new(&out))?;
    let triangles = ground.triangle_count() + buildings.triangle_count() + trees.triangle_count();
    println!("wrote {out}: {triangles} triangles");
    Ok(())
}
