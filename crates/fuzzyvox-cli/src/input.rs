//! Reading scans for `insert`: a file whose format follows its extension, or a robot
//! recording's point-cloud topic.

use std::path::{Path, PathBuf};

use anyhow::Context;
use fuzzyvox::PointCloud;
use fuzzyvox::bag::{Bag, BagError, read_bag_scans};
use fuzzyvox::io::octomap::{read_scan_graph, read_scan_log};
use fuzzyvox::io::{read_scan_list, read_text_cloud};
use nalgebra::Point3;

/// Scans and where they came from.
pub struct Input {
    /// One cloud per scan, each from its own origin.
    pub scans: Vec<PointCloud>,
    /// The file or recording.
    pub source: PathBuf,
    /// Points a recording's clouds held with a coordinate that is not finite (not inserted).
    pub dropped_points: usize,
}

/// The scans of `cloud` (see [`read_scans`]) or of a recording's `(bag, topic)` carried into
/// `frame`; exactly one of the two is given.
pub fn read_input(
    cloud: Option<&Path>,
    origin: Point3<f64>,
    bag: Option<(&Path, &str)>,
    frame: &str,
) -> anyhow::Result<Input> {
    match (cloud, bag) {
        (Some(path), None) => Ok(Input {
            scans: read_scans(path, origin)?,
            source: path.to_path_buf(),
            dropped_points: 0,
        }),
        (None, Some((path, topic))) => {
            let reading = || format!("reading {}", path.display());
            let bag = Bag::open(path).with_context(reading)?;
            let scans = read_bag_scans(&bag, topic, frame)
                .map_err(|e| with_frame_hint(e, frame))
                .with_context(reading)?;
            Ok(Input {
                scans: scans.scans,
                source: path.to_path_buf(),
                dropped_points: scans.dropped_points,
            })
        }
        _ => anyhow::bail!("give --cloud or --bag with --topic"),
    }
}

/// A missing transform often means the clouds are meant to stay in their own frame: say how.
fn with_frame_hint(error: BagError, frame: &str) -> anyhow::Error {
    match &error {
        BagError::NoTransform { source_frame, .. } if source_frame != frame => anyhow::anyhow!(
            "{error} (to map in the clouds' own frame instead, give --frame {source_frame})"
        ),
        _ => error.into(),
    }
}

/// The scans in `path`: every node of an OctoMap scan graph (`.graph`) or scan log (`.log`),
/// each from its own pose, every cloud of a scan list (`.list`: `CLOUD ox oy oz` per line), each
/// from its own origin, or one text cloud (`x y z [confidence]`) seen from `origin`.
fn read_scans(path: &Path, origin: Point3<f64>) -> anyhow::Result<Vec<PointCloud>> {
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
