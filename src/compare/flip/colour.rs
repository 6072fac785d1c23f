//! The colour spaces FLIP works in (Andersson et al. 2020, section 3): linear sRGB, CIE XYZ, the opponent space
//! YCxCz in which the contrast sensitivity filters act, CIELAB with the Hunt adjustment, and the HyAB distance.
//!
//! All in f32, as the reference implementation computes them, so that a mean FLIP agrees with it to the
//! rounding of a sum rather than of a different formulation.

/// The reference white \[XYZ\]: linear sRGB (1, 1, 1), i.e. the rows of [`linear_rgb_to_xyz`]'s matrix summed
/// (D65 for sRGB's primaries).
pub const WHITE: [f32; 3] = [0.950_428_5, 1.0, 1.088_900_4];

/// sRGB's transfer function undone: an encoded value in [0, 1] to linear (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear sRGB to CIE XYZ (sRGB primaries, the white [`WHITE`]).
pub fn linear_rgb_to_xyz(c: [f32; 3]) -> [f32; 3] {
    const M: [[f32; 3]; 3] = [
        [0.412_386_56, 0.357_591_5, 0.180_450_49],
        [0.212_636_82, 0.715_182_96, 0.072_180_2],
        [0.019_330_62, 0.119_197_16, 0.950_372_6],
    ];
    M.map(|row| row[0] * c[0] + row[1] * c[1] + row[2] * c[2])
}

/// CIE XYZ to linear sRGB: the inverse of [`linear_rgb_to_xyz`]'s matrix.
pub fn xyz_to_linear_rgb(c: [f32; 3]) -> [f32; 3] {
    const M: [[f32; 3]; 3] = [
        [3.241_003_2, -1.537_399, -0.498_615_9],
        [-0.969_224_3, 1.875_93, 0.041_554_226],
        [0.055_639_42, -0.204_011_2, 1.057_149],
    ];
    M.map(|row| row[0] * c[0] + row[1] * c[1] + row[2] * c[2])
}

/// XYZ to YCxCz (Zhang & Wandell's S-CIELAB opponent space, linear in XYZ): `Y' = 116 Y/Yn − 16`,
/// `Cx = 500 (X/Xn − Y/Yn)`, `Cz = 200 (Y/Yn − Z/Zn)`; CIELAB without its cube roots.
pub fn xyz_to_ycxcz(c: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = [c[0] / WHITE[0], c[1] / WHITE[1], c[2] / WHITE[2]];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// The inverse of [`xyz_to_ycxcz`].
pub fn ycxcz_to_xyz(c: [f32; 3]) -> [f32; 3] {
    let y = (c[0] + 16.0) / 116.0;
    let x = y + c[1] / 500.0;
    let z = y - c[2] / 200.0;
    [x * WHITE[0], y * WHITE[1], z * WHITE[2]]
}

/// XYZ to CIELAB (CIE 15:2004): `f(t) = t^(1/3)` above `(6/29)³`, its tangent line `t/(3 (6/29)²) + 4/29` below.
pub fn xyz_to_lab(c: [f32; 3]) -> [f32; 3] {
    const DELTA: f32 = 6.0 / 29.0;
    let f = |t: f32| if t > DELTA * DELTA * DELTA { t.cbrt() } else { t / (3.0 * DELTA * DELTA) + 4.0 / 29.0 };
    let [fx, fy, fz] = [f(c[0] / WHITE[0]), f(c[1] / WHITE[1]), f(c[2] / WHITE[2])];
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The Hunt adjustment: chroma scaled by `0.01 L*`, so that dark colours differ less (the Hunt effect: colourfulness
/// grows with luminance).
pub fn hunt(lab: [f32; 3]) -> [f32; 3] {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

/// The HyAB distance (Abasi et al. 2020): city-block in lightness, Euclidean in chroma; better than ΔE for large
/// differences.
pub fn hyab(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (da, db) = (a[1] - b[1], a[2] - b[2]);
    (a[0] - b[0]).abs() + (da * da + db * db).sqrt()
}

/// The largest colour difference FLIP normalises by: HyAB between Hunt-adjusted green and blue (the most distant
/// pair of sRGB's primaries in that space), raised to `q_c`.
pub fn max_colour_difference(q_c: f32) -> f32 {
    let green = hunt(xyz_to_lab(linear_rgb_to_xyz([0.0, 1.0, 0.0])));
    let blue = hunt(xyz_to_lab(linear_rgb_to_xyz([0.0, 0.0, 1.0])));
    hyab(green, blue).powf(q_c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_maps_to_the_white_point_and_back() {
        let w = linear_rgb_to_xyz([1.0; 3]);
        for k in 0..3 {
            assert!((w[k] - WHITE[k]).abs() < 1e-6, "{w:?}");
        }
        let lab = xyz_to_lab(w);
        assert!((lab[0] - 100.0).abs() < 1e-4 && lab[1].abs() < 1e-4 && lab[2].abs() < 1e-4, "{lab:?}");
        let ycc = xyz_to_ycxcz(w);
        assert!((ycc[0] - 100.0).abs() < 1e-4 && ycc[1].abs() < 1e-4 && ycc[2].abs() < 1e-4, "{ycc:?}");
    }

    #[test]
    fn conversions_invert() {
        for c in [[0.2, 0.5, 0.9], [1.0, 0.0, 0.0], [0.01, 0.3, 0.02]] {
            let back = xyz_to_linear_rgb(ycxcz_to_xyz(xyz_to_ycxcz(linear_rgb_to_xyz(c))));
            for k in 0..3 {
                assert!((back[k] - c[k]).abs() < 1e-5, "{c:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn srgb_decoding_is_continuous_at_its_knee() {
        let below = srgb_to_linear(0.040_45);
        let above = srgb_to_linear(0.040_450_01);
        assert!((below - above).abs() < 1e-6, "{below} {above}");
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn hyab_is_city_block_in_lightness_and_euclidean_in_chroma() {
        assert_eq!(hyab([50.0, 3.0, 4.0], [40.0, 0.0, 0.0]), 15.0);
        assert!(max_colour_difference(1.0) > 100.0);
    }
}
