use fuzzyvox_core::error::Result;
use fuzzyvox_core::geometry::PinholeIntrinsics;
use fuzzyvox_core::image::{Frame, GrayImage};
use nalgebra::{Isometry3, Vector3};
use rayon::prelude::*;

use super::scene::Scene;
use super::texture::{albedo, scramble, unit_hash};

/// A rendered view: a grayscale image in `[0, 1]` and the true depth along the optical axis
/// (NaN where the ray meets nothing: sky), both row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderedFrame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Intensity per pixel.
    pub image: Vec<f32>,
    /// True depth (metres along the optical axis) per pixel, NaN for sky.
    pub depth: Vec<f32>,
}

impl RenderedFrame {
    /// The rendered image as the depth stage's input: a frame taken by `intrinsics` (those it
    /// was rendered with) at `world_from_camera` and `timestamp`.
    pub fn to_frame(
        &self,
        intrinsics: PinholeIntrinsics,
        world_from_camera: Isometry3<f64>,
        timestamp: f64,
    ) -> Result<Frame> {
        let image = GrayImage::new(self.width, self.height, self.image.clone())?;
        Frame::new(image, intrinsics, world_from_camera, timestamp)
    }
}

/// Direction of the sun for shading (unit, pointing towards the sun): high, from behind the
/// cameras of the scenarios, so that walls facing them are lit.
fn sun() -> Vector3<f64> {
    Vector3::new(-0.5, -0.3, 0.8).normalize()
}

