//! Plan a flight through a fuzzy map built from two scans of a wall with a window, and compare
//! it with the same request in the standard log-odds map.
//!
//! Run: `cargo run --release --example plan_flight`

use fuzzyvox::VoxelMapMut;
use fuzzyvox::plan::{PlannerConfig, plan_path};
use fuzzyvox::{
    FuzzyConfig, FuzzyMap, IntegrationOptions, LogOddsConfig, LogOddsMap, PointCloud, VoxelMap,
};
use nalgebra::Point3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A 6 m × 3 m wall at x = 4 m with a 1.2 m window, and a back wall at x = 8 m seen
    // through it.
    let mut points = Vec::new();
    for i in 0..120 {
        for j in 0..60 {
            let (y, z) = (-3.0 + 0.05 * f64::from(i), 0.05 * f64::from(j));
            let window = (-0.6..0.6).contains(&y) && (0.9..2.1).contains(&z);
            points.push(Point3::new(if window { 8.0 } else { 4.0 }, y, z));
        }
    }
    let mut fuzzy = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
    let mut standard = LogOddsMap::new(LogOddsConfig::new(0.1)?)?;
    for origin in [
        Point3::new(0.0, -0.5, 1.0),
        Point3::new(0.0, 0.5, 1.0),
        Point3::new(0.0, 0.0, 2.0),
    ] {
        let scan = PointCloud::new(origin, points.clone())?;
        fuzzy.integrate_cloud(&scan, &IntegrationOptions::default())?;
        standard.integrate_cloud(&scan, &IntegrationOptions::default())?;
    }

    let config = PlannerConfig {
        vehicle_radius: 0.2,
        ..PlannerConfig::default()
    };
    let (from, to) = (Point3::new(2.0, -0.5, 1.5), Point3::new(6.0, 0.0, 1.5));
    for (name, map) in [("fuzzy", &fuzzy as &dyn VoxelMap), ("log-odds", &standard)] {
        match plan_path(map, &from, &to, &config) {
            Ok(path) => {
                println!(
                    "{name:>8}: {:.2} m, {} waypoints, min safety {:.2}, min clearance {:.2} m",
                    path.length,
                    path.waypoints.len(),
                    path.min_safety,
                    path.min_clearance
                );
                for p in &path.waypoints {
                    println!("            {:.2}, {:.2}, {:.2}", p.x, p.y, p.z);
                }
            }
            Err(why) => println!("{name:>8}: no path: {why}"),
        }
    }
    Ok(())
}
