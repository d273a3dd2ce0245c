//! The three maps as Python classes. They share every method but their constructors (a macro
//! writes the shared ones); `FuzzyMap` adds `operator` and `merge`.

use fuzzyvox_core::storage::BLOCK_CELLS;
use fuzzyvox_core::{
    AlphaConfig, AlphaCutMap as RustAlpha, AnyMap, DepthFrame, Family, FuzzyConfig,
    FuzzyMap as RustFuzzy, IntegrationOptions, IntegrationStats, IntervalDepthImage, KeyBox,
    LogOddsConfig, LogOddsMap as RustLogOdds, Memberships, PinholeIntrinsics, PointCloud, TConorm,
    VoxelClass, VoxelMap, pose_from_matrix,
};
use fuzzyvox_io::octomap::write_bt_max_likelihood;
use fuzzyvox_io::ply::{PlyEncoding, write_ply};
use nalgebra::Point3;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple, PyType};

use crate::arrays;
use crate::errors::{OrRaise, invalid};

/// The class names, in code order: `classes()` returns these codes.
pub const CLASS_NAMES: [&str; 4] = ["occupied", "free", "ambiguous", "unknown"];

/// A class given as a name or a code.
pub fn class_of(obj: &Bound<'_, PyAny>) -> PyResult<VoxelClass> {
    if let Ok(code) = obj.extract::<usize>() {
        return VoxelClass::ALL
            .get(code)
            .copied()
            .ok_or_else(|| invalid(format!("class code {code} is not one of 0..=3")));
    }
    let name: String = obj.extract().map_err(|_| {
        invalid("a class is a name (occupied, free, ambiguous, unknown) or a code 0..=3")
    })?;
    VoxelClass::ALL
        .iter()
        .copied()
        .find(|c| c.name() == name.trim().to_lowercase())
        .ok_or_else(|| {
            invalid(format!(
                "unknown class {name:?}: expected occupied, free, ambiguous or unknown"
            ))
        })
}

fn stats_dict<'py>(py: Python<'py>, stats: &IntegrationStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("integrated", stats.integrated)?;
    d.set_item("skipped", stats.skipped)?;
    d.set_item("clipped", stats.clipped)?;
    d.set_item("voxels_updated", stats.voxels_updated)?;
    Ok(d)
}

/// A Rust map as the Python object of its class.
pub fn wrap(py: Python<'_>, map: AnyMap) -> PyResult<Py<PyAny>> {
    Ok(match map {
        m @ AnyMap::Fuzzy(_) => Py::new(py, FuzzyMap { map: m })?.into_any(),
        m @ AnyMap::LogOdds(_) => Py::new(py, LogOddsMap { map: m })?.into_any(),
        m @ AnyMap::Alpha(_) => Py::new(py, AlphaCutMap { map: m })?.into_any(),
    })
}

/// Runs `f` on the map behind any of the three classes.
pub fn with_map<R>(obj: &Bound<'_, PyAny>, f: impl FnOnce(&AnyMap) -> R) -> PyResult<R> {
    if let Ok(m) = obj.cast::<FuzzyMap>() {
        return Ok(f(&m.borrow().map));
    }
    if let Ok(m) = obj.cast::<LogOddsMap>() {
        return Ok(f(&m.borrow().map));
    }
    if let Ok(m) = obj.cast::<AlphaCutMap>() {
        return Ok(f(&m.borrow().map));
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "expected a FuzzyMap, LogOddsMap or AlphaCutMap, got {}",
        obj.get_type().name()?
    )))
}

/// Per-point queries: each point's key, then `f` of its memberships (an error for a point
/// outside the key range or not finite).
fn per_point<T: Send>(
    py: Python<'_>,
    map: &AnyMap,
    points: &Bound<'_, PyAny>,
    f: impl Fn(&dyn VoxelMap, Memberships) -> T + Send + Sync,
) -> PyResult<Vec<T>> {
    let points = arrays::points(points, "points")?;
    py.detach(|| {
        let map = map.as_map();
        let resolution = map.resolution();
        points
            .iter()
            .map(|p| Ok(f(map, map.memberships_at(resolution.key_of(p)?))))
            .collect::<fuzzyvox_core::Result<Vec<T>>>()
    })
    .or_raise()
}

