//! Images and posed frames as the depth stage takes them, and the geometry of a rectified pair:
//! plain data that the file readers make and the depth stage consumes, kept here so that a
//! reader needs no depth stage.
//!
//! - [`GrayImage`]: one `f32` plane, `NaN` where a pixel has no value;
//! - [`Frame`]: a posed image of a stream;
//! - [`StereoGeometry`]: a rectified pair's cameras, from disparity to depth.

mod frame;
mod gray;
mod stereo;

pub use frame::Frame;
pub use gray::GrayImage;
pub use stereo::{MAX_DISPARITIES, MIN_BASELINE, StereoGeometry};
