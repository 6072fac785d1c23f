//! Cameras: placement in world space and projection to Vulkan clip space.
//!
//! Conventions (the glTF camera model): the camera looks down its local −Z with +Y up. Clip space is Vulkan's:
//! `x_ndc` right, `y_ndc` down (the projection flips y so that world-up is image-up), depth `z_ndc ∈ [0, 1]` with 0
//! at the near plane. The framebuffer's aspect ratio (width/height) always replaces the file's `aspectRatio`;
//! an orthographic camera keeps its `ymag` and takes `xmag = ymag · aspect`.

use glam::{DMat4, DVec3, DVec4};

use super::BoundingSphere;

/// Projection of a camera. Angles in radians, distances in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective with vertical field of view `yfov`; `zfar = None` is an infinite far plane.
    Perspective { yfov: f64, znear: f64, zfar: Option<f64> },
    /// Orthographic with half-height `ymag` \[m\].
    Orthographic { ymag: f64, znear: f64, zfar: f64 },
}

/// A camera in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position \[m\].
    pub eye: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit up vector, orthogonal to `forward`.
    pub up: DVec3,
    pub projection: Projection,
}

/// Default vertical field of view of the automatic camera \[degrees\].
pub const AUTO_FOV_DEGREES: f64 = 45.0;
/// Elevation and azimuth of the automatic camera's viewing direction, seen from the scene \[degrees\]: front
/// (+Z), a little to the right (+X) and above.
pub const AUTO_ELEVATION_DEGREES: f64 = 20.0;
pub const AUTO_AZIMUTH_DEGREES: f64 = 30.0;

impl Camera {
    /// A camera at `eye` looking at `target`. Returns `None` when the two coincide or `up` is parallel to the view.
    pub fn look_at(eye: DVec3, target: DVec3, up: DVec3, projection: Projection) -> Option<Self> {
        Self::looking(eye, target - eye, up, projection)
    }

    /// A camera at `eye` looking along `direction`, `up` made orthogonal to it.
    pub fn looking(eye: DVec3, direction: DVec3, up: DVec3, projection: Projection) -> Option<Self> {
        let forward = direction.try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let up = right.cross(forward);
        Some(Self { eye, forward, up, projection })
    }

    /// A perspective camera that sees the whole sphere, from the default direction.
    pub fn frame_sphere(sphere: BoundingSphere, aspect: f64, yfov: f64) -> Self {
        let (el, az) = (AUTO_ELEVATION_DEGREES.to_radians(), AUTO_AZIMUTH_DEGREES.to_radians());
        let towards_eye = DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        let radius = if sphere.radius > 0.0 { sphere.radius } else { 1.0 };
        // The sphere fits in the narrower of the two view cones: distance = r / sin(half-angle).
        let half_y = 0.5 * yfov;
        let half_x = (aspect * half_y.tan()).atan();
        let distance = radius / half_y.min(half_x).sin();
        let eye = sphere.center + towards_eye * distance;
        let (znear, zfar) = near_far_around(eye, BoundingSphere { center: sphere.center, radius });
        Self::look_at(eye, sphere.center, DVec3::Y, Projection::Perspective { yfov, znear, zfar: Some(zfar) })
            .expect("default direction is not vertical")
    }

    /// World → view: view space has the camera at the origin looking down −Z, +Y up (right-handed).
    pub fn view_from_world(&self) -> DMat4 {
        let right = self.forward.cross(self.up);
        let back = -self.forward;
        DMat4::from_cols(
            DVec4::new(right.x, self.up.x, back.x, 0.0),
            DVec4::new(right.y, self.up.y, back.y, 0.0),
            DVec4::new(right.z, self.up.z, back.z, 0.0),
            DVec4::new(-right.dot(self.eye), -self.up.dot(self.eye), -back.dot(self.eye), 1.0),
        )
    }

    /// View → Vulkan clip space for a framebuffer of this aspect ratio (width/height).
    pub fn clip_from_view(&self, aspect: f64) -> DMat4 {
        match self.projection {
            Projection::Perspective { yfov, znear, zfar } => {
                let f = 1.0 / (0.5 * yfov).tan();
                // depth = z_clip / w_clip is 0 at z_view = −znear and 1 at z_view = −zfar (→ 1 as zfar → ∞).
                let (a, b) = match zfar {
                    Some(zfar) => (zfar / (znear - zfar), znear * zfar / (znear - zfar)),
                    None => (-1.0, -znear),
                };
                DMat4::from_cols(
                    DVec4::new(f / aspect, 0.0, 0.0, 0.0),
                    DVec4::new(0.0, -f, 0.0, 0.0),
                    DVec4::new(0.0, 0.0, a, -1.0),
                    DVec4::new(0.0, 0.0, b, 0.0),
                )
            }
            Projection::Orthographic { ymag, znear, zfar } => {
                let xmag = ymag * aspect;
                let depth = 1.0 / (znear - zfar);
                DMat4::from_cols(
                    DVec4::new(1.0 / xmag, 0.0, 0.0, 0.0),
                    DVec4::new(0.0, -1.0 / ymag, 0.0, 0.0),
                    DVec4::new(0.0, 0.0, depth, 0.0),
                    DVec4::new(0.0, 0.0, znear * depth, 1.0),
                )
            }
        }
    }

