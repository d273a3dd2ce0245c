//! OctoMap itself, for the tests that check fuzzyvox against it: `scripts/octomap_check.cpp`
//! built against Debian's `liboctomap-dev`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Compiles `scripts/octomap_check.cpp` into the target directory, or returns `None` after
/// printing why when OctoMap is not installed (a failure with `FUZZYVOX_REQUIRE_OCTOMAP=1`).
pub fn octomap_tool(test: &str) -> Option<PathBuf> {
    let header = Path::new("/usr/include/octomap/octomap.h");
    let compiler = Command::new("g++")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !(compiler && header.exists()) {
        let why = format!(
            "{test}: OctoMap is not installed (g++ found: {compiler}, {} found: {}) \
             (apt-get install liboctomap-dev)",
            header.display(),
            header.exists()
        );
        assert!(
            std::env::var("FUZZYVOX_REQUIRE_OCTOMAP").as_deref() != Ok("1"),
            "FUZZYVOX_REQUIRE_OCTOMAP=1 but {why}"
        );
        eprintln!("SKIPPED {why}");
        return None;
    }
    // One binary per test: tests run in parallel, and running a binary while another test
    // rewrites it fails with "text file busy".
    let tool = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("octomap_check-{test}"));
    let source = super::repo_root().join("scripts/octomap_check.cpp");
    let output = Command::new("g++")
        .args(["-O2", "-std=c++17"])
        .arg(&source)
        .arg("-o")
        .arg(&tool)
        .args(["-loctomap", "-loctomath"])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "compiling {} failed:\n{}",
        source.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    Some(tool)
}

/// OctoMap's view of a `.bt` file: (nodes, leaves, occupied voxels, free voxels, resolution).
pub fn octomap_info(tool: &Path, file: &Path) -> (usize, usize, u64, u64, f64) {
    let output = Command::new(tool).arg("count").arg(file).output().unwrap();
    assert!(
        output.status.success(),
        "OctoMap could not read {}: {}",
        file.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    let line = String::from_utf8(output.stdout).unwrap();
    let json: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    let number = |key: &str| json[key].as_u64().unwrap();
    (
        number("nodes") as usize,
        number("leaves") as usize,
        number("occupied_voxels"),
        number("free_voxels"),
        json["resolution"].as_f64().unwrap(),
    )
}
