//! The held-out experiments on real data (`fuzzyvox rgbd`, `fuzzyvox mono`) as functions that
//! return the command's `--json` report as a dict.

use std::path::PathBuf;

use fuzzyvox_core::{Family, MapKind};
use fuzzyvox_eval::{
    HeldOutConfig, HeldOutRun, MonoConfig, PriorMap, RealFlightConfig, run_mono, run_rgbd,
    save_held_out_maps,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;

use crate::errors::{OrRaise, invalid};
use crate::scenario::json_to_py;

/// `model` as the command takes it: names of map kinds (``fuzzy``, ``logodds``, ``alpha``) or
/// ``all``, comma-separated.
fn kinds_of(model: &str) -> PyResult<Vec<MapKind>> {
    let mut kinds = Vec::new();
    for name in model.split(',') {
        if name.trim() == "all" {
            kinds.extend(MapKind::ALL);
        } else {
            kinds.push(name.parse::<MapKind>().or_raise()?);
        }
    }
    Ok(kinds)
}

/// Keyword arguments read one at a time, each with its default; any left over is refused, as
/// Python refuses an unexpected keyword.
struct Options<'py> {
    given: Option<Bound<'py, PyDict>>,
    read: Vec<&'static str>,
}

impl<'py> Options<'py> {
    fn new(given: Option<&Bound<'py, PyDict>>) -> Self {
        Self {
            given: given.cloned(),
            read: Vec::new(),
        }
    }

    /// The option `key`, or `default` when it is not given (or `None`).
    fn get<T: for<'a> FromPyObject<'a, 'py, Error = PyErr>>(
        &mut self,
        key: &'static str,
        default: T,
    ) -> PyResult<T> {
        self.read.push(key);
        match self
            .given
            .as_ref()
            .map(|d| d.get_item(key))
            .transpose()?
            .flatten()
        {
            Some(value) if !value.is_none() => value
                .extract()
                .map_err(|e| PyTypeError::new_err(format!("{key}: {e}"))),
            _ => Ok(default),
        }
    }

    /// Refuses the options nobody read.
    fn finish(self, function: &str) -> PyResult<()> {
        let Some(given) = self.given else {
            return Ok(());
        };
        for key in given.keys() {
            let key: String = key.extract()?;
            if !self.read.contains(&key.as_str()) {
                return Err(PyTypeError::new_err(format!(
                    "{function}() got an unexpected keyword argument '{key}'"
                )));
            }
        }
        Ok(())
    }
}

/// The maps' settings from the options both functions share (the flags of `rgbd`, with the
/// command's defaults).
fn held_out_config(res: f64, options: &mut Options) -> PyResult<HeldOutConfig> {
    let model: String = options.get("model", "all".to_string())?;
    let op: String = options.get("op", "product".to_string())?;
    let operator: Family = op
        .parse()
        .map_err(|e| invalid(format!("operator {op:?}: {e}")))?;
    let models = kinds_of(&model)?;
    let defaults = HeldOutConfig::new(res);
    let prior: Option<PathBuf> = options.get("prior", None)?;
    let prior_confidence = options.get("prior_confidence", 0.5f32)?;
    let config = HeldOutConfig {
        resolution: res,
        models,
        holdout: options.get("holdout", defaults.holdout)?,
        pixel_step: options.get("pixel_step", defaults.pixel_step)?,
        cast_range: options.get("cast_range", defaults.cast_range)?,
        stop_at_ambiguous: options.get("stop_at_ambiguous", defaults.stop_at_ambiguous)?,
        operator,
        cuts: options.get("cuts", defaults.cuts)?,
        evidence: defaults.evidence,
        prior: prior.map(|path| PriorMap {
            path,
            confidence: prior_confidence,
        }),
    };
    config.validate().or_raise()?;
    Ok(config)
}

/// Runs `run` with the GIL released, saves its maps into `save` when given, and returns its
/// report as a dict.
fn report_of<'py, R: Serialize + Send>(
    py: Python<'py>,
    save: Option<PathBuf>,
    run: impl FnOnce() -> fuzzyvox_core::Result<HeldOutRun<R>> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let run = py
        .detach(|| {
            let run = run()?;
            if let Some(dir) = &save {
                save_held_out_maps(dir, &run.maps)?;
            }
            Ok::<_, fuzzyvox_core::Error>(run)
        })
        .or_raise()?;
    json_to_py(py, &run.report)
}

