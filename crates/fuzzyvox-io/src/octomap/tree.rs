//! OctoMap trees as read-only maps: every query, the cost field, the planner and the exporters
//! run on a robot's existing OctoMap without converting it.
//!
//! The tree is kept as compact as OctoMap keeps it, and more: pruned leaves (cubes of `2^k`
//! voxels per side that are all in one state) stay single nodes, never expanded into voxels.
//! Nodes live in two flat arrays, five bytes each:
//!
//! - `masks[i]`: bit `c` set when child `c` exists (0 for a leaf);
//! - `data[i]`: for an inner node, the index of its first child (its children are stored
//!   side by side, in child order); for a leaf, the bits of its log-odds (`f32`).
//!
//! A query descends at most 16 levels; child `c` of node `i` is `data[i] + popcount(masks[i]
//! & ((1 << c) - 1))`.

use std::path::Path;

use fuzzyvox_core::error::{Error, FormatError, Result};
use fuzzyvox_core::map::{LogOddsConfig, VoxelCounts, VoxelMap};
use fuzzyvox_core::measures::{MeasureConfig, Memberships};
use fuzzyvox_core::storage::{Resolution, VoxelKey};

use super::bt::{BtMap, FILE_HEADER as BT_HEADER, cube_keys};
use super::keys::{KEY_OFFSET, TREE_DEPTH, child_corner, voxel_key};
use super::leaf::OctreeLeaf;
use super::ot::{OT_HEADER, decode_ot};

/// Which OctoMap file a tree was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OctreeFormat {
    /// A max-likelihood binary tree (`.bt`): every leaf free or occupied, read at OctoMap's
    /// clamping probabilities (0.1192 and 0.971) as OctoMap reads it.
    Binary,
    /// A full tree (`.ot`) with a log-odds value per node.
    Full,
}

impl OctreeFormat {
    /// A short name: `octomap-bt` or `octomap-ot`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Binary => "octomap-bt",
            Self::Full => "octomap-ot",
        }
    }
}

/// A read-only map over an OctoMap tree (`.bt` or `.ot`, any tree depth).
///
/// Memberships are those of the log-odds map, `μO = p` and `μE = 1 - p` with `p` the leaf's
/// occupancy probability, so with the default measures a voxel is occupied exactly when
/// `p > 0.5`, free when `p < 0.5`, and unknown where the tree has no node, as in OctoMap.
/// Counts are those of finest-level voxels (a pruned leaf counts every voxel it covers).
///
/// ```no_run
/// use fuzzyvox_io::octomap::OcTreeMap;
/// use fuzzyvox_core::{VoxelClass, VoxelMap};
/// use nalgebra::Point3;
///
/// let map = OcTreeMap::read("geb079.bt".as_ref())?;
/// let counts = map.counts();
/// println!("{} occupied, {} free voxels", counts.occupied, counts.free);
/// let class = map.class_at_point(&Point3::new(0.0, 0.0, 1.0))?;
/// assert_ne!(class, VoxelClass::Ambiguous);
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
///
/// The map is read-only: it is no [`VoxelMapMut`](fuzzyvox_core::map::VoxelMapMut), so integrating
/// into it does not compile (start a fuzzy map from it with
/// [`FuzzyMap::add_prior`](fuzzyvox_core::FuzzyMap::add_prior) instead):
///
/// ```compile_fail
/// use fuzzyvox_io::octomap::OcTreeMap;
/// use fuzzyvox_core::{IntegrationOptions, PointCloud, VoxelMapMut};
///
/// fn integrate(map: &mut dyn VoxelMapMut, cloud: &PointCloud) {
///     map.integrate_cloud(cloud, &IntegrationOptions::default()).unwrap();
/// }
/// let mut map = OcTreeMap::decode(b"").unwrap();
/// let cloud = PointCloud::new(nalgebra::Point3::origin(), vec![]).unwrap();
/// integrate(&mut map, &cloud);
/// ```
#[derive(Clone, Debug)]
pub struct OcTreeMap {
    resolution: Resolution,
    measures: MeasureConfig,
    format: OctreeFormat,
    node_count: usize,
    leaf_count: usize,
    counts: VoxelCounts,
    masks: Vec<u8>,
    data: Vec<u32>,
}

