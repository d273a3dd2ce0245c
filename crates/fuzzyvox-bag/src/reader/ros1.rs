//! ROS 1 bags (format 2.0) through the `rosbag` crate: chunks (uncompressed, bz2 or lz4), the
//! connection records inside them, and their message records.

use std::path::{Path, PathBuf};

use rosbag::{ChunkRecord, MessageRecord, RosBag};
use rustc_hash::FxHashMap;

use super::{Connection, Encoding, ROS1_MAGIC, RawMessage};
use crate::error::{BagError, Result};

/// An opened ROS 1 bag (memory-mapped by `rosbag`).
pub(super) struct Ros1Bag {
    path: PathBuf,
    bag: RosBag,
}

impl std::fmt::Debug for Ros1Bag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros1Bag").field("path", &self.path).finish()
    }
}

impl Ros1Bag {
    /// Opens `path` after checking that its header's index position lies inside the file (a
    /// truncated bag, or one whose recording never finished, has it wrong).
    pub(super) fn open(path: &Path) -> Result<Self> {
        let io = |source| BagError::Io {
            path: path.to_path_buf(),
            source,
        };
        let damaged = |detail: String| BagError::Damaged {
            path: path.to_path_buf(),
            detail,
        };
        let len = std::fs::metadata(path).map_err(io)?.len();
        let (start, index_pos) = {
            use std::io::Read;
            let mut head = Vec::new();
            std::fs::File::open(path)
                .map_err(io)?
                .take(1 << 16)
                .read_to_end(&mut head)
                .map_err(io)?;
            header_positions(&head).ok_or_else(|| damaged("unreadable bag header record".into()))?
        };
        if index_pos < start || index_pos > len {
            return Err(damaged(format!(
                "the header puts the index at byte {index_pos}, outside the file's {start} to \
                 {len} (a truncated bag, or one whose recording did not finish: `rosbag reindex` \
                 repairs the latter)"
            )));
        }
        let bag = RosBag::new(path).map_err(|e| damaged(e.to_string()))?;
        // The index section (connections, chunk infos) must read whole too: a cut there means a
        // damaged copy even when the chunks before it survived.
        for record in bag.index_records() {
            record.map_err(|e| damaged(format!("index section: {e}")))?;
        }
        Ok(Self {
            path: path.to_path_buf(),
            bag,
        })
    }

    pub(super) fn for_each_message(
        &self,
        visit: &mut dyn FnMut(RawMessage<'_>) -> Result<()>,
    ) -> Result<()> {
        let damaged = |e: rosbag::Error| BagError::Damaged {
            path: self.path.clone(),
            detail: e.to_string(),
        };
        let mut connections: FxHashMap<u32, Connection> = FxHashMap::default();
        for record in self.bag.chunk_records() {
            let ChunkRecord::Chunk(chunk) = record.map_err(damaged)? else {
                continue;
            };
            for message in chunk.messages() {
                match message.map_err(damaged)? {
                    MessageRecord::Connection(c) => {
                        connections.insert(
                            c.id,
                            Connection {
                                topic: c.topic.to_string(),
                                msg_type: c.tp.to_string(),
                                encoding: Encoding::Ros1,
                            },
                        );
                    }
                    MessageRecord::MessageData(m) => {
                        let connection =
                            connections
                                .get(&m.conn_id)
                                .ok_or_else(|| BagError::Damaged {
                                    path: self.path.clone(),
                                    detail: format!(
                                        "a message on connection {} before its connection record",
                                        m.conn_id
                                    ),
                                })?;
                        visit(RawMessage {
                            connection,
                            log_time: m.time,
                            data: m.data,
                        })?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Where the records start and where the header says the index is: the magic, then the bag
/// header record (`u32` header length, `name=value` fields each behind a `u32` length, `u32`
/// data length, padding). `None` when the bytes do not hold a whole header record.
fn header_positions(bytes: &[u8]) -> Option<(u64, u64)> {
    let rest = bytes.strip_prefix(ROS1_MAGIC)?;
    let (header_len, rest) = split_u32(rest)?;
    let (mut fields, rest) = rest.split_at_checked(header_len as usize)?;
    let (data_len, _) = split_u32(rest)?;
    let mut index_pos = None;
    while !fields.is_empty() {
        let (field_len, rest) = split_u32(fields)?;
        let (field, rest) = rest.split_at_checked(field_len as usize)?;
        if let Some(value) = field.strip_prefix(b"index_pos=") {
            index_pos = Some(u64::from_le_bytes(value.try_into().ok()?));
        }
        fields = rest;
    }
    let start = ROS1_MAGIC.len() as u64 + 4 + u64::from(header_len) + 4 + u64::from(data_len);
    Some((start, index_pos?))
}

/// A little-endian `u32` and the bytes after it.
fn split_u32(bytes: &[u8]) -> Option<(u32, &[u8])> {
    let (head, rest) = bytes.split_first_chunk::<4>()?;
    Some((u32::from_le_bytes(*head), rest))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(fields: &[&[u8]], data_len: u32) -> Vec<u8> {
        let mut body = Vec::new();
        for f in fields {
            body.extend((f.len() as u32).to_le_bytes());
            body.extend(*f);
        }
        let mut bytes = ROS1_MAGIC.to_vec();
        bytes.extend((body.len() as u32).to_le_bytes());
        bytes.extend(body);
        bytes.extend(data_len.to_le_bytes());
        bytes
    }

    #[test]
    fn the_header_gives_the_start_of_the_records_and_the_index() {
        let mut index = b"index_pos=".to_vec();
        index.extend(5000u64.to_le_bytes());
        let bytes = header(&[b"op=\x03", &index], 4000);
        let (start, at) = header_positions(&bytes).unwrap();
        assert_eq!(at, 5000);
        assert_eq!(start, bytes.len() as u64 + 4000);
        // A cut header, a field longer than the header, no index: none.
        assert_eq!(header_positions(&bytes[..20]), None);
        assert_eq!(header_positions(&header(&[b"op=\x03"], 0)), None);
        let mut bad = header(&[&index], 0);
        bad[13] = 200;
        assert_eq!(header_positions(&bad), None);
    }
}
