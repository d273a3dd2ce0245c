//! Integrates a very large point cloud, streamed in chunks, and reports the process's peak
//! memory: the map's memory depends on the space observed, not on the number of points, so ten
//! million points need no more memory than one million.
//!
//! A simulated scanner moves around a 30 m × 30 m × 5 m hall with pillars; each chunk is one
//! sweep of `CHUNK` rays from one position. Only one chunk exists at a time.
//!
//! ```sh
//! cargo run --release --example large_cloud                      # 10,000,000 points
//! cargo run --release --example large_cloud -- 1000000 100000 0.1
//! ```
//!
//! Arguments: total points (default 10,000,000), points per chunk (default 100,000), resolution
//! in metres (default 0.1).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::VoxelMapMut;
use std::time::Instant;

use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud};
use nalgebra::{Point3, Vector3};

/// SplitMix64: a small deterministic generator, so the example needs no extra crate.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The hall: walls at x, y = ±15 m, floor at 0, ceiling at 5 m, and square pillars 1 m wide
/// on a 6 m grid.
fn hit(origin: &Point3<f64>, direction: &Vector3<f64>) -> f64 {
    let mut t = f64::INFINITY;
    for axis in 0..3 {
        let (lo, hi) = if axis == 2 { (0.0, 5.0) } else { (-15.0, 15.0) };
        let d = direction[axis];
        if d > 1e-12 {
            t = t.min((hi - origin[axis]) / d);
        } else if d < -1e-12 {
            t = t.min((lo - origin[axis]) / d);
        }
    }
    for px in [-12.0, -6.0, 0.0, 6.0, 12.0] {
        for py in [-12.0, -6.0, 0.0, 6.0, 12.0] {
            // Slab test against the pillar's square cross-section (full height).
            let (mut near, mut far) = (0.0f64, t);
            for (axis, centre) in [(0, px), (1, py)] {
                let d = direction[axis];
                let (lo, hi) = (centre - 0.5, centre + 0.5);
                if d.abs() < 1e-12 {
                    if origin[axis] < lo || origin[axis] > hi {
                        near = f64::INFINITY;
                    }
                    continue;
                }
                let (a, b) = ((lo - origin[axis]) / d, (hi - origin[axis]) / d);
                near = near.max(a.min(b));
                far = far.min(a.max(b));
            }
            if near <= far && near > 0.0 {
                t = t.min(near);
            }
        }
    }
    t
}

/// One sweep of `rays` rays from a position on a loop around the hall.
fn sweep(index: usize, rays: usize, rng: &mut Rng) -> PointCloud {
    let angle = index as f64 * 0.37;
    let origin = Point3::new(9.0 * angle.cos(), 9.0 * angle.sin(), 1.5);
    let mut points = Vec::with_capacity(rays);
    let mut confidence = Vec::with_capacity(rays);
    for _ in 0..rays {
        let theta = rng.uniform(0.0, std::f64::consts::TAU);
        let z = rng.uniform(-0.6, 0.6);
        let r = (1.0 - z * z).sqrt();
        let direction = Vector3::new(r * theta.cos(), r * theta.sin(), z);
        let range = hit(&origin, &direction) + rng.uniform(-0.02, 0.02);
        points.push(origin + direction * range);
        confidence.push((1.0 - range / 40.0).clamp(0.05, 1.0) as f32);
    }
    PointCloud::new(origin, points)
        .and_then(|cloud| cloud.with_confidence(confidence))
        .expect("finite origin and confidences in [0, 1]")
}

/// The process's peak resident memory so far (`VmHWM`), in MiB, where `/proc` has it.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let total: usize = args.next().map_or(Ok(10_000_000), |a| a.parse())?;
    let chunk: usize = args.next().map_or(Ok(100_000), |a| a.parse())?;
    let resolution: f64 = args.next().map_or(Ok(0.1), |a| a.parse())?;
    if chunk == 0 {
        return Err("the chunk size must be positive".into());
    }
    let mut map = FuzzyMap::new(FuzzyConfig::new(resolution)?)?;
    let options = IntegrationOptions::default();
    let mut rng = Rng(7);
    let started = Instant::now();
    let (mut done, mut index) = (0usize, 0usize);
    let mut integrated = 0usize;
    while done < total {
        let rays = chunk.min(total - done);
        let cloud = sweep(index, rays, &mut rng);
        integrated += map.integrate_cloud(&cloud, &options)?.integrated;
        done += rays;
        index += 1;
        if index % 20 == 0 || done == total {
            println!(
                "{done:>11} points in {index:>4} chunks, {:>7.1} s, peak RSS {:.0} MiB, map {:.0} MiB",
                started.elapsed().as_secs_f64(),
                peak_rss_mib().unwrap_or(f64::NAN),
                map.memory_bytes() as f64 / (1 << 20) as f64,
            );
        }
    }
    let counts = map.counts();
    println!(
        "integrated {integrated} points in chunks of {chunk} at {resolution} m in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    println!(
        "map: {} occupied, {} free voxels, {:.1} MiB",
        counts.occupied,
        counts.free,
        map.memory_bytes() as f64 / (1 << 20) as f64
    );
    match peak_rss_mib() {
        Some(peak) => println!("peak RSS (VmHWM): {peak:.1} MiB"),
        None => println!("peak RSS: unavailable (no /proc/self/status)"),
    }
    Ok(())
}
