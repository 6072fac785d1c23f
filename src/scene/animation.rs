//! A glTF animation sampled at one time (glTF 2.0 §3.11): each channel's sampler gives its node's translation,
//! rotation, scale or morph weights at `t` by its keyframes, `STEP`, `LINEAR` (rotations by spherical linear
//! interpolation) or `CUBICSPLINE` (Hermite, with the file's in- and out-tangents). Before the first key the
//! first value holds, after the last the last. The sampled values replace the nodes' own before the hierarchy is
//! walked, so skins, morphs, cameras and lights all follow the pose.

use std::collections::HashMap;

use glam::{DQuat, DVec3};
use serde_json::Value;

use super::gltf::accessor::AccessorReader;
use super::gltf::document::{lookup, Root};

/// A node's pose at the sampled time: whichever of its properties an animation channel drives.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodePose {
    pub translation: Option<DVec3>,
    pub rotation: Option<DQuat>,
    pub scale: Option<DVec3>,
    pub weights: Option<Vec<f64>>,
}

/// Keyframe interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Interpolation {
    Step,
    Linear,
    CubicSpline,
}

/// Samples animation `index` at `time` \[s\]: the pose of every node it drives.
pub fn sample(root: &Root, reader: &AccessorReader, index: usize, time: f64) -> Result<HashMap<u64, NodePose>, String> {
    let count = root.animations.len();
    let animation =
        root.animations.get(index).ok_or_else(|| format!("animation {index} does not exist (the file has {count})"))?;
    let what = format!("animation {index}");
    let field = |v: &Value, key: &str| v.get(key).cloned().unwrap_or(Value::Null);
    let channels = field(animation, "channels");
    let samplers = field(animation, "samplers");
    let (Some(channels), Some(samplers)) = (channels.as_array(), samplers.as_array()) else {
        return Err(format!("{what}: needs 'channels' and 'samplers' arrays"));
    };
    let mut poses: HashMap<u64, NodePose> = HashMap::new();
    for (c, channel) in channels.iter().enumerate() {
        let owner = format!("{what} channel {c}");
        let sampler_index = channel.get("sampler").and_then(Value::as_u64).ok_or(format!("{owner}: no sampler"))?;
        let sampler = lookup(samplers, sampler_index, &owner, "sampler")?;
        let target = channel.get("target").ok_or(format!("{owner}: no target"))?;
        // A channel without a node (an extension's target) drives nothing sunshade draws.
        let Some(node) = target.get("node").and_then(Value::as_u64) else { continue };
        lookup(&root.nodes, node, &owner, "node")?;
        let path = target.get("path").and_then(Value::as_str).ok_or(format!("{owner}: no target path"))?;
        let interpolation = match sampler.get("interpolation").and_then(Value::as_str).unwrap_or("LINEAR") {
            "STEP" => Interpolation::Step,
            "LINEAR" => Interpolation::Linear,
            "CUBICSPLINE" => Interpolation::CubicSpline,
            other => return Err(format!("{owner}: interpolation '{other}' is not a glTF interpolation")),
        };
        let input = sampler.get("input").and_then(Value::as_u64).ok_or(format!("{owner}: sampler has no input"))?;
        let output = sampler.get("output").and_then(Value::as_u64).ok_or(format!("{owner}: sampler has no output"))?;
        let times = reader.read(input, &format!("{owner} input"), "SCALAR")?.values;
        if times.is_empty() || times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
            return Err(format!("{owner}: keyframe times must be finite, increasing and not empty"));
        }
        let (kind, n) = match path {
            "translation" | "scale" => ("VEC3", 3),
            "rotation" => ("VEC4", 4),
            "weights" => ("SCALAR", 0),
            _ => continue, // "pointer" and extension paths: nothing sunshade draws
        };
        let values = reader.read(output, &format!("{owner} output"), kind)?.values;
        let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
        let n = if n == 0 { values.len() / (times.len() * per_key).max(1) } else { n };
        if n == 0 || values.len() != times.len() * per_key * n || values.iter().any(|v| !v.is_finite()) {
            return Err(format!(
                "{owner}: {} output values for {} keyframes of {n} components",
                values.len(),
                times.len()
            ));
        }
        let v = interpolate(&times, &values, n, interpolation, time, path == "rotation");
        let pose = poses.entry(node).or_default();
        match path {
            "translation" => pose.translation = Some(DVec3::new(v[0], v[1], v[2])),
            "scale" => pose.scale = Some(DVec3::new(v[0], v[1], v[2])),
            "rotation" => {
                let q = DQuat::from_xyzw(v[0], v[1], v[2], v[3]);
                pose.rotation = Some(if q.length_squared() > 0.0 { q.normalize() } else { DQuat::IDENTITY });
            }
            _ => pose.weights = Some(v),
        }
    }
    Ok(poses)
}

