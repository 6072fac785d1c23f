//! Shadow rays on devices without ray queries: the occluders' BVH (`visibility::occluder_bvh`, the tree the
//! reference's rays walk) laid out for the fragment shader, which walks it in software (shaders/bvh.glsl,
//! defined `SUNSHADE_RAY_BVH`; its shadow rays take the nodes in depth-first order without a stack, [`threaded`],
//! binding 18). Binding 12 holds the nodes ([`BvhNodeGpu`]); binding 14 the occluder records
//! (`layout::occluder_records`) in the tree's leaf order, so that a leaf's `first..first + count` indexes them
//! directly; the triangles' corners are read from binding 17 (each vertex's position) by the records' global
//! indices, the same f32 world positions the reference's f64 rays are cast against. All three are texel buffers.
//!
//! **Padding for f32.** The tree's boxes are built in f64 and padded by 1e-9 relative; the shader's slab test
//! runs in f32, and must never cut a box the ray touches (a box only decides what is tested, so padding costs time,
//! never correctness). Each slab distance `(bound − o) · (1/d)` is three roundings of at most `2⁻²⁴` relative, on
//! a difference of at most `2M` (M the largest coordinate magnitude of the scene: shadow rays start on its
//! surfaces), so the point it places along the ray is off by at most about `6 · 2⁻²⁴ M < 2⁻²¹ M`; the boxes are
//! widened by [`F32_BOX_PAD`]` · M` (eight times that) before rounding to f32, whose own rounding (`2⁻²⁴ M`) the
//! pad covers too.

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use crate::scene::Scene;

/// The boxes' widening for the f32 slab test, relative to the scene's largest coordinate magnitude: `2⁻¹⁸`.
pub const F32_BOX_PAD: f64 = 1.0 / 262_144.0;

/// One node of the tree (`BvhNode` in shaders/bindings.glsl; 32 bytes, std430): its box \[m\] in f32, widened by
/// [`F32_BOX_PAD`], and `first`/`count` as in `visibility::Bvh::nodes`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct BvhNodeGpu {
    pub min: [f32; 3],
    pub first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

/// What the walk's buffers are built from: every triangle of the scene in world space and its occluder record
/// (`layout::occluder_records`), kept by the upload and laid out by [`WalkSource::layout`] when a render first casts
/// rays (the tree costs about 50 ms for brdfs.glb's 45 632 triangles, which a render by maps or without shadows
/// need not pay).
pub struct WalkSource {
    triangles: Vec<[DVec3; 3]>,
    records: Vec<[u32; 4]>,
}

impl WalkSource {
    /// The scene's triangles and records, the meshes' vertices at these `vertex_offsets` in the vertex buffer.
    pub fn new(scene: &Scene, vertex_offsets: &[i32]) -> Self {
        Self {
            triangles: crate::visibility::occluder_triangles(scene),
            records: super::layout::occluder_records(scene, vertex_offsets, true),
        }
    }

    /// Every triangle of the scene in world space \[m\] and its occluder record, in the same order.
    pub fn triangles_and_records(&self) -> (&[[DVec3; 3]], &[[u32; 4]]) {
        (&self.triangles, &self.records)
    }

    /// The nodes of the occluders' tree (`visibility::Bvh` over the same triangles) and the records in its leaf
    /// order. A scene without triangles gets a leaf of one record whose three corners are the same vertex, a
    /// degenerate triangle no ray meets (the watertight test's det is 0; a count of 0 would read as an inner node).
    pub fn layout(&self) -> (Vec<BvhNodeGpu>, Vec<[u32; 4]>) {
        let bvh = crate::visibility::Bvh::new(self.triangles.clone());
        if bvh.triangle_count() == 0 {
            return (vec![BvhNodeGpu { min: [0.0; 3], first: 0, max: [0.0; 3], count: 1 }], vec![[0; 4]]);
        }
        let magnitude = bvh.nodes().next().map_or(0.0, |(min, max, _, _)| min.abs().max(max.abs()).max_element());
        let pad = F32_BOX_PAD * magnitude + 1e-30;
        let nodes = bvh
            .nodes()
            .map(|(min, max, first, count)| BvhNodeGpu {
                min: (min - pad).as_vec3().to_array(),
                max: (max + pad).as_vec3().to_array(),
                first,
                count,
            })
            .collect();
        (nodes, bvh.order().iter().map(|&i| self.records[i as usize]).collect())
    }
}

/// A leaf's `count` in [`threaded`]'s nodes marks an inner node.
pub const THREADED_INNER: u32 = u32::MAX;

