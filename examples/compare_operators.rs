//! The same observations into fuzzy maps with several t-conorms, side by side.
//!
//! Six scans of a 4 × 2 m wall 4 m away, from six positions, with range-dependent noise and a
//! few low-confidence outliers in front of the wall (the kind structure from motion produces).
//! Each map aggregates exactly the same evidence; only the operator `S` differs. The table shows
//! how each operator trades completeness of the wall against spurious voxels and conflict.
//!
//! Run: `cargo run --release --example compare_operators`

use fuzzyvox::VoxelMapMut;
use fuzzyvox::{
    Family, FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, TConorm, VoxelClass, VoxelMap,
};
use nalgebra::Point3;

/// A small deterministic pseudo-random generator (SplitMix64), so the example needs no crate.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        lo + (hi - lo) * (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

const WALL_X: f64 = 4.0;
const RESOLUTION: f64 = 0.1;

/// Six scans of the wall: points on it with noise that grows with range, confidence that falls
/// with range, and 3 % outliers in front of it at confidence 0.2.
fn scans() -> Result<Vec<PointCloud>, fuzzyvox::Error> {
    let mut rng = Rng(42);
    let mut scans = Vec::new();
    for s in 0..6 {
        let origin = Point3::new(0.4 * f64::from(s), -1.0 + 0.4 * f64::from(s), 1.0);
        let (mut points, mut confidence) = (Vec::new(), Vec::new());
        for _ in 0..4000 {
            let target = Point3::new(WALL_X, rng.uniform(-2.0, 2.0), rng.uniform(0.0, 2.0));
            let range = (target - origin).norm();
            if rng.uniform(0.0, 1.0) < 0.03 {
                // An outlier somewhere along the ray, in front of the wall.
                let t = rng.uniform(0.3, 0.9);
                points.push(origin + (target - origin) * t);
                confidence.push(0.2);
            } else {
                let noise = rng.uniform(-1.0, 1.0) * 0.004 * range * range;
                points.push(target + (target - origin).normalize() * noise);
                confidence.push((1.0 - range / 10.0) as f32);
            }
        }
        scans.push(PointCloud::new(origin, points)?.with_confidence(confidence)?);
    }
    Ok(scans)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scans = scans()?;
    let operators = [
        "max",
        "product",
        "einstein",
        "hamacher:0.5",
        "dombi:2",
        "yager:2",
        "aczel-alsina:2",
        "lukasiewicz",
    ];
    println!(
        "{} scans, {} points, {} m voxels; wall at x = {WALL_X} m\n",
        scans.len(),
        scans.iter().map(|s| s.len()).sum::<usize>(),
        RESOLUTION
    );
    println!(
        "| operator | wall found (occupied) | ambiguous on the wall | occupied elsewhere | free |"
    );
    println!("|---|---|---|---|---|");
    for name in operators {
        let family: Family = name.parse()?;
        let config = FuzzyConfig::new(RESOLUTION)?.with_operator(TConorm::new(family)?);
        let mut map = FuzzyMap::new(config)?;
        for scan in &scans {
            map.integrate_cloud(scan, &IntegrationOptions::default())?;
        }
        // The wall band: voxels within one voxel of the wall plane (the noise spreads the
        // points over it), over the wall's 40 × 20 voxel extent.
        let wall_layer = (WALL_X / RESOLUTION).round() as i32;
        let mut found = vec![false; 40 * 20];
        let (mut band_ambiguous, mut elsewhere) = (0usize, 0usize);
        for (key, memberships) in map.cells() {
            let class = map.measure_config().classify(memberships);
            let (column, row) = (key.y + 20, key.z);
            let in_band = (key.x - wall_layer).abs() <= 1;
            if in_band && (0..40).contains(&column) && (0..20).contains(&row) {
                let cell = &mut found[(row * 40 + column) as usize];
                *cell |= class == VoxelClass::Occupied;
                band_ambiguous += usize::from(class == VoxelClass::Ambiguous);
            } else if class == VoxelClass::Occupied {
                elsewhere += 1;
            }
        }
        let counts = map.counts();
        let wall_found = found.iter().filter(|&&f| f).count() as f64 / found.len() as f64;
        println!(
            "| `{name}` | {:.1} % | {band_ambiguous} | {elsewhere} | {} |",
            100.0 * wall_found,
            counts.free,
        );
    }
    println!(
        "\nmax never adds views up: one view decides, and no voxel here reaches the free \
         threshold. The operators that add evidence up fastest (Łukasiewicz, Einstein) also \
         saturate both memberships on the noisy wall, so more of it is ambiguous. See \
         docs/operators.md for how to choose."
    );
    Ok(())
}
