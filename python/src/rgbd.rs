//! RGB-D folders (the 7-Scenes / 3DMatch layout) as interval depth frames, for
//! `integrate_depth`.

use fuzzyvox_io::rgbd::RgbdFolder as RustFolder;
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{OrRaise, invalid};

/// An RGB-D folder: ``frame-N.depth.png`` (millimetres) with ``frame-N.pose.txt`` per frame and
/// ``camera-intrinsics.txt``. ``frame(i)`` reads frame ``i`` as Kinect depth with its noise
/// intervals, as a dict of ``integrate_depth``'s arguments: ``m.integrate_depth(**folder.frame(i))``.
#[pyclass(module = "fuzzyvox", frozen)]
pub struct RgbdFolder {
    inner: RustFolder,
}

#[pymethods]
impl RgbdFolder {
    #[new]
    fn new(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let inner = py.detach(|| RustFolder::open(&path)).or_raise()?;
        Ok(Self { inner })
    }

    /// The frames' numbers (the N of ``frame-N``), in order.
    #[getter]
    fn numbers(&self) -> Vec<u64> {
        self.inner.frames.iter().map(|f| f.number).collect()
    }

    fn __len__(&self) -> usize {
        self.inner.frames.len()
    }

    /// Frame ``index`` (its position, 0 first) as a dict: ``near``, ``value``, ``far`` and
    /// ``confidence`` as (H, W) float32 arrays (``P± = z ± 2σ(z)`` with Kinect's axial noise;
    /// 0 where the sensor has no depth), ``fx``, ``fy``, ``cx``, ``cy`` and the 4x4 ``pose``.
    fn frame<'py>(&self, py: Python<'py>, index: isize) -> PyResult<Bound<'py, PyDict>> {
        let n = self.inner.frames.len() as isize;
        let i = if index < 0 { index + n } else { index };
        if !(0..n).contains(&i) {
            return Err(invalid(format!(
                "frame index {index} is out of range for {n} frames"
            )));
        }
        let folder = &self.inner;
        let frame = py
            .detach(|| folder.read_kinect_frame(i as usize))
            .or_raise()?;
        let image = frame.image();
        let (w, h) = (image.width() as usize, image.height() as usize);
        let plane = |v: &[f32]| -> PyResult<_> {
            Array2::from_shape_vec((h, w), v.to_vec())
                .map(|a| a.into_pyarray(py))
                .map_err(|e| invalid(e.to_string()))
        };
        let d = PyDict::new(py);
        d.set_item("near", plane(image.near())?)?;
        d.set_item("value", plane(image.depth())?)?;
        d.set_item("far", plane(image.far())?)?;
        d.set_item("confidence", plane(image.confidence())?)?;
        let k = frame.intrinsics();
        d.set_item("fx", k.fx())?;
        d.set_item("fy", k.fy())?;
        d.set_item("cx", k.cx())?;
        d.set_item("cy", k.cy())?;
        let pose = frame.world_from_camera().to_homogeneous();
        let rows: Vec<f64> = (0..4)
            .flat_map(|r| (0..4).map(move |c| pose[(r, c)]))
            .collect();
        d.set_item(
            "pose",
            Array2::from_shape_vec((4, 4), rows)
                .map(|a| a.into_pyarray(py))
                .map_err(|e| invalid(e.to_string()))?,
        )?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "RgbdFolder({:?}, frames={})",
            self.inner.dir.display().to_string(),
            self.inner.frames.len()
        )
    }
}
