//! Camera paths: strafing along a wall, receding from it, and random flights.

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// The camera pose at `position` looking along `forward` (any length), with the image's x axis
/// horizontal (camera x right, y down, z forward; world z up). A vertical `forward` uses the
/// world x axis as "right".
pub fn look_at(position: Point3<f64>, forward: Vector3<f64>) -> Isometry3<f64> {
    let z = forward.try_normalize(1e-12).unwrap_or_else(Vector3::x);
    let x = z
        .cross(&Vector3::z())
        .try_normalize(1e-9)
        .unwrap_or_else(Vector3::x);
    let y = z.cross(&x);
    let rotation = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
    Isometry3::from_parts(
        Translation3::from(position.coords),
        UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

/// `count` poses moving sideways by `step` metres along `along`, all looking along `forward`:
/// the motion that gives stereo its best geometry.
pub fn strafe(
    start: Point3<f64>,
    along: Vector3<f64>,
    forward: Vector3<f64>,
    step: f64,
    count: usize,
) -> Vec<Isometry3<f64>> {
    let along = along.try_normalize(1e-12).unwrap_or_else(Vector3::y);
    (0..count)
        .map(|i| look_at(start + along * (step * i as f64), forward))
        .collect()
}

/// `count` poses moving backwards by `step` metres along the look direction: motion along
/// the view, the poorest geometry for stereo.
pub fn recede(
    start: Point3<f64>,
    forward: Vector3<f64>,
    step: f64,
    count: usize,
) -> Vec<Isometry3<f64>> {
    let back = -forward.try_normalize(1e-12).unwrap_or_else(Vector3::x);
    (0..count)
        .map(|i| look_at(start + back * (step * i as f64), forward))
        .collect()
}

/// A seeded random flight: waypoints uniformly in the box `low`..`high`, flown in straight
/// legs of `step` metres, looking in a random direction (yaw uniform, pitch between -25° and
/// 5°) that turns slowly along each leg. `is_clear(a, b)` says whether the straight leg from
/// `a` to `b` is free to fly (`a == b` for a single point): the start and every waypoint are
/// drawn again until it holds (up to a thousand times each). Returns `count` poses.
pub fn random_flight(
    seed: u64,
    low: Point3<f64>,
    high: Point3<f64>,
    step: f64,
    count: usize,
    is_clear: &dyn Fn(&Point3<f64>, &Point3<f64>) -> bool,
) -> Vec<Isometry3<f64>> {
    let mut state = seed;
    let mut uniform = move |lo: f64, hi: f64| {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let h = super::texture::hash3(state as i64, 0, 0, seed);
        lo + (hi - lo) * ((h >> 11) as f64 / (1u64 << 53) as f64)
    };
    let point = |uniform: &mut dyn FnMut(f64, f64) -> f64| {
        Point3::new(
            uniform(low.x, high.x),
            uniform(low.y, high.y),
            uniform(low.z, high.z),
        )
    };
    let step = step.max(1e-3);
    let mut position = point(&mut uniform);
    for _ in 0..1000 {
        if is_clear(&position, &position) {
            break;
        }
        position = point(&mut uniform);
    }
    let mut yaw = uniform(0.0, std::f64::consts::TAU);
    let mut poses = Vec::with_capacity(count);
    while poses.len() < count {
        let mut target = point(&mut uniform);
        for _ in 0..1000 {
            if is_clear(&position, &target) {
                break;
            }
            target = point(&mut uniform);
        }
        let (next_yaw, pitch) = (
            uniform(0.0, std::f64::consts::TAU),
            uniform(-25f64.to_radians(), 5f64.to_radians()),
        );
        let leg = target - position;
        let steps = ((leg.norm() / step).ceil() as usize).max(1);
        for s in 0..steps {
            if poses.len() == count {
                break;
            }
            let t = s as f64 / steps as f64;
            let heading = yaw + t * wrap(next_yaw - yaw);
            let forward = Vector3::new(
                heading.cos() * pitch.cos(),
                heading.sin() * pitch.cos(),
                pitch.sin(),
            );
            poses.push(look_at(position + leg * t, forward));
        }
        position = target;
        yaw = next_yaw;
    }
    poses
}

/// An angle difference wrapped into (-π, π].
fn wrap(angle: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let a = angle.rem_euclid(tau);
    if a > std::f64::consts::PI { a - tau } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_follows_the_camera_convention() {
        let pose = look_at(Point3::origin(), Vector3::x());
        // Camera z forward = world x; camera x right = world -y; camera y down = world -z.
        assert!((pose.rotation * Vector3::z() - Vector3::x()).norm() < 1e-12);
        assert!((pose.rotation * Vector3::x() + Vector3::y()).norm() < 1e-12);
        assert!((pose.rotation * Vector3::y() + Vector3::z()).norm() < 1e-12);
        fuzzyvox_core::geometry::validate_pose(&look_at(Point3::origin(), Vector3::z())).unwrap();
    }

    #[test]
    fn paths_have_the_requested_shape() {
        let s = strafe(Point3::origin(), Vector3::y(), Vector3::x(), 0.5, 4);
        assert_eq!(s.len(), 4);
        assert!((s[3].translation.vector - Vector3::new(0.0, 1.5, 0.0)).norm() < 1e-12);
        let r = recede(Point3::origin(), Vector3::x(), 1.0, 3);
        assert!((r[2].translation.vector - Vector3::new(-2.0, 0.0, 0.0)).norm() < 1e-12);
        let low = Point3::new(-10.0, -10.0, 2.0);
        let high = Point3::new(10.0, 10.0, 8.0);
        let a = random_flight(5, low, high, 0.5, 200, &|_, _| true);
        assert_eq!(a.len(), 200);
        assert_eq!(a, random_flight(5, low, high, 0.5, 200, &|_, _| true));
        assert_ne!(a, random_flight(6, low, high, 0.5, 200, &|_, _| true));
        for p in &a {
            let t = p.translation.vector;
            assert!(t.x >= -10.0 && t.x <= 10.0 && t.z >= 2.0 && t.z <= 8.0);
        }
        // Legs that must stay in the half x >= 0 do.
        let east = |a: &Point3<f64>, b: &Point3<f64>| a.x >= 0.0 && b.x >= 0.0;
        let kept = random_flight(5, low, high, 0.5, 200, &east);
        assert!(kept.iter().all(|p| p.translation.vector.x >= 0.0));
    }
}
