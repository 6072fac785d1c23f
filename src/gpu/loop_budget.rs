//! lavapipe's loop limiter. llvmpipe (Mesa's gallivm, which compiles lavapipe's shaders) guards against endless
//! loops with one counter per shader invocation, shared by every loop of the shader: 65535 iterations in all
//! (`LP_MAX_TGSI_LOOP_ITERATIONS`, decremented at the end of each iteration of any loop). Once it is spent, every
//! loop exits after its current iteration and the shader goes on with whatever its sums hold: silently, a lobe
//! grid left unfinished or a shadow ray's walk of the occluders' BVH stopped before it found the hit. A fragment
//! runs its loops as a SIMD group (8 pixels on a 256-bit CPU), so the count is the group's iterations, each loop
//! running as long as any of its lanes does.
//!
//! Measured on Mesa 22.3.6's lavapipe (docs/platform.md; Mesa 25.0.7's did not cut the same loops short):
//! sunset.glb with shadow rays walking the BVH at 96 × 72 and 8² shadow rays a pixel, 39 pixels brighter than the
//! reference (rays along the ground at the setting sun took up to 624 steps each, nodes and leaf triangles, with
//! median splits); with 4² rays a pixel, none. The sky's three lobe grids at 162² (79 218 iterations) exceed it on
//! their own.
//!
//! A loop of known count counts too: a slab test looped over three axes spends three iterations a box; called
//! axis by axis (`slab_axis`), overcast.glb at 96 × 72 passes 32² shadow rays where the loop was refused at 12²
//! (docs/platform.md).
//!
//! What sunshade does: every fragment ends with a probe loop of [`LOOP_PROBE_ITERATIONS`] iterations, a count the
//! compiler cannot see (a uniform), which stops after one exactly when the budget is spent; such a fragment writes
//! the alpha [`LOOP_BUDGET_SPENT`] (shaders/fragment.glsl, `coverage_alpha`), and the renderer refuses the image
//! ([`check`]). On devices without the limiter the probe always runs its two iterations.

use crate::film::Image;

/// The iterations of the probe loop (`lights.counts.z`; `LOOP_PROBE_ITERATIONS` in shaders/bindings.glsl).
pub const LOOP_PROBE_ITERATIONS: u32 = 2;
/// The coverage alpha of a fragment whose loops the limiter cut short (`LOOP_BUDGET_SPENT`).
pub const LOOP_BUDGET_SPENT: f32 = -1.0;
/// The limiter's budget per shader invocation on llvmpipe.
pub const LLVMPIPE_LOOP_ITERATIONS: u32 = 65535;

/// `Err` naming how many pixels the limiter cut short (and where the first one is), if any did.
pub fn check(image: &Image, device: &str) -> Result<(), String> {
    let Some((count, (x, y))) = image.alpha_count_and_first(LOOP_BUDGET_SPENT) else { return Ok(()) };
    Err(format!(
        "{device} cut the loops of {count} pixel(s) short (the first at ({x}, {y})): llvmpipe runs at most \
         {LLVMPIPE_LOOP_ITERATIONS} loop iterations a fragment, all loops together, and then stops them silently \
         (docs/platform.md); render with fewer samples (--samples, --sun-samples, --shadow-samples) or on a device \
         without that limit"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_with_a_spent_pixel_is_refused_and_others_pass() {
        let mut image = Image::new(4, 3);
        for p in image.pixels_mut() {
            *p = [1.0, 2.0, 3.0, 1.0];
        }
        assert!(check(&image, "llvmpipe").is_ok());
        image.pixels_mut()[6][3] = LOOP_BUDGET_SPENT;
        let e = check(&image, "llvmpipe").unwrap_err();
        assert!(e.contains("1 pixel(s)") && e.contains("(2, 1)"), "{e}");
    }
}