    /// World → clip, in f64 (both renderers round this once to f32).
    pub fn clip_from_world(&self, aspect: f64) -> DMat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }

    pub fn is_orthographic(&self) -> bool {
        matches!(self.projection, Projection::Orthographic { .. })
    }
}

/// Near and far planes that enclose the sphere as seen from `eye`, with margins; a near plane of 1/1000 of the
/// radius when the eye is inside the sphere.
pub fn near_far_around(eye: DVec3, sphere: BoundingSphere) -> (f64, f64) {
    let d = eye.distance(sphere.center);
    let znear = ((d - sphere.radius) * 0.9).max(sphere.radius * 1e-3);
    let zfar = (d + sphere.radius) * 1.01;
    (znear, zfar.max(znear * 2.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn project(m: DMat4, p: DVec3) -> DVec3 {
        let c = m * p.extend(1.0);
        c.truncate() / c.w
    }

    #[test]
    fn perspective_maps_near_far_and_flips_y() {
        let cam = Camera::look_at(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::ZERO,
            DVec3::Y,
            Projection::Perspective { yfov: 90f64.to_radians(), znear: 1.0, zfar: Some(9.0) },
        )
        .unwrap();
        let m = cam.clip_from_world(2.0);
        assert!((project(m, DVec3::new(0.0, 0.0, 4.0)).z - 0.0).abs() < 1e-12);
        assert!((project(m, DVec3::new(0.0, 0.0, -4.0)).z - 1.0).abs() < 1e-12);
        // A point above the axis at 45° lands at the top edge: y_ndc = −1.
        let top = project(m, DVec3::new(0.0, 2.0, 3.0));
        assert!((top.y + 1.0).abs() < 1e-12, "{top}");
        // A point to the right at 45° lands at x_ndc = 1/aspect.
        let right = project(m, DVec3::new(2.0, 0.0, 3.0));
        assert!((right.x - 0.5).abs() < 1e-12, "{right}");
    }

    #[test]
    fn infinite_far_plane_tends_to_one() {
        let cam = Camera::looking(
            DVec3::ZERO,
            -DVec3::Z,
            DVec3::Y,
            Projection::Perspective { yfov: 1.0, znear: 0.5, zfar: None },
        )
        .unwrap();
        let m = cam.clip_from_world(1.0);
        assert!(project(m, DVec3::new(0.0, 0.0, -0.5)).z.abs() < 1e-12);
        let far = project(m, DVec3::new(0.0, 0.0, -1e9)).z;
        assert!(far < 1.0 && far > 1.0 - 1e-8);
    }

    #[test]
    fn orthographic_uses_aspect_for_x() {
        let cam = Camera::looking(
            DVec3::new(0.0, 10.0, 0.0),
            -DVec3::Y,
            -DVec3::Z,
            Projection::Orthographic { ymag: 2.0, znear: 1.0, zfar: 11.0 },
        )
        .unwrap();
        let m = cam.clip_from_world(1.5);
        let p = project(m, DVec3::new(3.0, 0.0, -2.0));
        // Looking down with up = −Z: +X is image-right, −Z is image-up.
        assert!((p.x - 1.0).abs() < 1e-12 && (p.y + 1.0).abs() < 1e-12 && (p.z - 0.9).abs() < 1e-12, "{p}");
    }

    #[test]
    fn framing_keeps_sphere_inside_the_view() {
        let sphere = BoundingSphere { center: DVec3::new(1.0, 2.0, 3.0), radius: 2.0 };
        for aspect in [0.5, 1.0, 2.0] {
            let cam = Camera::frame_sphere(sphere, aspect, 45f64.to_radians());
            let m = cam.clip_from_world(aspect);
            for dir in [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z] {
                let p = project(m, sphere.center + dir * sphere.radius);
                assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && (0.0..=1.0).contains(&p.z), "{aspect} {dir} {p}");
            }
        }
    }

    #[test]
    fn degenerate_look_at_is_refused() {
        let proj = Projection::Perspective { yfov: 1.0, znear: 0.1, zfar: None };
        assert!(Camera::look_at(DVec3::ONE, DVec3::ONE, DVec3::Y, proj).is_none());
        assert!(Camera::look_at(DVec3::ZERO, DVec3::Y, DVec3::Y, proj).is_none());
    }
}
