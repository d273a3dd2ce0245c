//! Where flights go: start/goal pairs drawn from the truth alone, with one configuration
//! ([`QueryConfig`]) and one drawer ([`draw_queries`]) for every experiment: the open-loop
//! flights of `eval`, the closed-loop flights of `fly` and the runs on real frames.
//!
//! The queries never depend on the maps being compared, so every map answers the same
//! queries whichever maps sit beside it.

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_core::storage::{Resolution, VoxelKey};
use fuzzyvox_plan::PlannerConfig;
use fuzzyvox_sim::unit_hash;
use nalgebra::Point3;
use rustc_hash::FxHashMap;
use serde::Serialize;

use super::world::Obstacles;

/// How start/goal pairs are drawn (and the planner that flies them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryConfig {
    /// Number of start/goal pairs.
    pub queries: usize,
    /// Seed of the draw.
    pub seed: u64,
    /// Planner settings (the vehicle radius is also the radius of the collision check).
    pub planner: PlannerConfig,
    /// Smallest and largest straight-line distance between start and goal, metres.
    pub distance: (f64, f64),
    /// Lowest and highest flight altitude of starts and goals, metres.
    pub altitude: (f64, f64),
    /// Extra distance, metres, beyond the vehicle radius that starts and goals keep from every
    /// true surface. Default: one voxel diagonal of the 0.2 m maps (0.35 m).
    pub surface_margin: f64,
}

impl Default for QueryConfig {
    /// The open-loop experiments' draw: 100 pairs 6 to 25 m apart, 1 to 20 m up.
    fn default() -> Self {
        Self {
            queries: 100,
            seed: 1,
            planner: PlannerConfig::default(),
            distance: (6.0, 25.0),
            altitude: (1.0, 20.0),
            surface_margin: 0.2 * 3f64.sqrt(),
        }
    }
}

impl QueryConfig {
    /// The closed-loop flights' draw: `queries` pairs 8 to 20 m apart, 1.5 to 6 m up, 0.5 m
    /// beyond the vehicle radius from every surface, planned with `planner`.
    pub fn closed_loop(queries: usize, seed: u64, planner: PlannerConfig) -> Self {
        Self {
            queries,
            seed,
            planner,
            distance: (8.0, 20.0),
            altitude: (1.5, 6.0),
            surface_margin: 0.5,
        }
    }

    /// Checks every value.
    pub fn validate(self) -> Result<Self> {
        self.planner.validate()?;
        for (name, (lo, hi)) in [
            ("flight distance range", self.distance),
            ("altitude", self.altitude),
        ] {
            if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo) {
                return Err(Error::InvalidParameter {
                    name,
                    value: lo,
                    expected: "0 <= low < high, finite",
                });
            }
        }
        if !(self.surface_margin.is_finite() && self.surface_margin >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "surface margin",
                value: self.surface_margin,
                expected: "a finite distance >= 0 m",
            });
        }
        Ok(self)
    }

    /// How far starts and goals keep from every true surface: the vehicle radius plus the
    /// surface margin.
    pub fn clearance(&self) -> f64 {
        self.planner.vehicle_radius + self.surface_margin
    }

    fn within_distance(&self, from: &Point3<f64>, to: &Point3<f64>) -> bool {
        let d = (to - from).norm();
        d >= self.distance.0 && d <= self.distance.1
    }
}

/// One start/goal pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlightQuery {
    /// Start (a voxel centre).
    pub from: Point3<f64>,
    /// Goal (a voxel centre).
    pub to: Point3<f64>,
    /// Length of the path the truth allows between them, metres, when the drawer planned one
    /// (the yardstick of a flight's length).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_length: Option<f64>,
}

/// Finds the truth's path between two points and gives its length; `None`: not connected.
pub type Connect<'a> = &'a dyn Fn(&Point3<f64>, &Point3<f64>) -> Result<Option<f64>>;

/// Where candidate starts and goals come from.
#[derive(Clone, Copy)]
pub enum Candidates<'a> {
    /// Voxels a reference map (what the cameras could know of the truth) calls free, from
    /// which it lets a vehicle take off: every voxel within the planner's required clearance
    /// (vehicle radius plus a voxel diagonal, see `fuzzyvox_plan::CostField`) is free and
    /// safe in it.
    Reference(&'a dyn VoxelMap),
    /// Voxels a reference map calls free, as [`Candidates::Reference`] takes them, but within
    /// `reach` metres of a point of `path` (where the camera went) instead of within the
    /// altitude band: for real footage, whose world frame need not have z up.
    NearPath {
        /// The reference map.
        reference: &'a dyn VoxelMap,
        /// Where the camera went.
        path: &'a [Point3<f64>],
        /// How far from the path candidates may lie, metres.
        reach: f64,
    },
    /// Voxel centres drawn uniformly in a horizontal box (`[[x0, y0], [x1, y1]]`), kept when
    /// `connect` finds the truth's path between them (its length becomes
    /// [`FlightQuery::reference_length`]). For flights into space nobody has seen yet.
    Uniform {
        /// The horizontal box.
        extent: [[f64; 2]; 2],
        /// The voxel grid the points are snapped to (its centres).
        resolution: Resolution,
        /// The truth's path between two candidates.
        connect: Connect<'a>,
    },
}

