//! Surface materials: which BRDF a surface reflects with, and its parameters.
//!
//! Evaluation of the BRDFs lives in `shading::brdf`; this module only holds the parameters a scene gives.

/// The reflectance model of a material and its parameters (dimensionless reflectances in [0, 1], linear RGB).
#[derive(Clone, Debug, PartialEq)]
pub enum Brdf {
    /// Lambertian: `ρ = albedo/π` [1/sr].
    Lambert { albedo: [f32; 3] },
}

/// A surface material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The glTF name, or `material N`, or `default material`.
    pub name: String,
    /// glTF `doubleSided`: back faces are drawn with the normal reversed. Single-sided back faces are culled.
    pub double_sided: bool,
    pub brdf: Brdf,
}

impl Material {
    /// glTF's default material: single-sided, white Lambertian (albedo 1).
    pub fn default_material() -> Self {
        Self { name: "default material".into(), double_sided: false, brdf: Brdf::Lambert { albedo: [1.0; 3] } }
    }
}
