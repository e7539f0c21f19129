//! The Cg article's controls, as plain state and arithmetic (no window, no Vulkan): three
//! modes — scene (the camera), model (the selected caster), light (the selected light) — in
//! each of which a left drag turns by an arcball quaternion (Shoemake), Ctrl + drag moves along
//! the view's X/Y and Shift + drag along its Z; the wheel zooms.
//!
//! What the user did is kept apart from what the scene's motion does: the camera is replaced,
//! a mesh's edit is a world-space matrix applied after its motion, and a light's edit is a
//! rotation about the world origin and a translation, applied after its path.

use glam::{Mat3, Mat4, Quat, Vec2, Vec3};
use umbrage_scene::{Camera, Light, LightKind};

/// What a drag moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// The camera (the whole scene turns about the world origin).
    #[default]
    Scene,
    /// The selected caster (it turns about its own origin).
    Model,
    /// The selected light (it turns about the world origin).
    Light,
}

impl Mode {
    /// `scene`, `model` or `light`.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Scene => "scene",
            Mode::Model => "model",
            Mode::Light => "light",
        }
    }
}

/// What a left drag does, from the modifiers held when it started.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DragKind {
    /// Arcball rotation.
    Rotate,
    /// Along the view's X and Y (Ctrl).
    TranslateXy,
    /// Along the view's Z (Shift).
    TranslateZ,
}

impl DragKind {
    /// The drag for the modifiers held.
    pub fn from_modifiers(ctrl: bool, shift: bool) -> DragKind {
        match (ctrl, shift) {
            (true, _) => DragKind::TranslateXy,
            (false, true) => DragKind::TranslateZ,
            _ => DragKind::Rotate,
        }
    }
}

/// A light's edit: rotation about the world origin, then a translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightEdit {
    /// Rotation about the world origin (position and direction).
    pub rotation: Quat,
    /// Translation after it.
    pub offset: Vec3,
}

impl Default for LightEdit {
    fn default() -> Self {
        LightEdit { rotation: Quat::IDENTITY, offset: Vec3::ZERO }
    }
}

impl LightEdit {
    /// `l` (as its path puts it) with the edit applied.
    pub fn apply(&self, l: &Light) -> Light {
        let mut out = l.clone();
        if self.rotation != Quat::IDENTITY || self.offset != Vec3::ZERO {
            if l.kind != LightKind::Directional {
                out.position = self.rotation * l.position + self.offset;
            }
            out.direction = (self.rotation * l.direction).normalize();
        }
        out
    }
}

/// The user's edits of the scene.
#[derive(Clone, Debug)]
pub struct Edits {
    /// The camera.
    pub camera: Camera,
    /// Per mesh: world-space matrix applied after the mesh's (moving) transform.
    pub meshes: Vec<Mat4>,
    /// Per light.
    pub lights: Vec<LightEdit>,
}

impl Edits {
    /// No edits yet: the scene's camera, identity everywhere else.
    pub fn new(camera: Camera, meshes: usize, lights: usize) -> Edits {
        Edits { camera, meshes: vec![Mat4::IDENTITY; meshes], lights: vec![LightEdit::default(); lights] }
    }
}

/// The camera's orthonormal basis: right, up, back (view-space X, Y, Z in world space).
pub fn camera_basis(c: &Camera) -> Mat3 {
    let fwd = (c.target - c.eye).normalize();
    let right = fwd.cross(c.up).normalize();
    let up = right.cross(fwd);
    Mat3::from_cols(right, up, -fwd)
}

/// A window position on Shoemake's arcball: the unit sphere over the window's inscribed
/// circle, points outside it on its rim. View space (x right, y up, z towards the viewer).
pub fn arcball_point(p: Vec2, size: Vec2) -> Vec3 {
    let s = size.x.min(size.y).max(1.0);
    let v = Vec2::new((2.0 * p.x - size.x) / s, (size.y - 2.0 * p.y) / s);
    let r2 = v.length_squared();
    if r2 <= 1.0 {
        Vec3::new(v.x, v.y, (1.0 - r2).sqrt())
    } else {
        (v / r2.sqrt()).extend(0.0)
    }
}

