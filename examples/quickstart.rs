//! Quickstart: map a small scene from two scans, then ask what the map knows about a few
//! places.
//!
//! Run: `cargo run --release --example quickstart`

use fuzzyvox::VoxelMapMut;
use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelMap};
use nalgebra::Point3;

fn main() -> Result<(), fuzzyvox::Error> {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;

    // A wall at x = 4 m seen from two places; the second scan is less sure of itself
    // (confidence 0.4), as a far or poorly placed camera would be.
    for (origin, confidence) in [
        (Point3::new(0.0, 0.0, 1.0), 1.0),
        (Point3::new(0.0, 2.0, 1.0), 0.4),
    ] {
        let mut points = Vec::new();
        for i in 0..60 {
            for j in 0..30 {
                points.push(Point3::new(
                    4.0,
                    -3.0 + 0.1 * f64::from(i),
                    0.1 * f64::from(j),
                ));
            }
        }
        let n = points.len();
        let scan = PointCloud::new(origin, points)?.with_confidence(vec![confidence; n])?;
        let stats = map.integrate_cloud(&scan, &IntegrationOptions::default())?;
        println!(
            "scan from {origin}: {} points, {} voxels updated",
            stats.integrated, stats.voxels_updated
        );
    }

    let counts = map.counts();
    println!(
        "map: {} occupied, {} free, {} ambiguous, {} unknown voxels",
        counts.occupied, counts.free, counts.ambiguous, counts.unknown
    );
    for (name, place) in [
        ("in front of the wall", Point3::new(2.0, 0.0, 1.0)),
        ("on the wall", Point3::new(4.05, 0.0, 1.0)),
        ("behind the wall", Point3::new(5.0, 0.0, 1.0)),
    ] {
        let m = map.measures_at_point(&place)?;
        println!(
            "{name:>22}: class {:<9} occupied {:.2} free {:.2} safety {:.2} indeterminacy {:.2}",
            m.class.name(),
            m.occupied,
            m.free,
            m.safety,
            m.indeterminacy
        );
    }
    Ok(())
}