fn key_box(map: &AnyMap, lo: &Bound<'_, PyAny>, hi: &Bound<'_, PyAny>) -> PyResult<KeyBox> {
    let a = arrays::point(lo, "box corner lo")?;
    let b = arrays::point(hi, "box corner hi")?;
    KeyBox::from_points(&map.as_map().resolution(), &a, &b).or_raise()
}

macro_rules! map_class {
    ($name:ident, $pyname:literal, $doc:literal, { $($extra:tt)* }) => {
        #[doc = $doc]
        #[pyclass(name = $pyname, module = "fuzzyvox")]
        pub struct $name {
            pub(crate) map: AnyMap,
        }

        #[pymethods]
        impl $name {
            $($extra)*

            /// Voxel edge length in metres.
            #[getter]
            fn resolution(&self) -> f64 {
                self.map.as_map().resolution().size()
            }

            /// The map's kind: ``"fuzzy"``, ``"logodds"`` or ``"alpha"``.
            #[getter]
            fn kind(&self) -> &'static str {
                self.map.kind().name()
            }

            /// Integrates one point cloud as one scan and returns its statistics
            /// (``integrated``, ``skipped``, ``clipped``, ``voxels_updated``).
            ///
            /// ``points`` is an (N, 3) float64 array (read in place when it is one), ``origin``
            /// the sensor position, ``confidence`` an optional (N,) array in [0, 1] (1 for every point
            /// without one), ``max_range`` cuts longer rays. Points that are not finite are
            /// skipped and counted in ``skipped``, as in the Rust library. The GIL is released
            /// while the scan is integrated. On error the map is unchanged.
            #[pyo3(signature = (points, origin=None, confidence=None, max_range=None))]
            fn integrate_cloud<'py>(
                &mut self,
                py: Python<'py>,
                points: &Bound<'py, PyAny>,
                origin: Option<&Bound<'py, PyAny>>,
                confidence: Option<&Bound<'py, PyAny>>,
                max_range: Option<f64>,
            ) -> PyResult<Bound<'py, PyDict>> {
                let points = arrays::points(points, "points")?;
                let origin = match origin {
                    Some(o) => arrays::point(o, "origin")?,
                    None => Point3::origin(),
                };
                let n = points.len();
                let mut cloud = PointCloud::new(origin, points).or_raise()?;
                if let Some(c) = confidence {
                    cloud = cloud
                        .with_confidence(arrays::vector_f32(c, "confidence", n)?)
                        .or_raise()?;
                }
                let options = IntegrationOptions { max_range };
                let map = &mut self.map;
                let stats = py
                    .detach(|| map.as_map_mut().integrate_cloud(&cloud, &options))
                    .or_raise()?;
                stats_dict(py, &stats)
            }

            /// Integrates one interval depth image as one scan: ``near``, ``value`` (the depth),
            /// ``far`` and ``confidence`` are (H, W) float32 arrays (depth along the optical axis,
            /// metres; 0 or NaN marks a pixel without depth), ``fx, fy, cx, cy`` the pinhole
            /// intrinsics and ``pose`` the 4x4 world-from-camera matrix. Returns the statistics
            /// as ``integrate_cloud`` does.
            #[allow(clippy::too_many_arguments)]
            fn integrate_depth<'py>(
                &mut self,
                py: Python<'py>,
                near: &Bound<'py, PyAny>,
                value: &Bound<'py, PyAny>,
                far: &Bound<'py, PyAny>,
                confidence: &Bound<'py, PyAny>,
                fx: f64,
                fy: f64,
                cx: f64,
                cy: f64,
                pose: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyDict>> {
                let (h, w, near) = arrays::plane_f32(near, "near")?;
                let mut planes = Vec::new();
                for (plane, what) in [(value, "value"), (far, "far"), (confidence, "confidence")] {
                    let (ph, pw, v) = arrays::plane_f32(plane, what)?;
                    if (ph, pw) != (h, w) {
                        return Err(invalid(format!(
                            "{what} has shape ({ph}, {pw}), near has ({h}, {w})"
                        )));
                    }
                    planes.push(v);
                }
                let (Ok(width), Ok(height)) = (u32::try_from(w), u32::try_from(h)) else {
                    return Err(invalid("the depth image is too large"));
                };
                let confidence = planes.pop().unwrap_or_default();
                let far = planes.pop().unwrap_or_default();
                let value = planes.pop().unwrap_or_default();
                let pose = pose_from_matrix(&arrays::matrix4(pose, "pose")?).or_raise()?;
                let intrinsics = PinholeIntrinsics::new(width, height, fx, fy, cx, cy).or_raise()?;
                let image = IntervalDepthImage::new(width, height, near, value, far, confidence)
                    .or_raise()?;
                let frame = DepthFrame::new(intrinsics, pose, image).or_raise()?;
                let map = &mut self.map;
                let stats = py
                    .detach(|| {
                        map.as_map_mut()
                            .integrate_depth(&frame, &IntegrationOptions::default())
                    })
                    .or_raise()?;
                stats_dict(py, &stats)
            }

            /// The memberships (occupied μO, free μE) at each point: an (N, 2) float32 array.
            fn memberships<'py>(
                &self,
                py: Python<'py>,
                points: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray2<f32>>> {
                let m = per_point(py, &self.map, points, |_, m| [m.occupied, m.free])?;
                Ok(arrays::rows_out(py, m.into_iter().flatten().collect(), 2))
            }

            /// The ambiguity ``T(μO, μE)`` at each point: an (N,) float32 array.
            fn ambiguity<'py>(
                &self,
                py: Python<'py>,
                points: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f32>>> {
                let v = per_point(py, &self.map, points, |map, m| {
                    map.measure_config().measures(m).ambiguity
                })?;
                Ok(arrays::vector_out(py, v))
            }

            /// The indeterminacy ``T(1 - μO, 1 - μE)`` at each point: an (N,) float32 array.
            fn indeterminacy<'py>(
                &self,
                py: Python<'py>,
                points: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f32>>> {
                let v = per_point(py, &self.map, points, |map, m| {
                    map.measure_config().measures(m).indeterminacy
                })?;
                Ok(arrays::vector_out(py, v))
            }

            /// The safety at each point (very free, not occupied, not ambiguous, not unknown):
            /// an (N,) float32 array in [0, 1].
            fn safety<'py>(
                &self,
                py: Python<'py>,
                points: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f32>>> {
                let v = per_point(py, &self.map, points, |map, m| {
                    map.measure_config().measures(m).safety
                })?;
                Ok(arrays::vector_out(py, v))
            }

            /// The class at each point: an (N,) int8 array of codes (0 occupied, 1 free,
            /// 2 ambiguous, 3 unknown; ``fuzzyvox.CLASS_NAMES`` in code order), or with
            /// ``names=True`` a list of those names.
            #[pyo3(signature = (points, names=false))]
            fn classes<'py>(
                &self,
                py: Python<'py>,
                points: &Bound<'py, PyAny>,
                names: bool,
            ) -> PyResult<Bound<'py, PyAny>> {
                let v = per_point(py, &self.map, points, |map, m| map.measure_config().classify(m))?;
                if names {
                    let names: Vec<&str> = v.iter().map(|c| c.name()).collect();
                    return Ok(PyList::new(py, names)?.into_any());
                }
                let codes: Vec<i8> = v.iter().map(|c| c.index() as i8).collect();
                Ok(arrays::vector_out(py, codes).into_any())
            }

            /// Whether any voxel of the box with corners ``lo`` and ``hi`` (world coordinates)
            /// is of class ``cls`` (a name or a code). Voxels never observed are unknown.
            fn any_in_box(
                &self,
                py: Python<'_>,
                lo: &Bound<'_, PyAny>,
                hi: &Bound<'_, PyAny>,
                cls: &Bound<'_, PyAny>,
            ) -> PyResult<bool> {
                let region = key_box(&self.map, lo, hi)?;
                let class = class_of(cls)?;
                let map = &self.map;
                Ok(py.detach(|| map.as_map().any_in_box(&region, class)))
            }

            /// Voxel counts per class (a dict keyed by class name) over the box with corners
            /// ``lo`` and ``hi``; every voxel of the box is counted, unobserved ones as unknown.
            fn counts_in_box<'py>(
                &self,
                py: Python<'py>,
                lo: &Bound<'py, PyAny>,
                hi: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyDict>> {
                let region = key_box(&self.map, lo, hi)?;
                if region.voxel_count() > 1 << 31 {
                    return Err(invalid(format!(
                        "the box holds {} voxels; at most 2^31 are counted",
                        region.voxel_count()
                    )));
                }
                let map = &self.map;
                let counts = py.detach(|| {
                    let map = map.as_map();
                    let config = map.measure_config();
                    let mut counts = [0usize; 4];
                    let mut cells = [Memberships::default(); BLOCK_CELLS];
                    for block in region.blocks() {
                        map.block_memberships(block, &mut cells);
                        let whole = region.covers_block(block);
                        for (i, m) in cells.iter().enumerate() {
                            if whole || region.contains(block.voxel(i)) {
                                counts[config.classify(*m).index()] += 1;
                            }
                        }
                    }
                    counts
                });
                let d = PyDict::new(py);
                for (name, n) in CLASS_NAMES.iter().zip(counts) {
                    d.set_item(name, n)?;
                }
                Ok(d)
            }

            /// The centres of the observed voxels of class ``cls`` (a name or a code), as an
            /// (M, 3) float64 array in storage order; with ``lo`` and ``hi``, only those inside
            /// that box.
            #[pyo3(signature = (cls, lo=None, hi=None))]
            fn centres<'py>(
                &self,
                py: Python<'py>,
                cls: &Bound<'py, PyAny>,
                lo: Option<&Bound<'py, PyAny>>,
                hi: Option<&Bound<'py, PyAny>>,
            ) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let class = class_of(cls)?;
                let region = match (lo, hi) {
                    (Some(lo), Some(hi)) => Some(key_box(&self.map, lo, hi)?),
                    (None, None) => None,
                    _ => return Err(invalid("give both box corners lo and hi, or neither")),
                };
                let map = &self.map;
                let flat: Vec<f64> = py.detach(|| {
                    let map = map.as_map();
                    let config = map.measure_config();
                    let resolution = map.resolution();
                    map.cells()
                        .filter(|(k, m)| {
                            config.classify(*m) == class
                                && region.as_ref().is_none_or(|r| r.contains(*k))
                        })
                        .flat_map(|(k, _)| {
                            let c = resolution.center(k);
                            [c.x, c.y, c.z]
                        })
                        .collect()
                });
                Ok(arrays::rows_out(py, flat, 3))
            }

            /// Every observed voxel (one some evidence reached), in storage order: its centre,
            /// an (M, 3) float64 array, and its memberships (μO, μE), an (M, 2) float32 array.
            #[allow(clippy::type_complexity)]
            fn voxels<'py>(
                &self,
                py: Python<'py>,
            ) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f32>>) {
                let map = &self.map;
                let (centres, memberships): (Vec<[f64; 3]>, Vec<[f32; 2]>) = py.detach(|| {
                    let map = map.as_map();
                    let resolution = map.resolution();
                    map.cells()
                        .map(|(k, m)| {
                            let c = resolution.center(k);
                            ([c.x, c.y, c.z], [m.occupied, m.free])
                        })
                        .unzip()
                });
                (
                    arrays::rows_out(py, centres.into_iter().flatten().collect(), 3),
                    arrays::rows_out(py, memberships.into_iter().flatten().collect(), 2),
                )
            }

            /// Centres of the occupied voxels: an (M, 3) float64 array.
            fn occupied_centres<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                self.centres(py, &CLASS_NAMES[0].into_pyobject(py)?.into_any(), None, None)
            }

            /// Centres of the free voxels: an (M, 3) float64 array.
            fn free_centres<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                self.centres(py, &CLASS_NAMES[1].into_pyobject(py)?.into_any(), None, None)
            }

            /// Voxel counts per class over the allocated blocks: a dict keyed by class name.
            fn counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let c = self.map.as_map().counts();
                let d = PyDict::new(py);
                d.set_item("occupied", c.occupied)?;
                d.set_item("free", c.free)?;
                d.set_item("ambiguous", c.ambiguous)?;
                d.set_item("unknown", c.unknown)?;
                Ok(d)
            }

            /// Heap memory the map holds, in bytes.
            fn memory_bytes(&self) -> usize {
                self.map.as_map().memory_bytes()
            }

            /// The map as the bytes of a native ``.fvx`` file.
            fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
                let map = &self.map;
                let bytes = py.detach(|| map.to_bytes());
                PyBytes::new(py, &bytes)
            }

            /// A map of this class from the bytes of a native file (``to_bytes``).
            #[classmethod]
            fn from_bytes(_cls: &Bound<'_, PyType>, py: Python<'_>, data: &[u8]) -> PyResult<Self> {
                let data = data.to_vec();
                let map = py.detach(|| AnyMap::from_bytes_of_kind(&data, $pyname)).or_raise()?;
                Ok(Self { map })
            }

            /// Saves the map atomically as a native ``.fvx`` file.
            fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
                let map = &self.map;
                py.detach(|| map.save(&path)).or_raise()
            }

            /// Loads a native ``.fvx`` file holding a map of this class.
            #[classmethod]
            fn load(_cls: &Bound<'_, PyType>, py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
                let map = py
                    .detach(|| {
                        let bytes = std::fs::read(&path).map_err(|source| fuzzyvox_core::Error::Io {
                            path: path.clone(),
                            source,
                        })?;
                        AnyMap::from_bytes_of_kind(&bytes, $pyname).map_err(|e| match e {
                            fuzzyvox_core::Error::Format { reason, .. } => {
                                fuzzyvox_core::Error::Format { path: path.clone(), reason }
                            }
                            other => other,
                        })
                    })
                    .or_raise()?;
                Ok(Self { map })
            }

            /// Writes an OctoMap binary tree (``.bt``, maximum likelihood) that OctoMap's tools
            /// read; returns (occupied, free) leaf counts.
            fn export_bt(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<(usize, usize)> {
                let map = &self.map;
                py.detach(|| write_bt_max_likelihood(&path, map.as_map())).or_raise()
            }

            /// Writes one PLY vertex per observed voxel centre of the given classes (names or
            /// codes; occupied by default), coloured by class; returns the number of vertices.
            #[pyo3(signature = (path, classes=None, ascii=false))]
            fn export_ply(
                &self,
                py: Python<'_>,
                path: std::path::PathBuf,
                classes: Option<Vec<Bound<'_, PyAny>>>,
                ascii: bool,
            ) -> PyResult<usize> {
                let classes = match classes {
                    Some(list) => list.iter().map(class_of).collect::<PyResult<Vec<_>>>()?,
                    None => vec![VoxelClass::Occupied],
                };
                let encoding = if ascii { PlyEncoding::Ascii } else { PlyEncoding::BinaryLittleEndian };
                let map = &self.map;
                py.detach(|| write_ply(map.as_map(), &classes, encoding, &path)).or_raise()
            }

            /// A deep copy.
            fn copy(&self) -> Self {
                Self { map: self.map.clone() }
            }

            fn __copy__(&self) -> Self {
                self.copy()
            }

            fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
                self.copy()
            }

            /// Pickles through the native file bytes.
            fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
                let py = slf.py();
                let bytes = slf.borrow().to_bytes(py);
                let rebuild = slf.get_type().getattr("from_bytes")?;
                PyTuple::new(py, [rebuild, PyTuple::new(py, [bytes])?.into_any()])
            }

            fn __repr__(&self) -> String {
                let c = self.map.as_map().counts();
                format!(
                    "{}(resolution={}, occupied={}, free={}, ambiguous={})",
                    $pyname,
                    self.map.as_map().resolution().size(),
                    c.occupied,
                    c.free,
                    c.ambiguous
                )
            }
        }
    };
}

