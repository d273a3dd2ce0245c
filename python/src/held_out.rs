//! The held-out experiments on real data (`fuzzyvox rgbd`, `fuzzyvox mono`) as functions that
//! return the command's `--json` report as a dict.

use std::path::{Path, PathBuf};

use fuzzyvox_core::{AnyMap, Family, MapKind};
use fuzzyvox_eval::{HeldOutConfig, MonoConfig, PriorMap, run_mono, run_rgbd};
use pyo3::prelude::*;

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

/// The maps' settings from the keyword arguments both functions share.
#[allow(clippy::too_many_arguments)]
fn held_out_config(
    res: f64,
    model: &str,
    holdout: usize,
    pixel_step: u32,
    cast_range: f64,
    stop_at_ambiguous: bool,
    op: &str,
    cuts: u32,
    prior: Option<PathBuf>,
    prior_confidence: f32,
) -> PyResult<HeldOutConfig> {
    let operator: Family = op
        .parse()
        .map_err(|e| invalid(format!("operator {op:?}: {e}")))?;
    let models = kinds_of(model)?;
    if !models.contains(&MapKind::Fuzzy) && operator != Family::Product {
        return Err(invalid("op applies to the fuzzy model only"));
    }
    let config = HeldOutConfig {
        resolution: res,
        models,
        holdout,
        pixel_step,
        cast_range,
        stop_at_ambiguous,
        operator,
        cuts,
        prior: prior.map(|path| PriorMap {
            path,
            confidence: prior_confidence,
        }),
    };
    config.validate().or_raise()?;
    Ok(config)
}

/// Saves every map as ``DIR/MODEL.fvx``.
fn save_all(maps: &[AnyMap], dir: &Path) -> fuzzyvox_core::Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| fuzzyvox_core::Error::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    for map in maps {
        map.save(dir.join(format!("{}.fvx", map.kind().name())))?;
    }
    Ok(())
}

/// Runs ``fuzzyvox rgbd``: builds the maps from the sensor depth of the RGB-D folder ``dir``
/// (``frame-N.depth.png``, ``frame-N.pose.txt``, ``camera-intrinsics.txt``) at ``res`` metres
/// from every frame but every ``holdout``-th, ray-casts them into the held-out frames and
/// returns the report as a dict with the keys of ``fuzzyvox rgbd --json``. The keyword
/// arguments are the command's flags with their defaults; ``model`` is ``"all"``, a name, a
/// or comma-separated names; ``save`` writes every map there as
/// ``MODEL.fvx``. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    dir, res, model="all", holdout=5, pixel_step=1,
    cast_range=8.0, stop_at_ambiguous=false, op="product", cuts=10, prior=None,
    prior_confidence=0.5, save=None
))]
#[allow(clippy::too_many_arguments)]
pub fn rgbd<'py>(
    py: Python<'py>,
    dir: PathBuf,
    res: f64,
    model: &str,
    holdout: usize,
    pixel_step: u32,
    cast_range: f64,
    stop_at_ambiguous: bool,
    op: &str,
    cuts: u32,
    prior: Option<PathBuf>,
    prior_confidence: f32,
    save: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let config = held_out_config(
        res,
        model,
        holdout,
        pixel_step,
        cast_range,
        stop_at_ambiguous,
        op,
        cuts,
        prior,
        prior_confidence,
    )?;
    let run = py
        .detach(|| {
            let run = run_rgbd(&dir, &config, &mut |_, _, _| {})?;
            if let Some(save) = &save {
                save_all(&run.maps, save)?;
            }
            Ok::<_, fuzzyvox_core::Error>(run)
        })
        .or_raise()?;
    json_to_py(py, &run.report)
}

/// Runs ``fuzzyvox mono``: streams the posed colour images of ``dir`` (every frame but every
/// ``holdout``-th) through pair selection and the one-camera depth stage, builds the maps at
/// ``res`` metres from its depth images and checks them against the sensor depth of the
/// held-out frames; returns the report as a dict with the keys of ``fuzzyvox mono --json``.
/// The keyword arguments are the command's flags with their defaults (``views`` matched at
/// once, poses from a TUM ``trajectory``, ``extrinsics`` file of ``depth_from_color``, the
/// depth range ``near`` to ``far``, ``min_baseline`` of a pair); ``out`` writes every map there
/// as ``MODEL.fvx``. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    dir, res, model="all", holdout=5, pixel_step=1,
    cast_range=8.0, stop_at_ambiguous=false, op="product", cuts=10, prior=None,
    prior_confidence=0.5, views=2, trajectory=None, extrinsics=None, near=0.3, far=8.0,
    min_baseline=0.05, out=None
))]
#[allow(clippy::too_many_arguments)]
pub fn mono<'py>(
    py: Python<'py>,
    dir: PathBuf,
    res: f64,
    model: &str,
    holdout: usize,
    pixel_step: u32,
    cast_range: f64,
    stop_at_ambiguous: bool,
    op: &str,
    cuts: u32,
    prior: Option<PathBuf>,
    prior_confidence: f32,
    views: u32,
    trajectory: Option<PathBuf>,
    extrinsics: Option<PathBuf>,
    near: f64,
    far: f64,
    min_baseline: f64,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let config = MonoConfig {
        held_out: held_out_config(
            res,
            model,
            holdout,
            pixel_step,
            cast_range,
            stop_at_ambiguous,
            op,
            cuts,
            prior,
            prior_confidence,
        )?,
        views,
        trajectory,
        extrinsics,
        near,
        far,
        min_baseline,
    };
    config.validate().or_raise()?;
    let run = py
        .detach(|| {
            let run = run_mono(&dir, &config, &mut |_, _, _| {})?;
            if let Some(out) = &out {
                save_all(&run.maps, out)?;
            }
            Ok::<_, fuzzyvox_core::Error>(run)
        })
        .or_raise()?;
    json_to_py(py, &run.report)
}
