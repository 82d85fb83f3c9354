//! Camera → the per-pixel ray frame the shader and the reference both use, and
//! the view frustum (to check, e.g., that the teapot scene's sphere is out of view).

use crate::scene::Camera;
use glam::DVec3;

/// Primary ray for pixel (x, y), counted from the top-left: from `eye` along
/// `top_left + x * step_x + y * step_y` (pixel centres; `step_y` points down).
/// `top_left` is relative to the eye: with an absolute image plane, a camera at
/// 1e5 or 1e6 would round every f32 ray target to a grid coarser than a pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayFrame {
    pub eye: DVec3,
    /// From the eye to the centre of the top-left pixel.
    pub top_left: DVec3,
    pub step_x: DVec3,
    pub step_y: DVec3,
}

impl RayFrame {
    pub fn new(cam: &Camera, width: u32, height: u32) -> RayFrame {
        let forward = (cam.look_at - cam.eye).normalize();
        let right = forward.cross(cam.up).normalize();
        let up = right.cross(forward);
        let half_h = (cam.fov_y.to_radians() * 0.5).tan();
        let half_w = half_h * width as f64 / height as f64;
        let step_x = right * (2.0 * half_w / width as f64);
        let step_y = -up * (2.0 * half_h / height as f64);
        let top_left = forward - right * half_w + up * half_h + 0.5 * step_x + 0.5 * step_y;
        RayFrame { eye: cam.eye, top_left, step_x, step_y }
    }

    /// The frame as the GPU's uniform buffer holds it (every vector in f32).
    pub fn rounded_to_f32(&self) -> RayFrame {
        let v = |x: DVec3| x.as_vec3().as_dvec3();
        RayFrame { eye: v(self.eye), top_left: v(self.top_left), step_x: v(self.step_x), step_y: v(self.step_y) }
    }

    /// Unit direction through the centre of pixel (x, y).
    pub fn dir(&self, x: f64, y: f64) -> DVec3 {
        (self.top_left + x * self.step_x + y * self.step_y).normalize()
    }
}

/// The four side planes of the view pyramid, normals pointing inwards.
#[derive(Debug, Clone, Copy)]
pub struct Frustum {
    eye: DVec3,
    normals: [DVec3; 4],
}

impl Frustum {
    pub fn new(frame: &RayFrame, width: u32, height: u32) -> Frustum {
        // Image-plane corners (pixel edges, not centres).
        let tl = frame.top_left - 0.5 * frame.step_x - 0.5 * frame.step_y;
        let tr = tl + width as f64 * frame.step_x;
        let bl = tl + height as f64 * frame.step_y;
        let br = tr + height as f64 * frame.step_y;
        let centre = (tl + br) * 0.5;
        let mut normals = [tl.cross(tr), tr.cross(br), br.cross(bl), bl.cross(tl)].map(|n| n.normalize());
        for n in &mut normals {
            if n.dot(centre) < 0.0 {
                *n = -*n;
            }
        }
        Frustum { eye: frame.eye, normals }
    }

    /// Whether any part of the sphere can be seen (it is in front of every side plane).
    pub fn sees_sphere(&self, center: DVec3, radius: f64) -> bool {
        let forward = self.normals.iter().copied().sum::<DVec3>();
        let rel = center - self.eye;
        self.normals.iter().all(|n| n.dot(rel) > -radius) && forward.dot(rel) > -radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera { eye: DVec3::new(0.0, 0.0, 5.0), look_at: DVec3::ZERO, up: DVec3::Y, fov_y: 90.0 }
    }

    #[test]
    fn centre_pixel_looks_at_target_and_y_goes_down() {
        let f = RayFrame::new(&cam(), 101, 101);
        let d = f.dir(50.0, 50.0);
        assert!((d - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        assert!(f.dir(50.0, 0.0).y > 0.0, "row 0 is the top of the image");
        assert!(f.dir(0.0, 50.0).x < 0.0, "column 0 is the left of the image");
    }

    #[test]
    fn frustum_sees_what_is_in_front_only() {
        let f = RayFrame::new(&cam(), 100, 100);
        let fr = Frustum::new(&f, 100, 100);
        assert!(fr.sees_sphere(DVec3::ZERO, 0.5));
        assert!(!fr.sees_sphere(DVec3::new(0.0, 0.0, 10.0), 0.5), "behind the eye");
        assert!(!fr.sees_sphere(DVec3::new(20.0, 0.0, 0.0), 0.5), "far to the right");
        assert!(fr.sees_sphere(DVec3::new(5.0, 0.0, 0.0), 0.5), "45 degree edge at distance 5 is inside");
    }
}
