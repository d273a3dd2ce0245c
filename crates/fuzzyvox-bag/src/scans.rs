//! Point clouds of a recording as scans: every `PointCloud2` on a topic, carried into the map
//! frame by the TF tree at its stamp, seen from its sensor's origin.

use nalgebra::Point3;
use rayon::prelude::*;

use fuzzyvox_core::integrate::PointCloud;

use crate::error::{BagError, Result};
use crate::messages::{Message, PointCloud2, TfMessage};
use crate::pointcloud::cloud_points;
use crate::reader::{Bag, RawMessage};
use crate::tf::TfTree;

/// The TF topics: `/tf` (dynamic) and `/tf_static`.
pub const TF_TOPIC: &str = "/tf";
/// See [`TF_TOPIC`].
pub const TF_STATIC_TOPIC: &str = "/tf_static";

/// The scans of one cloud topic.
#[derive(Clone, Debug)]
pub struct BagScans {
    /// One scan per cloud, in the order of the clouds' stamps (recording order among equal
    /// stamps), points and origin in the map frame.
    pub scans: Vec<PointCloud>,
    /// Each scan's stamp, seconds.
    pub stamps: Vec<f64>,
    /// The clouds' own frame (of the first cloud).
    pub sensor_frame: String,
    /// Points dropped because a coordinate was not finite.
    pub dropped_points: usize,
}

/// Adds a TF message to `tree` when `message` is one (on `/tf` or `/tf_static`, of a TF type);
/// returns whether it was.
pub(crate) fn add_tf(tree: &mut TfTree, message: &RawMessage<'_>, index: usize) -> Result<bool> {
    let topic = message.connection.topic.as_str();
    let is_static = topic == TF_STATIC_TOPIC;
    if !(topic == TF_TOPIC || is_static) || !TfMessage::is_type(&message.connection.msg_type) {
        return Ok(false);
    }
    for t in &TfMessage::decode(message, index)?.transforms {
        tree.add(t, is_static);
    }
    Ok(true)
}

/// The types of topics, for "no such topic" errors: every topic whose type is one of `M`'s.
pub(crate) fn topics_of<M: Message>(bag: &Bag) -> Result<Vec<String>> {
    let mut topics: Vec<String> = Vec::new();
    bag.for_each_message(&mut |m| {
        if M::is_type(&m.connection.msg_type) && !topics.contains(&m.connection.topic) {
            topics.push(m.connection.topic.clone());
        }
        Ok(())
    })?;
    topics.sort();
    Ok(topics)
}

/// Reads every `PointCloud2` on `topic` and carries each into `frame` with the TF tree at the
/// cloud's stamp: its points become map coordinates and its sensor origin the scan's origin.
/// A cloud already in `frame` needs no transform (its origin is the frame's origin).
///
/// Errors: no cloud on `topic` (listing the cloud topics there are), a topic of another type, a
/// damaged message or cloud layout, a missing transform (naming the frames and the stamp).
/// Nothing is returned unless every cloud decodes and has its transform.
pub fn read_bag_scans(bag: &Bag, topic: &str, frame: &str) -> Result<BagScans> {
    let mut tree = TfTree::new();
    let mut clouds: Vec<(u64, usize, PointCloud2)> = Vec::new();
    let mut tf_index = 0;
    bag.for_each_message(&mut |m| {
        if add_tf(&mut tree, &m, tf_index)? {
            tf_index += 1;
            return Ok(());
        }
        if m.connection.topic != topic {
            return Ok(());
        }
        if !PointCloud2::is_type(&m.connection.msg_type) {
            return Err(BagError::WrongType {
                topic: topic.to_string(),
                found: m.connection.msg_type.clone(),
                expected: "sensor_msgs/PointCloud2",
            });
        }
        let index = clouds.len();
        clouds.push((m.log_time, index, PointCloud2::decode(&m, index)?));
        Ok(())
    })?;
    if clouds.is_empty() {
        return Err(BagError::UnknownTopic {
            topic: topic.to_string(),
            kind: "point cloud",
            available: topics_of::<PointCloud2>(bag)?,
        });
    }
    clouds.sort_by_key(|(_, index, cloud)| (cloud.header.stamp_ns, *index));
    let decoded: Vec<(PointCloud, f64, usize)> = clouds
        .par_iter()
        .map(|(_, index, cloud)| {
            let points = cloud_points(cloud).map_err(|detail| BagError::BadMessage {
                topic: topic.to_string(),
                msg_type: "sensor_msgs/PointCloud2".into(),
                index: *index,
                detail,
            })?;
            let header = &cloud.header;
            let world_from_sensor = tree.pose_of(frame, header)?;
            let world: Vec<Point3<f64>> = points
                .points
                .iter()
                .map(|p| world_from_sensor * p)
                .collect();
            let origin = Point3::from(world_from_sensor.translation.vector);
            Ok((
                PointCloud::new(origin, world)?,
                header.stamp_seconds(),
                points.dropped,
            ))
        })
        .collect::<Vec<Result<_>>>()
        .into_iter()
        // The first bad cloud in stamp order, whatever the threads did.
        .collect::<Result<_>>()?;
    let sensor_frame = clouds
        .first()
        .map(|(_, _, c)| c.header.frame_id.clone())
        .unwrap_or_default();
    let dropped_points = decoded.iter().map(|d| d.2).sum();
    let (scans, stamps) = decoded.into_iter().map(|(s, t, _)| (s, t)).unzip();
    Ok(BagScans {
        scans,
        stamps,
        sensor_frame,
        dropped_points,
    })
}