/// The tree's nodes in depth-first order for a walk without a stack (Smits, "Efficiency issues for ray tracing",
/// 1998): an inner node's first child follows it, and each node's `first` is where the walk goes when the ray
/// misses its box (the node after its subtree); `count` is a leaf's record (its `first`) or [`THREADED_INNER`].
pub fn threaded(nodes: &[BvhNodeGpu]) -> Vec<BvhNodeGpu> {
    let mut out: Vec<BvhNodeGpu> = Vec::with_capacity(nodes.len());
    // (node, whether its subtree is done): a node is written when first met, its skip when its subtree is done.
    let mut todo = vec![(0usize, false)];
    let mut at: Vec<usize> = Vec::with_capacity(nodes.len());
    while let Some((i, done)) = todo.pop() {
        let n = nodes[i];
        if done {
            let k = at.pop().expect("a node's place");
            out[k].first = out.len() as u32;
            continue;
        }
        at.push(out.len());
        let inner = n.count == 0;
        out.push(BvhNodeGpu { first: 0, count: if inner { THREADED_INNER } else { n.first }, ..n });
        todo.push((i, true));
        if inner {
            todo.push((n.first as usize + 1, false));
            todo.push((n.first as usize, false));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every f32 box holds its f64 box widened by the f32 pad, and the leaves' records are the triangles'.
    #[test]
    fn the_f32_boxes_hold_the_trees_boxes_with_their_pad() {
        // 300 triangles of a grid (a tree several levels deep), far from the origin.
        let mut mesh = crate::scene::Mesh::default();
        for i in 0..10u32 {
            for j in 0..15u32 {
                let at = |di: u32, dj: u32| glam::Vec3::new((i + di) as f32 * 0.37, 1e3, (j + dj) as f32 * 0.21 + 5e2);
                let v = mesh.positions.len() as u32;
                mesh.positions.extend([at(0, 0), at(1, 0), at(0, 1), at(1, 1)]);
                mesh.indices.extend([v, v + 1, v + 2, v + 2, v + 1, v + 3]);
            }
        }
        mesh.material = 3;
        let scene = Scene { meshes: vec![mesh], ..Default::default() };
        let (nodes, records) = WalkSource::new(&scene, &vec![0; scene.meshes.len()]).layout();
        let bvh = crate::visibility::occluder_bvh(&scene);
        for (gpu, (min, max, first, count)) in nodes.iter().zip(bvh.nodes()) {
            let lo = DVec3::from_array(gpu.min.map(f64::from));
            let hi = DVec3::from_array(gpu.max.map(f64::from));
            assert!(lo.cmple(min).all() && hi.cmpge(max).all(), "{gpu:?} against {min} {max}");
            assert_eq!((gpu.first, gpu.count), (first, count));
        }
        assert!(nodes.len() > 31, "{} nodes", nodes.len());
        // The shader's walk is sized by the same constants.
        let glsl = include_str!("../../shaders/bvh.glsl");
        use crate::visibility::bvh::{LEAF_SIZE, STACK_SIZE};
        assert!(glsl.contains(&format!("#define BVH_LEAF_SIZE {LEAF_SIZE}u\n")), "BVH_LEAF_SIZE");
        assert!(glsl.contains(&format!("#define BVH_STACK_SIZE {STACK_SIZE}\n")), "BVH_STACK_SIZE");
        assert_eq!(records.len(), bvh.triangle_count());
        // A scene without triangles: one leaf holding one degenerate record.
        let (empty, dummy) = WalkSource::new(&Scene::default(), &[]).layout();
        assert_eq!((empty.len(), empty[0].count, dummy), (1, 1, vec![[0; 4]]));
        // Leaf order: record k is the triangle order()[k], its corners' global indices and material.
        for (k, &t) in bvh.order().iter().enumerate() {
            let idx = &scene.meshes[0].indices[3 * t as usize..3 * t as usize + 3];
            assert_eq!(records[k], [idx[0], idx[1], idx[2], 3]);
        }
        check_threaded(&nodes);
        check_threaded(&empty);
    }

    /// The threaded nodes are the tree's in depth-first order: each node's box, an inner node's first child right
    /// after it, its skip the node after its subtree, a leaf its record; the root's skip is past the last node.
    fn check_threaded(nodes: &[BvhNodeGpu]) {
        let threaded = threaded(nodes);
        assert_eq!(threaded.len(), nodes.len());
        fn visit(nodes: &[BvhNodeGpu], threaded: &[BvhNodeGpu], n: usize, k: &mut usize) {
            let (orig, here) = (nodes[n], threaded[*k]);
            assert_eq!((here.min, here.max), (orig.min, orig.max), "node {n} at {k}");
            let at = *k;
            *k += 1;
            if orig.count == 0 {
                assert_eq!(here.count, THREADED_INNER);
                visit(nodes, threaded, orig.first as usize, k);
                visit(nodes, threaded, orig.first as usize + 1, k);
            } else {
                assert_eq!(here.count, orig.first, "a leaf's record");
            }
            assert_eq!(threaded[at].first as usize, *k, "node {n}'s skip");
        }
        let mut k = 0;
        visit(nodes, &threaded, 0, &mut k);
        assert_eq!((k, threaded[0].first as usize), (nodes.len(), nodes.len()));
    }
}
