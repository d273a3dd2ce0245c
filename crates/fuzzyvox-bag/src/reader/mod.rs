//! Opening a recording and visiting its messages, whatever its format: a ROS 1 bag
//! ([`ros1`], through the `rosbag` crate) or a ROS 2 bag stored as MCAP ([`mcap`], through
//! Foxglove's `mcap` crate), a single `.mcap` file or a bag folder with its `metadata.yaml`.

mod mcap;
mod ros1;

use std::path::{Path, PathBuf};

use crate::error::{BagError, Result};

/// How a message's bytes are serialised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// ROS 1 serialisation (little endian, no alignment).
    Ros1,
    /// OMG CDR with its 4-byte encapsulation header, as ROS 2 writes it.
    Cdr,
}

/// A topic and its message type as the recording names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Connection {
    /// The topic, e.g. `/camera/depth/points`.
    pub topic: String,
    /// The message type as written: `sensor_msgs/PointCloud2` in ROS 1,
    /// `sensor_msgs/msg/PointCloud2` in ROS 2.
    pub msg_type: String,
    /// How its messages are serialised.
    pub encoding: Encoding,
}

/// One message, borrowed for the duration of a visit.
#[derive(Clone, Copy, Debug)]
pub struct RawMessage<'a> {
    /// Its topic and type.
    pub connection: &'a Connection,
    /// When the recorder received it, nanoseconds since the epoch.
    pub log_time: u64,
    /// The serialised message.
    pub data: &'a [u8],
}

/// The formats [`Bag`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BagFormat {
    /// A ROS 1 bag (format 2.0).
    Ros1,
    /// A ROS 2 bag in MCAP files (a folder with `metadata.yaml`, or one `.mcap` file).
    Mcap,
}

impl BagFormat {
    /// `ros1` or `ros2`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ros1 => "ros1",
            Self::Mcap => "ros2",
        }
    }
}

/// An opened recording. Opening checks the container (magic, header, the files a folder
/// lists); messages are read and checked when visited.
#[derive(Debug)]
pub struct Bag {
    path: PathBuf,
    source: Source,
}

#[derive(Debug)]
enum Source {
    Ros1(ros1::Ros1Bag),
    Mcap(Vec<mcap::McapFile>),
}

/// The first bytes of a ROS 1 bag.
const ROS1_MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// The first bytes of an MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

impl Bag {
    /// Opens a ROS 1 `.bag`, an `.mcap` file or a ROS 2 bag folder, told apart by content.
    pub fn open(path: &Path) -> Result<Self> {
        let io = |source| BagError::Io {
            path: path.to_path_buf(),
            source,
        };
        let source = if path.is_dir() {
            Source::Mcap(mcap::open_folder(path)?)
        } else {
            let mut read = Vec::with_capacity(16);
            {
                use std::io::Read;
                let file = std::fs::File::open(path).map_err(io)?;
                file.take(16).read_to_end(&mut read).map_err(io)?;
            }
            if read.starts_with(ROS1_MAGIC) {
                Source::Ros1(ros1::Ros1Bag::open(path)?)
            } else if read.starts_with(MCAP_MAGIC) {
                Source::Mcap(vec![mcap::McapFile::read(path)?])
            } else {
                return Err(BagError::NotABag {
                    path: path.to_path_buf(),
                });
            }
        };
        Ok(Self {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads an MCAP recording held in memory (`name` stands for its path in errors).
    pub fn from_mcap_bytes(name: &Path, bytes: Vec<u8>) -> Result<Self> {
        if !bytes.starts_with(MCAP_MAGIC) {
            return Err(BagError::NotABag {
                path: name.to_path_buf(),
            });
        }
        Ok(Self {
            path: name.to_path_buf(),
            source: Source::Mcap(vec![mcap::McapFile::from_bytes(name, bytes)]),
        })
    }

    /// The path it was opened from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Its format.
    pub fn format(&self) -> BagFormat {
        match self.source {
            Source::Ros1(_) => BagFormat::Ros1,
            Source::Mcap(_) => BagFormat::Mcap,
        }
    }

    /// Calls `visit` with every message, in file order (files of a folder in the order its
    /// `metadata.yaml` lists them). Stops at the first error, of the file or of `visit`.
    pub fn for_each_message(
        &self,
        visit: &mut dyn FnMut(RawMessage<'_>) -> Result<()>,
    ) -> Result<()> {
        match &self.source {
            Source::Ros1(bag) => bag.for_each_message(visit),
            Source::Mcap(files) => files
                .iter()
                .try_for_each(|file| file.for_each_message(visit)),
        }
    }
}
