//! Camera → the per-pixel ray frame the shader and the reference both use, the
//! view frustum (to check, e.g., that the teapot scene's sphere is out of view),
//! and the orbit camera of the windowed apps (drag orbits, wheel zooms, R resets):
//! one implementation, so both APIs move the camera identically; and the local
//! origin: the point subtracted in f64 from every position before the GPU's f32
//! conversion, so that a scene far from the world origin is traced as if near it.

use crate::scene::{Camera, OriginMode, Scene};
use glam::DVec3;
use std::borrow::Cow;

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
        RayFrame {
            eye: cam.eye,
            top_left,
            step_x,
            step_y,
        }
    }

    /// The frame as the GPU's uniform buffer holds it (every vector in f32).
    pub fn rounded_to_f32(&self) -> RayFrame {
        let v = |x: DVec3| x.as_vec3().as_dvec3();
        RayFrame {
            eye: v(self.eye),
            top_left: v(self.top_left),
            step_x: v(self.step_x),
            step_y: v(self.step_y),
        }
    }

    /// The frame of `camera` with its eye relative to `scene`'s local origin:
    /// what the GPU and the reference trace. The directions are computed from
    /// the world-space camera first, so a translation never changes their rounding.
    pub fn local(scene: &Scene, camera: &Camera, width: u32, height: u32) -> RayFrame {
        let mut frame = RayFrame::new(camera, width, height);
        frame.eye -= local_origin(scene);
        frame
    }

    /// Unit direction through the centre of pixel (x, y).
    pub fn dir(&self, x: f64, y: f64) -> DVec3 {
        (self.top_left + x * self.step_x + y * self.step_y).normalize()
    }
}

/// The local origin's grid, in view distances: the origin is the look-at point
/// rounded to a multiple of the smallest power of two at or above this many
/// times the eye's distance from it.
pub const LOCAL_ORIGIN_GRID_VIEWS: f64 = 16.0;

/// The point subtracted (in f64) from every position of `scene` before the
/// f32 conversion. The scene's own camera decides it, not the orbit camera of
/// a window, so orbiting and zooming never move it: the window keeps the
/// buffers it uploaded and shows what `--headless` renders for the same view.
///
/// The look-at point is rounded to a power-of-two grid at least 16 view
/// distances wide: the coordinates the GPU sees then stay within about 16 view
/// distances of zero wherever the scene lies, and a scene whose target already
/// lies within 8 view distances of the world origin (every built-in scene and
/// most hard cases) gets exactly zero, so its buffers and images do not change
/// by a single bit. A power of two also keeps the subtraction exact in f64 for
/// coordinates of similar magnitude.
pub fn local_origin(scene: &Scene) -> DVec3 {
    match scene.origin {
        OriginMode::World => DVec3::ZERO,
        OriginMode::Local => {
            let cam = &scene.camera;
            let view = (cam.eye - cam.look_at).length();
            let grid = (LOCAL_ORIGIN_GRID_VIEWS * view).log2().ceil().exp2();
            if !(grid.is_finite() && grid > 0.0) {
                return DVec3::ZERO;
            }
            // `+ 0.0` turns a -0.0 into 0.0, so a near scene's origin is exactly zero.
            (cam.look_at / grid).round() * grid + DVec3::ZERO
        }
    }
}

/// `scene` with `local_origin` subtracted from its camera, lights, spheres and
/// triangles, still in f64: what the GPU buffers are made from and what the
/// reference traces. Borrowed unchanged when the origin is zero.
pub fn in_local_frame(scene: &Scene) -> Cow<'_, Scene> {
    let o = local_origin(scene);
    if o == DVec3::ZERO {
        return Cow::Borrowed(scene);
    }
    let mut s = scene.clone();
    s.camera.eye -= o;
    s.camera.look_at -= o;
    for l in &mut s.lights {
        l.position -= o;
    }
    for sp in &mut s.spheres {
        sp.center -= o;
    }
    for t in &mut s.triangles {
        t.p = t.p.map(|p| p - o);
    }
    Cow::Owned(s)
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
        let mut normals =
            [tl.cross(tr), tr.cross(br), br.cross(bl), bl.cross(tl)].map(|n| n.normalize());
        for n in &mut normals {
            if n.dot(centre) < 0.0 {
                *n = -*n;
            }
        }
        Frustum {
            eye: frame.eye,
            normals,
        }
    }

    /// Whether any part of the sphere can be seen (it is in front of every side plane).
    pub fn sees_sphere(&self, center: DVec3, radius: f64) -> bool {
        let forward = self.normals.iter().copied().sum::<DVec3>();
        let rel = center - self.eye;
        self.normals.iter().all(|n| n.dot(rel) > -radius) && forward.dot(rel) > -radius
    }
}

