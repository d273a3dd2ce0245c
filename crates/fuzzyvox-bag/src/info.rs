//! What a recording holds, as `rosbag info` and `ros2 bag info` tell it: its topics with their
//! types and message counts, its time span, and the frames of its TF tree.

use serde::Serialize;

use crate::error::Result;
use crate::reader::Bag;
use crate::scans::add_tf;
use crate::tf::{TfEdge, TfTree};

/// One topic and type with its message count. A topic recorded with two types (ROS 1's
/// `tf/tfMessage` beside `tf2_msgs/TFMessage`, say) has one entry per type.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct TopicInfo {
    /// The topic.
    pub name: String,
    /// The message type as recorded.
    #[serde(rename = "type")]
    pub msg_type: String,
    /// Messages.
    pub count: usize,
}

/// A recording's summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BagInfo {
    /// `ros1` or `ros2`.
    pub format: &'static str,
    /// Topics by name, then type.
    pub topics: Vec<TopicInfo>,
    /// All messages.
    pub message_count: usize,
    /// The first and last receive times, nanoseconds since the epoch (0 without messages).
    pub start_ns: u64,
    /// See `start_ns`.
    pub end_ns: u64,
    /// `end - start`, seconds.
    pub duration_s: f64,
    /// Every edge of the TF tree (`/tf` and `/tf_static`).
    pub tf: Vec<TfEdge>,
    /// TF transforms skipped because they were not rigid.
    pub tf_invalid: usize,
}

impl BagInfo {
    /// Reads every message of `bag` once; TF messages are decoded, others only counted.
    pub fn of(bag: &Bag) -> Result<Self> {
        let mut topics: Vec<TopicInfo> = Vec::new();
        let mut tree = TfTree::new();
        let (mut start, mut end, mut count) = (u64::MAX, 0, 0);
        let mut tf_index = 0;
        bag.for_each_message(&mut |m| {
            count += 1;
            start = start.min(m.log_time);
            end = end.max(m.log_time);
            let c = m.connection;
            match topics
                .iter_mut()
                .find(|t| t.name == c.topic && t.msg_type == c.msg_type)
            {
                Some(t) => t.count += 1,
                None => topics.push(TopicInfo {
                    name: c.topic.clone(),
                    msg_type: c.msg_type.clone(),
                    count: 1,
                }),
            }
            if add_tf(&mut tree, &m, tf_index)? {
                tf_index += 1;
            }
            Ok(())
        })?;
        topics.sort_by(|a, b| (&a.name, &a.msg_type).cmp(&(&b.name, &b.msg_type)));
        if count == 0 {
            start = 0;
        }
        Ok(Self {
            format: bag.format().name(),
            topics,
            message_count: count,
            start_ns: start,
            end_ns: end,
            duration_s: end.saturating_sub(start) as f64 * 1e-9,
            tf: tree.edges(),
            tf_invalid: tree.invalid(),
        })
    }
}
