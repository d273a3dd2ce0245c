//! What can go wrong with a recording, typed so that a caller can tell a damaged file from a
//! missing transform.

use std::path::PathBuf;

/// A recording could not be read, or its messages do not give what was asked for.
///
/// Nothing is written and no map changes when a call returns one of these: readers decode the
/// whole selection before they hand anything over.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BagError {
    /// The file or folder could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The path is neither a ROS 1 bag, an MCAP file nor a ROS 2 bag folder.
    #[error(
        "{path}: not a robot recording (expected a ROS 1 `.bag`, an `.mcap` file or a ROS 2 bag \
         folder with metadata.yaml)"
    )]
    NotABag {
        /// The path.
        path: PathBuf,
    },
    /// The recording is truncated or damaged.
    #[error("{path}: damaged recording: {detail}")]
    Damaged {
        /// The file.
        path: PathBuf,
        /// What is wrong, in words.
        detail: String,
    },
    /// The recording uses something this reader does not take (a storage plugin, a compression,
    /// a message encoding, a distortion model).
    #[error("{path}: {detail}")]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What, in words.
        detail: String,
    },
    /// No message on the topic asked for.
    #[error("no messages on topic `{topic}`; the recording's {kind} topics: {}", list(.available))]
    UnknownTopic {
        /// The topic asked for.
        topic: String,
        /// The kind of topic wanted ("point cloud", "image", "camera info").
        kind: &'static str,
        /// The topics of that kind the recording has.
        available: Vec<String>,
    },
    /// The topic carries another message type than the one asked for.
    #[error("topic `{topic}` carries {found}, not {expected}")]
    WrongType {
        /// The topic.
        topic: String,
        /// Its message type.
        found: String,
        /// The types wanted.
        expected: &'static str,
    },
    /// A message could not be decoded as its type.
    #[error("message {index} on `{topic}` ({msg_type}): {detail}")]
    BadMessage {
        /// The topic.
        topic: String,
        /// The message type.
        msg_type: String,
        /// The message's position on its topic, from 0.
        index: usize,
        /// What is wrong, in words.
        detail: String,
    },
    /// The TF tree does not carry the source frame into the target frame at that time.
    #[error("no transform from `{source_frame}` to `{target_frame}` at {stamp:.9} s: {detail}")]
    NoTransform {
        /// The frame of the data (a cloud's or an image's `header.frame_id`).
        source_frame: String,
        /// The frame asked for (`--frame`).
        target_frame: String,
        /// The data's stamp, seconds.
        stamp: f64,
        /// Why, in words (the frames there are, the times the edge covers).
        detail: String,
    },
    /// The decoded data was refused by the map or the depth stage.
    #[error(transparent)]
    Core(#[from] fuzzyvox_core::error::Error),
}

/// `a, b, c`, or `none` for an empty list.
fn list(items: &[String]) -> String {
    if items.is_empty() {
        "none".into()
    } else {
        items.join(", ")
    }
}

/// Results of this crate.
pub type Result<T> = std::result::Result<T, BagError>;
