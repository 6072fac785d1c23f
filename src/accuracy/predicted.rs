//! The predicted error of a render, from the bounds of its models ([`super::bounds`]), and `--tolerance`: for each
//! material, the cheapest sun model whose bound for its lobe meets a tolerance ([`Choice`]).
//!
//! What is bounded so far: the sun (delta or disk, its grid) over every analytic material of the scene, the sharpest
//! lobe a material can show (`bounds::sharpest_brdf`), and the GPU's f32 arithmetic. Estimated rather than bounded,
//! where `--tolerance` made the study: the lobe grids of disk lights and the sky on specular surfaces, a measured
//! material's grids, the sun's included, and where it holds in penumbrae (`--tolerance`'s default, not
//! `--tolerance-outside-penumbrae`) in a scene that shadows itself every grid with the shadow rays'
//! ([`super::refinement`]). What is not, and is named in [`Prediction::unbounded`] instead of being silently left out:
//! those grids without the study (on Lambertian surfaces the closed forms of disk lights and the sky are exact; the
//! small-source estimate is unbounded), penumbrae without that study, shadow maps, the device's interpolation (f32
//! barycentrics are bounded where `--tolerance` computes it: `super::interpolation`), and shadows turned off in a scene
//! that can shadow itself (there the error is up to 100%). An irradiance image has no lobes: its lights' closed forms
//! are exact (`predict_irradiance`).

use crate::scene::{Brdf, Scene};
use crate::settings::RenderSettings;
use crate::shading::{DiskModel, Quantity, ShadingOptions, Shadows, SunChoice, SunModel};

use super::refinement::LobeEstimate;

use super::bounds::{
    horizon_bound, horizon_error, peak_lower_bound, sharpest_brdf, sun_delta_bound, sun_grid_bound,
    sun_horizon_in_view, SunViewAngles, FLOOR_FRACTION, GPU_ARITHMETIC, MIN_GRID_FOR_BOUND,
};

/// The largest sun grid `--tolerance` considers [cells a side].
pub const MAX_TOLERANCE_SUN_GRID: u32 = 64;

/// How the GPU's fragment shader gets its barycentrics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Barycentrics {
    /// Computed in f64 (exact but for their rounding to f32).
    F64,
    /// Computed in f32: bounded per pixel by `accuracy::interpolation`, with `--tolerance`.
    F32,
    /// The device's interpolated varyings: no bound (the device's interpolation is not specified to a precision).
    Device,
}

/// Which renderer's error is predicted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Renderer {
    /// The GPU, with these barycentrics.
    Gpu { barycentrics: Barycentrics },
    /// The CPU reference (f64 throughout).
    Reference,
}

impl Renderer {
    /// The relative error its arithmetic adds to every bound: the GPU's f32 shading ([`GPU_ARITHMETIC`]); none for
    /// the f64 reference.
    pub fn arithmetic(self) -> f64 {
        match self {
            Renderer::Gpu { .. } => GPU_ARITHMETIC,
            Renderer::Reference => 0.0,
        }
    }
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

/// The prediction's name for f32 interpolation while its bound is not computed ([`Prediction::add_f32_bound`]).
const F32_UNBOUNDED: &str = "f32 interpolation (bounded with --tolerance)";
/// The prediction's names for what has no derived bound but the pixels refined on the reference cover
/// ([`Prediction::add_refined_pixels`]): measured materials' grids, specular lobes' grids under disk lights and the
/// sky, the visible fractions in penumbrae.
const MEASURED_UNBOUNDED: &str = "measured BRDFs (their grids)";
const DISK_LOBES_UNBOUNDED: &str = "the disk lights (their lobe grids)";
const SKY_LOBE_UNBOUNDED: &str = "the sky (its lobe grid)";
const PENUMBRAE_UNBOUNDED: &str =
    "penumbrae (the shadow rays' visible fractions: --tolerance without --tolerance-outside-penumbrae refines them)";

impl Prediction {
    /// Adds the bound of f32 interpolation (`accuracy::interpolation`), which it no longer lists as unbounded.
    pub fn add_f32_bound(&mut self, bound: f64) {
        self.unbounded.retain(|u| u != F32_UNBOUNDED);
        self.add_term("f32 interpolation (barycentric rounding, per pixel):", bound);
    }

