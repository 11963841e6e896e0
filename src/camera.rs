//! The pinhole camera of `raypipe render`: an eye, a point looked at, an up direction and a
//! vertical field of view, given on the command line or framed automatically from a scene's
//! bounding box.

use crate::scene::Scene;
use golden::{intersect, Faces, Ray64};
use serde::Serialize;

/// A pinhole camera (world units, degrees).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Camera {
    /// Eye position.
    pub eye: [f64; 3],
    /// The point at the image centre.
    pub look_at: [f64; 3],
    /// Up direction (need not be unit length or orthogonal to the view).
    pub up: [f64; 3],
    /// Vertical field of view in degrees, in (0, 180).
    pub fov: f64,
}

/// The direction the automatic view looks from, eye minus target before normalising: in
/// front (−z, where the scenes' open sides face: the Cornell box), to the right and above,
/// so that a closed model shows three of its sides and an open one its inside.
pub const AUTO_FROM: [f64; 3] = [0.45, 0.4, -1.0];

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

impl Camera {
    /// The view that frames the box `[lo, hi]` (Y up): looking at its centre from
    /// [`AUTO_FROM`], far enough that the box's bounding sphere fits the field of view `fov`
    /// in both image directions (aspect `width / height`).
    pub fn frame(lo: [f64; 3], hi: [f64; 3], fov: f64, aspect: f64) -> Camera {
        let c: [f64; 3] = std::array::from_fn(|a| (lo[a] + hi[a]) / 2.0);
        let r = (norm(sub(hi, lo)) / 2.0).max(1e-9);
        // the narrower of the two half-angles decides
        let half_v = (fov.to_radians() / 2.0).tan();
        let half = half_v.min(half_v * aspect).atan();
        let dist = 1.05 * r / half.sin();
        let d = unit(AUTO_FROM);
        Camera { eye: std::array::from_fn(|a| c[a] + dist * d[a]), look_at: c, up: [0.0, 1.0, 0.0], fov }
    }

    /// The automatic view of `scene`: [`Camera::frame`] of its bounding box, unless the box's
    /// centre is enclosed — the rays from it along ±x and ±z all hit a face turned towards
    /// it, as inside a building (Sponza), not inside a closed model whose faces turn away
    /// (the teapot) nor a room open on one side (the Cornell box) — where the eye stands
    /// inside: on the long horizontal axis, 85 % of the way from the centre to one end, at
    /// 30 % of the box's height, looking at the other end's centre.
    pub fn auto(scene: &Scene, fov: f64, aspect: f64) -> Camera {
        let (lo, hi) = scene.bounds();
        let c: [f64; 3] = std::array::from_fn(|a| (lo[a] + hi[a]) / 2.0);
        let faces_centre = |d: [f64; 3]| {
            let ray = Ray64 { o: c, d, tmin: 0.0, tmax: f64::INFINITY };
            let mut best: Option<(f64, usize)> = None;
            for (k, t) in scene.tris.iter().enumerate() {
                let r = intersect(&ray, t, Faces::default());
                if r.hit && best.is_none_or(|(bt, _)| r.t < bt) {
                    best = Some((r.t, k));
                }
            }
            best.is_some_and(|(_, k)| {
                let v = &scene.tris[k].v;
                let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
                n[0] * d[0] + n[1] * d[1] + n[2] * d[2] < 0.0
            })
        };
        let axes = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
        if !axes.iter().all(|&d| faces_centre(d)) {
            return Camera::frame(lo, hi, fov, aspect);
        }
        let a = if hi[0] - lo[0] >= hi[2] - lo[2] { 0 } else { 2 };
        let y = lo[1] + 0.3 * (hi[1] - lo[1]);
        let mut eye = [c[0], y, c[2]];
        eye[a] = c[a] - 0.85 * (hi[a] - lo[a]) / 2.0;
        let mut look_at = [c[0], y, c[2]];
        look_at[a] = hi[a];
        Camera { eye, look_at, up: [0.0, 1.0, 0.0], fov }
    }

