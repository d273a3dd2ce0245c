//! Helpers shared by the command's integration tests: the library tests' helpers (data,
//! scans, frames), running the command, and checks with a headless browser and OctoMap.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod browser;
pub mod octomap;

#[path = "../../../../tests/common/mod.rs"]
mod library;

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
