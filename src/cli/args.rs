//! Where the image goes: `--output` and its picture options (the flags that define the image are
//! `render::flags`).

use std::path::PathBuf;

use clap::Args;

use crate::film::{Exposure, ImageFormat};
use crate::render::flags::quantity::RequestedQuantity;
pub use crate::render::flags::*;

/// Where the image goes.
#[derive(Args, Clone, Debug)]
pub struct OutputArgs {
    /// Output image: .exr (float32 RGBA radiance), .pfm (float32 RGB), .png (8-bit sRGB, see --exposure).
    #[arg(short, long, value_name = "FILE", help_heading = "Output")]
    pub output: PathBuf,

    /// PNG exposure: EV stops (display value = radiance × 2^EV) or 'auto' (the default: the 99th percentile of the
    /// covered pixels displays at 80% of white).
    #[arg(long, allow_hyphen_values = true, value_name = "EV|auto", help_heading = "Output")]
    pub exposure: Option<Exposure>,

    /// Also write a false-colour PNG of the values (the Rec. 709 weighting of the channels, in the quantity's
    /// unit) on the viridis scale, with a legend; the scale runs from 0 to the 99th percentile rounded up to
    /// 1, 2 or 5 × 10ⁿ, or to --false-color-max.
    #[arg(long, value_name = "PNG", help_heading = "Output")]
    pub false_color: Option<PathBuf>,

    /// The top of the false-colour scale, in the quantity's unit (values above it show in the top colour).
    #[arg(long, value_name = "VALUE", value_parser = parse_positive, requires = "false_color", help_heading = "Output")]
    pub false_color_max: Option<f64>,
}

impl OutputArgs {
    /// Refuses, before any work, an output sunshade cannot write (see `check_output_path`) and an `--exposure`
    /// for a format that has none.
    pub fn check(&self) -> Result<(), super::CliError> {
        super::check_output_path(&self.output)?;
        if let Some(f) = &self.false_color {
            if ImageFormat::from_path(f) != Some(ImageFormat::Png) {
                return Err(super::CliError::Usage(format!(
                    "--false-color {}: a false-colour picture is a .png",
                    f.display()
                )));
            }
            super::check_output_path(f)?;
        }
        if self.exposure.is_some() && ImageFormat::from_path(&self.output) != Some(ImageFormat::Png) {
            return Err(super::CliError::Usage(format!(
                "--exposure applies to PNG output only ({} stores radiance unscaled)",
                self.output.display()
            )));
        }
        Ok(())
    }

    pub fn exposure(&self) -> Exposure {
        self.exposure.unwrap_or(Exposure::Auto)
    }

    /// Writes the false-colour picture of `image` (values in `quantity`'s unit) where `--false-color` asks for one.
    pub fn write_false_color(
        &self,
        image: &crate::film::Image,
        quantity: RequestedQuantity,
    ) -> Result<(), super::CliError> {
        let Some(path) = &self.false_color else { return Ok(()) };
        let max = self.false_color_max.unwrap_or_else(|| crate::plot::false_color::default_max(image));
        let unit = format!("{} [{}]", quantity.name(), quantity.unit_ascii());
        crate::plot::false_color::false_color(image, max, &unit)
            .write_png(path)
            .map_err(|e| super::CliError::Failure(anyhow::anyhow!("{}: {e}", path.display())))
    }
}
