//! The vertex transform, exactly as `shaders/scene.vert` computes it on the device.
//!
//! `clip = M (p, 1)` is evaluated column by column in f32, in this order, each product and each sum rounded
//! (the shader marks the result `precise`, which forbids fusing a multiply and an add into an FMA):
//!
//! ```text
//! clip = c0 * x
//! clip = clip + c1 * y
//! clip = clip + c2 * z
//! clip = clip + c3
//! ```
//!
//! Rust never contracts `a * b + c` into an FMA on its own, so writing the same expression gives the same bits.

use glam::{Mat4, Vec3, Vec4};

/// Clip-space position of a world-space point, bit-identical to the vertex shader's `gl_Position`.
pub fn clip_position(clip_from_world: &Mat4, p: Vec3) -> Vec4 {
    let mut clip = clip_from_world.x_axis * p.x;
    clip += clip_from_world.y_axis * p.y;
    clip += clip_from_world.z_axis * p.z;
    clip += clip_from_world.w_axis;
    clip
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_written_order_not_glams_product() {
        let m = Mat4::from_cols_array(&[
            0.1,
            0.2,
            0.3,
            0.4, //
            1.0 / 3.0,
            0.7,
            -0.9,
            0.01, //
            1e-3,
            -2.5,
            1.7,
            -1.0, //
            0.3,
            0.4,
            5.0,
            5.5,
        ]);
        let p = Vec3::new(0.123_456_7, -7.654_321, 3.333_333);
        let c = clip_position(&m, p);
        for k in 0..4 {
            let expected = ((m.x_axis[k] * p.x + m.y_axis[k] * p.y) + m.z_axis[k] * p.z) + m.w_axis[k];
            assert_eq!(c[k].to_bits(), expected.to_bits());
        }
    }
}
