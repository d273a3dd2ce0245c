//! Robot recordings as fuzzyvox input: ROS 1 bags and ROS 2 bags stored as MCAP.
//!
//! - [`Bag`] opens a recording (a ROS 1 `.bag`, an `.mcap` file or a ROS 2 bag folder with its
//!   `metadata.yaml`) and visits its messages;
//! - [`BagInfo`] summarises it as `rosbag info` does: topics, types, counts, time span, the TF
//!   tree;
//! - [`read_bag_scans`] turns the `sensor_msgs/PointCloud2` messages of a topic into scans in
//!   a map frame, each from its sensor's origin, with the poses of the TF tree ([`TfTree`]) at
//!   each cloud's stamp;
//! - [`BagFrames`] gives the colour images of a topic, with their camera's intrinsics and
//!   poses, to the one-camera depth stage.
//!
//! The containers are read by maintained crates (Foxglove's `mcap`, `rosbag`), the messages by
//! serde decoders of both wire formats (`cdr-encoding` for ROS 2, `roslibrust_serde_rosmsg`
//! for ROS 1). Every failure is a typed [`BagError`]; nothing is handed over unless the whole
//! selection decoded.

#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod error;
mod frames;
mod info;
pub mod messages;
mod pointcloud;
mod reader;
mod scans;
mod tf;

pub use error::{BagError, Result};
pub use frames::BagFrames;
pub use info::{BagInfo, TopicInfo};
pub use pointcloud::{CloudPoints, cloud_points};
pub use reader::{Bag, BagFormat, Connection, Encoding, RawMessage};
pub use scans::{BagScans, TF_STATIC_TOPIC, TF_TOPIC, read_bag_scans};
pub use tf::{TfEdge, TfTree};
