//! The unseen-surface guard: the loop does not fly through the parts of a surface its map has
//! not seen yet.
//!
//! Unknown space may be crossed at a cost (goals lie in space nobody has seen), and most of it
//! is empty. Unknown space next to a surface the map has begun to see is different: it is
//! usually the rest of that surface, seen too obliquely, too close or at the epipole of the
//! camera's motion (where depth from motion is undefined). The guard forbids, within
//! [`FlyConfig::unknown_guard`](super::FlyConfig::unknown_guard) metres of the vehicle, every
//! unknown voxel within
//! [`FlyConfig::guard_surface_reach`](super::FlyConfig::guard_surface_reach) of an occupied or
//! ambiguous voxel ("suspect" voxels), and every voxel within the vehicle's radius of one.
//! Suspects are remembered until the map learns what they are, so that the forbidden set does
//! not move with the vehicle (a set that moves makes paths flip from one frame to the next).
//!
//! The guard also takes as suspects, within [`FlyConfig::look_ahead`](super::FlyConfig::look_ahead)
//! of the vehicle, the unknown voxels that **lean occupied**
//! ([`UnknownGuard::add_leaning`]): occupied membership at least
//! [`FlyConfig::leaning_occupied`](super::FlyConfig::leaning_occupied) and above the free one.
//! A fuzzy map holds a surface seen only by motion along the view (a pair's `Q_ABD` caps its
//! confidence) or only once at such a membership, below the occupied class: the map has seen
//! something there, not nothing, and flying into it at the unknown-space cost is how a vehicle
//! hits what it saw badly. Only graded maps have such voxels (a log-odds voxel that leans
//! occupied is occupied).

use nalgebra::Point3;
use rustc_hash::FxHashSet;

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_plan::CostField;

/// The suspect voxels of one flight and the voxels they forbid, over the field's region.
#[derive(Clone, Debug, Default)]
pub struct UnknownGuard {
    /// Dense indices of the suspect voxels next to a surface.
    suspects: FxHashSet<usize>,
    /// Dense indices of the unknown voxels that lean occupied; kept while they still do.
    leaning: FxHashSet<usize>,
    /// Per dense index: forbidden (a suspect within the vehicle's radius).
    forbidden: Vec<bool>,
    /// The indices set in `forbidden`, to clear them.
    marked: Vec<usize>,
}