    /// The pixels no bound covers taken from the reference refined per pixel (`accuracy::converged::refine`,
    /// `render::refined_pixels`): `count` of them, each claimed within `claim` (two doublings of every grid
    /// changed it by less than a third of it), `unconverged` of them not, the largest last change `worst`. They
    /// are apart from the pixels the other terms bound, so the image's bound is the larger of the two (not their
    /// sum); what they cover is no longer listed as unbounded.
    pub fn add_refined_pixels(&mut self, count: usize, claim: f64, (unconverged, worst): (usize, f64)) {
        let covered = [MEASURED_UNBOUNDED, DISK_LOBES_UNBOUNDED, SKY_LOBE_UNBOUNDED, PENUMBRAE_UNBOUNDED];
        self.unbounded.retain(|u| !covered.contains(&u.as_str()));
        if count == 0 {
            self.terms.push(("no pixel without a bound (every light of every pixel settled):".into(), 0.0));
            return;
        }
        self.terms.push((
            format!(
                "the {count} pixel(s) no bound covers (penumbrae, lobes without a bound), from the reference \
                 refined per pixel until two doublings of every grid moved each by less than a third of the claim, \
                 apart from the rest:"
            ),
            claim,
        ));
        self.max_relative = self.max_relative.max(claim);
        if unconverged > 0 {
            self.unbounded.push(format!(
                "{unconverged} refined pixel(s) that did not converge (the largest last change {worst:.1e})"
            ));
        }
    }

    /// Adds a term to the bound and its terms: a derived bound, or a measured value (`what` says which).
    pub fn add_term(&mut self, what: &str, value: f64) {
        self.terms.push((what.into(), value));
        self.max_relative = (self.max_relative + value).min(1.0);
    }

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
        Brdf::Gltf { metallic, alpha, .. } => format!("glTF metallic={metallic} α={alpha}"),
    }
}

/// Whether `--tolerance` must estimate the lobe grids by refinement ([`super::trial`]): disk lights or the sky
/// over a scene with specular (or measured) materials.
pub fn lobes_need_study(scene: &Scene, settings: &RenderSettings) -> bool {
    (!settings.lights.disks.is_empty() || settings.lights.sky.is_some()) && !only_lambertian(scene)
}

/// Whether `--tolerance` must estimate the sun's grid by refinement too: a measured material under the sun (its
/// table's lookup has no derived curvature for the sun's bound).
pub fn sun_needs_study(scene: &Scene, settings: &RenderSettings) -> bool {
    settings.lights.sun.is_some() && has_measured(scene)
}

/// Whether `--tolerance` held in penumbrae (its default) must estimate the visible fractions' shadow-ray grids by
/// refinement (and so every grid with them, [`super::trial`]): the scene can shadow itself (`can_occlude`, shadows
/// asked for) and casts shadow rays, whose grids have no derived bound in a penumbra (an occluder's edge across a
/// light: the share of the cells it cuts, [`super::refinement`]).
pub fn penumbrae_need_study(settings: &RenderSettings, can_occlude: bool) -> bool {
    let lights = &settings.lights;
    let lit = !lights.is_empty();
    can_occlude && settings.shading.shadows == Shadows::Ray && lit
}

/// Whether every material some mesh uses is Lambertian at every pixel (no lobe: under disk lights and the sky
/// the closed-form irradiance is then the whole of their light, exact).
pub(crate) fn only_lambertian(scene: &Scene) -> bool {
    !has_measured(scene) && scene_lobes(scene).iter().all(|l| l.brdf.is_lambert())
}

/// Whether a material some mesh uses is measured.
fn has_measured(scene: &Scene) -> bool {
    scene.meshes.iter().any(|m| matches!(scene.materials.get(m.material).map(|m| &m.brdf), Some(Brdf::Measured { .. })))
}

/// The distinct sharpest BRDFs (by lobe: albedos do not change a relative error) of the scene's materials that
/// some mesh uses.
fn scene_brdfs(scene: &Scene) -> Vec<Brdf> {
    scene_lobes(scene).into_iter().map(|l| l.brdf).collect()
}

/// A distinct sharpest lobe of the scene's materials and the largest reflectances (over channels and the
/// materials that have it) it is scaled by: kd and ks as given, or for a metallic-roughness mapping at most the
/// base colour factor's largest channel (textures and vertex colours only multiply it by at most 1; ks at least
/// the mapping's 0.04).
struct SceneLobe {
    brdf: Brdf,
    kd_max: f64,
    ks_max: f64,
}

fn scene_lobes(scene: &Scene) -> Vec<SceneLobe> {
    let mut v: Vec<SceneLobe> = Vec::new();
    for mesh in &scene.meshes {
        if let Some(m) = scene.materials.get(mesh.material).filter(|m| !m.brdf.is_measured()) {
            let brdf = sharpest_brdf(m, scene);
            let largest = |c: [f32; 3]| c.iter().fold(0.0f64, |a, &x| a.max(x as f64));
            let (kd_max, ks_max) = match m.mapping {
                None => (largest(m.brdf.kd()), largest(m.brdf.ks())),
                Some(crate::scene::BrdfKind::Lambert) => (largest(m.pbr.base_color), 0.0),
                // glTF's lobe carries its own Fresnel weights: ks = 1.
                Some(crate::scene::BrdfKind::Gltf) => (largest(m.pbr.base_color), 1.0),
                Some(_) => (largest(m.pbr.base_color), largest(m.pbr.base_color).max(0.04)),
            };
            match v.iter_mut().find(|o| brdf_name(&o.brdf) == brdf_name(&brdf)) {
                Some(o) => {
                    o.kd_max = o.kd_max.max(kd_max);
                    o.ks_max = o.ks_max.max(ks_max);
                }
                None => v.push(SceneLobe { brdf, kd_max, ks_max }),
            }
        }
    }
    v
}

