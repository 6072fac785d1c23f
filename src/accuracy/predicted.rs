//! The predicted error of a render, from the bounds of its models ([`super::bounds`]), and `--tolerance`: the
//! cheapest sun model whose bound meets a tolerance.
//!
//! What is bounded so far: the sun (delta or disk, its grid) over every material of the scene, the sharpest
//! lobe a material can show (`bounds::sharpest_brdf`), and the GPU's f32 arithmetic. What is not, and is named
//! in [`Prediction::unbounded`] instead of being silently left out: disk lights and the sky (their lobe grids),
//! penumbrae (a shadow ray grid's visible fraction), shadow maps, f32 or device interpolation, and shadows turned
//! off in a scene that can shadow itself (there the error is up to 100%).

use crate::scene::{Brdf, Scene};
use crate::settings::RenderSettings;
use crate::shading::{ShadingOptions, Shadows, SunModel};

use super::bounds::{
    horizon_bound, sharpest_brdf, sun_delta_bound, sun_grid_bound, sun_horizon_in_view, SunViewAngles, GPU_ARITHMETIC,
    MIN_GRID_FOR_BOUND,
};

/// The largest sun grid `--tolerance` considers [cells a side].
pub const MAX_TOLERANCE_SUN_GRID: u32 = 64;

/// Which renderer's error is predicted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Renderer {
    /// The GPU, with this interpolation exact (f64 barycentrics) or not.
    Gpu { exact_interpolation: bool },
    /// The CPU reference (f64 throughout).
    Reference,
}

/// A render's predicted max relative error (with the diff's floor) and what it covers.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The bound over what is bounded.
    pub max_relative: f64,
    /// Each term: what it is, and its bound.
    pub terms: Vec<(String, f64)>,
    /// What the bound does not cover.
    pub unbounded: Vec<String>,
}

impl Prediction {
    /// The `-v` line: `predicted max relative error: 1.6e-4 (...)`.
    pub fn line(&self) -> String {
        let terms: Vec<String> = self.terms.iter().map(|(what, b)| format!("{what} {b:.1e}")).collect();
        let mut s = format!("predicted max relative error: {:.2e} ({})", self.max_relative, terms.join("; "));
        if !self.unbounded.is_empty() {
            s += &format!("; not bounded: {}", self.unbounded.join(", "));
        }
        s
    }

    /// For the output's metadata.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "max_relative_error": self.max_relative,
            "floor": "1% of the image's peak, as sunshade diff",
            "terms": self.terms.iter().map(|(w, b)| serde_json::json!({"term": w, "bound": b})).collect::<Vec<_>>(),
            "not_bounded": self.unbounded,
        })
    }
}

/// A short name of a BRDF for the terms.
fn brdf_name(brdf: &Brdf) -> String {
    match *brdf {
        Brdf::Lambert { .. } => "Lambert".into(),
        Brdf::Phong { exponent, .. } => format!("Phong e={exponent}"),
        Brdf::BlinnPhong { exponent, .. } => format!("Blinn-Phong e={exponent}"),
        Brdf::Ward { alpha_x, alpha_y, .. } if alpha_x == alpha_y => format!("Ward α={alpha_x}"),
        Brdf::Ward { alpha_x, alpha_y, .. } => format!("Ward αx={alpha_x} αy={alpha_y}"),
        Brdf::Measured { ref table, .. } => format!("measured {}", table.name),
    }
}

/// Whether a material some mesh uses is measured.
fn has_measured(scene: &Scene) -> bool {
    scene.meshes.iter().any(|m| matches!(scene.materials.get(m.material).map(|m| &m.brdf), Some(Brdf::Measured { .. })))
}

/// The distinct sharpest BRDFs (by lobe: albedos do not change a relative error) of the scene's materials that
/// some mesh uses.
fn scene_brdfs(scene: &Scene) -> Vec<Brdf> {
    let mut v: Vec<Brdf> = Vec::new();
    for mesh in &scene.meshes {
        if let Some(m) = scene.materials.get(mesh.material).filter(|m| !matches!(m.brdf, Brdf::Measured { .. })) {
            let b = sharpest_brdf(m, scene);
            if !v.iter().any(|o| brdf_name(o) == brdf_name(&b)) {
                v.push(b);
            }
        }
    }
    v
}

/// The sun's bound for one BRDF under these options; `horizon` is the scene's horizon term.
fn sun_bound(brdf: &Brdf, shading: &ShadingOptions, r: f64, horizon: f64, angles: SunViewAngles) -> f64 {
    match shading.sun {
        SunModel::Delta => sun_delta_bound(brdf, r, angles).max(horizon),
        SunModel::Disk => sun_grid_bound(brdf, r, shading.sun_samples_per_axis, angles),
    }
}

