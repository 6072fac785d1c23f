//! The scene in world units: triangle meshes in metres, materials, cameras and lights in radiometric units.
//!
//! This is the only module that knows glTF ([`load`], reading files through `gltf`, which treats them as untrusted;
//! textures are decoded here once, to linear f32 with their mip chains). Geometry is flattened once while loading: node transforms
//! are applied (in f64, rounded once to f32), normals are carried by the inverse transpose, triangles of mirrored
//! nodes are re-wound so that counter-clockwise is the front face everywhere, and flat normals are generated where
//! the file has none. Both renderers therefore consume exactly the same `f32` triangles.
//!
//! Axes are glTF's: right-handed, +Y up, metres.

pub mod animation;
pub mod camera;
pub mod deform;
mod gltf;
pub mod light;
mod load;
mod load_material;
mod load_mesh;
mod load_specular;
pub mod material;
pub mod measured;
pub mod tangent;
pub mod texture;

use glam::{DVec3, Vec3, Vec4};

pub use camera::{Camera, Projection};
pub use gltf::files::UriScope;
pub use light::{DiskLight, Light, Lights, Sun};
pub use load::{load, load_with_options, LoadError, LoadOptions, MAX_SCENE_VERTICES};
pub use material::{AlphaMode, Brdf, BrdfKind, Material, MetallicRoughness};
pub use texture::{Texture, TextureRef};

/// A loaded scene: everything both renderers need apart from the per-render settings.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Triangle meshes in world space.
    pub meshes: Vec<Mesh>,
    /// Materials; `Mesh::material` indexes this list.
    pub materials: Vec<Material>,
    /// Textures (mip chains and samplers); `TextureRef::texture` indexes this list.
    pub textures: Vec<Texture>,
    /// Cameras placed by the scene's nodes, in node order, each with the index of its glTF camera.
    pub cameras: Vec<(usize, Camera)>,
    /// Lights the scene defines (the CLI may override or add to them).
    pub lights: Lights,
    /// Things the loader skipped or changed, each one line (skipped primitive modes, ignored lights...).
    pub warnings: Vec<String>,
}

/// One triangle list in world space, all of one material.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// A name for messages: the glTF mesh name (or index) and primitive index.
    pub name: String,
    /// Vertex positions in world space \[m\].
    pub positions: Vec<Vec3>,
    /// Unit vertex normals in world space (a zero vector where the file's normal was zero).
    pub normals: Vec<Vec3>,
    /// Unit tangents (the αx direction of anisotropic BRDFs) orthogonal to the normals, w = handedness ±1:
    /// from TANGENT, else from TEXCOORD_0, else [`tangent::default_tangent`].
    pub tangents: Vec<Vec4>,
    /// Texture coordinates per set (TEXCOORD_0, TEXCOORD_1), each empty or one per vertex; (0, 0) is the image's
    /// top-left corner.
    pub tex_coords: [Vec<[f32; 2]>; 2],
    /// COLOR_0 as linear RGBA (alpha 1 where the file gives RGB), empty where the file has none.
    pub colors: Vec<[f32; 4]>,
    /// Triangle list; counter-clockwise (seen from the front) in world space.
    pub indices: Vec<u32>,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// An axis-aligned box in world space \[m\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

/// A sphere enclosing the scene \[m\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    pub center: DVec3,
    pub radius: f64,
}

impl Scene {
    /// Replaces every material's BRDF by the `--brdf` mapping of its glTF metallic-roughness parameters
    /// ([`Brdf::from_metallic_roughness`]).
    pub fn map_brdfs(&mut self, kind: BrdfKind) {
        for m in &mut self.materials {
            m.brdf = Brdf::from_metallic_roughness(kind, m.pbr);
            m.mapping = Some(kind);
        }
    }

    /// Multiplies every material's emitted radiance by `scale` (`--emission-scale`: W/(m²·sr) per unit of glTF's
    /// emissive factor).
    pub fn scale_emission(&mut self, scale: f32) {
        for m in &mut self.materials {
            m.emission = m.emission.map(|e| e * scale);
        }
    }

    /// The largest emitted radiance [W/(m²·sr)] of any channel of any material a mesh uses (an emissive texture
    /// only multiplies it by at most 1).
    pub fn largest_emission(&self) -> f32 {
        self.meshes
            .iter()
            .filter_map(|mesh| self.materials.get(mesh.material))
            .flat_map(|m| m.emission)
            .fold(0.0, f32::max)
    }

    /// Gives every material the measured BRDF `table` (`--merl`), read with `lookup`: its textures and factors
    /// no longer set the BRDF (emission, normal maps and alpha still apply).
    pub fn use_measured(&mut self, table: &measured::SharedMeasuredBrdf, lookup: measured::MeasuredLookup) {
        for m in &mut self.materials {
            m.brdf = Brdf::Measured { table: table.clone(), lookup };
            m.mapping = None;
        }
    }

    /// Reads every measured material's table with `lookup` (`--merl-lookup`).
    pub fn set_measured_lookup(&mut self, lookup: measured::MeasuredLookup) {
        for m in &mut self.materials {
            if let Brdf::Measured { lookup: l, .. } = &mut m.brdf {
                *l = lookup;
            }
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(Mesh::triangle_count).sum()
    }

    /// Whether a material is alpha-masked (`alphaMode: MASK`): its triangles let light and the camera through
    /// where the mask cuts them away, so occlusion needs their texture, not their geometry alone.
    pub fn has_alpha_masks(&self) -> bool {
        self.materials.iter().any(|m| matches!(m.alpha, AlphaMode::Mask(_)))
    }

    /// The box around every vertex that a triangle uses, or `None` for a scene without triangles.
    pub fn bounds(&self) -> Option<Aabb> {
        let mut used = self.meshes.iter().flat_map(|m| m.indices.iter().map(move |&i| m.positions[i as usize]));
        let first = used.next()?.as_dvec3();
        let (min, max) = used.fold((first, first), |(lo, hi), p| (lo.min(p.as_dvec3()), hi.max(p.as_dvec3())));
        Some(Aabb { min, max })
    }

    /// A sphere around every used vertex: centred on the box centre, radius the farthest vertex from it.
    pub fn bounding_sphere(&self) -> Option<BoundingSphere> {
        let b = self.bounds()?;
        let center = (b.min + b.max) * 0.5;
        let radius = self
            .meshes
            .iter()
            .flat_map(|m| m.indices.iter().map(move |&i| m.positions[i as usize]))
            .map(|p| p.as_dvec3().distance(center))
            .fold(0.0, f64::max);
        Some(BoundingSphere { center, radius })
    }
}