/// A camera orbiting its look-at point: drag changes yaw (around the scene's
/// `up`) and pitch, the wheel changes the distance. Angles rather than an
/// accumulated rotation, so that repeated drags never drift or roll the horizon.
#[derive(Debug, Clone, PartialEq)]
pub struct Orbit {
    home: Camera,
    /// Unit `up`, and two unit axes spanning the plane at right angles to it;
    /// yaw 0 is the home eye's direction projected onto that plane.
    up: DVec3,
    axis_a: DVec3,
    axis_b: DVec3,
    pub yaw: f64,
    pub pitch: f64,
    pub distance: f64,
}

impl Orbit {
    /// Radians of orbit per window height dragged: a full drag turns half a circle.
    pub const RADIANS_PER_HEIGHT: f64 = std::f64::consts::PI;
    /// Each wheel line brings the eye this much closer.
    pub const ZOOM_PER_LINE: f64 = 0.9;
    /// Pitch stays this far from the poles, where `up` and the view direction
    /// would coincide and the ray frame would be undefined.
    pub const MAX_PITCH: f64 = 89.0 * std::f64::consts::PI / 180.0;

    pub fn new(cam: &Camera) -> Orbit {
        let up = cam.up.normalize();
        let offset = cam.eye - cam.look_at;
        let distance = offset.length();
        let flat = offset - up * offset.dot(up);
        // An eye straight above the target has no yaw; any axis at right angles will do.
        let axis_a = if flat.length() > 1e-9 * distance.max(1.0) {
            flat.normalize()
        } else {
            up.any_orthonormal_vector()
        };
        let axis_b = up.cross(axis_a);
        let pitch = (offset.dot(up) / distance).clamp(-1.0, 1.0).asin();
        Orbit {
            home: cam.clone(),
            up,
            axis_a,
            axis_b,
            yaw: 0.0,
            pitch,
            distance,
        }
    }

    /// The camera these angles describe (same target, up and field of view).
    pub fn camera(&self) -> Camera {
        let flat = self.axis_a * self.yaw.cos() + self.axis_b * self.yaw.sin();
        let dir = flat * self.pitch.cos() + self.up * self.pitch.sin();
        Camera {
            eye: self.home.look_at + dir * self.distance,
            ..self.home.clone()
        }
    }

    /// A mouse drag of (dx, dy) pixels in a window `height` pixels tall: right
    /// turns the scene right (the eye moves left), down tilts it towards the viewer.
    pub fn drag(&mut self, dx: f64, dy: f64, height: u32) {
        let k = Self::RADIANS_PER_HEIGHT / height.max(1) as f64;
        self.yaw = (self.yaw - dx * k).rem_euclid(std::f64::consts::TAU);
        self.pitch = (self.pitch + dy * k).clamp(-Self::MAX_PITCH, Self::MAX_PITCH);
    }

    /// `lines` wheel lines (positive = away from the user = closer). Never
    /// through the target, never further than 100 times the home distance.
    pub fn zoom(&mut self, lines: f64) {
        let home = (self.home.eye - self.home.look_at).length();
        let d = self.distance * Self::ZOOM_PER_LINE.powf(lines);
        self.distance = d.clamp(home * 0.01, home * 100.0);
    }

    pub fn reset(&mut self) {
        *self = Orbit::new(&self.home.clone());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-9
    }

