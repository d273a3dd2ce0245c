//! ROS 2 bags stored as MCAP, through Foxglove's `mcap` crate (chunked or not, zstd or lz4
//! compressed chunks): one `.mcap` file, or a bag folder whose `metadata.yaml` lists them.

use std::path::{Path, PathBuf};

use rustc_hash::FxHashMap;
use serde::Deserialize;

use super::{Connection, Encoding, RawMessage};
use crate::error::{BagError, Result};

/// One MCAP file, read whole.
pub(super) struct McapFile {
    path: PathBuf,
    bytes: Vec<u8>,
}

impl std::fmt::Debug for McapFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapFile")
            .field("path", &self.path)
            .field("bytes", &self.bytes.len())
            .finish()
    }
}

/// The part of a ROS 2 bag's `metadata.yaml` the reader needs.
#[derive(Deserialize)]
struct Metadata {
    rosbag2_bagfile_information: BagfileInformation,
}

#[derive(Deserialize)]
struct BagfileInformation {
    storage_identifier: String,
    relative_file_paths: Vec<String>,
    #[serde(default)]
    compression_mode: Option<String>,
}

/// The MCAP files of a ROS 2 bag folder, in the order its `metadata.yaml` lists them.
pub(super) fn open_folder(dir: &Path) -> Result<Vec<McapFile>> {
    let path = dir.join("metadata.yaml");
    if !path.is_file() {
        return Err(BagError::NotABag {
            path: dir.to_path_buf(),
        });
    }
    let text = std::fs::read_to_string(&path).map_err(|source| BagError::Io {
        path: path.clone(),
        source,
    })?;
    let damaged = |detail: String| BagError::Damaged {
        path: path.clone(),
        detail,
    };
    let metadata: Metadata = serde_yaml_ng::from_str(&text).map_err(|e| damaged(e.to_string()))?;
    let info = metadata.rosbag2_bagfile_information;
    let unsupported = |detail: String| BagError::Unsupported {
        path: path.clone(),
        detail,
    };
    if info.storage_identifier != "mcap" {
        return Err(unsupported(format!(
            "storage `{}`: fuzzyvox reads ROS 2 bags stored as MCAP (`ros2 bag convert` turns \
             a sqlite3 bag into one)",
            info.storage_identifier
        )));
    }
    if let Some(mode) = info
        .compression_mode
        .filter(|m| !m.is_empty() && m != "NONE")
    {
        return Err(unsupported(format!(
            "rosbag2 compression `{mode}` is not read (MCAP's own chunk compression is: record              with `--storage-preset-profile zstd_fast` instead, or decompress with `ros2 bag              convert`)"
        )));
    }
    if info.relative_file_paths.is_empty() {
        return Err(damaged("the bag lists no files".into()));
    }
    info.relative_file_paths
        .iter()
        .map(|name| McapFile::read(&dir.join(name)))
        .collect()
}

impl McapFile {
    /// Reads a whole file.
    pub(super) fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| BagError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self::from_bytes(path, bytes))
    }

    /// An MCAP file held in memory.
    pub(super) fn from_bytes(path: &Path, bytes: Vec<u8>) -> Self {
        Self {
            path: path.to_path_buf(),
            bytes,
        }
    }

    pub(super) fn for_each_message(
        &self,
        visit: &mut dyn FnMut(RawMessage<'_>) -> Result<()>,
    ) -> Result<()> {
        let damaged = |e: mcap::McapError| BagError::Damaged {
            path: self.path.clone(),
            detail: e.to_string(),
        };
        let mut connections: FxHashMap<u16, Connection> = FxHashMap::default();
        for message in mcap::MessageStream::new(&self.bytes).map_err(damaged)? {
            let message = message.map_err(damaged)?;
            let channel = &message.channel;
            let connection = match connections.entry(channel.id) {
                std::collections::hash_map::Entry::Occupied(entry) => entry.into_mut(),
                std::collections::hash_map::Entry::Vacant(entry) => {
                    let encoding = match channel.message_encoding.as_str() {
                        "cdr" => Encoding::Cdr,
                        "ros1" => Encoding::Ros1,
                        other => {
                            return Err(BagError::Unsupported {
                                path: self.path.clone(),
                                detail: format!(
                                    "topic `{}` has message encoding `{other}`; fuzzyvox reads \
                                     `cdr` (ROS 2) and `ros1`",
                                    channel.topic
                                ),
                            });
                        }
                    };
                    entry.insert(Connection {
                        topic: channel.topic.clone(),
                        msg_type: channel
                            .schema
                            .as_ref()
                            .map(|s| s.name.clone())
                            .unwrap_or_default(),
                        encoding,
                    })
                }
            };
            visit(RawMessage {
                connection,
                log_time: message.log_time,
                data: &message.data,
            })?;
        }
        Ok(())
    }
}
