//! Robot recordings (ROS 1 bags, ROS 2 MCAP bags) from Python: what a recording holds, and its
//! point clouds as posed scans ready for `integrate_cloud`.

use std::path::PathBuf;

use fuzzyvox_bag::{Bag, BagError, BagInfo, read_bag_scans};
use numpy::PyArray2;
use pyo3::prelude::*;

use crate::arrays;
use crate::errors::raise_class;
use crate::scenario::json_to_py;

/// A recording's error as the matching Python exception: a file that cannot be read
/// (missing, not a recording, damaged) is `fuzzyvox.MapFileError` (an `OSError`); a topic, a
/// transform or a message that does not give what was asked is `fuzzyvox.InvalidInputError`.
fn bag_error(error: BagError) -> PyErr {
    let class = match &error {
        BagError::Io { .. } | BagError::NotABag { .. } | BagError::Damaged { .. } => "MapFileError",
        _ => "InvalidInputError",
    };
    raise_class(class, error.to_string())
}

/// What a recording holds, as ``fuzzyvox info --bag`` prints it: a dict with ``format``
/// (``ros1`` or ``ros2``), ``topics`` (``name``, ``type``, ``count`` each), ``message_count``,
/// ``start_ns``, ``end_ns``, ``duration_s``, ``tf`` (every edge of the TF tree) and
/// ``tf_invalid``. ``path`` is a ROS 1 ``.bag``, an ``.mcap`` file or a ROS 2 bag folder.
#[pyfunction]
pub fn bag_info<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let info = py
        .detach(|| Bag::open(&path).and_then(|bag| BagInfo::of(&bag)))
        .map_err(bag_error)?;
    json_to_py(py, &info)
}

/// The ``sensor_msgs/PointCloud2`` messages on ``topic`` as scans: a list of
/// ``(points, origin)``, an (N, 3) float64 array in ``frame`` and the sensor's origin there,
/// one per cloud in stamp order, posed by the TF tree at each cloud's stamp (a cloud already
/// in ``frame`` needs no transform). Integrate each with
/// ``map.integrate_cloud(points, origin=origin)``.
#[pyfunction]
#[pyo3(signature = (path, topic, frame = "map"))]
#[allow(clippy::type_complexity)]
pub fn read_bag<'py>(
    py: Python<'py>,
    path: PathBuf,
    topic: &str,
    frame: &str,
) -> PyResult<Vec<(Bound<'py, PyArray2<f64>>, (f64, f64, f64))>> {
    let scans = py
        .detach(|| Bag::open(&path).and_then(|bag| read_bag_scans(&bag, topic, frame)))
        .map_err(bag_error)?;
    Ok(scans
        .scans
        .iter()
        .map(|scan| {
            let o = scan.origin();
            (arrays::points_out(py, scan.points()), (o.x, o.y, o.z))
        })
        .collect())
}
