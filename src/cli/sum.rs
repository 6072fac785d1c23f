//! `sunshade sum A B ... -o TOTAL`: the per-pixel sum of float images of one size, e.g. the shards of an
//! accumulation rendered on several machines. Sums in f64 per channel (in the order given), rounded once to f32;
//! a pixel is covered where any input covers it (alpha the largest). Float images only: a PNG holds display
//! codes, not values to add.

use std::path::PathBuf;

use clap::Args;

use super::CliError;
use crate::film::{read_image, write_image_with, Exposure, Image, ImageFormat, Metadata};

#[derive(Args, Debug)]
pub struct SumCommand {
    /// The images to add (.exr or .pfm), all the same size.
    #[arg(required = true, num_args = 1.., value_name = "IMAGE")]
    pub inputs: Vec<PathBuf>,
    /// The sum (.exr or .pfm), written atomically.
    #[arg(short, long, value_name = "EXR|PFM")]
    pub output: PathBuf,
}

/// The per-pixel sum of `images` (at least one, all of one size; the caller checks), in f64.
pub fn sum(images: &[Image]) -> Image {
    let (w, h) = (images[0].width(), images[0].height());
    let mut total = Image::new(w, h);
    for (k, out) in total.pixels_mut().iter_mut().enumerate() {
        let mut acc = [0.0f64; 3];
        let mut alpha = 0.0f32;
        for image in images {
            let p = image.pixels()[k];
            for c in 0..3 {
                acc[c] += p[c] as f64;
            }
            alpha = alpha.max(p[3]);
        }
        *out = [acc[0] as f32, acc[1] as f32, acc[2] as f32, alpha];
    }
    total
}

pub fn run(a: &SumCommand) -> Result<(), CliError> {
    let float = |p: &PathBuf| matches!(ImageFormat::from_path(p), Some(ImageFormat::Exr | ImageFormat::Pfm));
    for p in a.inputs.iter().chain([&a.output]) {
        if !float(p) {
            return Err(CliError::Usage(format!("{}: sum adds float images (.exr or .pfm)", p.display())));
        }
    }
    super::check_output_path(&a.output)?;
    let mut images = Vec::with_capacity(a.inputs.len());
    for p in &a.inputs {
        let image = read_image(p).map_err(|e| CliError::Usage(e.to_string()))?;
        if let Some(first) = images.first().map(|i: &Image| (i.width(), i.height())) {
            if (image.width(), image.height()) != first {
                return Err(CliError::Usage(format!(
                    "{}: {}x{}, but {} is {}x{}: sum adds images of one size",
                    p.display(),
                    image.width(),
                    image.height(),
                    a.inputs[0].display(),
                    first.0,
                    first.1
                )));
            }
        }
        images.push(image);
    }
    // The sum holds what its inputs hold: one quantity, recorded in the output (refused when they differ).
    let quantities: Vec<Option<(String, String)>> = a.inputs.iter().map(|p| crate::film::read_quantity(p)).collect();
    if let Some(i) = quantities.iter().position(|q| q.is_some() && *q != quantities[0]) {
        let name = |q: &Option<(String, String)>| q.as_ref().map_or("no recorded quantity".into(), |q| q.0.clone());
        return Err(CliError::Usage(format!(
            "{} holds {} and {} holds {}: sum adds images of one quantity",
            a.inputs[i].display(),
            name(&quantities[i]),
            a.inputs[0].display(),
            name(&quantities[0])
        )));
    }
    let mut metadata = Metadata::default();
    if let Some((name, unit)) = &quantities[0] {
        let text = format!("{name} {unit} per linear RGB channel; A = coverage");
        metadata.text.push(("quantity".into(), text));
    }
    write_image_with(&sum(&images), &a.output, Exposure::Ev(0.0), &metadata)?;
    Ok(())
}
