//! Polylines and headings: advancing along a path, the point ahead, turning at a limited rate.

use nalgebra::{Point3, Vector3};

/// Moves `step` metres along `path` (its first point is the vehicle) and returns the new
/// position; the path loses the waypoints passed and starts at the new position.
pub(super) fn advance(path: &mut Vec<Point3<f64>>, step: f64) -> Point3<f64> {
    let mut left = step;
    while path.len() >= 2 {
        let (a, b) = (path[0], path[1]);
        let leg = (b - a).norm();
        if leg > left {
            let p = a + (b - a) * (left / leg);
            path[0] = p;
            return p;
        }
        left -= leg;
        path.remove(0);
    }
    path.first().copied().unwrap_or(Point3::origin())
}

/// The point `distance` metres along `path` (its end when the path is shorter; paths from the
/// planner are never empty).
pub(super) fn point_ahead(path: &[Point3<f64>], distance: f64) -> Point3<f64> {
    let mut left = distance;
    for pair in path.windows(2) {
        let leg = (pair[1] - pair[0]).norm();
        if leg >= left {
            return pair[0] + (pair[1] - pair[0]) * (left / leg.max(1e-12));
        }
        left -= leg;
    }
    path.last().copied().unwrap_or(Point3::origin())
}

/// `from` turned about the vertical towards `to` (both level unit vectors) by at most `max`
/// radians (`to` itself when it is that near).
pub(super) fn turn_towards(from: Vector3<f64>, to: Vector3<f64>, max: f64) -> Vector3<f64> {
    let angle = from.x.mul_add(to.y, -(from.y * to.x)).atan2(from.dot(&to));
    if angle.abs() <= max {
        return to;
    }
    let turn = angle.clamp(-max, max);
    let (sin, cos) = turn.sin_cos();
    Vector3::new(
        from.x * cos - from.y * sin,
        from.x * sin + from.y * cos,
        0.0,
    )
}

/// The horizontal part of `v`, normalised; `None` when it is (nearly) vertical.
pub(super) fn level(v: Vector3<f64>) -> Option<Vector3<f64>> {
    Vector3::new(v.x, v.y, 0.0).try_normalize(1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advancing_follows_the_polyline() {
        let mut path = vec![
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(1.0, 0.0, 1.0),
            Point3::new(1.0, 2.0, 1.0),
        ];
        let p = advance(&mut path, 0.5);
        assert_eq!(p, Point3::new(0.5, 0.0, 1.0));
        let p = advance(&mut path, 1.0);
        assert!((p - Point3::new(1.0, 0.5, 1.0)).norm() < 1e-12);
        assert_eq!(path.len(), 2);
        let p = advance(&mut path, 5.0);
        assert_eq!(p, Point3::new(1.0, 2.0, 1.0));
        assert_eq!(point_ahead(&[Point3::origin()], 3.0), Point3::origin());
    }

    #[test]
    fn the_camera_turns_at_most_its_rate() {
        let (x, y) = (Vector3::x(), Vector3::y());
        let max = 22.5f64.to_radians();
        // A quarter turn to the left takes four frames, the first one 22.5° of it.
        let first = turn_towards(x, y, max);
        assert!((first.y.atan2(first.x) - max).abs() < 1e-12, "{first:?}");
        // To the right as well; a small turn is made at once.
        let right = turn_towards(x, -y, max);
        assert!((right.y.atan2(right.x) + max).abs() < 1e-12, "{right:?}");
        let small = Vector3::new(1.0, 0.1, 0.0).normalize();
        assert!((turn_towards(x, small, max) - small).norm() < 1e-12);
        assert!((turn_towards(x, x, max) - x).norm() < 1e-15);
    }
}
