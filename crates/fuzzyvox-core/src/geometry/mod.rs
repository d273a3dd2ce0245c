//! Cameras and poses.
//!
//! Conventions: metres and radians; world frame right-handed with z up; camera frame x right,
//! y down, z forward (OpenCV). Poses are named by the frames they map between, so that
//! `world_from_camera * point_in_camera` reads correctly.

mod intrinsics;
mod pose;

pub use intrinsics::PinholeIntrinsics;
pub use pose::{pose_from_matrix, validate_pose};
