//! Reading scans for `insert`: the format follows the file extension.

use std::path::Path;

use anyhow::Context;
use fuzzyvox::PointCloud;
use fuzzyvox::io::read_text_cloud;
use nalgebra::Point3;

/// The scans in `path`: one for a text cloud (`x y z [confidence]`, seen from `origin`).
pub fn read_scans(path: &Path, origin: Point3<f64>) -> anyhow::Result<Vec<PointCloud>> {
    let cloud = read_text_cloud(path, origin)
        .with_context(|| format!("reading the cloud {}", path.display()))?;
    Ok(vec![cloud])
}
