//! Which shadow technique a render uses, and why (`-v` prints the reason): the user's `--shadows` and the scene
//! (whether anything can occlude a light at all). The device decides only how the rays are traced.

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
/// [`super::can_occlude`]) or cannot occlude a light. `Auto` gives shadow rays on every device (the visible
/// fractions the reference computes), none where nothing can occlude a light; shadow maps only when asked for.
pub fn choose(requested: Shadows, lights: &Lights, can_occlude: bool) -> ShadowChoice {
    match requested {
        Shadows::None => ShadowChoice::new(Shadows::None, "--shadows none"),
        _ if lights.is_empty() => ShadowChoice::new(Shadows::None, "no lights"),
        Shadows::Auto if !can_occlude => ShadowChoice::new(
            Shadows::None,
            "auto: the scene is one closed convex body, which cannot shadow itself (the image is exact unshadowed)",
        ),
        Shadows::Auto => ShadowChoice::new(Shadows::Ray, "auto: shadow rays"),
        Shadows::Ray => ShadowChoice::new(Shadows::Ray, "--shadows ray"),
        Shadows::Map => ShadowChoice::new(Shadows::Map, "--shadows map"),
    }
}

/// The reference's technique: the GPU's, with f64 rays for every technique but `none`: it is the truth the GPU's
/// techniques are measured against. For `map` the rays shadow the lights the maps stand for (the sun and the
/// first disks, `ShadowedLights::MAPPED`), so that `render --check` compares the same model; the maps' own error
/// lies at shadow edges (`cpu::render_with_map_edges`).
pub fn choose_reference(requested: Shadows, lights: &Lights, can_occlude: bool) -> ShadowChoice {
    let mut choice = choose(requested, lights, can_occlude);
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
        assert_eq!(choose(Shadows::Auto, &lit, true).technique, Shadows::Ray);
        assert_eq!(choose(Shadows::Auto, &lit, false).technique, Shadows::None);
        assert_eq!(choose(Shadows::Ray, &lit, false).technique, Shadows::Ray);
        assert_eq!(choose(Shadows::Ray, &Lights::default(), true).technique, Shadows::None);
        assert_eq!(choose(Shadows::Map, &lit, true).technique, Shadows::Map);
        assert_eq!(choose_reference(Shadows::Map, &lit, true).technique, Shadows::Map);
        assert_eq!(choose_reference(Shadows::None, &lit, true).technique, Shadows::None);
        assert_eq!(choose_reference(Shadows::Auto, &lit, true).technique, Shadows::Ray);
    }
}
