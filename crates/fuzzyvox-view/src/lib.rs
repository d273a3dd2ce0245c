//! Seeing a map in 3D: [`page`] writes one self-contained HTML page per map (WebGL2, instanced
//! voxels, orbit/pan/zoom, class toggles, a legend with the measure's range, axes and a scale in
//! metres, trajectories and flights, hover to read a voxel) that opens offline by double click.
//! The page's script and markup live in `assets/` and are written by fuzzyvox alone.

pub mod page;
pub mod paths;

pub use page::{
    DEFAULT_MAX_FREE, PagePath, PageSummary, PathKind, ViewerOptions, escape_html, viewer_page,
    write_viewer_page,
};
pub use paths::{parse_paths, read_paths};
