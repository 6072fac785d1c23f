//! Static poses of deformable meshes (glTF 2.0 §3.7.2.2 morph targets, §3.7.3 skins), in f64: a morph adds each
//! target's displacements times its weight; a skin moves each vertex by the weighted sum of its joints'
//! matrices, `S = Σ wⱼ · W(jointⱼ) · IBMⱼ`.

use glam::DMat4;

/// `base += weight · displacement` component by component; `n` components per element of `displacement`, at
/// most as many as `base` has per element (a VEC3 tangent target onto VEC4 tangents; VEC3 colours onto VEC4).
pub fn morph(base: &mut [f64], displacement: &[f64], n: usize, weight: f64) {
    let count = displacement.len() / n.max(1);
    if count == 0 {
        return;
    }
    let stride = base.len() / count;
    for (i, d) in displacement.chunks_exact(n).enumerate() {
        for (c, &v) in d.iter().enumerate().take(stride) {
            base[i * stride + c] += weight * v;
        }
    }
}

/// Each vertex's skinning matrix from its four joints and weights (JOINTS_0, WEIGHTS_0, as read) and the
/// joints' matrices `W(joint) · IBM`. A joint index past the skin's joints is an error; the weights are used as
/// given (glTF asks exporters to normalise them).
pub fn skin_matrices(joint_matrices: &[DMat4], joints: &[f64], weights: &[f64]) -> Result<Vec<DMat4>, String> {
    joints
        .chunks_exact(4)
        .zip(weights.chunks_exact(4))
        .enumerate()
        .map(|(v, (j, w))| {
            let mut m = DMat4::ZERO;
            for k in 0..4 {
                if w[k] == 0.0 {
                    continue;
                }
                let joint = joint_matrices.get(j[k] as usize).ok_or_else(|| {
                    format!("vertex {v}: joint {} is past the skin's {} joints", j[k], joint_matrices.len())
                })?;
                m += *joint * w[k];
            }
            Ok(m)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn morph_adds_weighted_displacements() {
        let mut p = vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        morph(&mut p, &[1.0, 0.0, 0.0, 0.0, 2.0, 0.0], 3, 0.5);
        assert_eq!(p, [0.5, 1.0, 2.0, 3.0, 5.0, 5.0]);
        // A VEC3 target onto VEC4 elements leaves the fourth component.
        let mut t = vec![1.0, 0.0, 0.0, -1.0];
        morph(&mut t, &[0.0, 1.0, 0.0], 3, 1.0);
        assert_eq!(t, [1.0, 1.0, 0.0, -1.0]);
    }

    #[test]
    fn skin_blends_joint_matrices() {
        let a = DMat4::from_translation(DVec3::X);
        let b = DMat4::from_translation(DVec3::Y * 3.0);
        let m = skin_matrices(&[a, b], &[0.0, 1.0, 0.0, 0.0], &[0.25, 0.75, 0.0, 0.0]).unwrap();
        assert_eq!(m[0].transform_point3(DVec3::ZERO), DVec3::new(0.25, 2.25, 0.0));
        assert!(skin_matrices(&[a], &[3.0, 0.0, 0.0, 0.0], &[1.0, 0.0, 0.0, 0.0]).unwrap_err().contains("joint 3"));
    }
}