    /// Checks that the camera defines a view: finite numbers, eye ≠ look-at, up not parallel
    /// to the view direction, 0 < fov < 180.
    pub fn check(&self) -> Result<(), String> {
        let all = self.eye.iter().chain(&self.look_at).chain(&self.up).chain([&self.fov]);
        if all.into_iter().any(|v| !v.is_finite()) {
            return Err("camera: --eye, --look-at, --up and --fov must be finite numbers".into());
        }
        if !(self.fov > 0.0 && self.fov < 180.0) {
            return Err(format!("camera: --fov {} is not in (0, 180) degrees", self.fov));
        }
        let w = sub(self.look_at, self.eye);
        if norm(w) == 0.0 {
            return Err("camera: --eye and --look-at are the same point".into());
        }
        let u = cross(unit(w), self.up);
        if norm(u) <= 1e-9 * norm(self.up) || norm(self.up) == 0.0 {
            return Err("camera: --up is zero or parallel to the view direction".into());
        }
        Ok(())
    }

    /// The direction of the primary ray through pixel `(i, j)` of a `width × height` image
    /// (row 0 at the top, through pixel centres; not normalised).
    pub fn ray_dir(&self, i: u32, j: u32, width: u32, height: u32) -> [f64; 3] {
        let w = unit(sub(self.look_at, self.eye));
        let u = unit(cross(w, self.up));
        let v = cross(u, w);
        let t = (self.fov.to_radians() / 2.0).tan();
        let sx = ((i as f64 + 0.5) / width as f64 * 2.0 - 1.0) * t * width as f64 / height as f64;
        let sy = (1.0 - (j as f64 + 0.5) / height as f64 * 2.0) * t;
        std::array::from_fn(|a| w[a] + sx * u[a] + sy * v[a])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_automatic_view_sees_the_whole_box() {
        let (lo, hi) = ([-3.0, 0.0, -2.0], [3.434, 3.15, 2.0]);
        for aspect in [0.5, 1.0, 2.0] {
            let cam = Camera::frame(lo, hi, 45.0, aspect);
            cam.check().unwrap();
            let w = unit(sub(cam.look_at, cam.eye));
            // every corner lies inside the view cone of the narrower half-angle
            let half = (22.5f64.to_radians().tan() * aspect.min(1.0)).atan();
            for k in 0..8 {
                let p = [
                    if k & 1 == 0 { lo[0] } else { hi[0] },
                    if k & 2 == 0 { lo[1] } else { hi[1] },
                    if k & 4 == 0 { lo[2] } else { hi[2] },
                ];
                let d = unit(sub(p, cam.eye));
                let ang = (d[0] * w[0] + d[1] * w[1] + d[2] * w[2]).acos();
                assert!(ang < half, "corner {p:?} at {ang} rad outside {half}");
            }
        }
    }

    #[test]
    fn the_centre_pixel_looks_at_the_target_and_up_is_up() {
        let cam = Camera { eye: [0.0, 0.0, -5.0], look_at: [0.0, 0.0, 0.0], up: [0.0, 1.0, 0.0], fov: 60.0 };
        let d = cam.ray_dir(50, 50, 101, 101);
        assert!(d[0].abs() < 1e-12 && d[1].abs() < 1e-12 && d[2] > 0.0);
        // row 0 is the top of the image: its rays go up
        assert!(cam.ray_dir(50, 0, 101, 101)[1] > 0.0);
        // right-handed: looking along +z with +y up, the image's left is +x (no mirror)
        let left = cam.ray_dir(0, 50, 101, 101)[0];
        let right = cam.ray_dir(100, 50, 101, 101)[0];
        assert!(left == -right && left > 0.0);
        // the top row's ray makes half the field of view with the axis (to the pixel centre)
        let top = cam.ray_dir(50, 0, 101, 101);
        let ang = (top[1] / top[2]).atan().to_degrees();
        assert!((ang - 30.0).abs() < 0.5, "{ang}");
    }

    #[test]
    fn bad_cameras_are_refused() {
        let ok = Camera { eye: [0.0, 0.0, -5.0], look_at: [0.0; 3], up: [0.0, 1.0, 0.0], fov: 45.0 };
        assert!(ok.check().is_ok());
        for bad in [
            Camera { eye: [0.0; 3], ..ok },
            Camera { up: [0.0, 0.0, 1.0], ..ok },
            Camera { up: [0.0; 3], ..ok },
            Camera { fov: 0.0, ..ok },
            Camera { fov: 180.0, ..ok },
            Camera { fov: f64::NAN, ..ok },
            Camera { eye: [f64::INFINITY, 0.0, 0.0], ..ok },
        ] {
            assert!(bad.check().is_err(), "{bad:?}");
        }
    }
}
