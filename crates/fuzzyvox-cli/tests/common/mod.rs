//! Helpers shared by the command's integration tests: the library tests' helpers (data,
//! scans, frames), running the command, and checks with a headless browser and OctoMap.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod browser;
pub mod octomap;

#[path = "../../../../tests/common/mod.rs"]
mod library;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

// Each test binary uses a few of these.
#[allow(unused_imports)]
pub use library::{Rng, data_dir, room_scan, wall_frame};

/// Runs the `fuzzyvox` binary built for these tests with `args`.
pub fn fuzzyvox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fuzzyvox"))
        .args(args)
        .output()
        .expect("running fuzzyvox")
}

/// The one JSON object a command printed on standard output; fails the test, showing the
/// command's standard error, when the command failed.
pub fn json(output: &Output) -> serde_json::Value {
    assert!(
        output.status.success(),
        "fuzzyvox failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("one JSON object on stdout")
}

/// The repository's root (the command's crate is `crates/fuzzyvox-cli` in it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Writes `cloud` (text, one point a line) as `dir/wall.xyz` and inserts it, as seen from
/// (0, 0, 0.5), into a fuzzy map at 0.1 m saved as `dir/wall.fvx`; returns the map's path.
pub fn insert_wall(dir: &Path, cloud: &str) -> PathBuf {
    let cloud_path = dir.join("wall.xyz");
    std::fs::write(&cloud_path, cloud).unwrap();
    let map = dir.join("wall.fvx");
    json(&fuzzyvox(&[
        "insert",
        "--cloud",
        cloud_path.to_str().unwrap(),
        "--res",
        "0.1",
        "--origin",
        "0,0,0.5",
        "--out",
        map.to_str().unwrap(),
        "--json",
    ]));
    map
}
