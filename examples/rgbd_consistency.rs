//! How well the frames of an RGB-D folder agree with each other, against the Kinect noise model.
//!
//! For frame pairs `gap` frames apart, every 4th pixel of the first frame is back-projected,
//! moved into the second camera with the two poses, and its depth compared with what the second
//! frame measured at that pixel (pairs more than 15 cm apart are different surfaces and are
//! skipped). Two independent readings of one surface differ by more than `2√2 σ(z)` in about 5 %
//! of pixels if the noise model (σ of `io::rgbd::kinect_sigma`) and the poses are right; a larger
//! share means the frames disagree beyond what the model admits, and maps built from them will
//! hold conflicting evidence near surfaces.
//!
//! Run: `cargo run --release --example rgbd_consistency [-- DIR]`
//! (default `../shared/data/rgbd-7scenes-redkitchen`).

use std::path::PathBuf;

use fuzzyvox::io::rgbd::{RgbdFolder, kinect_sigma};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).map_or_else(
        || PathBuf::from("../shared/data/rgbd-7scenes-redkitchen"),
        PathBuf::from,
    );
    let folder = RgbdFolder::open(&dir)?;
    for gap in [1usize, 5] {
        let (mut differences, mut beyond) = (Vec::new(), 0usize);
        for first in (0..folder.frames.len().saturating_sub(gap)).step_by(3) {
            let a = folder.read_kinect_frame(first)?;
            let b = folder.read_kinect_frame(first + gap)?;
            let (k, width) = (a.intrinsics(), a.intrinsics().width() as usize);
            let b_from_a = b.world_from_camera().inverse() * a.world_from_camera();
            for v in (0..k.height() as usize).step_by(4) {
                for u in (0..width).step_by(4) {
                    let z = a.image().depth()[v * width + u];
                    if !(z.is_finite() && z > 0.0) {
                        continue;
                    }
                    let p = b_from_a * k.back_project(u as f64, v as f64, f64::from(z));
                    let Some((ub, vb)) = b.intrinsics().pixel_of(&p) else {
                        continue;
                    };
                    let measured = b.image().depth()[vb as usize * width + ub as usize];
                    let difference = f64::from(measured) - p.z;
                    if measured > 0.0 && difference.abs() < 0.15 {
                        differences.push(difference.abs());
                        let sigma = f64::from(kinect_sigma(measured));
                        beyond += usize::from(difference.abs() > 2.0 * 2f64.sqrt() * sigma);
                    }
                }
            }
        }
        if differences.is_empty() {
            println!("{gap} frame(s) apart: no overlapping pixels");
            continue;
        }
        differences.sort_by(f64::total_cmp);
        let n = differences.len();
        println!(
            "{gap} frame(s) apart: {n} pixel pairs, |Δz| median {:.1} mm, 90th percentile {:.1} mm; \
             {:.1} % beyond 2√2σ",
            1e3 * differences[n / 2],
            1e3 * differences[n * 9 / 10],
            100.0 * beyond as f64 / n as f64
        );
    }
    Ok(())
}
