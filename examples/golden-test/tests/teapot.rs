//! A user's image test: the teapot under a low sun must match its golden image and the CPU reference.

use std::path::Path;

use sunshade::testing::{self, CheckedRenderer};
use sunshade::{assert_images_close, assert_matches_golden};

fn here(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p).display().to_string()
}

#[test]
fn teapot_at_sunset_matches_its_golden_and_the_reference() {
    let scene = here("../../models/teapot.glb");
    // `--shadows none` keeps this golden about the sun's model alone; `auto` (the default) casts shadow rays, the
    // same image on every lavapipe, but an image with shadows also moves with the scene's other triangles.
    let flags =
        ["--width", "64", "--height", "48", "--sun-elevation", "8", "--sun-azimuth", "250", "--shadows", "none"];
    let job = testing::job(&scene, &flags).expect("valid flags");
    let mut gpu = CheckedRenderer::new();
    let image = gpu.render_job(&job).expect("rendered");
    // An independent computation: the CPU reference with the device's sub-pixel bits.
    let reference = testing::reference(&job, &gpu.reference_options()).expect("reference");
    assert_images_close!(image, reference);
    // And the image the project accepted: a missing golden fails in CI; UPDATE_GOLDENS=1 rewrites it.
    assert_matches_golden!(image, here("goldens/teapot-sunset.exr"));
}
