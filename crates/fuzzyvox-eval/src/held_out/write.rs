//! A held-out run's maps on disk, to look at: each map's native file, a top view and a viewer
//! page, with the camera's path.

use std::path::{Path, PathBuf};

use fuzzyvox_core::error::Result;
use fuzzyvox_core::map::AnyMap;
use fuzzyvox_figure::palette::PATH_OK;
use fuzzyvox_figure::{Overlay, View, ViewColor, ViewSpec, save_png, view_figure};
use fuzzyvox_view::{PagePath, PathKind, ViewerOptions, write_viewer_page};
use nalgebra::Point3;

/// Saves every map of a run into `dir` (made when missing) as `MODEL.fvx`; returns the files.
pub fn save_held_out_maps(dir: &Path, maps: &[AnyMap]) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|source| fuzzyvox_core::error::Error::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    maps.iter()
        .map(|map| {
            let native = dir.join(format!("{}.fvx", map.kind().name()));
            map.save(&native)?;
            Ok(native)
        })
        .collect()
}

/// Writes every map of a run into `dir` (made when missing): `MODEL.fvx`, `MODEL-top.png` (its
/// occupied voxels from above, coloured by height, with the camera's path, as `fuzzyvox export
/// --png --view top --color height` draws them) and `MODEL.html` (its 3D viewer page with the
/// camera's path). `title` names the run in the figures. Returns the files written.
pub fn write_held_out_maps(
    dir: &Path,
    title: &str,
    maps: &[AnyMap],
    cameras: &[Point3<f64>],
) -> Result<Vec<PathBuf>> {
    let mut files = save_held_out_maps(dir, maps)?;
    for map in maps {
        let name = map.kind().name();

        let top = dir.join(format!("{name}-top.png"));
        let camera = Overlay {
            points: cameras.iter().map(|p| [p.x, p.y]).collect(),
            color: PATH_OK,
            mark_start: true,
        };
        let figure = view_figure(
            map.as_map(),
            &ViewSpec::new(View::Top, ViewColor::Height),
            &format!("{title}, {name} map: occupied voxels by height, the camera's path"),
            vec![camera],
            1,
        )?;
        save_png(&figure, &top)?;
        files.push(top);

        let page = dir.join(format!("{name}.html"));
        let mut options = ViewerOptions::new(format!("{title}, {name} map"), name);
        options.color = ViewColor::Height;
        options.paths = vec![PagePath {
            name: "camera".into(),
            kind: PathKind::Trajectory,
            ok: true,
            points: cameras.iter().map(|p| [p.x, p.y, p.z]).collect(),
        }];
        write_viewer_page(map.as_map(), &options, &page)?;
        files.push(page);
    }
    Ok(files)
}