/// The index in `lobes` (from [`scene_brdfs`]) of material `material`'s sharpest lobe; `None` for a measured
/// material, which has none there.
fn lobe_of(scene: &Scene, lobes: &[Brdf], material: usize) -> Option<usize> {
    let m = scene.materials.get(material).filter(|m| !m.brdf.is_measured())?;
    let name = brdf_name(&sharpest_brdf(m, scene));
    lobes.iter().position(|b| brdf_name(b) == name)
}

/// The shading options the surfaces of lobe `lobe` of `lobes` are rendered with: those of the first material
/// some mesh uses whose sharpest lobe it is (`--tolerance` chooses the same for every material of a lobe).
fn lobe_shading(scene: &Scene, settings: &RenderSettings, lobes: &[Brdf], lobe: usize) -> ShadingOptions {
    scene
        .meshes
        .iter()
        .map(|m| m.material)
        .find(|&i| lobe_of(scene, lobes, i) == Some(lobe))
        .map_or(settings.shading, |i| settings.shading_for(i))
}

/// The delta sun's horizon term per lobe of the scene (in [`scene_lobes`]' order) given the peak `rendered` of a
/// delta render of it [W/(m²·sr)]: each lobe's absolute horizon error (`bounds::horizon_error`) over the floor of
/// the truth's peak, that peak bounded below by `bounds::peak_lower_bound`; never more than the floor-based
/// [`horizon_bound`]. `None` where the scene shows no horizon to the sun.
fn horizon_terms(scene: &Scene, settings: &RenderSettings, arithmetic: f64, rendered: Option<f64>) -> Option<Vec<f64>> {
    let sun = settings.lights.sun.as_ref()?;
    let r = 0.5 * sun.angular_diameter as f64;
    let l = sun.direction.as_dvec3();
    if !sun_horizon_in_view(scene, l, r) {
        return None;
    }
    let lobes = scene_lobes(scene);
    let Some(rendered) = rendered else { return Some(vec![horizon_bound(r); lobes.len()]) };
    let angles = SunViewAngles::of(&settings.camera, settings.aspect(), l);
    let e_perp = sun.irradiance.iter().fold(0.0f64, |a, &x| a.max(x as f64));
    let errors: Vec<f64> =
        lobes.iter().map(|o| horizon_error(&o.brdf, o.kd_max, o.ks_max, r, e_perp, angles)).collect();
    let lobe_bound = lobes.iter().map(|o| sun_delta_bound(&o.brdf, r, angles)).fold(0.0, f64::max);
    let peak = peak_lower_bound(rendered, arithmetic, errors.iter().fold(0.0, |a: f64, &b| a.max(b)), lobe_bound);
    Some(
        errors
            .iter()
            .map(|&e| if peak > 0.0 { (e / (FLOOR_FRACTION * peak)).min(horizon_bound(r)) } else { horizon_bound(r) })
            .collect(),
    )
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
    predict_with_peak(scene, settings, renderer, can_occlude, None, None)
}

/// [`predict`] for the GPU's pixels where the pixels of the lobes flagged in `refined_lobes` ([`Choice`]) are
/// refined on the reference: their sun terms are not the image's (the refined pixels' claim is,
/// [`Prediction::add_refined_pixels`]).
pub fn predict_refining(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    refined_lobes: &[bool],
) -> Prediction {
    predict_terms(scene, settings, renderer, can_occlude, (None, None), refined_lobes)
}

/// [`predict`], where a delta sun's render is known to peak at `rendered` [W/(m²·sr)] (its own image's peak): the
/// horizon term is then taken against that peak (`horizon_terms`) instead of the material's own response.
/// `lobes`: the refinement's estimate of the lobe grids under disk lights and the sky where one was made
/// ([`super::refinement`]); it adds to the sun's term (both err at the same pixels).
pub fn predict_with_peak(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    rendered: Option<f64>,
    lobes: Option<&LobeEstimate>,
) -> Prediction {
    predict_terms(scene, settings, renderer, can_occlude, (rendered, lobes), &[])
}

