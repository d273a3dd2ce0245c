//! The read and write traits: region queries agree between block summaries and cell reads, and
//! the writer the read-only map's compile-fail doctest uses compiles for a writable map.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox_core::map::FunctionMap;
use fuzzyvox_core::{
    AlphaConfig, AlphaCutMap, FuzzyConfig, FuzzyMap, IntegrationOptions, KeyBox, LogOddsConfig,
    LogOddsMap, PointCloud, VoxelClass, VoxelKey, VoxelMap, VoxelMapMut,
};
use nalgebra::Point3;

/// The writer of `FunctionMap`'s compile-fail doctest.
fn integrate(map: &mut impl VoxelMapMut, cloud: &PointCloud) {
    map.integrate_cloud(cloud, &IntegrationOptions::default())
        .unwrap();
}

/// A room's walls seen from its centre (`far` = 0), or points beyond them (`far` = 1.5 m) whose
/// rays cross the walls: together, occupied walls with free evidence on them (ambiguous), free
/// space inside and unknown space beyond.
fn room(far: f64) -> PointCloud {
    let mut points = Vec::new();
    for i in 0..60 {
        for j in 0..20 {
            let (a, h) = (
                f64::from(i) / 60.0 * std::f64::consts::TAU,
                f64::from(j) * 0.1,
            );
            let r = 2.0 + 0.5 * (3.0 * a).sin() + far;
            points.push(Point3::new(r * a.cos(), r * a.sin(), h - 0.9));
        }
    }
    PointCloud::new(Point3::origin(), points).unwrap()
}

/// Boxes of every kind: inside one block, cut by block boundaries, covering whole blocks,
/// reaching unobserved space, and one voxel.
fn boxes() -> Vec<KeyBox> {
    let mut out = vec![KeyBox::new(VoxelKey::new(3, 3, 3), VoxelKey::new(3, 3, 3))];
    for (lo, hi) in [(-40, 40), (-16, 15), (-5, 7), (10, 30), (-24, -20), (1, 2)] {
        for (zlo, zhi) in [(-8, 7), (0, 0), (-3, 12)] {
            out.push(KeyBox::new(
                VoxelKey::new(lo, lo / 2, zlo),
                VoxelKey::new(hi, hi, zhi),
            ));
        }
    }
    out
}

/// Checks every class on every box; returns which classes some box held.
fn check_against_cells(map: &dyn VoxelMap) -> [bool; 4] {
    // The same memberships behind the trait's default answer (cell reads).
    let cells = FunctionMap::new(map.resolution(), |k| map.memberships_at(k))
        .with_measures(*map.measure_config())
        .unwrap();
    let mut seen = [false; 4];
    for region in boxes() {
        for class in VoxelClass::ALL {
            let expected = cells.any_in_box(&region, class);
            assert_eq!(
                map.any_in_box(&region, class),
                expected,
                "{class:?} in {region:?}"
            );
            seen[class.index()] |= expected;
        }
    }
    seen
}

#[test]
fn region_queries_from_block_summaries_agree_with_cell_reads() {
    let mut fuzzy = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let mut logodds = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
    let mut alpha = AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap();
    for cloud in [room(0.0), room(1.5)] {
        integrate(&mut fuzzy, &cloud);
        integrate(&mut logodds, &cloud);
        integrate(&mut alpha, &cloud);
    }
    // The fuzzy map has every class; a log-odds cell (μO + μE = 1) is never ambiguous.
    assert_eq!(check_against_cells(&fuzzy), [true; 4]);
    assert_eq!(check_against_cells(&logodds), [true, true, false, true]);
    assert_eq!(check_against_cells(&alpha), [true, true, false, true]);
}