/// Runs ``fuzzyvox rgbd``: builds the maps from the sensor depth of the RGB-D folder ``dir``
/// (``frame-N.depth.png``, ``frame-N.pose.txt``, ``camera-intrinsics.txt``) at ``res`` metres
/// from every frame but every ``holdout``-th, ray-casts them into the held-out frames and
/// returns the report as a dict with the keys of ``fuzzyvox rgbd --json``. The keyword options
/// are the command's flags with their defaults: ``model`` (``"all"``, a name or comma-separated
/// names), ``holdout`` (5), ``pixel_step`` (1), ``cast_range`` (8.0), ``stop_at_ambiguous``
/// (False), ``op`` (``"product"``), ``cuts`` (10), ``prior`` (None), ``prior_confidence``
/// (0.5); ``save`` writes every map there as ``MODEL.fvx``. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (dir, res, **options))]
pub fn rgbd<'py>(
    py: Python<'py>,
    dir: PathBuf,
    res: f64,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut options = Options::new(options);
    let config = held_out_config(res, &mut options)?;
    let save: Option<PathBuf> = options.get("save", None)?;
    options.finish("rgbd")?;
    report_of(py, save, || run_rgbd(&dir, &config, &mut |_, _, _| {}))
}

/// Runs ``fuzzyvox mono``: streams the posed colour images of ``dir`` (every frame but every
/// ``holdout``-th) through pair selection and the one-camera depth stage, builds the maps at
/// ``res`` metres from its depth images and checks them against the sensor depth of the
/// held-out frames; returns the report as a dict with the keys of ``fuzzyvox mono --json``.
/// The keyword options are those of :func:`rgbd` (but ``save``) and the command's own flags
/// with their defaults: ``views`` matched at once (2), poses from a TUM ``trajectory``, an
/// ``extrinsics`` file of ``depth_from_color``, the depth range ``near`` (0.3) to ``far`` (8.0),
/// ``min_baseline`` of a pair (0.05); ``plan`` flights through every map (``None``: none; as
/// ``fuzzyvox mono --plan``, with ``seed`` (1) and the vehicle's ``radius`` (0.2)); ``out``
/// writes every map there as ``MODEL.fvx``. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (dir, res, **options))]
pub fn mono<'py>(
    py: Python<'py>,
    dir: PathBuf,
    res: f64,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut options = Options::new(options);
    let held_out = held_out_config(res, &mut options)?;
    let defaults = MonoConfig::new(res);
    let config = MonoConfig {
        // The depth stage's checked images take the evidence model made for them.
        held_out: HeldOutConfig {
            evidence: defaults.held_out.evidence,
            ..held_out
        },
        views: options.get("views", defaults.views)?,
        trajectory: options.get("trajectory", None)?,
        extrinsics: options.get("extrinsics", None)?,
        near: options.get("near", defaults.near)?,
        far: options.get("far", defaults.far)?,
        min_baseline: options.get("min_baseline", defaults.min_baseline)?,
        consistency: {
            let mut check = defaults.consistency;
            check.neighbours = options.get("consistency", check.neighbours)?;
            check.min_agreeing = options.get("min_agreeing", check.min_agreeing)?;
            check
        },
        flights: None,
    };
    let plan: Option<usize> = options.get("plan", None)?;
    let config = MonoConfig {
        flights: match plan {
            Some(queries) => {
                let flights = RealFlightConfig::new(queries);
                Some(RealFlightConfig {
                    seed: options.get("seed", flights.seed)?,
                    vehicle_radius: options.get("radius", flights.vehicle_radius)?,
                    ..flights
                })
            }
            None => None,
        },
        ..config
    };
    let out: Option<PathBuf> = options.get("out", None)?;
    options.finish("mono")?;
    config.validate().or_raise()?;
    report_of(py, out, || run_mono(&dir, &config, &mut |_, _, _| {}))
}