/// [`predict_with_peak`]'s terms, the sun's of the lobes flagged in `refined_lobes` left out ([`predict_refining`]).
fn predict_terms(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    (rendered, lobes): (Option<f64>, Option<&LobeEstimate>),
    refined_lobes: &[bool],
) -> Prediction {
    if settings.shading.quantity == Quantity::Irradiance {
        return predict_irradiance(settings, renderer, can_occlude);
    }
    let mut p = Prediction { max_relative: 0.0, terms: Vec::new(), unbounded: Vec::new() };
    let lights = &settings.lights;
    let shading = &settings.shading;
    let sun_studied = lobes.is_some_and(|e| e.sun_grid);
    if let Some(sun) = lights.sun.as_ref().filter(|_| !sun_studied) {
        let r = 0.5 * sun.angular_diameter as f64;
        let l = sun.direction.as_dvec3();
        let angles = SunViewAngles::of(&settings.camera, settings.aspect(), l);
        let arithmetic = renderer.arithmetic();
        // Each lobe with the sun model of its materials (`RenderSettings::shading_for`).
        let brdfs = scene_brdfs(scene);
        let models: Vec<ShadingOptions> = (0..brdfs.len()).map(|i| lobe_shading(scene, settings, &brdfs, i)).collect();
        let any_delta = models.iter().any(|m| m.sun == SunModel::Delta);
        let horizons = if any_delta { horizon_terms(scene, settings, arithmetic, rendered) } else { None };
        let model = |m: &ShadingOptions| match (m.sun, rendered.is_some() && horizons.is_some()) {
            (SunModel::Delta, false) => "delta sun".to_string(),
            (SunModel::Delta, true) => {
                format!("delta sun (horizon against the image's peak, {:.3e})", rendered.unwrap_or(0.0))
            }
            (SunModel::Disk, _) => format!("disk sun {}²", m.sun_samples_per_axis),
        };
        for (i, (brdf, m)) in brdfs.iter().zip(&models).enumerate() {
            if refined_lobes.get(i) == Some(&true) {
                p.terms.push((
                    format!("{}: no sun grid reaches the tolerance, its pixels refined:", brdf_name(brdf)),
                    0.0,
                ));
                continue;
            }
            let horizon = horizons.as_ref().map_or(0.0, |h| h[i]);
            let b = sun_bound(brdf, m, r, horizon, angles);
            p.terms.push((format!("{}, {}:", model(m), brdf_name(brdf)), b));
            p.max_relative = p.max_relative.max(b);
        }
        if any_delta && can_occlude && shading.shadows != Shadows::None {
            p.terms.push(("delta sun's hard shadow edge across the penumbra:".into(), 1.0));
            p.max_relative = 1.0;
        }
    }
    if has_measured(scene) && lobes.is_none() {
        p.unbounded.push(MEASURED_UNBOUNDED.into());
    }
    let lambertian = only_lambertian(scene);
    if !lights.disks.is_empty() {
        match (lambertian, shading.disk, lobes) {
            (true, DiskModel::Exact, _) => p.terms.push(("disk lights, exact, on Lambertian surfaces:".into(), 0.0)),
            (true, DiskModel::SmallSource, _) => p.unbounded.push("the disk lights' small-source estimate".into()),
            (false, DiskModel::Exact, None) => p.unbounded.push(DISK_LOBES_UNBOUNDED.into()),
            (false, DiskModel::Exact, Some(_)) => {}
            (false, DiskModel::SmallSource, _) => {
                p.unbounded.push("the disk lights (their lobe grids and the small-source estimate)".into())
            }
        }
    }
    if lights.sky.is_some() {
        match (lambertian, lobes) {
            (true, _) => p.terms.push(("the sky on Lambertian surfaces:".into(), 0.0)),
            (false, None) => p.unbounded.push(SKY_LOBE_UNBOUNDED.into()),
            (false, Some(_)) => {}
        }
    }
    if let Some(estimate) = lobes.filter(|e| !lambertian || e.sun_grid || e.shadow_grid) {
        p.terms.push((estimate.term(), estimate.gci));
        p.max_relative += estimate.gci;
    }
    occlusion_and_arithmetic(&mut p, settings, renderer, can_occlude, lobes);
    p
}

