//! One scan of an OctoMap scan graph or log: a sensor pose and the points it measured.

use fuzzyvox_core::error::Result;
use fuzzyvox_core::geometry::validate_pose;
use fuzzyvox_core::integrate::PointCloud;
use nalgebra::{Isometry3, Point3};

/// One scan as OctoMap stores it: points in the sensor frame and the sensor's pose in the world.
///
/// Both [`read_scan_graph`](super::read_scan_graph) and [`read_scan_log`](super::read_scan_log)
/// validate the pose; points may be NaN or infinite (integration skips and counts them).
#[derive(Clone, Debug, PartialEq)]
pub struct ScanNode {
    /// The sensor's pose: maps points from the sensor frame into the world frame.
    pub world_from_sensor: Isometry3<f64>,
    /// The measured end points, in the sensor frame (metres).
    pub points_in_sensor: Vec<Point3<f64>>,
    /// The node's id: stored in `.graph` files, the 0-based scan index for logs.
    pub id: u32,
}

impl ScanNode {
    /// The scan as a world-frame [`PointCloud`] seen from the sensor position (the pose's
    /// translation), ready to integrate.
    ///
    /// The pose is checked again here because the fields are public and may have been edited.
    pub fn to_cloud(&self) -> Result<PointCloud> {
        validate_pose(&self.world_from_sensor)?;
        let points = self
            .points_in_sensor
            .iter()
            .map(|p| self.world_from_sensor * p)
            .collect();
        PointCloud::new(
            Point3::from(self.world_from_sensor.translation.vector),
            points,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn cloud_is_in_the_world_frame() {
        let node = ScanNode {
            world_from_sensor: Isometry3::from_parts(
                Translation3::new(1.0, 2.0, 3.0),
                UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            ),
            points_in_sensor: vec![Point3::new(1.0, 0.0, 0.0), Point3::new(f64::NAN, 0.0, 0.0)],
            id: 4,
        };
        let cloud = node.to_cloud().unwrap();
        assert_eq!(cloud.origin(), Point3::new(1.0, 2.0, 3.0));
        let p = cloud.points()[0];
        assert!((p - Point3::new(1.0, 3.0, 3.0)).norm() < 1e-12, "{p}");
        assert!(cloud.points()[1].x.is_nan());

        let mut broken = node;
        broken.world_from_sensor.translation.vector.y = f64::NAN;
        assert!(broken.to_cloud().is_err());
    }
}