impl OcTreeMap {
    /// Reads a `.bt` or `.ot` file, told apart by its first line, not by its name.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = crate::bounded::read_regular(path)?;
        Self::decode(&bytes).map_err(|reason| Error::Format {
            path: path.to_path_buf(),
            reason,
        })
    }

    /// Decodes the bytes of a `.bt` or `.ot` file.
    pub fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        if bytes.starts_with(BT_HEADER.as_bytes()) {
            Self::from_bt(&super::decode_bt(bytes)?)
        } else if bytes.starts_with(OT_HEADER.as_bytes()) {
            let tree = decode_ot(bytes)?;
            Self::from_leaves(
                OctreeFormat::Full,
                tree.resolution,
                tree.node_count,
                &tree.leaves,
            )
        } else {
            Err(FormatError::Invalid(format!(
                "not an OctoMap tree: the first line must be `{BT_HEADER}` (.bt) or \
                 `{OT_HEADER}` (.ot)"
            )))
        }
    }

    /// The map of a decoded `.bt` tree, its leaves at OctoMap's clamping log-odds.
    pub fn from_bt(bt: &BtMap) -> Result<Self, FormatError> {
        let defaults = LogOddsConfig::new(bt.resolution)
            .map_err(|e| FormatError::Invalid(format!("resolution {} m: {e}", bt.resolution)))?;
        let occupied = fuzzyvox_core::map::logodds_of(defaults.clamp_max);
        let free = fuzzyvox_core::map::logodds_of(defaults.clamp_min);
        let leaves: Vec<OctreeLeaf> = bt
            .leaves
            .iter()
            .map(|l| OctreeLeaf {
                key: l.key,
                depth: l.depth,
                log_odds: if l.occupied { occupied } else { free },
            })
            .collect();
        Self::from_leaves(OctreeFormat::Binary, bt.resolution, bt.node_count, &leaves)
    }

    /// Builds the map from a tree's leaves in pre-order (Morton order of their corners), as
    /// both file formats list them. `node_count` is the file's node count, reported by
    /// [`node_count`](Self::node_count).
    pub fn from_leaves(
        format: OctreeFormat,
        resolution: f64,
        node_count: usize,
        leaves: &[OctreeLeaf],
    ) -> Result<Self, FormatError> {
        let resolution = Resolution::new(resolution)
            .map_err(|e| FormatError::Invalid(format!("resolution {resolution} m: {e}")))?;
        let mut map = Self {
            resolution,
            measures: MeasureConfig::default(),
            format,
            node_count,
            leaf_count: leaves.len(),
            counts: VoxelCounts::default(),
            masks: Vec::new(),
            data: Vec::new(),
        };
        let corners = leaves
            .iter()
            .map(octomap_corner)
            .collect::<Result<Vec<_>, _>>()?;
        if !leaves.is_empty() {
            map.masks.push(0);
            map.data.push(0);
            map.build(0, 0, leaves, &corners)?;
        }
        map.masks.shrink_to_fit();
        map.data.shrink_to_fit();
        map.counts = map.count_leaves();
        Ok(map)
    }

    /// The same map with another measure configuration.
    pub fn with_measures(mut self, measures: MeasureConfig) -> Result<Self> {
        self.measures = measures.validate()?;
        self.counts = self.count_leaves();
        Ok(self)
    }

    /// The file format the tree came from.
    pub fn format(&self) -> OctreeFormat {
        self.format
    }

    /// Number of tree nodes in the file, inner nodes and the root included (OctoMap's `size()`).
    pub fn node_count(&self) -> usize {
        self.node_count
    }

    /// Number of leaves (OctoMap's `getNumLeafNodes()`).
    pub fn leaf_count(&self) -> usize {
        self.leaf_count
    }

    /// The leaf holding a voxel, or `None` where the tree has no node (unknown space).
    pub fn leaf_at(&self, key: VoxelKey) -> Option<OctreeLeaf> {
        let k = [key.x, key.y, key.z].map(|c| {
            c.checked_add(KEY_OFFSET)
                .filter(|k| (0..1 << TREE_DEPTH).contains(k))
        });
        let [Some(x), Some(y), Some(z)] = k else {
            return None;
        };
        let (x, y, z) = (x as u32, y as u32, z as u32);
        let mut node = 0usize;
        for depth in 0..=TREE_DEPTH {
            let mask = *self.masks.get(node)?;
            let data = *self.data.get(node)?;
            if mask == 0 {
                let side = 1u32 << (TREE_DEPTH - depth);
                let corner = |v: u32| (v & !(side - 1)) as i32 - KEY_OFFSET;
                return Some(OctreeLeaf {
                    key: VoxelKey::new(corner(x), corner(y), corner(z)),
                    depth,
                    log_odds: f32::from_bits(data),
                });
            }
            let child = child_index([x, y, z], depth)?;
            if mask & (1 << child) == 0 {
                return None;
            }
            node = data as usize + (mask & ((1u8 << child) - 1)).count_ones() as usize;
        }
        None
    }

    /// Every leaf in pre-order (Morton order of their corners), pruned leaves as one cube each.
    pub fn leaves(&self) -> impl Iterator<Item = OctreeLeaf> + '_ {
        let mut stack: Vec<(usize, u8, [u32; 3])> = Vec::new();
        if !self.masks.is_empty() {
            stack.push((0, 0, [0; 3]));
        }
        std::iter::from_fn(move || {
            while let Some((node, depth, corner)) = stack.pop() {
                let mask = self.masks.get(node).copied().unwrap_or_default();
                let data = self.data.get(node).copied().unwrap_or_default();
                if mask == 0 {
                    return Some(OctreeLeaf {
                        key: voxel_key(corner),
                        depth,
                        log_odds: f32::from_bits(data),
                    });
                }
                // Push the children last first, so that they pop in child order.
                let mut slot = data as usize + mask.count_ones() as usize;
                for child in (0..8u32).rev() {
                    if mask & (1 << child) == 0 {
                        continue;
                    }
                    slot -= 1;
                    let at = child_corner(corner, depth, child);
                    stack.push((slot, depth + 1, at));
                }
            }
            None
        })
    }

    /// The log-odds of every node in storage order, inner nodes holding the largest log-odds of
    /// their children (as OctoMap's `updateInnerOccupancy` leaves them), for the `.ot` writer.
    pub(super) fn node_values(&self) -> Vec<f32> {
        let mut values: Vec<f32> = self.data.iter().map(|&d| f32::from_bits(d)).collect();
        // Children are stored after their parent, so a reverse sweep sees them first.
        for node in (0..self.masks.len()).rev() {
            let mask = self.masks.get(node).copied().unwrap_or_default();
            if mask == 0 {
                continue;
            }
            let first = self.data.get(node).copied().unwrap_or_default() as usize;
            let children = values
                .get(first..first + mask.count_ones() as usize)
                .unwrap_or_default();
            let max = children.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            if let Some(v) = values.get_mut(node) {
                *v = max;
            }
        }
        values
    }

    /// The raw node arrays (masks, data) for the `.ot` writer.
    pub(super) fn nodes(&self) -> (&[u8], &[u32]) {
        (&self.masks, &self.data)
    }

    /// Builds node `node` at `depth` from the leaves inside its cube.
    fn build(
        &mut self,
        node: usize,
        depth: u8,
        leaves: &[OctreeLeaf],
        corners: &[[u32; 3]],
    ) -> Result<(), FormatError> {
        if let ([leaf], [_]) = (leaves, corners)
            && leaf.depth == depth
        {
            self.set(node, 0, leaf.log_odds.to_bits());
            return Ok(());
        }
        if depth >= TREE_DEPTH || leaves.iter().any(|l| l.depth <= depth) {
            return Err(FormatError::Invalid(format!(
                "overlapping leaves at tree depth {depth}"
            )));
        }
        // Group the leaves by child; pre-order lists the children in ascending order.
        let mut groups: Vec<(u8, usize)> = Vec::with_capacity(8);
        for (i, corner) in corners.iter().enumerate() {
            let child = child_index(*corner, depth).unwrap_or_default();
            match groups.last() {
                Some(&(last, _)) if last == child => {}
                Some(&(last, _)) if last > child => {
                    return Err(FormatError::Invalid(
                        "tree leaves are not in pre-order".into(),
                    ));
                }
                _ => groups.push((child, i)),
            }
        }
        let first = self.masks.len();
        let Ok(first_index) = u32::try_from(first) else {
            return Err(FormatError::Invalid(
                "the tree has more than 2^32 nodes".into(),
            ));
        };
        let mask = groups.iter().fold(0u8, |m, &(c, _)| m | (1 << c));
        self.set(node, mask, first_index);
        self.masks.resize(first + groups.len(), 0);
        self.data.resize(first + groups.len(), 0);
        for (g, &(_, start)) in groups.iter().enumerate() {
            let end = groups.get(g + 1).map_or(leaves.len(), |&(_, s)| s);
            let (Some(l), Some(c)) = (leaves.get(start..end), corners.get(start..end)) else {
                continue;
            };
            self.build(first + g, depth + 1, l, c)?;
        }
        Ok(())
    }

    fn set(&mut self, node: usize, mask: u8, data: u32) {
        if let (Some(m), Some(d)) = (self.masks.get_mut(node), self.data.get_mut(node)) {
            *m = mask;
            *d = data;
        }
    }

    /// Finest-level voxel counts per class, one classification per leaf.
    fn count_leaves(&self) -> VoxelCounts {
        let mut counts = [0usize; 4];
        for leaf in self.leaves() {
            let class = self.measures.classify(leaf.memberships());
            let voxels = usize::try_from(leaf.voxel_count()).unwrap_or(usize::MAX);
            if let Some(c) = counts.get_mut(class.index()) {
                *c = c.saturating_add(voxels);
            }
        }
        let [occupied, free, ambiguous, unknown] = counts;
        VoxelCounts {
            occupied,
            free,
            ambiguous,
            unknown,
        }
    }
}