/// The prediction of an irradiance image: no material enters, so no lobe grid; each light's irradiance is its
/// closed form (the disk sun's, partly set disk included; an exact disk light's projected solid angle; the sky's
/// `π L (1 + cos t)/2`), exact but for the arithmetic. Left unbounded: the delta sun where its disk would
/// straddle a surface's horizon (absolute error up to `(2/(3π)) r E⊥`, which no floor relates to the image's
/// peak without knowing it), the small-source estimate, and occlusion as for radiance (`--tolerance`, which
/// studies penumbrae, is for radiance only).
fn predict_irradiance(settings: &RenderSettings, renderer: Renderer, can_occlude: bool) -> Prediction {
    let mut p = Prediction { max_relative: 0.0, terms: Vec::new(), unbounded: Vec::new() };
    let (lights, shading) = (&settings.lights, &settings.shading);
    if lights.sun.is_some() {
        match shading.sun {
            SunModel::Disk => p.terms.push(("irradiance of the disk sun (closed form):".into(), 0.0)),
            SunModel::Delta => p.unbounded.push("the delta sun near surfaces' horizons".into()),
        }
    }
    if !lights.disks.is_empty() {
        match shading.disk {
            DiskModel::Exact => p.terms.push(("irradiance of the disk lights (exact):".into(), 0.0)),
            DiskModel::SmallSource => p.unbounded.push("the disk lights' small-source estimate".into()),
        }
    }
    if lights.sky.is_some() {
        p.terms.push(("irradiance of the sky (closed form):".into(), 0.0));
    }
    occlusion_and_arithmetic(&mut p, settings, renderer, can_occlude, None);
    p
}

/// The terms every prediction shares: occlusion (shadows off in a scene that can shadow itself, the light of the
/// sky and of disk lights past the mapped ones through occluders where shadow maps leave them unoccluded, and what
/// no bound covers: the maps, penumbrae unless `estimate` refined the shadow rays' grids), and the renderer's
/// arithmetic and interpolation.
fn occlusion_and_arithmetic(
    p: &mut Prediction,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    estimate: Option<&LobeEstimate>,
) {
    if can_occlude {
        match settings.shading.shadows {
            Shadows::None => {
                p.terms.push(("shadows off in a scene that can shadow itself:".into(), 1.0));
                p.max_relative = 1.0;
            }
            Shadows::Map => {
                // The maps are the sun's and the first MAPPED_DISKS disk lights'; the sky and further disks have
                // none and shine through occluders, as with shadows off (a point under a body gets their whole
                // light for none).
                if settings.lights.sky.is_some() {
                    p.terms.push(("the sky unshadowed (shadow maps are the sun's and disk lights'):".into(), 1.0));
                    p.max_relative = 1.0;
                }
                if settings.lights.disks.len() > crate::shading::MAPPED_DISKS {
                    let term =
                        format!("disk lights after the first {} unshadowed (no map):", crate::shading::MAPPED_DISKS);
                    p.terms.push((term, 1.0));
                    p.max_relative = 1.0;
                }
                p.unbounded.push("the shadow maps".into())
            }
            _ if estimate.is_some_and(|e| e.shadow_grid) => {}
            _ => p.unbounded.push(PENUMBRAE_UNBOUNDED.into()),
        }
    }
    if let Renderer::Gpu { barycentrics } = renderer {
        p.terms.push(("GPU f32 shading:".into(), GPU_ARITHMETIC));
        p.max_relative = (p.max_relative + GPU_ARITHMETIC).min(1.0);
        match barycentrics {
            Barycentrics::F64 => {}
            Barycentrics::F32 => p.unbounded.push(F32_UNBOUNDED.into()),
            Barycentrics::Device => p.unbounded.push("device interpolation".into()),
        }
    }
}

/// `--tolerance`'s models: the render's shading options and, where the materials' lobes chose differently, each
/// material's own sun model and grid (`RenderSettings::sun_per_material`).
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    pub shading: ShadingOptions,
    pub sun_per_material: Vec<Option<SunChoice>>,
    /// Per lobe of the scene (`scene_brdfs`' order), whether no sun grid up to 64² reaches the tolerance, so
    /// that its materials' pixels are refined on the reference (only where the caller refines pixels:
    /// `choose_sun_for_bounded_pixels`); empty where none is.
    pub refined_lobes: Vec<bool>,
}

impl Choice {
    /// The same models for every material.
    fn uniform(shading: ShadingOptions) -> Self {
        Self { shading, sun_per_material: Vec::new(), refined_lobes: Vec::new() }
    }

    /// Per material of `scene`, whether its lobe is one of [`Choice::refined_lobes`].
    pub fn refined_materials(&self, scene: &Scene) -> Vec<bool> {
        if !self.refined_lobes.contains(&true) {
            return Vec::new();
        }
        let brdfs = scene_brdfs(scene);
        (0..scene.materials.len())
            .map(|m| lobe_of(scene, &brdfs, m).is_some_and(|i| self.refined_lobes.get(i) == Some(&true)))
            .collect()
    }

    /// Renders with these models from now on.
    pub fn apply(self, settings: &mut RenderSettings) {
        settings.shading = self.shading;
        settings.sun_per_material = self.sun_per_material;
    }
}

