//! Plan a safe flight through a robot's existing OctoMap: OctoMap's own map of the FR-079
//! building (`geb079.bt`), read as it is, from a room through its door into the corridor.
//!
//! Run: `cargo run --release --example octomap_plan [-- PATH/TO/geb079.bt]` (default:
//! `$FUZZYVOX_DATA/octomap-samples/geb079.bt`, else `../shared/data/octomap-samples/geb079.bt`).

use std::path::PathBuf;

use fuzzyvox::io::load_map;
use fuzzyvox::plan::{PlannerConfig, plan_path};
use nalgebra::Point3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            std::env::var_os("FUZZYVOX_DATA")
                .map_or_else(|| PathBuf::from("../shared/data"), PathBuf::from)
                .join("octomap-samples/geb079.bt")
        });
    // Any map file: fuzzyvox's own, or an OctoMap `.bt` / `.ot`, told apart by content.
    let loaded = load_map(&path)?;
    let map = loaded.as_map();
    let counts = map.counts();
    println!(
        "{} ({}): {} occupied and {} free voxels at {} m, {:.1} MB in memory",
        path.display(),
        loaded.model_name(),
        counts.occupied,
        counts.free,
        map.resolution().size(),
        map.memory_bytes() as f64 / 1e6
    );

    // A vehicle of radius 0.15 m; unknown space is forbidden (the default).
    let config = PlannerConfig {
        vehicle_radius: 0.15,
        ..PlannerConfig::default()
    };
    let (from, to) = (Point3::new(1.24, -3.4, 1.0), Point3::new(18.0, -0.44, 0.92));
    let flight = plan_path(map, &from, &to, &config)?;
    println!(
        "{:.2} m through {} waypoints (min clearance {:.2} m from any blocked voxel centre):",
        flight.length,
        flight.waypoints.len(),
        flight.min_clearance
    );
    for p in &flight.waypoints {
        println!("  {:.2}, {:.2}, {:.2}", p.x, p.y, p.z);
    }
    Ok(())
}
