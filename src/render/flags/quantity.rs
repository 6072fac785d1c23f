//! What `--quantity` asks for: a quantity one frame renders (radiance, irradiance), or one accumulated over many
//! instants from irradiance frames (irradiation, sun-hours).

use crate::shading::Quantity;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RequestedQuantity {
    #[default]
    Radiance,
    Irradiance,
    /// `H = Σ E(tᵢ) Δtᵢ` [Wh/m²] over the steps of `--from/--to/--step`.
    Irradiation,
    /// Hours in which the direct sun on the surface reaches `--sun-hours-threshold` [h].
    SunHours,
}

impl RequestedQuantity {
    /// The quantity each rendered frame holds.
    pub fn frame(self) -> Quantity {
        match self {
            RequestedQuantity::Radiance => Quantity::Radiance,
            _ => Quantity::Irradiance,
        }
    }

    /// Whether it sums frames over time.
    pub fn is_accumulated(self) -> bool {
        matches!(self, RequestedQuantity::Irradiation | RequestedQuantity::SunHours)
    }

    pub fn name(self) -> &'static str {
        match self {
            RequestedQuantity::Irradiation => "irradiation",
            RequestedQuantity::SunHours => "sun-hours",
            q => q.frame().name(),
        }
    }

    /// The unit in ASCII, as image files record it.
    pub fn unit_ascii(self) -> &'static str {
        match self {
            RequestedQuantity::Irradiation => "Wh/m2",
            RequestedQuantity::SunHours => "h",
            q => q.frame().unit_ascii(),
        }
    }
}

/// An ASCII unit as files record it, as people read it: `W/(m2 sr)` → `W/(m²·sr)`, `Wh/m2` → `Wh/m²`.
pub fn pretty_unit(ascii: &str) -> String {
    ascii.replace("m2 sr", "m²·sr").replace("m2", "m²")
}

impl std::str::FromStr for RequestedQuantity {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let all = [Self::Radiance, Self::Irradiance, Self::Irradiation, Self::SunHours];
        all.into_iter().find(|q| q.name() == s).ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(|q| q.name()).collect();
            format!("'{s}' is not a quantity ({})", names.join(", "))
        })
    }
}