    #[test]
    fn orbit_round_trips_the_scene_camera() {
        let tilted = Camera {
            eye: DVec3::new(1.0, 2.0, 6.0),
            look_at: DVec3::new(0.5, -1.0, 0.0),
            up: DVec3::new(0.0, 2.0, 0.1),
            fov_y: 40.0,
        };
        let above = Camera {
            eye: DVec3::new(0.0, 5.0, 0.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y: 60.0,
        };
        for c in [cam(), tilted, above] {
            let o = Orbit::new(&c);
            let back = o.camera();
            assert!(close(back.eye, c.eye), "{c:?} -> {back:?}");
            assert_eq!(
                (back.look_at, back.up, back.fov_y),
                (c.look_at, c.up, c.fov_y)
            );
        }
    }

    #[test]
    fn drag_orbits_around_the_target_at_constant_distance() {
        let c = cam();
        let mut o = Orbit::new(&c);
        o.drag(150.0, 0.0, 300); // half a window: a quarter turn
        let e = o.camera().eye;
        assert!((e.length() - 5.0).abs() < 1e-9);
        assert!(
            e.x.abs() > 4.99,
            "a quarter turn puts the eye on the x axis: {e:?}"
        );
        assert!(e.x < 0.0, "dragging right moves the eye left");
        o.drag(-150.0, 0.0, 300);
        assert!(close(o.camera().eye, c.eye), "dragging back returns");
        o.drag(0.0, 75.0, 300); // 45 degrees up
        let e = o.camera().eye;
        assert!(
            (e.y - 5.0 * std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-9,
            "{e:?}"
        );
    }

    #[test]
    fn pitch_stops_short_of_the_poles() {
        let mut o = Orbit::new(&cam());
        o.drag(0.0, 10_000.0, 100);
        assert_eq!(o.pitch, Orbit::MAX_PITCH);
        let c = o.camera();
        let forward = (c.look_at - c.eye).normalize();
        assert!(
            forward.cross(c.up).length() > 0.01,
            "the view never looks along up"
        );
        o.drag(0.0, -20_000.0, 100);
        assert_eq!(o.pitch, -Orbit::MAX_PITCH);
    }

    #[test]
    fn zoom_is_geometric_clamped_and_reset_restores() {
        let mut o = Orbit::new(&cam());
        o.zoom(1.0);
        assert!((o.distance - 4.5).abs() < 1e-12);
        o.zoom(-2.0);
        assert!((o.distance - 5.0 / 0.9).abs() < 1e-12);
        o.zoom(1e6);
        assert!(
            (o.distance - 0.05).abs() < 1e-12,
            "never through the target"
        );
        o.zoom(-1e6);
        assert!((o.distance - 500.0).abs() < 1e-9);
        o.drag(33.0, 17.0, 200);
        o.reset();
        assert_eq!(o, Orbit::new(&cam()));
        assert!(close(o.camera().eye, cam().eye));
    }

    fn cam() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y: 90.0,
        }
    }

    #[test]
    fn centre_pixel_looks_at_target_and_y_goes_down() {
        let f = RayFrame::new(&cam(), 101, 101);
        let d = f.dir(50.0, 50.0);
        assert!((d - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        assert!(f.dir(50.0, 0.0).y > 0.0, "row 0 is the top of the image");
        assert!(
            f.dir(0.0, 50.0).x < 0.0,
            "column 0 is the left of the image"
        );
    }

    #[test]
    fn frustum_sees_what_is_in_front_only() {
        let f = RayFrame::new(&cam(), 100, 100);
        let fr = Frustum::new(&f, 100, 100);
        assert!(fr.sees_sphere(DVec3::ZERO, 0.5));
        assert!(
            !fr.sees_sphere(DVec3::new(0.0, 0.0, 10.0), 0.5),
            "behind the eye"
        );
        assert!(
            !fr.sees_sphere(DVec3::new(20.0, 0.0, 0.0), 0.5),
            "far to the right"
        );
        assert!(
            fr.sees_sphere(DVec3::new(5.0, 0.0, 0.0), 0.5),
            "45 degree edge at distance 5 is inside"
        );
    }
}
