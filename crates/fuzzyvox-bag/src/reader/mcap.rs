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

/// The longest record (or decompressed chunk) read from a file of `len` bytes: 64 times the
/// file or 256 MiB, whichever is more. Real chunks are a few MiB; a length beyond this is
/// damage, and is refused before anything is allocated for it.
fn record_limit(len: usize) -> usize {
    len.saturating_mul(64).max(256 << 20)
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

    /// Visits every message. `mcap`'s sans-io reader walks the file's records with a length
    /// limit ([`record_limit`]) and hands chunks over whole; each chunk is decompressed and
    /// checked here (size, CRC) and its records framed with checked lengths, then every record
    /// is parsed by `mcap`. (The crate's own chunk reader trusts the lengths inside a chunk: a
    /// damaged one overflows there.)
    pub(super) fn for_each_message(
        &self,
        visit: &mut dyn FnMut(RawMessage<'_>) -> Result<()>,
    ) -> Result<()> {
        use mcap::records::Record;
        use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

        let damaged = |detail: String| BagError::Damaged {
            path: self.path.clone(),
            detail,
        };
        let limit = record_limit(self.bytes.len());
        let options = LinearReaderOptions::default()
            .with_record_length_limit(limit)
            .with_emit_chunks(true);
        let mut reader = LinearReader::new_with_options(options);
        let mut rest: &[u8] = &self.bytes;
        let mut channels = Channels::default();
        while let Some(event) = reader.next_event() {
            match event.map_err(|e| damaged(e.to_string()))? {
                LinearReadEvent::ReadRequest(need) => {
                    let (now, later) = rest.split_at(need.min(rest.len()));
                    reader.insert(now.len()).copy_from_slice(now);
                    reader.notify_read(now.len());
                    rest = later;
                }
                LinearReadEvent::Record { data, opcode } => {
                    match mcap::parse_record(opcode, data).map_err(|e| damaged(e.to_string()))? {
                        Record::Chunk { header, data } => {
                            let plain = chunk_content(&header, &data, limit).map_err(damaged)?;
                            let mut records: &[u8] = &plain;
                            while !records.is_empty() {
                                let (opcode, body, after) =
                                    split_record(records).map_err(damaged)?;
                                let record = mcap::parse_record(opcode, body)
                                    .map_err(|e| damaged(e.to_string()))?;
                                channels.take(record, &self.path, visit)?;
                                records = after;
                            }
                        }
                        record => channels.take(record, &self.path, visit)?,
                    }
                }
            }
        }
        Ok(())
    }
}

/// The schemas and channels seen so far, by id.
#[derive(Default)]
struct Channels {
    schemas: FxHashMap<u16, String>,
    connections: FxHashMap<u16, Connection>,
}

impl Channels {
    /// Learns a schema or a channel, or hands a message to `visit`; other records are skipped.
    fn take(
        &mut self,
        record: mcap::records::Record<'_>,
        path: &Path,
        visit: &mut dyn FnMut(RawMessage<'_>) -> Result<()>,
    ) -> Result<()> {
        use mcap::records::Record;
        match record {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, header.name);
            }
            Record::Channel(channel) => {
                let encoding = match channel.message_encoding.as_str() {
                    "cdr" => Encoding::Cdr,
                    "ros1" => Encoding::Ros1,
                    other => {
                        return Err(BagError::Unsupported {
                            path: path.to_path_buf(),
                            detail: format!(
                                "topic `{}` has message encoding `{other}`; fuzzyvox reads \
                                 `cdr` (ROS 2) and `ros1`",
                                channel.topic
                            ),
                        });
                    }
                };
                let msg_type = self
                    .schemas
                    .get(&channel.schema_id)
                    .cloned()
                    .unwrap_or_default();
                self.connections.insert(
                    channel.id,
                    Connection {
                        topic: channel.topic,
                        msg_type,
                        encoding,
                    },
                );
            }
            Record::Message { header, data } => {
                let connection =
                    self.connections
                        .get(&header.channel_id)
                        .ok_or_else(|| BagError::Damaged {
                            path: path.to_path_buf(),
                            detail: format!(
                                "a message on channel {} before its channel record",
                                header.channel_id
                            ),
                        })?;
                visit(RawMessage {
                    connection,
                    log_time: header.log_time,
                    data: &data,
                })?;
            }
            _ => {}
        }
        Ok(())
    }
}

/// A chunk's records: its data decompressed (none, zstd or lz4, with the crates `mcap` uses),
/// checked against the chunk's uncompressed size (at most `limit`) and CRC.
fn chunk_content(
    header: &mcap::records::ChunkHeader,
    data: &[u8],
    limit: usize,
) -> std::result::Result<Vec<u8>, String> {
    let size = usize::try_from(header.uncompressed_size)
        .ok()
        .filter(|&size| size <= limit)
        .ok_or_else(|| {
            format!(
                "a chunk claims {} bytes uncompressed, more than this file can hold",
                header.uncompressed_size
            )
        })?;
    let plain = match header.compression.as_str() {
        "" => data.to_vec(),
        "zstd" => zstd::bulk::decompress(data, size).map_err(|e| format!("zstd chunk: {e}"))?,
        "lz4" => {
            use std::io::Read;
            let mut plain = Vec::with_capacity(size);
            lz4::Decoder::new(data)
                .and_then(|decoder| decoder.take(size as u64 + 1).read_to_end(&mut plain))
                .map_err(|e| format!("lz4 chunk: {e}"))?;
            plain
        }
        other => return Err(format!("chunk compression `{other}` is not zstd or lz4")),
    };
    if plain.len() != size {
        return Err(format!(
            "a chunk holds {} bytes uncompressed where its header says {size}",
            plain.len()
        ));
    }
    let crc = crc32fast::hash(&plain);
    if header.uncompressed_crc != 0 && crc != header.uncompressed_crc {
        return Err(format!(
            "a chunk's CRC is {crc:#010x} where its header says {:#010x}",
            header.uncompressed_crc
        ));
    }
    Ok(plain)
}

/// The first record of `bytes` (opcode, `u64` length, body) and the bytes after it.
fn split_record(bytes: &[u8]) -> std::result::Result<(u8, &[u8], &[u8]), String> {
    let (&opcode, rest) = bytes
        .split_first()
        .ok_or_else(|| "an empty record".to_string())?;
    let (len, rest) = rest
        .split_first_chunk::<8>()
        .ok_or_else(|| "a record cut inside its length".to_string())?;
    let len = u64::from_le_bytes(*len);
    usize::try_from(len)
        .ok()
        .and_then(|len| rest.split_at_checked(len))
        .map(|(body, after)| (opcode, body, after))
        .ok_or_else(|| format!("a record of {len} bytes in a chunk of {} bytes", rest.len()))
}
