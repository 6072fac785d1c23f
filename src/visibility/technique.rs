//! Which shadow technique a render uses, and why (`-v` prints the reason): the user's `--shadows`, the scene
//! (whether anything can occlude a light at all) and the device (whether it has ray queries).

use crate::scene::Lights;
use crate::shading::Shadows;

/// The technique a render uses: [`Shadows::None`], [`Shadows::Ray`] or [`Shadows::Map`], never `Auto`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShadowChoice {
    pub technique: Shadows,
    /// Why, in a few words, for `-v`.
    pub reason: String,
    /// Whether the reason deserves a warning (shadows were asked for and are not there).
    pub warning: bool,
}

impl ShadowChoice {
    fn new(technique: Shadows, reason: impl Into<String>) -> Self {
        Self { technique, reason: reason.into(), warning: false }
    }
}

/// The technique for `requested` on a scene whose triangles can (`can_occlude`, from
/// [`super::can_occlude`]) or cannot occlude a light, on a device with or without ray queries.
/// `Auto` gives rays with ray queries, and shadow maps (the sun and the first disk lights; the sky unoccluded,
/// warned) without them. `Ray` without ray queries is refused by the caller.
pub fn choose(requested: Shadows, lights: &Lights, can_occlude: bool, ray_queries: bool) -> ShadowChoice {
    match requested {
        Shadows::None => ShadowChoice::new(Shadows::None, "--shadows none"),
        _ if lights.is_empty() => ShadowChoice::new(Shadows::None, "no lights"),
        Shadows::Auto if !can_occlude => ShadowChoice::new(
            Shadows::None,
            "auto: the scene is one closed convex body, which cannot shadow itself (the image is exact unshadowed)",
        ),
        Shadows::Auto if ray_queries => ShadowChoice::new(Shadows::Ray, "auto: the device has ray queries"),
        Shadows::Auto => ShadowChoice::new(Shadows::Map, "auto: the device has no ray queries: shadow maps"),
        Shadows::Ray => ShadowChoice::new(Shadows::Ray, "--shadows ray"),
        Shadows::Map => ShadowChoice::new(Shadows::Map, "--shadows map"),
    }
}

/// The reference's technique: the GPU's, mirrored on a device with or without ray queries
/// (`device_ray_queries`), with f64 rays for every technique but `none`: it is the truth the GPU's techniques
/// are measured against. For `map` the rays shadow the lights the maps stand for (the sun and the first
/// disks, `ShadowedLights::MAPPED`), so that `render --check` compares the same model; the maps' own error lies
/// at shadow edges (`cpu::render_with_map_edges`).
pub fn choose_reference(
    requested: Shadows,
    lights: &Lights,
    can_occlude: bool,
    device_ray_queries: bool,
) -> ShadowChoice {
    let mut choice = choose(requested, lights, can_occlude, device_ray_queries);
    match choice.technique {
        Shadows::Map => {
            choice.reason = format!(
                "{}; the reference casts f64 rays for the lights the maps shadow (the sun, the first disk lights)",
                choice.reason
            );
        }
        Shadows::Ray if requested == Shadows::Auto => {
            choice.reason = "auto: the scene can shadow itself; the reference casts f64 rays".into();
        }
        _ => {}
    }
    choice
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sun;

    #[test]
    fn choices() {
        let lit = Lights {
            sun: Some(Sun { direction: glam::Vec3::Y, irradiance: [1.0; 3], angular_diameter: 0.01 }),
            ..Default::default()
        };
        assert_eq!(choose(Shadows::Auto, &lit, true, true).technique, Shadows::Ray);
        assert_eq!(choose(Shadows::Auto, &lit, true, false).technique, Shadows::Map);
        assert_eq!(choose(Shadows::Auto, &lit, false, false).technique, Shadows::None);
        assert_eq!(choose(Shadows::Auto, &lit, false, true).technique, Shadows::None);
        assert_eq!(choose(Shadows::Ray, &lit, false, true).technique, Shadows::Ray);
        assert_eq!(choose(Shadows::Ray, &Lights::default(), true, true).technique, Shadows::None);
        assert_eq!(choose_reference(Shadows::Map, &lit, true, true).technique, Shadows::Map);
        assert_eq!(choose_reference(Shadows::Map, &lit, true, false).technique, Shadows::Map);
        assert_eq!(choose_reference(Shadows::None, &lit, true, true).technique, Shadows::None);
        assert_eq!(choose_reference(Shadows::Auto, &lit, true, true).technique, Shadows::Ray);
        assert_eq!(choose_reference(Shadows::Auto, &lit, true, false).technique, Shadows::Map);
    }
}
