//! What a planned path is checked against: the obstacles of the true world, and the one path
//! check every experiment uses ([`path_collides`]).

use fuzzyvox_sim::Scene;
use nalgebra::Point3;

/// The true obstacles an experiment checks paths against and keeps starts and goals away from.
pub trait Obstacles: Sync {
    /// Distance from `point` to the nearest obstacle, metres (0 inside one).
    fn distance_to_surface(&self, point: &Point3<f64>) -> f64;
    /// Whether a ball of `radius` metres swept from `a` to `b` meets an obstacle.
    fn meets_swept_ball(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool;
}

/// A simulated scene's real geometry.
impl Obstacles for Scene {
    fn distance_to_surface(&self, point: &Point3<f64>) -> f64 {
        Scene::distance_to_surface(self, point)
    }

    fn meets_swept_ball(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool {
        self.intersects_swept_ball(a, b, radius)
    }
}

/// Whether a ball of `radius` swept along the path `waypoints` meets an obstacle of `world`
/// (a one-point path is checked as a ball at that point; an empty path meets nothing).
pub fn path_collides(world: &dyn Obstacles, waypoints: &[Point3<f64>], radius: f64) -> bool {
    match waypoints {
        [] => false,
        [only] => world.meets_swept_ball(only, only, radius),
        _ => waypoints
            .windows(2)
            .any(|w| world.meets_swept_ball(&w[0], &w[1], radius)),
    }
}