/// `--tolerance`: for each lobe of `scene` (each material, by its sharpest lobe) the cheapest sun model whose
/// predicted error (with the GPU's arithmetic on the GPU) is at most `tolerance`: the delta sun, else the smallest
/// disk grid from 4² up to 64² (`choose_sun_within`). `Err` says why no setting can promise it: lights or
/// techniques without a bound, or a lobe too sharp for 64².
pub fn choose_for_tolerance(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    tolerance: f64,
) -> Result<Choice, String> {
    choose_for_tolerance_with_peak(scene, settings, renderer, can_occlude, tolerance, None)
}

/// Whether a delta-sun render of `scene` is worth trying for `tolerance` before choosing (`delta_peak`'s
/// caller renders it and passes its peak to [`choose_for_tolerance_with_peak`]): the choice without it is not the
/// delta sun, the scene shows the sun a horizon, and every other term of the delta sun's bound meets the tolerance,
/// so that only the horizon term, taken against the render's peak, decides.
pub fn delta_worth_trying(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    tolerance: f64,
) -> bool {
    let Some(sun) = &settings.lights.sun else { return false };
    if can_occlude {
        return false;
    }
    let Ok(choice) = choose_for_tolerance(scene, settings, renderer, can_occlude, tolerance) else { return false };
    if choice.shading.sun == SunModel::Delta {
        return false;
    }
    let r = 0.5 * sun.angular_diameter as f64;
    let l = sun.direction.as_dvec3();
    if !sun_horizon_in_view(scene, l, r) {
        return false;
    }
    let angles = SunViewAngles::of(&settings.camera, settings.aspect(), l);
    let arithmetic = renderer.arithmetic();
    scene_brdfs(scene).iter().map(|b| sun_delta_bound(b, r, angles)).fold(0.0, f64::max) + arithmetic <= tolerance
}

/// [`choose_for_tolerance`], the delta sun's horizon term taken against the peak `delta_peak` [W/(m²·sr)] of a
/// delta render of the same scene and settings where one was made ([`delta_worth_trying`]).
pub fn choose_for_tolerance_with_peak(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    tolerance: f64,
    delta_peak: Option<f64>,
) -> Result<Choice, String> {
    let lights = &settings.lights;
    if lobes_need_study(scene, settings) && !has_measured(scene) {
        return Err(format!(
            "--tolerance {tolerance:e}: under disk lights and the sky only Lambertian surfaces have a derived bound \
             (their closed forms), and this scene has {} and specular materials: their lobe grids are estimated by \
             refinement, which renders the image several times (`render --tolerance` and `reference --tolerance` do; \
             docs/accuracy.md, \"Error bounds\")",
            if lights.sky.is_some() { "a sky" } else { "disk lights" }
        ));
    }
    choose_sun_within(scene, settings, renderer, can_occlude, tolerance, delta_peak)
}

/// What `--tolerance` refuses whatever the materials, or the settings with the disk lights' exact model (on
/// Lambertian surfaces the closed form, no error; the small-source estimate has no bound): the light of the sky
/// through occluders unless the shadow rays' grids are estimated by refinement (`shadow_grids`: the
/// promise held in penumbrae, [`penumbrae_need_study`]), the device's interpolation, shadows other than rays
/// where the scene can shadow itself.
///
/// The light of the sun and of disk lights through occluders is held outside their penumbrae, where a light's
/// visible fraction is exactly 0 or 1 whatever the shadow rays' grid (the prediction names the penumbrae as not
/// bounded); a disk light's penumbrae are where its shadows are, as the sun's (room.gltf's disk skylight: 222 of
/// 4096 pixels at 64²). The sky's penumbra is every point that sees an occluder above its horizon, nearly a whole
/// image that has occluders (overcast.glb: 2193 of 2461 pixels; brdfs.glb under a sky: 2515 of 2518), so a promise
/// outside it would be one about almost nothing: refused.
pub(crate) fn techniques_within(
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    shadow_grids: bool,
    tolerance: f64,
) -> Result<ShadingOptions, String> {
    if settings.lights.sky.is_some() && can_occlude && !shadow_grids {
        return Err(format!(
            "--tolerance {tolerance:e}: the scene can shadow itself, and the sky's penumbra is every point that sees \
             an occluder above its horizon (nearly the whole image), where its visible fraction has no bound (a \
             shadow-ray grid errs by the share of its cells an occluder's edge crosses): --tolerance without \
             --tolerance-outside-penumbrae estimates it by refinement (costly: it converges at first order), \
             --shadows none bounds the render against the unshadowed truth{}",
            match renderer {
                Renderer::Gpu { .. } => {
                    "; `sunshade reference` with the same scene flags studies it on the CPU instead, by slices (second \
                     order), as `render` does with `--visibility slices` (its default there)"
                }
                Renderer::Reference => "",
            }
        ));
    }
    let mut shading = settings.shading;
    shading.disk = DiskModel::Exact;
    if let Renderer::Gpu { barycentrics: Barycentrics::Device } = renderer {
        return Err(format!(
            "--tolerance {tolerance:e}: device interpolation has no error bound: use f64 or f32 (--interpolation)"
        ));
    }
    if can_occlude && shading.shadows != Shadows::Ray {
        return Err(format!(
            "--tolerance {tolerance:e}: the scene can shadow itself, and only shadow rays (--shadows ray, or auto) \
             render its shadows with a known error outside penumbrae"
        ));
    }
    Ok(shading)
}