/// The predicted error of rendering `scene` with `settings` (whose shadow technique is the one used) on
/// `renderer`; `can_occlude`: whether something in the scene can occlude a light.
pub fn predict(scene: &Scene, settings: &RenderSettings, renderer: Renderer, can_occlude: bool) -> Prediction {
    let mut p = Prediction { max_relative: 0.0, terms: Vec::new(), unbounded: Vec::new() };
    let lights = &settings.lights;
    let shading = &settings.shading;
    if let Some(sun) = &lights.sun {
        let r = 0.5 * sun.angular_diameter as f64;
        let l = sun.direction.as_dvec3();
        let angles = SunViewAngles::of(&settings.camera, settings.aspect(), l);
        let horizon =
            if shading.sun == SunModel::Delta && sun_horizon_in_view(scene, l, r) { horizon_bound(r) } else { 0.0 };
        let model = match shading.sun {
            SunModel::Delta => "delta sun".to_string(),
            SunModel::Disk => format!("disk sun {}²", shading.sun_samples_per_axis),
        };
        for brdf in scene_brdfs(scene) {
            let b = sun_bound(&brdf, shading, r, horizon, angles);
            p.terms.push((format!("{model}, {}:", brdf_name(&brdf)), b));
            p.max_relative = p.max_relative.max(b);
        }
    }
    if has_measured(scene) {
        p.unbounded.push("measured BRDFs (their tables' lookup and grids)".into());
    }
    if !lights.disks.is_empty() {
        p.unbounded.push("the disk lights".into());
    }
    if lights.sky.is_some() {
        p.unbounded.push("the sky".into());
    }
    if can_occlude {
        match shading.shadows {
            Shadows::None => {
                p.terms.push(("shadows off in a scene that can shadow itself:".into(), 1.0));
                p.max_relative = 1.0;
            }
            Shadows::Map => p.unbounded.push("the shadow maps".into()),
            _ => p.unbounded.push("penumbrae (the shadow rays' visible fractions)".into()),
        }
    }
    if let Renderer::Gpu { exact_interpolation } = renderer {
        p.terms.push(("GPU f32 shading:".into(), GPU_ARITHMETIC));
        p.max_relative = (p.max_relative + GPU_ARITHMETIC).min(1.0);
        if !exact_interpolation {
            p.unbounded.push("f32 or device interpolation".into());
        }
    }
    p
}

/// `--tolerance`: the cheapest sun model for `scene` whose predicted error (with the GPU's arithmetic on the
/// GPU) is at most `tolerance`: the delta sun, else the smallest disk grid from 4² up to 64². `Err` says why no
/// setting can promise it: lights or techniques without a bound, or a lobe too sharp for 64².
pub fn choose_for_tolerance(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    tolerance: f64,
) -> Result<ShadingOptions, String> {
    let lights = &settings.lights;
    if has_measured(scene) {
        return Err(format!(
            "--tolerance {tolerance:e}: measured BRDFs have no derived error bound (docs/measured.md measures their \
             lookup and grids)"
        ));
    }
    if !lights.disks.is_empty() || lights.sky.is_some() {
        return Err(format!(
            "--tolerance {tolerance:e}: error bounds are derived for the sun so far (docs/accuracy.md, \"Error \
             bounds\"); this scene has {}",
            if lights.sky.is_some() { "a sky" } else { "disk lights" }
        ));
    }
    let mut shading = settings.shading;
    if let Renderer::Gpu { exact_interpolation: false } = renderer {
        return Err(format!("--tolerance {tolerance:e}: f32 or device interpolation has no error bound: use f64"));
    }
    if can_occlude && shading.shadows != Shadows::Ray {
        return Err(format!(
            "--tolerance {tolerance:e}: the scene can shadow itself, and only shadow rays (--shadows ray, a device \
             with ray queries) render its shadows with a known error outside penumbrae"
        ));
    }
    let arithmetic = if matches!(renderer, Renderer::Gpu { .. }) { GPU_ARITHMETIC } else { 0.0 };
    let Some(sun) = &lights.sun else { return Ok(shading) };
    let r = 0.5 * sun.angular_diameter as f64;
    let l = sun.direction.as_dvec3();
    let angles = SunViewAngles::of(&settings.camera, settings.aspect(), l);
    let horizon = if sun_horizon_in_view(scene, l, r) { horizon_bound(r) } else { 0.0 };
    let brdfs = scene_brdfs(scene);
    let worst = |s: &ShadingOptions| brdfs.iter().map(|b| sun_bound(b, s, r, horizon, angles)).fold(0.0, f64::max);
    let meets = |s: &ShadingOptions| worst(s) + arithmetic <= tolerance;
    shading.sun = SunModel::Delta;
    if meets(&shading) {
        return Ok(shading);
    }
    shading.sun = SunModel::Disk;
    for k in MIN_GRID_FOR_BOUND..=MAX_TOLERANCE_SUN_GRID {
        shading.sun_samples_per_axis = k;
        if meets(&shading) {
            return Ok(shading);
        }
    }
    Err(format!(
        "--tolerance {tolerance:e}: the sun's bound is {:.1e} at {MAX_TOLERANCE_SUN_GRID}² samples, over the \
         tolerance (the sharpest lobe is too narrow for the sun's grid; docs/accuracy.md, \"Error bounds\")",
        worst(&shading) + arithmetic
    ))
}

/// The models of a render and their predicted error: `--tolerance`'s choice where one is asked
/// (`settings.shading` updated, shadows already resolved), then [`predict`] for the models used.
/// `scene_can_occlude`: whether something in the scene can occlude a light; with `--shadows none` asked for
/// (`asked`), the truth the bound is against is unshadowed too.
pub fn choose_and_predict(
    scene: &Scene,
    settings: &mut RenderSettings,
    renderer: Renderer,
    asked: Shadows,
    scene_can_occlude: bool,
    tolerance: Option<f64>,
) -> Result<Prediction, String> {
    let can_occlude = asked != Shadows::None && scene_can_occlude;
    if let Some(tolerance) = tolerance {
        settings.shading = choose_for_tolerance(scene, settings, renderer, can_occlude, tolerance)?;
    }
    Ok(predict(scene, settings, renderer, can_occlude))
}
