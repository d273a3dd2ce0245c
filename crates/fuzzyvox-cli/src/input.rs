//! Reading scans for `insert`: the format follows the file extension.

use std::path::Path;

use anyhow::Context;
use fuzzyvox::PointCloud;
use fuzzyvox::io::octomap::{read_scan_graph, read_scan_log};
use fuzzyvox::io::{read_scan_list, read_text_cloud};
use nalgebra::Point3;

/// The scans in `path`: every node of an OctoMap scan graph (`.graph`) or scan log (`.log`),
/// each from its own pose, every cloud of a scan list (`.list`: `CLOUD ox oy oz` per line), each
/// from its own origin, or one text cloud (`x y z [confidence]`) seen from `origin`.
pub fn read_scans(path: &Path, origin: Point3<f64>) -> anyhow::Result<Vec<PointCloud>> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let reading = || format!("reading {}", path.display());
    let nodes = match extension.as_deref() {
        Some("graph") => read_scan_graph(path).with_context(reading)?,
        Some("log") => read_scan_log(path).with_context(reading)?,
        Some("list") => return read_scan_list(path).with_context(reading),
        _ => return Ok(vec![read_text_cloud(path, origin).with_context(reading)?]),
    };
    nodes
        .iter()
        .map(|node| {
            node.to_cloud()
                .with_context(|| format!("scan node {} of {}", node.id, path.display()))
        })
        .collect()
}