/// [`choose_for_tolerance_with_peak`] but for the lobe grids under disk lights and the sky on specular surfaces,
/// which the caller estimates by refinement ([`super::trial`]): the sun's models for `tolerance`, and what the
/// other techniques refuse.
///
/// The sun's model is chosen per lobe, each the cheapest that its own bound allows: a pixel's error is that of
/// its own material's terms (`super::bounds`), so a wide lobe or a Lambertian surface need not pay for the
/// sharpest lobe's grid (on brdfs.glb at 1e-4 the anisotropic Ward's 16² against the isotropic Ward's 6²). The
/// render's own `sun` is the delta sun only where every lobe took it, and its `sun_samples_per_axis` the finest
/// grid chosen; where the lobes chose alike no material gets its own.
pub(crate) fn choose_sun_within(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    tolerance: f64,
    delta_peak: Option<f64>,
) -> Result<Choice, String> {
    if has_measured(scene) {
        return Err(format!(
            "--tolerance {tolerance:e}: measured BRDFs have no derived error bound; their grids are estimated by \
             refinement, which renders the image several times (`render --tolerance` and `reference --tolerance` \
             do; docs/accuracy.md, \"Error bounds\")"
        ));
    }
    let shading = techniques_within(settings, renderer, can_occlude, false, tolerance)?;
    choose_sun_of_lobes(scene, settings, shading, (renderer, can_occlude), (tolerance, false), delta_peak)
}

/// `--tolerance` where the pixels no bound covers are refined on the reference (`render::refined_pixels`): the
/// disk lights' exact model, and the sun's models of the analytic lobes as [`choose_sun_within`] chooses them; a
/// measured material's pixels, the light of the sky through occluders and the pixels of a lobe too narrow for any
/// sun grid ([`Choice::refined_lobes`], a near-mirror metal) are the refined pixels' part.
pub(crate) fn choose_sun_for_bounded_pixels(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: Renderer,
    can_occlude: bool,
    tolerance: f64,
) -> Result<Choice, String> {
    let shading = techniques_within(settings, renderer, can_occlude, true, tolerance)?;
    choose_sun_of_lobes(scene, settings, shading, (renderer, can_occlude), (tolerance, true), None)
}

/// Whether the pixels of material `material` have no derived bound under the lights of `settings`, so that
/// `--tolerance` refines them on the reference (`render::refined_pixels`): a measured material under any light (its
/// table's grids), an analytic one whose sharpest lobe is not Lambertian under disk lights or the sky (its lobe
/// grids). An irradiance image has no material in it.
pub fn material_unbounded(scene: &Scene, settings: &RenderSettings, material: usize) -> bool {
    let Some(m) = scene.materials.get(material) else { return false };
    let lights = &settings.lights;
    if settings.shading.quantity == Quantity::Irradiance || lights.is_empty() {
        return false;
    }
    if m.brdf.is_measured() {
        return true;
    }
    let lobed = !super::bounds::sharpest_brdf(m, scene).is_lambert();
    lobed && (!lights.disks.is_empty() || lights.sky.is_some())
}

