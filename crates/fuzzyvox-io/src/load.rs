//! Opening a map whatever format its file holds: fuzzyvox's own maps, and OctoMap's `.bt` and
//! `.ot` trees as read-only maps. The format is told by the file's first bytes, not its name.

use std::io::Read;
use std::path::Path;

use fuzzyvox_core::error::{Error, FormatError, Result};
use fuzzyvox_core::file::{MAGIC, MapHeader};
use fuzzyvox_core::map::{AnyMap, VoxelMap};

use super::octomap::{OcTreeMap, OctreeFormat};

/// The first line of OctoMap's binary trees (`.bt`) and full trees (`.ot`).
const BT_FIRST_LINE: &[u8] = b"# Octomap OcTree binary file";
const OT_FIRST_LINE: &[u8] = b"# Octomap OcTree file";

/// A map read from any format fuzzyvox reads.
#[derive(Clone, Debug)]
pub enum LoadedMap {
    /// A fuzzyvox map file (`.fvx`): fuzzy, log-odds or alpha-cut.
    Native {
        /// The file's header (format version, kind, operator).
        header: MapHeader,
        /// The map.
        map: AnyMap,
    },
    /// An OctoMap tree (`.bt` or `.ot`), read-only.
    OctoMap(OcTreeMap),
}

impl LoadedMap {
    /// The map through the interface every map implements.
    pub fn as_map(&self) -> &dyn VoxelMap {
        match self {
            Self::Native { map, .. } => map.as_map(),
            Self::OctoMap(tree) => tree,
        }
    }

    /// What the file holds: `fuzzy`, `logodds` or `alpha` for fuzzyvox maps, `octomap-bt` or
    /// `octomap-ot` for OctoMap trees.
    pub fn model_name(&self) -> &'static str {
        match self {
            Self::Native { header, .. } => header.kind.name(),
            Self::OctoMap(tree) => tree.format().name(),
        }
    }

    /// The fuzzyvox map, when the file held one.
    pub fn native(&self) -> Option<&AnyMap> {
        match self {
            Self::Native { map, .. } => Some(map),
            Self::OctoMap(_) => None,
        }
    }
}

/// Which format a file's first bytes announce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapFormat {
    /// A fuzzyvox map file (`.fvx`).
    Native,
    /// An OctoMap tree, binary (`.bt`) or full (`.ot`).
    OctoMap(OctreeFormat),
}

impl MapFormat {
    /// Tells the format from a file's first bytes (28 are enough), or `None` when they match
    /// none that fuzzyvox reads.
    pub fn sniff(start: &[u8]) -> Option<Self> {
        if start.starts_with(MAGIC) {
            Some(Self::Native)
        } else if start.starts_with(BT_FIRST_LINE) {
            Some(Self::OctoMap(OctreeFormat::Binary))
        } else if start.starts_with(OT_FIRST_LINE) {
            Some(Self::OctoMap(OctreeFormat::Full))
        } else {
            None
        }
    }
}

/// Opens a map of any format fuzzyvox reads, chosen by the file's content: a fuzzyvox map, an
/// OctoMap `.bt` or an OctoMap `.ot`. Anything else is a [`FormatError::UnknownMapFormat`].
///
/// ```no_run
/// use fuzzyvox_io::load_map;
///
/// let map = load_map("geb079.bt".as_ref())?;
/// println!("{}: {} occupied voxels", map.model_name(), map.as_map().counts().occupied);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
pub fn load_map(path: &Path) -> Result<LoadedMap> {
    let mut start = Vec::with_capacity(32);
    std::fs::File::open(path)
        .and_then(|f| f.take(32).read_to_end(&mut start))
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
    match MapFormat::sniff(&start) {
        Some(MapFormat::Native) => {
            let (header, map) = AnyMap::load_with_header(path)?;
            Ok(LoadedMap::Native { header, map })
        }
        Some(MapFormat::OctoMap(_)) => Ok(LoadedMap::OctoMap(OcTreeMap::read(path)?)),
        None => Err(Error::Format {
            path: path.to_path_buf(),
            reason: FormatError::UnknownMapFormat,
        }),
    }
}