/// Decoding a map of a known class.
trait FromBytesOfKind: Sized {
    fn from_bytes_of_kind(bytes: &[u8], class: &str) -> fuzzyvox_core::Result<Self>;
}

impl FromBytesOfKind for AnyMap {
    fn from_bytes_of_kind(bytes: &[u8], class: &str) -> fuzzyvox_core::Result<Self> {
        Ok(match class {
            "FuzzyMap" => AnyMap::Fuzzy(RustFuzzy::from_bytes(bytes)?),
            "LogOddsMap" => AnyMap::LogOdds(RustLogOdds::from_bytes(bytes)?),
            _ => AnyMap::Alpha(RustAlpha::from_bytes(bytes)?),
        })
    }
}

/// Parses a t-conorm given as ``NAME`` or ``NAME:PARAM``.
pub fn operator_of(text: &str) -> PyResult<TConorm> {
    let family: Family = text
        .parse()
        .map_err(|e| invalid(format!("operator {text:?}: {e}")))?;
    TConorm::new(family).map_err(|e| invalid(format!("operator {text:?}: {e}")))
}

map_class!(
    FuzzyMap,
    "FuzzyMap",
    "The dual-set fuzzy map: per voxel how occupied (μO) and how free (μE), each aggregated \
     from evidence with a t-conorm ``op`` (``\"product\"``, the probabilistic sum, by default; \
     any name of ``fuzzyvox.operators()``, with a parameter as ``\"dombi:2\"``).\n\n\
     ``FuzzyMap(res, op=\"product\")`` makes an empty map of voxels ``res`` metres wide.",
    {
        #[new]
        #[pyo3(signature = (res, op="product"))]
        fn new(res: f64, op: &str) -> PyResult<Self> {
            let config = FuzzyConfig::new(res)
                .or_raise()?
                .with_operator(operator_of(op)?);
            Ok(Self {
                map: AnyMap::Fuzzy(RustFuzzy::new(config).or_raise()?),
            })
        }

        /// The aggregation t-conorm, as ``NAME`` or ``NAME:PARAM`` (``fuzzyvox.parse_operator``
        /// reads it back).
        #[getter]
        fn operator(&self) -> String {
            match &self.map {
                AnyMap::Fuzzy(m) => m.operator().family().to_string(),
                _ => String::new(),
            }
        }

        /// Merges another fuzzy map of the same resolution and operator into this one, voxel by
        /// voxel with the t-conorm: the result equals integrating both maps' scans into one map.
        fn merge(&mut self, py: Python<'_>, other: &Bound<'_, FuzzyMap>) -> PyResult<()> {
            let other = other
                .try_borrow()
                .map_err(|_| invalid("a map cannot be merged into itself"))?;
            let (AnyMap::Fuzzy(this), AnyMap::Fuzzy(that)) = (&mut self.map, &other.map) else {
                return Err(invalid("merge takes two fuzzy maps"));
            };
            py.detach(|| this.merge(that)).or_raise()
        }
    }
);