/// [`choose_sun_within`] from the techniques `shading` allows: each analytic lobe's sun model.
fn choose_sun_of_lobes(
    scene: &Scene,
    settings: &RenderSettings,
    mut shading: ShadingOptions,
    (renderer, can_occlude): (Renderer, bool),
    (tolerance, refine_unreachable): (f64, bool),
    delta_peak: Option<f64>,
) -> Result<Choice, String> {
    let lights = &settings.lights;
    let arithmetic = renderer.arithmetic();
    let Some(sun) = &lights.sun else { return Ok(Choice::uniform(shading)) };
    let r = 0.5 * sun.angular_diameter as f64;
    let l = sun.direction.as_dvec3();
    let angles = SunViewAngles::of(&settings.camera, settings.aspect(), l);
    let horizons = horizon_terms(scene, settings, arithmetic, delta_peak);
    let brdfs = scene_brdfs(scene);
    let mut chosen = Vec::with_capacity(brdfs.len());
    let mut refined_lobes = vec![false; brdfs.len()];
    for (i, brdf) in brdfs.iter().enumerate() {
        let bound =
            |s: &ShadingOptions| sun_bound(brdf, s, r, horizons.as_ref().map_or(0.0, |h| h[i]), angles) + arithmetic;
        // Where the scene shadows itself the delta sun's single shadow ray draws a hard edge across the penumbra
        // (pixels up to 100% off), so only the disk is considered there.
        let mut s = ShadingOptions { sun: SunModel::Delta, ..shading };
        if !can_occlude && bound(&s) <= tolerance {
            chosen.push(SunChoice { sun: SunModel::Delta, sun_samples_per_axis: shading.sun_samples_per_axis });
            continue;
        }
        s.sun = SunModel::Disk;
        let grid = (MIN_GRID_FOR_BOUND..=MAX_TOLERANCE_SUN_GRID).find(|&k| {
            s.sun_samples_per_axis = k;
            bound(&s) <= tolerance
        });
        let Some(k) = grid else {
            if refine_unreachable {
                // Its pixels are taken from the reference; the GPU's grid for them is the cheapest.
                refined_lobes[i] = true;
                chosen.push(SunChoice { sun: SunModel::Disk, sun_samples_per_axis: MIN_GRID_FOR_BOUND });
                continue;
            }
            return Err(format!(
                "--tolerance {tolerance:e}: the sun's bound for {} is {:.1e} at {MAX_TOLERANCE_SUN_GRID}² samples, \
                 over the tolerance (the lobe is too narrow for the sun's grid; docs/accuracy.md, \"Error bounds\")",
                brdf_name(brdf),
                bound(&s)
            ));
        };
        chosen.push(SunChoice { sun: SunModel::Disk, sun_samples_per_axis: k });
    }
    let finest = chosen.iter().filter(|c| c.sun == SunModel::Disk).map(|c| c.sun_samples_per_axis).max();
    shading.sun = if finest.is_some() { SunModel::Disk } else { SunModel::Delta };
    shading.sun_samples_per_axis = finest.unwrap_or(shading.sun_samples_per_axis);
    let refined_lobes = if refined_lobes.contains(&true) { refined_lobes } else { Vec::new() };
    if chosen.windows(2).all(|w| w[0] == w[1]) {
        return Ok(Choice { refined_lobes, ..Choice::uniform(shading) });
    }
    // Each material gets its lobe's choice.
    let sun_per_material = (0..scene.materials.len()).map(|m| lobe_of(scene, &brdfs, m).map(|i| chosen[i])).collect();
    Ok(Choice { shading, sun_per_material, refined_lobes })
}

/// What `--tolerance`'s choice and a render's prediction are for: the scene, the renderer whose error is
/// predicted, the shadows asked for, and whether anything in the scene can occlude a light.
#[derive(Clone, Copy)]
pub struct Request<'a> {
    pub scene: &'a Scene,
    pub renderer: Renderer,
    pub asked: Shadows,
    pub scene_can_occlude: bool,
}

impl Request<'_> {
    /// Whether the truth the render is measured against has shadows: something can occlude a light and shadows
    /// are asked for (with `--shadows none` the truth is unshadowed too).
    pub fn can_occlude(&self) -> bool {
        self.asked != Shadows::None && self.scene_can_occlude
    }
}

/// The models of a render and their predicted error: `--tolerance`'s choice where one is asked
/// (`settings.shading` updated, shadows already resolved), then [`predict`] for the models used.
/// `delta_peak`: the peak of a delta-sun render of the scene made for the choice ([`delta_worth_trying`]), also
/// the prediction's where the delta sun is chosen.
pub fn choose_and_predict(
    request: Request,
    settings: &mut RenderSettings,
    tolerance: Option<f64>,
    delta_peak: Option<f64>,
) -> Result<Prediction, String> {
    let Request { scene, renderer, .. } = request;
    let can_occlude = request.can_occlude();
    if let Some(tolerance) = tolerance {
        choose_for_tolerance_with_peak(scene, settings, renderer, can_occlude, tolerance, delta_peak)?.apply(settings);
    }
    // A delta render's peak bounds the truth's peak below whichever image is kept: it serves every lobe that took
    // the delta sun.
    let peak = delta_peak.filter(|_| settings.uses_sun_model(SunModel::Delta));
    Ok(predict_with_peak(scene, settings, renderer, can_occlude, peak, None))
}

/// Whether `choose_and_predict` should be given a delta render's peak: `--tolerance` asked, and
/// [`delta_worth_trying`].
pub fn delta_trial(request: Request, settings: &RenderSettings, tolerance: Option<f64>) -> bool {
    let can_occlude = request.can_occlude();
    tolerance.is_some_and(|t| delta_worth_trying(request.scene, settings, request.renderer, can_occlude, t))
}
