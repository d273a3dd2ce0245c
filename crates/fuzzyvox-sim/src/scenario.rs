//! The paper's two scenarios: a wall seen first by strafing and then by receding cameras, and a
//! random flight over terrain with buildings and trees.

use fuzzyvox_core::error::Result;
use fuzzyvox_core::geometry::PinholeIntrinsics;
use nalgebra::{Isometry3, Point3, Vector3};

use super::render::{RenderedFrame, render};
use super::scene::{Scene, SurfaceKind};
use super::texture::unit_hash;
use super::trajectory::{look_at, random_flight};

/// A scene, a camera, and the stereo pairs taken along a flight through it.
#[derive(Clone)]
pub struct Scenario {
    /// `wall` or `random`.
    pub name: &'static str,
    /// The world.
    pub scene: Scene,
    /// The camera.
    pub intrinsics: PinholeIntrinsics,
    /// Stereo pairs as (reference, other) `world_from_camera` poses, in flight order.
    pub pairs: Vec<(Isometry3<f64>, Isometry3<f64>)>,
    /// Named phases of the flight as ranges of pair indices (the wall scenario's `strafe` and
    /// `recede`; the random scenario has one phase, `flight`).
    pub phases: Vec<(&'static str, std::ops::Range<usize>)>,
    /// Farthest distance the cameras and maps consider, metres.
    pub max_range: f64,
    /// The x/y box `[[x_min, y_min], [x_max, y_max]]` that figures of the scenario show.
    pub extent: [[f64; 2]; 2],
    /// The heights (low, high) that figures colour occupied voxels between; top-down figures
    /// leave out what lies below the low one (the ground).
    pub heights: [f64; 2],
    /// Altitudes (low, high) of the starts and goals of planned flights, metres.
    pub flight_altitude: (f64, f64),
    /// Straight-line distances (shortest, longest) between a flight's start and goal, metres.
    pub flight_distance: (f64, f64),
}

impl Scenario {
    /// Renders pair `index` (reference view first) with the sensor noise of `seed`: the views
    /// that the experiment runner and the exported frames share. `None` past the last pair.
    pub fn render_pair(&self, index: usize, seed: u64) -> Option<[RenderedFrame; 2]> {
        let (reference, other) = self.pairs.get(index)?;
        let noise = seed.wrapping_mul(1_000_003).wrapping_add(index as u64);
        let view = |pose: &Isometry3<f64>, side: u64| {
            render(
                &self.scene,
                &self.intrinsics,
                pose,
                noise.wrapping_mul(2).wrapping_add(side),
                self.max_range * 4.0,
            )
        };
        let (a, b) = rayon::join(|| view(reference, 0), || view(other, 1));
        Some([a, b])
    }
}

/// The camera of both scenarios: 320 × 240 pixels, 60° horizontal field of view.
pub fn camera() -> Result<PinholeIntrinsics> {
    let f = 160.0 / (30f64.to_radians()).tan();
    PinholeIntrinsics::new(320, 240, f, f, 159.5, 119.5)
}

/// The wall scenario: a 30 m × 8 m textured wall 12 m ahead over flat ground (every face of
/// the wall and the ground lies 1.3 cm off the voxel grids of 5, 10 and 20 cm, so that no
/// surface coincides with a voxel face and counts on both sides of it). Six strafe pairs move sideways along the wall looking at it
/// (0.4 m baseline: good stereo geometry); then six receding pairs move straight back from it,
/// looking nearly level at it (0.4 m along the view: poor geometry, where monocular depth is
/// least certain).
pub fn wall() -> Result<Scenario> {
    let mut scene = Scene::new();
    scene.add_ground(0.013, 400.0).add_box(
        Point3::new(12.263, 0.013, 4.013),
        Vector3::new(0.25, 15.0, 4.0),
        0.0,
        SurfaceKind::Wall,
    );
    let look = Vector3::new(1.0, 0.0, -0.03);
    let mut pairs = Vec::new();
    for i in 0..6 {
        let y = -3.0 + 1.0 * f64::from(i);
        let a = look_at(Point3::new(0.0, y, 2.0), look);
        let b = look_at(Point3::new(0.0, y + 0.4, 2.0), look);
        pairs.push((b, a));
    }
    for i in 0..6 {
        let x = -1.0 - 1.0 * f64::from(i);
        let a = look_at(Point3::new(x, 0.5, 2.0), look);
        let b = look_at(Point3::new(x - 0.4, 0.5, 2.0), look);
        pairs.push((b, a));
    }
    Ok(Scenario {
        name: "wall",
        scene,
        intrinsics: camera()?,
        pairs,
        phases: vec![("strafe", 0..6), ("recede", 6..12)],
        max_range: 40.0,
        extent: [[-8.0, -16.0], [20.0, 16.0]],
        heights: [0.3, 8.0],
        flight_altitude: (0.8, 3.5),
        flight_distance: (3.0, 15.0),
    })
}

/// The random-flight scenario: 120 m × 120 m of flat ground with buildings (boxes 6–16 m wide,
/// 5–25 m tall, any heading) and trees, flown over at 4–20 m along random legs that keep 1.5 m
/// from every object, looking in random directions; each pair is two consecutive poses 0.6 m
/// apart. Deterministic for a seed.
pub fn random(pairs: usize, seed: u64) -> Result<Scenario> {
    let mut scene = Scene::new();
    scene.add_ground(0.013, 600.0);
    let mut n = 0i64;
    let mut uniform = |lo: f64, hi: f64| {
        n += 1;
        lo + (hi - lo) * f64::from(unit_hash(n, 1, 2, seed))
    };
    for _ in 0..14 {
        let center = Point3::new(uniform(-60.0, 60.0), uniform(-60.0, 60.0), 0.0);
        let (w, d, h) = (uniform(3.0, 8.0), uniform(3.0, 8.0), uniform(2.5, 12.5));
        scene.add_box(
            Point3::new(center.x, center.y, h),
            Vector3::new(w, d, h),
            uniform(0.0, std::f64::consts::PI),
            SurfaceKind::Building,
        );
    }
    for _ in 0..40 {
        let base = Point3::new(uniform(-60.0, 60.0), uniform(-60.0, 60.0), 0.013);
        let height = uniform(2.0, 5.0);
        scene.add_tree(base, uniform(0.15, 0.4), height, uniform(1.0, 2.5));
    }
    // Legs keep 1.5 m from every object.
    let clear = |a: &Point3<f64>, b: &Point3<f64>| !scene.intersects_swept_ball(a, b, 1.5);
    let poses = random_flight(
        seed,
        Point3::new(-45.0, -45.0, 4.0),
        Point3::new(45.0, 45.0, 20.0),
        0.6,
        pairs + 1,
        &clear,
    );
    let pairs_list: Vec<_> = poses.windows(2).map(|w| (w[1], w[0])).collect();
    Ok(Scenario {
        name: "random",
        scene,
        intrinsics: camera()?,
        phases: vec![("flight", 0..pairs_list.len())],
        pairs: pairs_list,
        max_range: 60.0,
        extent: [[-65.0, -65.0], [65.0, 65.0]],
        heights: [0.3, 25.0],
        flight_altitude: (1.0, 20.0),
        flight_distance: (6.0, 25.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenarios_have_their_pairs_and_are_deterministic() {
        let w = wall().unwrap();
        assert_eq!(w.pairs.len(), 12);
        assert_eq!(w.phases[1], ("recede", 6..12));
        let a = random(50, 3).unwrap();
        let b = random(50, 3).unwrap();
        assert_eq!(a.pairs.len(), 50);
        assert_eq!(a.pairs, b.pairs);
        assert_eq!(a.scene.len(), b.scene.len());
        let origin = a.pairs[0].0.translation.vector.into();
        let down = -Vector3::z();
        assert_eq!(
            a.scene.cast_ray(&origin, &down, 100.0).map(|h| h.distance),
            b.scene.cast_ray(&origin, &down, 100.0).map(|h| h.distance)
        );
        assert_ne!(random(50, 4).unwrap().pairs, a.pairs);
        // No camera flies inside or next to an object.
        for seed in [1, 5] {
            let s = random(100, seed).unwrap();
            for (pose, _) in &s.pairs {
                let p = pose.translation.vector.into();
                assert!(s.scene.distance_to_surface(&p) >= 1.4, "seed {seed}: {p}");
            }
        }
    }
}
