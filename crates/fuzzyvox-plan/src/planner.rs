//! A planner that follows a map as it grows: it owns the cost field of a region and updates it
//! from the blocks each integration changed.

use fuzzyvox_core::error::Result;
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::storage::VoxelKey;
use nalgebra::Point3;

use crate::config::PlannerConfig;
use crate::cost_field::CostField;
use crate::error::PlanError;
use crate::field_update::FieldUpdate;
use crate::path::{Path, plan_in_field};
use crate::region::PlanningRegion;
use crate::smooth::{LegVoxels, legs_clear};

/// The cost field of one region of one map, kept current as the map changes.
///
/// [`Planner::update`] asks the map which blocks it wrote since the field last saw it
/// ([`VoxelMap::changed_blocks_since`]) and updates only around them, so a frame's update
/// costs in proportion to what the frame changed, not to the region; the field it leaves is
/// bit for bit the one a full [`CostField::build`] gives. Maps that do not report their
/// changes (read-only maps) never change, and a map whose version went backwards is rebuilt.
///
/// ```
/// use fuzzyvox_plan::{Planner, PlannerConfig, PlanningRegion, UnknownPolicy};
/// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelKey, VoxelMap, VoxelMapMut};
/// use nalgebra::Point3;
///
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.2)?)?;
/// let config = PlannerConfig { unknown: UnknownPolicy::Cost(1.0), ..PlannerConfig::default() };
/// let region = PlanningRegion::new(VoxelKey::new(-5, -15, -15), VoxelKey::new(25, 15, 15))?;
/// let mut planner = Planner::new(&map, region, config)?;
/// let wall: Vec<_> = (-10..=10)
///     .flat_map(|y| (-10..=10).map(move |z| Point3::new(3.0, 0.1 * y as f64, 0.1 * z as f64)))
///     .collect();
/// map.integrate_cloud(&PointCloud::new(Point3::origin(), wall)?, &IntegrationOptions::default())?;
/// let update = planner.update(&map);
/// assert!(update.voxels_flipped > 0 && !update.rebuilt);
/// let path = planner.plan(VoxelKey::new(0, 0, 0), VoxelKey::new(22, 0, 0))?;
/// assert!(path.length > 4.4);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct Planner {
    field: CostField,
    /// The map's write version the field reflects (`None` for maps that do not report one).
    version: Option<u64>,
    /// How many updates changed the field.
    generation: u64,
}

impl Planner {
    /// Builds the field of `region` from `map`.
    pub fn new(map: &dyn VoxelMap, region: PlanningRegion, config: PlannerConfig) -> Result<Self> {
        Ok(Self {
            field: CostField::build(map, region, config)?,
            version: map.write_version(),
            generation: 0,
        })
    }

    /// Brings the field up to date with `map` (the map it was built from): updates around the
    /// blocks written since the last update, or rebuilds the whole field when the map cannot
    /// say which those are.
    pub fn update(&mut self, map: &dyn VoxelMap) -> FieldUpdate {
        let now = map.write_version();
        let changed = match (self.version, now) {
            (Some(before), Some(after)) if after >= before => map.changed_blocks_since(before),
            (None, None) => Some(Vec::new()),
            _ => None,
        };
        self.version = now;
        let update = match changed {
            Some(blocks) => self.field.update(map, &blocks),
            None => {
                let region = *self.field.region();
                let config = *self.field.config();
                // The configuration was validated when the field was first built.
                if let Ok(field) = CostField::build(map, region, config) {
                    self.field = field;
                }
                FieldUpdate {
                    rebuilt: true,
                    ..FieldUpdate::default()
                }
            }
        };
        if update.rebuilt || update.voxels_changed > 0 || update.voxels_flipped > 0 {
            self.generation += 1;
        }
        update
    }

    /// A count that grows with every update that changed the field (a voxel's class, safety,
    /// clearance or cost, or a rebuild): while it stays the same, every plan through the field
    /// gives the same result.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The current field.
    pub fn field(&self) -> &CostField {
        &self.field
    }

    /// A* from `start` to `goal` through the current field ([`plan_in_field`]).
    pub fn plan(&self, start: VoxelKey, goal: VoxelKey) -> std::result::Result<Path, PlanError> {
        plan_in_field(&self.field, start, goal)
    }

    /// Whether every straight leg of `waypoints` crosses only traversable voxels of the
    /// current field (the test the planner's own shortcuts pass), for a step the caller is
    /// about to take. For a path the planner gave, kept while the map grows, see
    /// [`is_path_clear_avoiding`](Planner::is_path_clear_avoiding).
    pub fn is_clear(&self, waypoints: &[Point3<f64>]) -> bool {
        self.is_clear_avoiding(waypoints, &|_| false)
    }

    /// [`is_clear`](Planner::is_clear) that also refuses every voxel (dense index) for which
    /// `avoid` is true, the first waypoint's voxel excepted (the vehicle is there already).
    pub fn is_clear_avoiding(
        &self,
        waypoints: &[Point3<f64>],
        avoid: &dyn Fn(usize) -> bool,
    ) -> bool {
        legs_clear(&self.field, waypoints, avoid, LegVoxels::Ray)
    }

    /// Whether a path the planner gave (waypoints at voxel centres, the first where the
    /// vehicle is) is still clear in the current field: every leg crosses only traversable
    /// voxels that `avoid` allows, the first waypoint's voxel excepted. A leg crosses the
    /// voxels it passes through over a stretch of positive length; where it meets a voxel edge
    /// or corner exactly, the voxels that only touch it there do not count, as in A*'s own
    /// steps between diagonal neighbours. So every path the planner gives is clear in the
    /// field it was planned in, which [`is_clear_avoiding`](Planner::is_clear_avoiding)'s ray
    /// walk does not promise where a path passes a corner diagonally.
    pub fn is_path_clear_avoiding(
        &self,
        waypoints: &[Point3<f64>],
        avoid: &dyn Fn(usize) -> bool,
    ) -> bool {
        legs_clear(&self.field, waypoints, avoid, LegVoxels::Interior)
    }
}