/// The value at `t` of keyframes `times` with `n` components each (`CUBICSPLINE`: in-tangent, value, out-tangent
/// per key). `rotation`: quaternions, blended by slerp along the shorter arc (LINEAR) or renormalised (cubic).
fn interpolate(times: &[f64], values: &[f64], n: usize, mode: Interpolation, t: f64, rotation: bool) -> Vec<f64> {
    let stride = if mode == Interpolation::CubicSpline { 3 * n } else { n };
    let value_at = |k: usize| -> &[f64] {
        let base = k * stride + if mode == Interpolation::CubicSpline { n } else { 0 };
        &values[base..base + n]
    };
    let last = times.len() - 1;
    if t <= times[0] {
        return value_at(0).to_vec();
    }
    if t >= times[last] {
        return value_at(last).to_vec();
    }
    // The key interval holding t: times[k] ≤ t < times[k + 1].
    let k = times.partition_point(|&x| x <= t) - 1;
    let dt = times[k + 1] - times[k];
    let u = if dt > 0.0 { (t - times[k]) / dt } else { 0.0 };
    let (a, b) = (value_at(k), value_at(k + 1));
    match mode {
        Interpolation::Step => a.to_vec(),
        Interpolation::Linear if rotation => {
            let qa = DQuat::from_slice(a);
            let qb = DQuat::from_slice(b);
            qa.slerp(qb, u).to_array().to_vec()
        }
        Interpolation::Linear => (0..n).map(|c| a[c] + u * (b[c] - a[c])).collect(),
        Interpolation::CubicSpline => {
            let out_a = &values[k * stride + 2 * n..k * stride + 3 * n];
            let in_b = &values[(k + 1) * stride..(k + 1) * stride + n];
            let (u2, u3) = (u * u, u * u * u);
            (0..n)
                .map(|c| {
                    (2.0 * u3 - 3.0 * u2 + 1.0) * a[c]
                        + (u3 - 2.0 * u2 + u) * dt * out_a[c]
                        + (-2.0 * u3 + 3.0 * u2) * b[c]
                        + (u3 - u2) * dt * in_b[c]
                })
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyframes_interpolate_and_hold_at_the_ends() {
        let times = [0.0, 1.0, 3.0];
        let values = [0.0, 10.0, 30.0];
        let at = |m, t| interpolate(&times, &values, 1, m, t, false)[0];
        assert_eq!(at(Interpolation::Linear, -1.0), 0.0);
        assert_eq!(at(Interpolation::Linear, 0.5), 5.0);
        assert_eq!(at(Interpolation::Linear, 2.0), 20.0);
        assert_eq!(at(Interpolation::Linear, 9.0), 30.0);
        assert_eq!(at(Interpolation::Step, 2.9), 10.0);
        // Cubic with zero tangents: smoothstep between the values.
        let cubic = [0.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 30.0, 0.0];
        let c = interpolate(&times, &cubic, 1, Interpolation::CubicSpline, 0.5, false)[0];
        assert!((c - 5.0).abs() < 1e-12);
        // Rotations: slerp half way between identity and a quarter turn about z is an eighth turn.
        let q1 = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let quats: Vec<f64> = [DQuat::IDENTITY, q1].iter().flat_map(|q| q.to_array()).collect();
        let h = interpolate(&[0.0, 1.0], &quats, 4, Interpolation::Linear, 0.5, true);
        let want = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4);
        assert!(DQuat::from_slice(&h).angle_between(want) < 1e-12);
    }
}
