//! The GPU's pixels that f32 leaves further from the reference's f64 image than `--tolerance` allows, taken from
//! that image instead.
//!
//! **Why.** Where `--tolerance` studies its grids on the reference (the penumbrae by slices), the reference's image
//! at the kept settings is rendered in full, and the GPU's image is measured against it (a term of the prediction).
//! At a few pixels f32 geometry decides more than the tolerance leaves: self-shadowing at a smooth mesh's
//! terminator (teapot.glb at 512²: 16 pixels over 1e-5, the worst 2.7e-3 where the sun is 3% visible, its absolute
//! fraction 7.9e-5 apart) and contact shadows (cube.glb at 64²: 1.5e-4, 1.1e-5 of the sun). There the GPU
//! refused T by name. The reference's pixel is already computed and within the rest of the prediction of the
//! truth, so those pixels are taken from it: every pixel then lies within `T − rest` of the reference, the image
//! within T of the truth. `-v` names how many, and `--check` still compares the GPU's own image.

use crate::compare::{default_floor, pixel_difference};
use crate::film::Image;

/// Replaces each pixel of `image` whose relative difference from `reference` (the diff's floor from the
/// reference's peak, as `refinement::max_difference` measures it) exceeds `budget` with the reference's pixel;
/// returns how many it replaced. Both images have the same size.
pub fn take_from_reference(image: &mut Image, reference: &Image, budget: f64) -> usize {
    let floor = default_floor(reference);
    let mut taken = 0;
    for (a, &b) in image.pixels_mut().iter_mut().zip(reference.pixels()) {
        // A NaN's difference is infinite (`pixel_difference`), so it is taken too.
        if (a[3] > 0.0 || b[3] > 0.0) && pixel_difference(*a, b, floor).rel > budget {
            *a = b;
            taken += 1;
        }
    }
    taken
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::refinement::max_difference;

    #[test]
    fn pixels_past_the_budget_are_the_references_and_no_others_move() {
        let mut reference = Image::new(4, 1);
        let mut image = Image::new(4, 1);
        for (i, (r, g)) in reference.pixels_mut().iter_mut().zip(image.pixels_mut()).enumerate() {
            *r = [100.0, 100.0, 100.0, 1.0];
            *g = *r;
            g[1] += [0.0, 0.05, 0.2, f32::NAN][i];
        }
        let before = image.clone();
        assert!(max_difference(&image, &reference).is_infinite(), "a NaN counts as infinite");
        assert_eq!(take_from_reference(&mut image, &reference, 1e-3), 2, "2e-3 and the NaN");
        assert_eq!(image.pixels()[..2], before.pixels()[..2]);
        assert_eq!(image.pixels()[2..], reference.pixels()[2..]);
        let apart = max_difference(&image, &reference);
        assert!(apart <= 1e-3 && apart > 4e-4, "{apart}");
    }
}