/// Renders the scene from a camera: one ray per pixel centre, the hit shaded by its world-fixed
/// texture under a sun and ambient light, plus mild sensor noise; rays that meet nothing within
/// `max_distance` see a smooth sky whose brightness depends only on elevation. Rows are
/// rendered in parallel; the noise is a hash of `(seed, pixel)`, so the image is the same for
/// any number of threads, and independent from one seed to another.
pub fn render(
    scene: &Scene,
    intrinsics: &PinholeIntrinsics,
    world_from_camera: &Isometry3<f64>,
    seed: u64,
    max_distance: f64,
) -> RenderedFrame {
    let (width, height) = (intrinsics.width(), intrinsics.height());
    let origin = world_from_camera.translation.vector.into();
    let rotation = world_from_camera.rotation;
    let sun = sun();
    // Independent noise for every seed, consecutive ones included (see `scramble`).
    let noise_seed = scramble(seed);
    let rows: Vec<(Vec<f32>, Vec<f32>)> = (0..height)
        .into_par_iter()
        .map(|v| {
            let mut image = Vec::with_capacity(width as usize);
            let mut depth = Vec::with_capacity(width as usize);
            for u in 0..width {
                let in_camera = intrinsics.back_project(f64::from(u), f64::from(v), 1.0);
                let direction = rotation * in_camera.coords;
                let noise = (unit_hash(i64::from(u), i64::from(v), 7, noise_seed) - 0.5) * 0.02;
                match scene.cast_ray(&origin, &direction, max_distance) {
                    Some(hit) => {
                        let light = 0.35 + 0.65 * hit.normal.dot(&sun).max(0.0) as f32;
                        image.push((albedo(&hit.point, hit.kind) * light + noise).clamp(0.0, 1.0));
                        // The ray direction has unit depth, so depth = distance / |direction|.
                        depth.push((hit.distance / in_camera.coords.norm()) as f32);
                    }
                    None => {
                        let elevation = direction.normalize().z as f32;
                        image.push((0.72 + 0.2 * elevation + noise * 0.2).clamp(0.0, 1.0));
                        depth.push(f32::NAN);
                    }
                }
            }
            (image, depth)
        })
        .collect();
    let mut frame = RenderedFrame {
        width,
        height,
        image: Vec::with_capacity((width * height) as usize),
        depth: Vec::with_capacity((width * height) as usize),
    };
    for (image, depth) in rows {
        frame.image.extend(image);
        frame.depth.extend(depth);
    }
    frame
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SurfaceKind;
    use crate::trajectory::look_at;
    use nalgebra::Point3;

    /// Open ground, a wall centred at x = 12 m (16 m wide, 6 m high, turned 0.2 rad) and a
    /// tree in front of it.
    fn scene() -> Scene {
        let (wall_center, wall_half) = (Point3::new(12.0, 0.0, 3.0), Vector3::new(0.3, 8.0, 3.0));
        let tree_base = Point3::new(6.0, 2.0, 0.0);
        let mut s = Scene::new();
        s.add_ground(0.0, 200.0)
            .add_box(wall_center, wall_half, 0.2, SurfaceKind::Wall)
            .add_tree(tree_base, 0.25, 2.5, 1.2);
        s
    }

    #[test]
    fn true_depth_equals_an_independent_ray_cast() {
        let s = scene();
        let k = PinholeIntrinsics::new(64, 48, 50.0, 50.0, 31.5, 23.5).unwrap();
        let pose = look_at(Point3::new(0.0, 0.0, 1.5), Vector3::new(1.0, 0.1, -0.05));
        let frame = render(&s, &k, &pose, 3, 100.0);
        let mut hits = 0;
        for v in 0..48 {
            for u in 0..64 {
                let in_camera = k.back_project(f64::from(u), f64::from(v), 1.0);
                let direction = pose.rotation * in_camera.coords;
                let reference =
                    s.cast_ray_brute_force(&pose.translation.vector.into(), &direction, 100.0);
                let depth = frame.depth[(v * 64 + u) as usize];
                match reference {
                    Some(hit) => {
                        // The point at that depth on the pixel's ray is the independent hit.
                        let point =
                            pose * k.back_project(f64::from(u), f64::from(v), f64::from(depth));
                        assert!((point - hit.point).norm() < 1e-3, "pixel ({u}, {v})");
                        hits += 1;
                    }
                    None => assert!(depth.is_nan()),
                }
            }
        }
        assert!(hits > 1000);
        assert!(frame.image.iter().all(|v| (0.0..=1.0).contains(v)));
    }

    #[test]
    fn the_same_seed_gives_the_same_image_on_any_thread_count() {
        let s = scene();
        let k = PinholeIntrinsics::new(80, 60, 60.0, 60.0, 39.5, 29.5).unwrap();
        let pose = look_at(Point3::new(0.0, -1.0, 2.0), Vector3::new(1.0, 0.2, -0.1));
        let frames: Vec<_> = [1, 2, 4]
            .into_iter()
            .map(|threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| render(&s, &k, &pose, 9, 100.0))
            })
            .collect();
        // Depth holds NaN for sky, so compare bit patterns.
        let bits = |f: &RenderedFrame| {
            (
                f.image.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                f.depth.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            )
        };
        assert!(
            bits(&frames[0]) == bits(&frames[1]),
            "1 and 2 threads differ"
        );
        assert!(
            bits(&frames[0]) == bits(&frames[2]),
            "1 and 4 threads differ"
        );
        let other = render(&s, &k, &pose, 10, 100.0);
        assert!(
            bits(&other).0 != bits(&frames[0]).0,
            "another seed, other noise"
        );
        assert!(bits(&other).1 == bits(&frames[0]).1, "the same true depth");
    }

    #[test]
    fn consecutive_seeds_give_unrelated_noise() {
        // Sky only: the image is the smooth sky plus the noise. Unscrambled, seeds that differ
        // in their low bits gave the same noise with columns swapped (`u` xor the difference),
        // a pattern that matched between consecutive frames.
        let s = Scene::default();
        let k = PinholeIntrinsics::new(64, 48, 60.0, 60.0, 31.5, 23.5).unwrap();
        let pose = look_at(Point3::new(0.0, 0.0, 2.0), Vector3::new(1.0, 0.0, 0.3));
        for (a, b) in [(2u64, 3u64), (16, 17), (31, 32), (64, 127)] {
            let (fa, fb) = (
                render(&s, &k, &pose, a, 100.0),
                render(&s, &k, &pose, b, 100.0),
            );
            // The sky is the same in both, so the difference is the noises' difference; with
            // the columns-swapped noise of the old hash, that difference at `u` and at
            // `u ^ (a ^ b)` cancel exactly.
            let swap = (a ^ b) as u32;
            let d = |u: u32, v: u32| {
                let i = (v * 64 + u) as usize;
                fb.image[i] - fa.image[i]
            };
            let (mut cancel, mut compared) = (0, 0);
            for v in 0..48u32 {
                for u in 0..64u32 {
                    let w = u ^ swap;
                    if w < 64 && w != u {
                        compared += 1;
                        cancel += usize::from((d(u, v) + d(w, v)).abs() < 1e-6);
                    }
                }
            }
            assert!(compared > 0);
            assert!(
                cancel * 20 < compared,
                "seeds {a}, {b}: {cancel} of {compared} cancel"
            );
        }
    }
}