/// The world-space rotation of a drag from `a` to `b` (window pixels) seen by `camera`.
pub fn arcball_rotation(camera: &Camera, a: Vec2, b: Vec2, size: Vec2) -> Quat {
    let (pa, pb) = (arcball_point(a, size), arcball_point(b, size));
    if pa.distance_squared(pb) < 1e-12 {
        return Quat::IDENTITY;
    }
    let basis = camera_basis(camera);
    Quat::from_rotation_arc(basis * pa, basis * pb).normalize()
}

/// The world-space translation of a drag by `delta` pixels, for something `distance` from the
/// eye: it follows the cursor (X/Y), or moves away as the cursor moves up (Z).
pub fn drag_translation(camera: &Camera, kind: DragKind, delta: Vec2, distance: f32, height: f32) -> Vec3 {
    let basis = camera_basis(camera);
    let per_pixel = 2.0 * distance.max(camera.near) * (camera.fov_y_deg.to_radians() * 0.5).tan() / height.max(1.0);
    match kind {
        DragKind::TranslateXy => (basis.x_axis * delta.x - basis.y_axis * delta.y) * per_pixel,
        DragKind::TranslateZ => basis.z_axis * delta.y * per_pixel,
        DragKind::Rotate => Vec3::ZERO,
    }
}

/// Moves the camera towards its target by `steps` wheel notches (negative: away).
pub fn zoom(camera: &Camera, steps: f32) -> Camera {
    let mut c = camera.clone();
    let d = c.eye - c.target;
    let len = (d.length() * 0.9f32.powf(steps)).clamp(c.near * 4.0, 1e6);
    c.eye = c.target + d.normalize() * len;
    c
}

/// One step of a drag, in window pixels.
#[derive(Clone, Copy, Debug)]
pub struct Stroke {
    /// Where the cursor was.
    pub from: Vec2,
    /// Where it is.
    pub to: Vec2,
    /// The window's size.
    pub size: Vec2,
}

