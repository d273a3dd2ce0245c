//! Posed frames: an image with its camera, pose and time.

use nalgebra::{Isometry3, Vector3};

use super::gray::GrayImage;
use crate::error::{Error, Result};
use crate::geometry::{PinholeIntrinsics, validate_pose};

/// One posed image of the stream.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    image: GrayImage,
    intrinsics: PinholeIntrinsics,
    world_from_camera: Isometry3<f64>,
    timestamp: f64,
}

impl Frame {
    /// A frame: the image size must match the intrinsics, the pose be valid and the timestamp
    /// (seconds) finite.
    pub fn new(
        image: GrayImage,
        intrinsics: PinholeIntrinsics,
        world_from_camera: Isometry3<f64>,
        timestamp: f64,
    ) -> Result<Self> {
        validate_pose(&world_from_camera)?;
        crate::error::finite("timestamp", timestamp)?;
        if image.width() != intrinsics.width() || image.height() != intrinsics.height() {
            return Err(Error::SizeMismatch {
                what: "frame image pixels (intrinsics width × height)",
                expected: intrinsics.width() as usize * intrinsics.height() as usize,
                found: image.pixels().len(),
            });
        }
        Ok(Self {
            image,
            intrinsics,
            world_from_camera,
            timestamp,
        })
    }

    /// The image.
    pub fn image(&self) -> &GrayImage {
        &self.image
    }

    /// The camera.
    pub fn intrinsics(&self) -> &PinholeIntrinsics {
        &self.intrinsics
    }

    /// The pose.
    pub fn world_from_camera(&self) -> &Isometry3<f64> {
        &self.world_from_camera
    }

    /// Time (s).
    pub fn timestamp(&self) -> f64 {
        self.timestamp
    }

    /// Look direction (camera +z) in the world.
    pub fn look_direction(&self) -> Vector3<f64> {
        self.world_from_camera.rotation * Vector3::z()
    }
}