impl UnknownGuard {
    /// A guard that forbids nothing yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the suspects within `radius` metres of `position`, drops the suspects the map no
    /// longer holds unknown, and recomputes what they forbid.
    pub fn update(
        &mut self,
        field: &CostField,
        position: &Point3<f64>,
        radius: f64,
        surface_reach: f64,
    ) {
        if radius <= 0.0
            && self.suspects.is_empty()
            && self.leaning.is_empty()
            && self.marked.is_empty()
        {
            // Off, and nothing left from before: nothing to forbid.
            return;
        }
        let region = *field.region();
        let dims = region.dims();
        let size = field.resolution().size();
        if radius > 0.0
            && let Ok(here) = field.resolution().key_of(position)
            && region.index_of(here).is_some()
        {
            let min = region.min();
            let centre = [
                i64::from(here.x) - i64::from(min.x),
                i64::from(here.y) - i64::from(min.y),
                i64::from(here.z) - i64::from(min.z),
            ];
            self.add_suspects(field, centre, radius / size, surface_reach / size);
        }
        self.suspects
            .retain(|&index| field.class(index) == VoxelClass::Unknown);
        self.leaning
            .retain(|&index| field.class(index) == VoxelClass::Unknown);

        for &index in &self.marked {
            self.forbidden[index] = false;
        }
        self.marked.clear();
        self.forbidden.resize(region.len(), false);
        let pad = (field.config().vehicle_radius / size).ceil() as i64;
        let near = (field.config().vehicle_radius / size).powi(2) + 1e-9;
        let mut suspects: Vec<usize> = self.suspects.union(&self.leaning).copied().collect();
        suspects.sort_unstable();
        for index in suspects {
            let u = region.coordinates_at(index);
            for z in (u[2] - pad).max(0)..=(u[2] + pad).min(dims[2] as i64 - 1) {
                for y in (u[1] - pad).max(0)..=(u[1] + pad).min(dims[1] as i64 - 1) {
                    for x in (u[0] - pad).max(0)..=(u[0] + pad).min(dims[0] as i64 - 1) {
                        let c = [x, y, z];
                        if squared(c, u) <= near {
                            let i = region.index_at(c);
                            if !self.forbidden[i] {
                                self.forbidden[i] = true;
                                self.marked.push(i);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Adds as suspects the unknown voxels of `field` within `radius` metres of `position`
    /// whose memberships in `map` lean occupied: occupied membership at least `threshold` and
    /// above the free membership. Drops, wherever they are, the ones added before that no
    /// longer lean occupied (later frames saw through them). A threshold above 1 (or a radius
    /// of 0) adds nothing. Call before [`UnknownGuard::update`], which turns suspects into
    /// forbidden voxels.
    pub fn add_leaning(
        &mut self,
        map: &dyn VoxelMap,
        field: &CostField,
        position: &Point3<f64>,
        radius: f64,
        threshold: f32,
    ) {
        let leans = |index: usize| {
            let m = map.memberships_at(field.region().key_at(index));
            m.occupied >= threshold && m.occupied > m.free
        };
        self.leaning.retain(|&index| leans(index));
        if radius <= 0.0 || threshold.is_nan() || threshold > 1.0 {
            return;
        }
        let region = *field.region();
        let dims = region.dims();
        let resolution = field.resolution();
        let Some(here) = resolution
            .key_of(position)
            .ok()
            .and_then(|key| region.index_of(key))
        else {
            return;
        };
        let centre = region.coordinates_at(here);
        let r = (radius / resolution.size()).ceil() as i64;
        let ball = (radius / resolution.size()).powi(2) + 1e-9;
        for z in (centre[2] - r).max(0)..=(centre[2] + r).min(dims[2] as i64 - 1) {
            for y in (centre[1] - r).max(0)..=(centre[1] + r).min(dims[1] as i64 - 1) {
                for x in (centre[0] - r).max(0)..=(centre[0] + r).min(dims[0] as i64 - 1) {
                    let c = [x, y, z];
                    if squared(c, centre) > ball {
                        continue;
                    }
                    let i = region.index_at(c);
                    if field.class(i) == VoxelClass::Unknown
                        && !self.leaning.contains(&i)
                        && leans(i)
                    {
                        self.leaning.insert(i);
                    }
                }
            }
        }
    }

    /// Unknown voxels within `reach` voxels of an occupied or ambiguous voxel, within
    /// `radius` voxels of `centre` (region coordinates).
    fn add_suspects(&mut self, field: &CostField, centre: [i64; 3], radius: f64, reach: f64) {
        let region = field.region();
        let dims = region.dims();
        let r = radius.ceil() as i64;
        let lo: [i64; 3] = std::array::from_fn(|a| (centre[a] - r).max(0));
        let hi: [i64; 3] = std::array::from_fn(|a| (centre[a] + r).min(dims[a] as i64 - 1));
        let s = reach.floor() as i64;
        let within = reach * reach + 1e-9;
        let ball = radius * radius + 1e-9;
        for z in (lo[2] - s).max(0)..=(hi[2] + s).min(dims[2] as i64 - 1) {
            for y in (lo[1] - s).max(0)..=(hi[1] + s).min(dims[1] as i64 - 1) {
                for x in (lo[0] - s).max(0)..=(hi[0] + s).min(dims[0] as i64 - 1) {
                    let surface = [x, y, z];
                    if !matches!(
                        field.class(region.index_at(surface)),
                        VoxelClass::Occupied | VoxelClass::Ambiguous
                    ) {
                        continue;
                    }
                    for sz in (z - s).max(lo[2])..=(z + s).min(hi[2]) {
                        for sy in (y - s).max(lo[1])..=(y + s).min(hi[1]) {
                            for sx in (x - s).max(lo[0])..=(x + s).min(hi[0]) {
                                let c = [sx, sy, sz];
                                if squared(c, surface) <= within && squared(c, centre) <= ball {
                                    let i = region.index_at(c);
                                    if field.class(i) == VoxelClass::Unknown {
                                        self.suspects.insert(i);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// The forbidden voxels (dense indices), in the order the last update found them: while
    /// this list stays the same, so does what the guard forbids.
    pub fn forbidden_voxels(&self) -> &[usize] {
        &self.marked
    }

    /// Whether the voxel at a dense index of the field's region is forbidden.
    pub fn forbids(&self, index: usize) -> bool {
        self.forbidden.get(index).copied().unwrap_or(false)
    }

    /// Number of suspect voxels (next to a surface, or leaning occupied).
    pub fn suspects(&self) -> usize {
        self.suspects.union(&self.leaning).count()
    }
}

fn squared(a: [i64; 3], b: [i64; 3]) -> f64 {
    (0..3).map(|i| ((a[i] - b[i]) as f64).powi(2)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::map::FunctionMap;
    use fuzzyvox_core::measures::Memberships;
    use fuzzyvox_core::storage::{Resolution, VoxelKey};
    use fuzzyvox_plan::{PlannerConfig, PlanningRegion, UnknownPolicy};

    /// A 6 × 6 × 2 m box at 0.2 m: free everywhere, but a wall at x = 15 (occupied for
    /// y < 15, unknown beyond: the part not seen yet) and a patch of unknown space far from
    /// it at x = 3; with `seen`, the wall's unknown part has been seen free.
    fn wall_field(seen: bool) -> CostField {
        let resolution = Resolution::new(0.2).unwrap();
        let map = FunctionMap::new(resolution, move |key| {
            let free = Memberships {
                occupied: 0.0,
                free: 0.95,
            };
            let unknown = Memberships::default();
            if key.x == 15 && key.y < 15 {
                Memberships {
                    occupied: 0.95,
                    free: 0.0,
                }
            } else if (key.x == 15 && !seen) || (key.x == 3 && (10..20).contains(&key.y)) {
                unknown
            } else {
                free
            }
        });
        let region = PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(29, 29, 9)).unwrap();
        let config = PlannerConfig {
            unknown: UnknownPolicy::Cost(2.0),
            ..PlannerConfig::default()
        };
        CostField::build(&map, region, config).unwrap()
    }

    #[test]
    fn unknown_next_to_a_surface_is_forbidden_and_remembered() {
        let field = wall_field(false);
        let region = *field.region();
        let index = |x, y, z| region.index_of(VoxelKey::new(x, y, z)).unwrap();
        let centre = |x, y, z| field.resolution().center(VoxelKey::new(x, y, z));
        let mut guard = UnknownGuard::new();
        guard.update(&field, &centre(12, 15, 5), 2.0, 0.6);
        // The wall's unknown continuation, and voxels within the vehicle's radius of it.
        assert!(guard.forbids(index(15, 16, 5)));
        assert!(guard.forbids(index(14, 16, 5)));
        assert!(!guard.forbids(index(13, 16, 5)));
        // Beyond the surface reach (3 voxels from the last occupied one at y = 14).
        assert!(!guard.forbids(index(15, 20, 5)));
        // Unknown space far from any surface is left to the planner's policy.
        assert!(!guard.forbids(index(3, 15, 5)));
        assert!(guard.suspects() > 0);
        // Remembered when the vehicle has moved away...
        guard.update(&field, &centre(3, 3, 5), 2.0, 0.6);
        assert!(guard.forbids(index(15, 16, 5)));
        // ...until the map has seen what the suspects are.
        guard.update(&wall_field(true), &centre(3, 3, 5), 2.0, 0.6);
        assert_eq!(guard.suspects(), 0);
        assert!(!guard.forbids(index(15, 16, 5)));
        // A radius of 0 adds nothing; a fresh guard forbids nothing.
        let mut off = UnknownGuard::new();
        off.update(&field, &centre(12, 15, 5), 0.0, 0.6);
        assert_eq!(off.suspects(), 0);
        assert!(!UnknownGuard::new().forbids(index(15, 16, 5)));
    }

    #[test]
    fn unknown_that_leans_occupied_is_forbidden() {
        let resolution = Resolution::new(0.2).unwrap();
        // Free space with one voxel seen as a surface below the occupied class (0.43), one
        // with a trace of occupied evidence (0.1) and one that leans free.
        let map = FunctionMap::new(resolution, |key| match (key.x, key.y, key.z) {
            (10, 10, 5) => Memberships {
                occupied: 0.43,
                free: 0.0,
            },
            (10, 20, 5) => Memberships {
                occupied: 0.1,
                free: 0.0,
            },
            (20, 10, 5) => Memberships {
                occupied: 0.35,
                free: 0.4,
            },
            _ => Memberships {
                occupied: 0.0,
                free: 0.95,
            },
        });
        let region = PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(29, 29, 9)).unwrap();
        let config = PlannerConfig {
            unknown: UnknownPolicy::Cost(2.0),
            ..PlannerConfig::default()
        };
        let field = CostField::build(&map, region, config).unwrap();
        let index = |x, y, z| region.index_of(VoxelKey::new(x, y, z)).unwrap();
        assert!(
            !field.is_blocked(index(10, 10, 5)),
            "unknown, crossed at a cost"
        );
        let at = resolution.center(VoxelKey::new(15, 15, 5));
        let mut guard = UnknownGuard::new();
        guard.add_leaning(&map, &field, &at, 3.0, 0.3);
        guard.update(&field, &at, 0.0, 0.6);
        assert_eq!(guard.suspects(), 1);
        assert!(guard.forbids(index(10, 10, 5)));
        // And every voxel within the vehicle's radius of it.
        assert!(guard.forbids(index(11, 10, 5)));
        assert!(!guard.forbids(index(12, 10, 5)));
        assert!(!guard.forbids(index(10, 20, 5)));
        assert!(!guard.forbids(index(20, 10, 5)));
        // Later frames see through it (free above occupied): it no longer leans, and the
        // guard lets it go, wherever the vehicle is.
        let seen = FunctionMap::new(resolution, |key| match (key.x, key.y, key.z) {
            (10, 10, 5) => Memberships {
                occupied: 0.43,
                free: 0.45,
            },
            _ => Memberships {
                occupied: 0.0,
                free: 0.95,
            },
        });
        let far_away = resolution.center(VoxelKey::new(25, 25, 5));
        guard.add_leaning(&seen, &field, &far_away, 3.0, 0.3);
        guard.update(&field, &far_away, 0.0, 0.6);
        assert_eq!(guard.suspects(), 0);
        assert!(!guard.forbids(index(10, 10, 5)));
        // Out of reach, or off (a threshold above 1), nothing is added.
        let mut far = UnknownGuard::new();
        far.add_leaning(
            &map,
            &field,
            &resolution.center(VoxelKey::new(25, 25, 5)),
            2.0,
            0.3,
        );
        let mut off = UnknownGuard::new();
        off.add_leaning(&map, &field, &at, 3.0, 1.5);
        assert_eq!((far.suspects(), off.suspects()), (0, 0));
    }
}