map_class!(
    LogOddsMap,
    "LogOddsMap",
    "The standard log-odds occupancy map (OctoMap's update rule and defaults), a baseline.\n\n\
     ``LogOddsMap(res)`` makes an empty map of voxels ``res`` metres wide.",
    {
        #[new]
        fn new(res: f64) -> PyResult<Self> {
            let config = LogOddsConfig::new(res).or_raise()?;
            Ok(Self {
                map: AnyMap::LogOdds(RustLogOdds::new(config).or_raise()?),
            })
        }
    }
);

map_class!(
    AlphaCutMap,
    "AlphaCutMap",
    "The alpha-cut map: a log-odds map that integrates each confidence-weighted scan as \
     ``cuts`` nested crisp cuts, a baseline.\n\n\
     ``AlphaCutMap(res, cuts=10)`` makes an empty map of voxels ``res`` metres wide.",
    {
        #[new]
        #[pyo3(signature = (res, cuts=10))]
        fn new(res: f64, cuts: u32) -> PyResult<Self> {
            let mut config = AlphaConfig::new(res).or_raise()?;
            config.cuts = cuts;
            Ok(Self {
                map: AnyMap::Alpha(RustAlpha::new(config).or_raise()?),
            })
        }

        /// Number of nested confidence cuts.
        #[getter]
        fn cuts(&self) -> u32 {
            match &self.map {
                AnyMap::Alpha(m) => m.config().cuts,
                _ => 0,
            }
        }
    }
);