/// Draws [`QueryConfig::queries`] start/goal pairs: from `candidates`, within the altitude
/// band and the distance range, at least [`QueryConfig::clearance`] from every obstacle of
/// `world`. Deterministic for the seed; fewer pairs come back when too few candidates exist.
pub fn draw_queries(
    world: &dyn Obstacles,
    candidates: Candidates,
    config: &QueryConfig,
) -> Result<Vec<FlightQuery>> {
    let config = config.validate()?;
    match candidates {
        Candidates::Reference(reference) => {
            let (low, high) = config.altitude;
            let in_band = |p: &Point3<f64>| p.z >= low && p.z <= high;
            from_reference(world, reference, &in_band, &config)
        }
        Candidates::NearPath {
            reference,
            path,
            reach,
        } => {
            if !(reach.is_finite() && reach > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "reach from the camera path",
                    value: reach,
                    expected: "a finite distance > 0 m",
                });
            }
            let near = |p: &Point3<f64>| path.iter().any(|c| (p - c).norm() <= reach);
            from_reference(world, reference, &near, &config)
        }
        Candidates::Uniform {
            extent,
            resolution,
            connect,
        } => uniform(world, extent, resolution, connect, &config),
    }
}

/// Pairs of `reference`'s free voxels whose centres `keep` accepts.
fn from_reference(
    world: &dyn Obstacles,
    reference: &dyn VoxelMap,
    keep: &dyn Fn(&Point3<f64>) -> bool,
    config: &QueryConfig,
) -> Result<Vec<FlightQuery>> {
    let planner = config.planner;
    let resolution = reference.resolution();
    let measures = reference.measure_config();
    let mut candidates: Vec<VoxelKey> = reference
        .cells()
        .filter(|&(key, m)| {
            measures.classify(m) == VoxelClass::Free && keep(&resolution.center(key))
        })
        .map(|(key, _)| key)
        .collect();
    candidates.sort_unstable();
    let mut queries = Vec::new();
    if candidates.len() < 2 {
        return Ok(queries);
    }
    // Every voxel whose centre lies closer than the planner's required clearance.
    let required = planner.vehicle_radius + 3f64.sqrt() * resolution.size();
    let reach = (required / resolution.size()).ceil() as i32;
    let mut ball = Vec::new();
    for dz in -reach..=reach {
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let d2 = f64::from(dx * dx + dy * dy + dz * dz) * resolution.size().powi(2);
                if d2 < required * required {
                    ball.push((dx, dy, dz));
                }
            }
        }
    }
    let safe = |key: VoxelKey| {
        let m = reference.measures_at(key);
        m.class == VoxelClass::Free && m.safety >= planner.safety_threshold
    };
    let mut usable: FxHashMap<VoxelKey, bool> = FxHashMap::default();
    let mut is_usable = |key: VoxelKey| {
        *usable.entry(key).or_insert_with(|| {
            ball.iter()
                .all(|&(dx, dy, dz)| safe(VoxelKey::new(key.x + dx, key.y + dy, key.z + dz)))
                && world.distance_to_surface(&resolution.center(key)) >= config.clearance()
        })
    };
    let pick = |n: i64, salt: i64| {
        let u = unit_hash(n, salt, 97, config.seed);
        ((u as f64 * candidates.len() as f64) as usize).min(candidates.len() - 1)
    };
    let mut draw = 0i64;
    let attempts = 200 * config.queries as i64 + 1000;
    while queries.len() < config.queries && draw < attempts {
        draw += 1;
        let (a, b) = (candidates[pick(draw, 1)], candidates[pick(draw, 2)]);
        let (from, to) = (resolution.center(a), resolution.center(b));
        if config.within_distance(&from, &to) && is_usable(a) && is_usable(b) {
            queries.push(FlightQuery {
                from,
                to,
                reference_length: None,
            });
        }
    }
    Ok(queries)
}

fn uniform(
    world: &dyn Obstacles,
    extent: [[f64; 2]; 2],
    resolution: Resolution,
    connect: Connect,
    config: &QueryConfig,
) -> Result<Vec<FlightQuery>> {
    let [[x0, y0], [x1, y1]] = extent;
    let (z0, z1) = config.altitude;
    // Voxel centres, so that every map answers about the same voxel.
    let point = |draw: i64, salt: i64| {
        let uniform = |lo: f64, hi: f64, axis: i64| {
            lo + (hi - lo) * f64::from(unit_hash(draw, salt + axis, 131, config.seed))
        };
        let p = Point3::new(uniform(x0, x1, 0), uniform(y0, y1, 1), uniform(z0, z1, 2));
        resolution.key_of(&p).map(|key| resolution.center(key))
    };
    let mut queries = Vec::new();
    let attempts = 500 * config.queries as i64 + 100;
    let mut draw = 0i64;
    while queries.len() < config.queries && draw < attempts {
        draw += 1;
        let from = point(draw, 1)?;
        let to = point(draw, 4)?;
        if !config.within_distance(&from, &to)
            || world.distance_to_surface(&from) < config.clearance()
            || world.distance_to_surface(&to) < config.clearance()
        {
            continue;
        }
        if let Some(length) = connect(&from, &to)? {
            queries.push(FlightQuery {
                from,
                to,
                reference_length: Some(length),
            });
        }
    }
    Ok(queries)
}