/// The OctoMap key of a leaf's corner, checked to lie in the 16-bit range and on the leaf's
/// own grid.
fn octomap_corner(leaf: &OctreeLeaf) -> Result<[u32; 3], FormatError> {
    let mut out = [0u32; 3];
    for (o, c) in out.iter_mut().zip([leaf.key.x, leaf.key.y, leaf.key.z]) {
        let k = c
            .checked_add(KEY_OFFSET)
            .filter(|k| (0..1 << TREE_DEPTH).contains(k))
            .ok_or_else(|| {
                FormatError::Invalid(format!("leaf key {c} is outside OctoMap's 16-bit range"))
            })?;
        *o = k as u32;
    }
    if leaf.depth > TREE_DEPTH || out.iter().any(|k| k % leaf.side() != 0) {
        return Err(FormatError::Invalid(format!(
            "leaf at depth {} does not start on its cube's grid",
            leaf.depth
        )));
    }
    Ok(out)
}

/// Which child of a node at `depth` holds the OctoMap key `k` (x in bit 0, y in 1, z in 2).
fn child_index(k: [u32; 3], depth: u8) -> Option<u8> {
    let bit = u32::from(TREE_DEPTH.checked_sub(depth + 1)?);
    let b = |v: u32| ((v >> bit) & 1) as u8;
    Some(b(k[0]) | (b(k[1]) << 1) | (b(k[2]) << 2))
}

impl VoxelMap for OcTreeMap {
    fn resolution(&self) -> Resolution {
        self.resolution
    }

    fn measure_config(&self) -> &MeasureConfig {
        &self.measures
    }

    fn memberships_at(&self, key: VoxelKey) -> Memberships {
        self.leaf_at(key)
            .map(|l| l.memberships())
            .unwrap_or_default()
    }

    fn counts(&self) -> VoxelCounts {
        self.counts
    }

    fn memory_bytes(&self) -> usize {
        self.masks.capacity() + self.data.capacity() * size_of::<u32>()
    }

    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, Memberships)> + '_> {
        Box::new(self.leaves().flat_map(|leaf| {
            let m = leaf.memberships();
            cube_keys(leaf.key, leaf.side()).map(move |k| (k, m))
        }))
    }
}
