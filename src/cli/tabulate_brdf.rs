//! `sunshade tabulate-brdf --model M ... -o FILE.binary`: an analytic BRDF written as a MERL table, sampled at
//! each bin's centre, where sunshade's lookup places its samples (`shading::measured`), and missing (negative)
//! where the light or the view is below the horizon, as the database's files are. For testing measured materials
//! against their analytic source, and for comparing lookups (docs/measured.md).

use std::io::Write;
use std::path::PathBuf;

use clap::Args;

use super::args::parse_radiance;
use super::CliError;
use crate::film::write_atomically;
use crate::scene::measured::merl_bytes;
use crate::scene::{Brdf, BrdfKind};
use crate::shading::measured::{brdf_about_z, tabulate};

#[derive(Args, Debug)]
pub struct TabulateBrdfArgs {
    /// The analytic model.
    #[arg(long, value_name = "lambert|phong|blinn-phong|ward|gltf")]
    pub model: BrdfKind,
    /// Diffuse reflectance kd (the albedo for Lambert, the base colour for glTF): one value or r,g,b.
    #[arg(long, value_parser = parse_radiance, value_name = "KD|R,G,B")]
    pub kd: [f64; 3],
    /// Specular reflectance ks: one value or r,g,b.
    #[arg(long, value_parser = parse_radiance, value_name = "KS|R,G,B", default_value = "0")]
    pub ks: [f64; 3],
    /// Phong / Blinn-Phong exponent.
    #[arg(long, default_value_t = 0.0)]
    pub exponent: f64,
    /// Ward α (isotropic); glTF's GGX α (roughness²).
    #[arg(long, default_value_t = 0.1)]
    pub alpha: f64,
    /// glTF's metallic.
    #[arg(long, default_value_t = 0.0)]
    pub metallic: f64,
    /// The MERL file to write (atomically).
    #[arg(short, long, value_name = "FILE.binary")]
    pub output: PathBuf,
}

pub fn run(a: &TabulateBrdfArgs) -> Result<(), CliError> {
    let (kd, ks) = (a.kd.map(|x| x as f32), a.ks.map(|x| x as f32));
    let shape = if matches!(a.model, BrdfKind::Ward | BrdfKind::Gltf) { a.alpha } else { a.exponent };
    let ks = if a.model == BrdfKind::Gltf { [a.metallic as f32; 3] } else { ks };
    let brdf = Brdf::of_kind(a.model, kd, ks, shape as f32);
    brdf.validate().map_err(CliError::Usage)?;
    let planes = tabulate(|l, v| brdf_about_z(&brdf, l, v));
    let bytes = merl_bytes(&planes);
    write_atomically(&a.output, |out| out.write_all(&bytes))
        .map_err(|e| CliError::Failure(anyhow::anyhow!("cannot write '{}': {e}", a.output.display())))?;
    Ok(())
}
