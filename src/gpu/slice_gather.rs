//! Where the GPU's slices could not gather a light's occluders (shaders/slices.glsl): a pixel whose light's cone
//! holds more triangles than a fragment keeps (`MAX_SLICE_TRIANGLES`) writes the alpha [`SLICES_OVERFLOWED`]
//! (fragment.glsl's `coverage_alpha`), and the renderer refuses the image ([`check`]) rather than let those pixels
//! take the grid's rays under a rule that says slices: `render --check` would then compare them with the
//! reference's slices, and `--tolerance` would read a first-order error where it expects the slices'.

use crate::film::Image;

/// The coverage alpha of a fragment whose slices gathered too many triangles (`SLICES_OVERFLOWED`).
pub const SLICES_OVERFLOWED: f32 = -2.0;
/// The most triangles the slices of one pixel and light gather (`MAX_SLICE_TRIANGLES` in shaders/slices.glsl).
pub const MAX_SLICE_TRIANGLES: u32 = 1024;

/// `Err` naming how many pixels gathered too many triangles (and where the first one is), if any did.
pub fn check(image: &Image) -> Result<(), String> {
    let Some((count, (x, y))) = image.alpha_count_and_first(SLICES_OVERFLOWED) else { return Ok(()) };
    Err(format!(
        "--visibility slices: {count} pixel(s) (the first at ({x}, {y})) see more than {MAX_SLICE_TRIANGLES} \
         triangles in a light's cone, more than the GPU's slices gather a pixel; --visibility grid casts rays there, \
         and `sunshade reference --visibility slices` has no such limit"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflowed_pixels_are_counted_and_named_and_the_loop_budgets_are_not() {
        let mut image = Image::new(5, 2);
        image.pixels_mut().iter_mut().for_each(|p| p[3] = 1.0);
        assert!(check(&image).is_ok());
        image.pixels_mut()[9][3] = SLICES_OVERFLOWED;
        image.pixels_mut()[7][3] = SLICES_OVERFLOWED;
        image.pixels_mut()[1][3] = crate::gpu::loop_budget::LOOP_BUDGET_SPENT;
        let e = check(&image).unwrap_err();
        assert!(e.contains("2 pixel(s)") && e.contains("(2, 1)") && e.contains("1024"), "{e}");
    }
}
