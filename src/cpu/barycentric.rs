//! Perspective-correct barycentrics of a pixel in a triangle, as the fragment shader computes them
//! (`triangle_barycentrics` and `pixel_ndc` in `shaders/transform.glsl`).
//!
//! 2D homogeneous rasterization (Olano & Greer, "Triangle Scan Conversion using 2D Homogeneous Coordinates",
//! 1997): shear the clip-space vertices so that the pixel's ray becomes the w axis,
//! `d = (x − ndc_x·w, y − ndc_y·w)`; then `bᵢ = d_j × d_k` over the cyclic pairs, and `λ = b / Σb`. For a point
//! `C = Σ λᵢ cᵢ` of the triangle this returns exactly its 3D barycentrics `λ`, whatever the signs of the `wᵢ`,
//! so triangles the device clipped at the near plane interpolate like any other.
//!
//! The device evaluates this in f32; the reference in f64 from the same f32 clip positions and the same f32 pixel
//! NDC, so the two differ only by the shader's rounding.

use glam::{DVec3, Vec2, Vec4};

/// NDC of the centre of pixel `(x, y)` in a `width × height` image, rounded to f32 as the shader rounds it:
/// `(2·(x + ½)) / size − 1`.
pub fn pixel_ndc(x: u32, y: u32, width: u32, height: u32) -> Vec2 {
    let frag = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
    (2.0 * frag) / Vec2::new(width as f32, height as f32) - Vec2::ONE
}

/// Perspective-correct barycentrics (f64) of the point with NDC `ndc` in the triangle `c` (clip space): the
/// weights the reference interpolates every attribute with. (The device rounds them to f32 for position, normal
/// and tangent, `triangle_barycentrics` in the shader, and keeps them in f64 for texture coordinates.)
pub fn triangle_barycentrics(c: [Vec4; 3], ndc: Vec2) -> DVec3 {
    triangle_barycentrics_exact(c, ndc)
}

/// The barycentrics in f64, as `triangle_barycentrics_exact` in the shader computes them where the device has
/// shaderFloat64 (the same operations in the same order, so the same bits).
pub fn triangle_barycentrics_exact(c: [Vec4; 3], ndc: Vec2) -> DVec3 {
    let (nx, ny) = (ndc.x as f64, ndc.y as f64);
    let d = c.map(|v| (v.x as f64 - nx * v.w as f64, v.y as f64 - ny * v.w as f64));
    let cross = |a: (f64, f64), b: (f64, f64)| a.0 * b.1 - a.1 * b.0;
    let b = DVec3::new(cross(d[1], d[2]), cross(d[2], d[0]), cross(d[0], d[1]));
    let sum = b.x + b.y + b.z;
    if sum == 0.0 {
        return DVec3::splat(1.0 / 3.0);
    }
    b / sum
}

/// The barycentrics as the shader's f32 `triangle_barycentrics_exact` computes them on a device without
/// shaderFloat64 (or with `--interpolation f32`): the same operations in the same order, each rounded to f32, no
/// fused multiply-add (the shader's `precise`). `accuracy::interpolation` bounds how far these are from
/// [`triangle_barycentrics_exact`].
pub fn triangle_barycentrics_f32(c: [Vec4; 3], ndc: Vec2) -> [f32; 3] {
    let d = c.map(|v| (v.x - ndc.x * v.w, v.y - ndc.y * v.w));
    let cross = |a: (f32, f32), b: (f32, f32)| a.0 * b.1 - a.1 * b.0;
    let b = [cross(d[1], d[2]), cross(d[2], d[0]), cross(d[0], d[1])];
    let sum = b[0] + b[1] + b[2];
    if sum == 0.0 {
        return [1.0 / 3.0; 3];
    }
    b.map(|x| x / sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn recovers_3d_barycentrics_under_perspective() {
        // A triangle in clip space with very different w; a point on it with known barycentrics.
        let c = [Vec4::new(-1.0, -0.5, 0.2, 1.0), Vec4::new(3.0, -1.0, 2.0, 4.0), Vec4::new(0.5, 2.5, 1.0, 3.0)];
        let l = DVec3::new(0.2, 0.5, 0.3);
        let p = c[0].as_dvec4() * l.x + c[1].as_dvec4() * l.y + c[2].as_dvec4() * l.z;
        let ndc = Vec2::new((p.x / p.w) as f32, (p.y / p.w) as f32);
        let got = triangle_barycentrics(c, ndc);
        assert!((got - l).length() < 1e-6, "{got} vs {l}");
    }

    #[test]
    fn handles_vertices_behind_the_eye() {
        // One vertex with w < 0 (behind the camera): the visible point still gets positive barycentrics.
        let c = [Vec4::new(0.0, 0.0, 0.5, 1.0), Vec4::new(1.0, 0.0, 0.5, 1.0), Vec4::new(0.0, 1.0, -2.0, -1.0)];
        let l = DVec3::new(0.5, 0.3, 0.2);
        let p = c[0].as_dvec4() * l.x + c[1].as_dvec4() * l.y + c[2].as_dvec4() * l.z;
        assert!(p.w > 0.0);
        let got = triangle_barycentrics(c, Vec2::new((p.x / p.w) as f32, (p.y / p.w) as f32));
        assert!((got - l).length() < 1e-6, "{got}");
    }

    #[test]
    fn pixel_centres_map_to_ndc() {
        assert_eq!(pixel_ndc(0, 0, 2, 4), Vec2::new(-0.5, -0.75));
        assert_eq!(pixel_ndc(1, 3, 2, 4), Vec2::new(0.5, 0.75));
        let _ = Vec3::ZERO;
    }
}
