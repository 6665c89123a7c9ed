//! The orbit camera: it looks at `target` from `distance` away, turned by `yaw` about the
//! up axis (+y) and raised by `pitch`; perspective with a vertical field of view.
//! Matrices are built in f64 and handed to the GPU relative to the scene's origin.

use glam::{DMat4, DVec2, DVec3, DVec4};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub target: DVec3,
    /// Radians about +y; 0 looks from +z towards −z.
    pub yaw: f64,
    /// Radians above the horizon, within ±[`Camera::MAX_PITCH`].
    pub pitch: f64,
    pub distance: f64,
    /// Vertical field of view, radians.
    pub fov_y: f64,
}

impl Camera {
    /// The default three-quarter view.
    pub const YAW: f64 = 35.0 * std::f64::consts::PI / 180.0;
    pub const PITCH: f64 = 25.0 * std::f64::consts::PI / 180.0;
    pub const FOV_Y: f64 = 35.0 * std::f64::consts::PI / 180.0;
    /// Just short of straight up or down, where the up axis would be undefined.
    pub const MAX_PITCH: f64 = 89.0 * std::f64::consts::PI / 180.0;

    /// A camera at `yaw`, `pitch` that frames the box `lo`..`hi` in a picture of aspect
    /// ratio `aspect` (width / height): the box's bounding sphere fits both directions.
    pub fn fit(lo: DVec3, hi: DVec3, yaw: f64, pitch: f64, aspect: f64) -> Camera {
        let radius = ((hi - lo).length() * 0.5).max(1e-12 * lo.abs().max(hi.abs()).max_element()).max(1e-30);
        let half_y = Camera::FOV_Y * 0.5;
        let half_x = (half_y.tan() * aspect.max(1e-6)).atan();
        let half = half_y.min(half_x);
        Camera {
            target: (lo + hi) * 0.5,
            yaw,
            pitch: pitch.clamp(-Camera::MAX_PITCH, Camera::MAX_PITCH),
            distance: radius / half.sin() * 1.05,
            fov_y: Camera::FOV_Y,
        }
    }

    /// Unit vector from the target towards the eye.
    pub fn backward(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        DVec3::new(cp * sy, sp, cp * cy)
    }

    pub fn eye(&self) -> DVec3 {
        self.target + self.backward() * self.distance
    }

    /// Turns the camera around its target.
    pub fn orbit(&mut self, dyaw: f64, dpitch: f64) {
        self.yaw = (self.yaw + dyaw).rem_euclid(std::f64::consts::TAU);
        self.pitch = (self.pitch + dpitch).clamp(-Camera::MAX_PITCH, Camera::MAX_PITCH);
    }

    /// Moves towards the target (`factor` < 1) or away (> 1).
    pub fn zoom(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            self.distance *= factor;
        }
    }

    /// Moves the target (and the eye with it) in the picture plane by `dx`, `dy` picture
    /// heights (x right, y up on screen).
    pub fn pan(&mut self, dx: f64, dy: f64) {
        let view = self.view();
        let right = DVec3::new(view.x_axis.x, view.y_axis.x, view.z_axis.x);
        let up = DVec3::new(view.x_axis.y, view.y_axis.y, view.z_axis.y);
        let height = 2.0 * self.distance * (self.fov_y * 0.5).tan();
        self.target += (right * dx + up * dy) * height;
    }

    /// World to eye space (right-handed, the eye looks along −z).
    pub fn view(&self) -> DMat4 {
        let eye = self.eye();
        let f = -self.backward();
        let s = f.cross(DVec3::Y).normalize();
        let u = s.cross(f);
        DMat4::from_cols(
            DVec4::new(s.x, u.x, -f.x, 0.0),
            DVec4::new(s.y, u.y, -f.y, 0.0),
            DVec4::new(s.z, u.z, -f.z, 0.0),
            DVec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
        )
    }

    /// Eye to Vulkan clip space for a picture of aspect `aspect`: y down, depth 0 at
    /// `near` and 1 at `far`.
    pub fn projection(&self, aspect: f64, near: f64, far: f64) -> DMat4 {
        let f = 1.0 / (self.fov_y * 0.5).tan();
        let depth = far / (near - far);
        DMat4::from_cols(
            DVec4::new(f / aspect, 0.0, 0.0, 0.0),
            DVec4::new(0.0, -f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, depth, -1.0),
            DVec4::new(0.0, 0.0, near * depth, 0.0),
        )
    }

    /// Where `p` lands in a `width`×`height` picture, in pixels (x right, y down; pixel
    /// (i, j) covers [i, i+1) × [j, j+1)); `None` behind the eye.
    pub fn project(&self, p: DVec3, width: u32, height: u32) -> Option<DVec2> {
        let aspect = f64::from(width) / f64::from(height);
        let clip = self.projection(aspect, 1.0, 2.0) * self.view() * DVec4::new(p.x, p.y, p.z, 1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = DVec2::new(clip.x, clip.y) / clip.w;
        Some(DVec2::new((ndc.x + 1.0) * 0.5 * f64::from(width), (ndc.y + 1.0) * 0.5 * f64::from(height)))
    }

    /// Near and far planes that hold a sphere of `radius` around `centre`.
    pub fn clip_planes(&self, centre: DVec3, radius: f64) -> (f64, f64) {
        let d = (centre - self.eye()).dot(-self.backward());
        let radius = radius.max(1e-30);
        let far = (d + radius * 1.01).max(radius * 1e-3);
        let near = (d - radius * 1.01).max(far * 1e-4);
        (near, far)
    }
}
