//! A scenario's frames on disk in the RGB-D folder layout (`frame-N.color.png`,
//! `frame-N.depth.png` with the true depth, `frame-N.pose.txt`, `camera-intrinsics.txt`), with
//! `pairs.txt` naming each stereo pair's frames: what `fuzzyvox simulate` writes, readable by
//! the RGB-D loaders and by anyone's own depth stage.

use std::fmt::Write as _;
use std::path::Path;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::file::write_atomic;
use fuzzyvox_io::rgbd_write::{
    write_depth_png_mm, write_gray_png, write_intrinsics_txt, write_pose_txt,
};

use super::scenario::Scenario;

/// Writes every pair's two views as frames `2i` (reference) and `2i + 1` (other), with the
/// sensor noise of `seed` (the same views the experiment runner renders), and `pairs.txt`.
/// `progress(done, total)` is called after each pair. Returns the number of frames written.
pub fn write_frames(
    dir: &Path,
    scenario: &Scenario,
    seed: u64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<usize> {
    let k = &scenario.intrinsics;
    write_intrinsics_txt(&dir.join("camera-intrinsics.txt"), k)?;
    let mut pairs = String::from("# reference_frame other_frame phase\n");
    let mut frames = 0;
    for (phase, range) in &scenario.phases {
        for index in range.clone() {
            let (Some(views), Some((reference, other))) =
                (scenario.render_pair(index, seed), scenario.pairs.get(index))
            else {
                continue;
            };
            for (side, (view, pose)) in views.iter().zip([reference, other]).enumerate() {
                let stem = format!("frame-{:06}", 2 * index + side);
                write_gray_png(
                    &dir.join(format!("{stem}.color.png")),
                    view.width,
                    view.height,
                    &view.image,
                )?;
                write_depth_png_mm(
                    &dir.join(format!("{stem}.depth.png")),
                    view.width,
                    view.height,
                    &view.depth,
                )?;
                write_pose_txt(&dir.join(format!("{stem}.pose.txt")), pose)?;
                frames += 1;
            }
            let _ = writeln!(pairs, "{} {} {phase}", 2 * index, 2 * index + 1);
            progress(index + 1, scenario.pairs.len());
        }
    }
    write_atomic(&dir.join("pairs.txt"), pairs.as_bytes())?;
    Ok(frames)
}