/// The edit of one drag step (`stroke`) in `mode`, on what `index` selects (a mesh or a light; ignored in scene mode). `origin`: the moved
/// thing's world origin (the mesh's or the light's position as drawn; the target in scene
/// mode).
pub fn drag(edits: &mut Edits, mode: Mode, kind: DragKind, index: usize, origin: Vec3, stroke: Stroke) {
    let Stroke { from: a, to: b, size } = stroke;
    let camera = edits.camera.clone();
    match kind {
        DragKind::Rotate => {
            let q = arcball_rotation(&camera, a, b, size);
            match mode {
                // The scene turns with the cursor: the camera turns the other way.
                Mode::Scene => {
                    let inv = q.inverse();
                    edits.camera.eye = inv * camera.eye;
                    edits.camera.target = inv * camera.target;
                    edits.camera.up = (inv * camera.up).normalize();
                }
                Mode::Model => {
                    if let Some(m) = edits.meshes.get_mut(index) {
                        *m = Mat4::from_translation(origin) * Mat4::from_quat(q) * Mat4::from_translation(-origin) * *m;
                    }
                }
                Mode::Light => {
                    if let Some(l) = edits.lights.get_mut(index) {
                        l.rotation = (q * l.rotation).normalize();
                        l.offset = q * l.offset;
                    }
                }
            }
        }
        _ => {
            let distance = (origin - camera.eye).length();
            let t = drag_translation(&camera, kind, b - a, distance, size.y);
            match mode {
                Mode::Scene => {
                    edits.camera.eye -= t;
                    edits.camera.target -= t;
                }
                Mode::Model => {
                    if let Some(m) = edits.meshes.get_mut(index) {
                        *m = Mat4::from_translation(t) * *m;
                    }
                }
                Mode::Light => {
                    if let Some(l) = edits.lights.get_mut(index) {
                        l.offset += t;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera { eye: Vec3::new(0.0, 0.0, 10.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0, near: 0.1 }
    }

    #[test]
    fn arcball_centre_is_the_pole_and_outside_is_the_rim() {
        let size = Vec2::new(200.0, 100.0);
        assert_eq!(arcball_point(Vec2::new(100.0, 50.0), size), Vec3::Z);
        let rim = arcball_point(Vec2::new(200.0, 50.0), size);
        assert!((rim - Vec3::X).length() < 1e-6, "{rim}");
    }

    #[test]
    fn a_horizontal_drag_turns_about_the_view_up_axis() {
        let size = Vec2::new(400.0, 400.0);
        let q = arcball_rotation(&cam(), Vec2::new(200.0, 200.0), Vec2::new(300.0, 200.0), size);
        let (axis, angle) = q.to_axis_angle();
        assert!(axis.distance(Vec3::Y) < 1e-5 && angle > 0.1, "{axis} {angle}");
    }

    #[test]
    fn light_drag_rotates_about_the_origin_keeping_the_distance() {
        let mut e = Edits::new(cam(), 0, 1);
        let size = Vec2::new(400.0, 400.0);
        drag(
            &mut e,
            Mode::Light,
            DragKind::Rotate,
            0,
            Vec3::ZERO,
            Stroke { from: Vec2::new(200.0, 200.0), to: Vec2::new(260.0, 170.0), size },
        );
        let l = Light {
            kind: LightKind::Point,
            position: Vec3::new(3.0, 4.0, 0.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            radius: None,
            cone_deg: 45.0,
            area: None,
        };
        let moved = e.lights[0].apply(&l);
        assert!((moved.position.length() - 5.0).abs() < 1e-4);
        assert!(moved.position.distance(l.position) > 0.1);
    }

    #[test]
    fn translation_follows_the_cursor() {
        let c = cam();
        // At the target's distance one window height spans 2 tan(30 deg) * 10 world units.
        let t = drag_translation(&c, DragKind::TranslateXy, Vec2::new(0.0, -100.0), 10.0, 100.0);
        assert!((t - Vec3::Y * 2.0 * 10.0 * 30f32.to_radians().tan()).length() < 1e-4, "{t}");
        let z = drag_translation(&c, DragKind::TranslateZ, Vec2::new(0.0, 10.0), 10.0, 100.0);
        assert!(z.z > 0.0 && z.x == 0.0);
    }

    #[test]
    fn scene_rotation_turns_the_camera_the_other_way() {
        let mut e = Edits::new(cam(), 0, 0);
        let size = Vec2::new(400.0, 400.0);
        drag(
            &mut e,
            Mode::Scene,
            DragKind::Rotate,
            0,
            Vec3::ZERO,
            Stroke { from: Vec2::new(200.0, 200.0), to: Vec2::new(300.0, 200.0), size },
        );
        // The scene turns right (counter-clockwise from above): the eye goes left (-x).
        assert!(e.camera.eye.x < -0.5, "{}", e.camera.eye);
        assert!((e.camera.eye.length() - 10.0).abs() < 1e-4);
    }

    #[test]
    fn zoom_approaches_the_target_but_never_passes_it() {
        let c = zoom(&cam(), 1.0);
        assert!((c.eye.z - 9.0).abs() < 1e-5);
        let c = zoom(&cam(), 1000.0);
        assert!(c.eye.z > 0.0);
    }

    #[test]
    fn model_rotation_keeps_its_origin() {
        let mut e = Edits::new(cam(), 1, 0);
        let o = Vec3::new(2.0, 0.0, 0.0);
        let size = Vec2::new(400.0, 400.0);
        drag(&mut e, Mode::Model, DragKind::Rotate, 0, o, Stroke { from: Vec2::new(200.0, 200.0), to: Vec2::new(200.0, 120.0), size });
        assert!(e.meshes[0].transform_point3(o).distance(o) < 1e-5);
        assert_ne!(e.meshes[0], Mat4::IDENTITY);
    }
}
