//! The viewer page: one self-contained HTML file (no server, no network, nothing to install)
//! that draws a map's voxels in 3D with WebGL2.
//!
//! The page carries the voxels as packed 16-byte records in base64 (`u16` index per axis
//! relative to the map's lowest voxel, the occupied and free memberships, ambiguity and safety
//! as `u16` fractions of 65535, the class), sorted by class so that each class is one instanced
//! draw call. Occupied and ambiguous voxels are all kept; free and unknown voxels, which can be
//! millions, are subsampled to [`ViewerOptions::max_free`] each by a hash of their key (the
//! same voxels on every run) and hidden until the reader shows them. The page logs
//! `fuzzyvox-view ready` to the console once its first frame is drawn.

use std::path::Path;

use base64::Engine as _;
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_core::storage::VoxelKey;
use fuzzyvox_figure::ViewColor;
use fuzzyvox_figure::palette::{
    PATH_COLLIDES, PATH_OK, PATH_OTHER, PATH_TRAJECTORY, VIRIDIS, class_color,
};
use serde::Serialize;
use serde_json::json;

const TEMPLATE: &str = include_str!("assets/viewer.html");
const SCRIPT: &str = include_str!("assets/viewer.js");

/// Bytes per voxel record.
pub const RECORD_BYTES: usize = 16;

/// Default cap on free (and on unknown) voxels written to a page.
pub const DEFAULT_MAX_FREE: usize = 300_000;

/// What kind of line a [`PagePath`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PathKind {
    /// Where the camera flew.
    Trajectory,
    /// A planned flight.
    Flight,
}

/// A line drawn over the map: the camera's trajectory or a planned flight.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PagePath {
    /// Its name in the legend.
    pub name: String,
    /// Trajectory or flight.
    pub kind: PathKind,
    /// For a flight, whether it stays clear of the scene (drawn red when not).
    pub ok: bool,
    /// Its points (x, y, z in metres).
    pub points: Vec<[f64; 3]>,
}

/// How the page shows the map.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewerOptions {
    /// The page's title.
    pub title: String,
    /// The model's name (`fuzzy`, `logodds`, `alpha`, `octomap-bt`, ...).
    pub model: String,
    /// The colour mode the page opens with (the reader can change it).
    pub color: ViewColor,
    /// At most this many free voxels, and half as many unknown ones, are written (a hash of
    /// the key picks them).
    pub max_free: usize,
    /// Whether free voxels are shown when the page opens.
    pub show_free: bool,
    /// Lines drawn over the map.
    pub paths: Vec<PagePath>,
}

impl ViewerOptions {
    /// Options with a title and the defaults: coloured by class, up to
    /// [`DEFAULT_MAX_FREE`] free voxels, hidden at first, no paths.
    pub fn new(title: impl Into<String>, model: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            model: model.into(),
            color: ViewColor::Class,
            max_free: DEFAULT_MAX_FREE,
            show_free: false,
            paths: Vec::new(),
        }
    }
}

/// What a page holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct PageSummary {
    /// Voxels written per class (occupied, free, ambiguous, unknown).
    pub drawn: [usize; 4],
    /// Voxels of each class in the map.
    pub total: [usize; 4],
    /// Size of the page in bytes.
    pub bytes: usize,
}

/// The page's name for a colour mode.
fn color_name(color: ViewColor) -> &'static str {
    match color {
        ViewColor::Class => "class",
        ViewColor::Height => "height",
        ViewColor::Occupied => "occupied",
        ViewColor::Free => "free",
        ViewColor::Ambiguity => "ambiguity",
        ViewColor::Safety => "safety",
    }
}

/// A fixed integer hash of a key (SplitMix64 finaliser), so that subsampling picks the same
/// voxels on every run and spreads them evenly.
fn key_hash(key: VoxelKey) -> u64 {
    let mut z =
        (u64::from(key.x as u32) << 42) ^ (u64::from(key.y as u32) << 21) ^ u64::from(key.z as u32);
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Builds the page for `map`. Fails when the map spans more than 65,536 voxels along an axis
/// (the page's indices are 16-bit) or an option is out of range.
pub fn viewer_page(map: &dyn VoxelMap, options: &ViewerOptions) -> Result<(String, PageSummary)> {
    if options.max_free == 0 {
        return Err(Error::InvalidParameter {
            name: "max free voxels",
            value: 0.0,
            expected: "at least 1",
        });
    }
    for p in &options.paths {
        if p.points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "path point",
                value: f64::NAN,
            });
        }
    }
    let config = map.measure_config();
    let mut by_class: [Vec<(VoxelKey, [u16; 4])>; 4] = Default::default();
    let quantise = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
    for (key, m) in map.cells() {
        let measures = config.measures(m);
        by_class[measures.class.index()].push((
            key,
            [
                quantise(measures.occupied),
                quantise(measures.free),
                quantise(measures.ambiguity),
                quantise(measures.safety),
            ],
        ));
    }
    let total = by_class.each_ref().map(Vec::len);
    // Free and unknown voxels beyond the cap: keep those whose hash falls in the first
    // `max_free / total` of the hash range.
    for (class, cap) in [
        (VoxelClass::Free, options.max_free),
        (VoxelClass::Unknown, options.max_free.div_ceil(2)),
    ] {
        let voxels = &mut by_class[class.index()];
        if voxels.len() > cap {
            let keep = (cap as u128 * u128::from(u64::MAX) / voxels.len() as u128) as u64;
            voxels.retain(|(k, _)| key_hash(*k) <= keep);
            voxels.sort_unstable_by_key(|(k, _)| key_hash(*k));
            voxels.truncate(cap);
        }
    }
    for voxels in &mut by_class {
        voxels.sort_unstable_by_key(|(k, _)| (k.z, k.y, k.x));
    }
    let all = || by_class.iter().flatten();
    let lo = all().fold([i32::MAX; 3], |lo, (k, _)| {
        [lo[0].min(k.x), lo[1].min(k.y), lo[2].min(k.z)]
    });
    let hi = all().fold([i32::MIN; 3], |hi, (k, _)| {
        [hi[0].max(k.x), hi[1].max(k.y), hi[2].max(k.z)]
    });
    let count: usize = by_class.iter().map(Vec::len).sum();
    if count > 0 && (0..3).any(|a| i64::from(hi[a]) - i64::from(lo[a]) > i64::from(u16::MAX)) {
        return Err(Error::InvalidParameter {
            name: "voxels along an axis",
            value: (0..3)
                .map(|a| f64::from(hi[a]) - f64::from(lo[a]) + 1.0)
                .fold(0.0, f64::max),
            expected: "at most 65536 for the viewer page: view a coarser map",
        });
    }
    let lo = if count == 0 { [0; 3] } else { lo };
    let mut bytes = Vec::with_capacity(count * RECORD_BYTES);
    let mut classes = Vec::new();
    let mut heights = [f64::INFINITY, f64::NEG_INFINITY];
    let resolution = map.resolution();
    for class in VoxelClass::ALL {
        let voxels = &by_class[class.index()];
        classes.push(json!({
            "name": class.name(),
            "color": class_color(class),
            "start": bytes.len() / RECORD_BYTES,
            "count": voxels.len(),
            "total": total[class.index()],
            "shown": match class {
                VoxelClass::Occupied | VoxelClass::Ambiguous => true,
                VoxelClass::Free => options.show_free,
                VoxelClass::Unknown => false,
            },
        }));
        for (key, values) in voxels {
            let z = resolution.center(*key).z;
            heights = [heights[0].min(z), heights[1].max(z)];
            for (axis, k) in [key.x, key.y, key.z].into_iter().enumerate() {
                bytes.extend_from_slice(&((k - lo[axis]) as u16).to_le_bytes());
            }
            for v in values {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            bytes.extend_from_slice(&[class.index() as u8, 0]);
        }
    }
    if !heights[0].is_finite() {
        heights = [0.0, 1.0];
    }
    let size = resolution.size();
    let origin = [0, 1, 2].map(|a| f64::from(lo[a]) * size);
    let data = json!({
        "title": options.title,
        "model": options.model,
        "resolution": size,
        "origin": origin,
        "color": color_name(options.color),
        "height": heights,
        "classes": classes,
        "voxels": base64::engine::general_purpose::STANDARD.encode(&bytes),
        "paths": options.paths,
    });
    // `<` appears only inside JSON strings, where `\u003c` means the same: the data can never
    // close its script element.
    let data = format!(
        "window.FUZZYVOX_DATA = {};",
        data.to_string().replace('<', "\\u003c")
    );
    // The script's colour map is the figures' own (one table for both).
    let stops: Vec<String> = VIRIDIS
        .iter()
        .map(|[r, g, b]| format!("[{r}, {g}, {b}]"))
        .collect();
    let path_colors = format!(
        "trajectory: {:?}, flight: {:?}, failed: {:?}, other: {:?}",
        PATH_TRAJECTORY, PATH_OK, PATH_COLLIDES, PATH_OTHER
    );
    let script = SCRIPT
        .replacen("/*FUZZYVOX_VIRIDIS*/", &stops.join(", "), 1)
        .replacen("/*FUZZYVOX_PATH_COLORS*/", &path_colors, 1);
    let page = fill_template(
        TEMPLATE,
        &[
            ("{{TITLE}}", &escape_html(&options.title)),
            ("/*FUZZYVOX_DATA*/", &data),
            ("/*FUZZYVOX_VIEWER_JS*/", &script),
        ],
    );
    let summary = PageSummary {
        drawn: by_class.each_ref().map(Vec::len),
        total,
        bytes: page.len(),
    };
    Ok((page, summary))
}

/// `template` with each placeholder replaced by its text. Only the template is searched, never
/// the text put in, so a title or path name that happens to spell a placeholder stays as it is.
fn fill_template(template: &str, fills: &[(&str, &str)]) -> String {
    let mut page =
        String::with_capacity(template.len() + fills.iter().map(|f| f.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some((at, (placeholder, text))) = fills
        .iter()
        .filter_map(|fill| rest.find(fill.0).map(|at| (at, fill)))
        .min_by_key(|(at, _)| *at)
    {
        page.push_str(&rest[..at]);
        page.push_str(text);
        rest = &rest[at + placeholder.len()..];
    }
    page.push_str(rest);
    page
}

/// Writes the page for `map` to `path` atomically (see [`viewer_page`]).
pub fn write_viewer_page(
    map: &dyn VoxelMap,
    options: &ViewerOptions,
    path: &Path,
) -> Result<PageSummary> {
    let (page, summary) = viewer_page(map, options)?;
    fuzzyvox_core::file::write_atomic(path, page.as_bytes())?;
    Ok(summary)
}

/// Text made safe for HTML.
pub fn escape_html(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::integrate::{IntegrationOptions, PointCloud};
    use fuzzyvox_core::map::{FuzzyConfig, FuzzyMap, VoxelMapMut};
    use nalgebra::Point3;

    /// A wall at x = 2 m, y in [0, 2), z in [0, 1): one point per 0.1 m cell, seen from
    /// (0.05, 1.05, 0.55).
    fn map() -> FuzzyMap {
        let cell_center = |n: i32| 0.05 + 0.1 * f64::from(n);
        let wall = (0..20)
            .flat_map(|i| (0..10).map(move |j| Point3::new(2.05, cell_center(i), cell_center(j))))
            .collect();
        let cloud = PointCloud::new(Point3::new(0.05, 1.05, 0.55), wall).unwrap();
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        map
    }

    fn data_of(page: &str) -> serde_json::Value {
        let start = page.find("window.FUZZYVOX_DATA = ").unwrap() + "window.FUZZYVOX_DATA = ".len();
        let end = start + page[start..].find(";</script>").unwrap();
        serde_json::from_str(&page[start..end]).unwrap()
    }

    #[test]
    fn the_page_carries_every_voxel_in_class_order() {
        let map = map();
        let mut options = ViewerOptions::new("wall </script><b>", "fuzzy");
        options.paths.push(PagePath {
            name: "camera".into(),
            kind: PathKind::Trajectory,
            ok: true,
            points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.5]],
        });
        let (page, summary) = viewer_page(&map, &options).unwrap();
        assert!(!page.contains("{{TITLE}}") && !page.contains("/*FUZZYVOX_DATA*/"));
        assert!(page.contains("wall &lt;/script&gt;&lt;b&gt;"));
        assert_eq!(
            page.matches("</script>").count(),
            2,
            "only the page's own scripts close"
        );
        let counts = map.counts();
        assert_eq!(summary.total[0], counts.occupied);
        assert_eq!(summary.drawn, summary.total, "a small map is written whole");
        let data = data_of(&page);
        assert_eq!(data["title"], "wall </script><b>");
        assert_eq!(data["paths"][0]["kind"], "trajectory");
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(data["voxels"].as_str().unwrap())
            .unwrap();
        assert_eq!(
            bytes.len(),
            summary.drawn.iter().sum::<usize>() * RECORD_BYTES
        );
        // Records sit in class order, each class where the page says it starts.
        for (class, entry) in data["classes"].as_array().unwrap().iter().enumerate() {
            let start = entry["start"].as_u64().unwrap() as usize;
            for i in start..start + entry["count"].as_u64().unwrap() as usize {
                assert_eq!(bytes[i * RECORD_BYTES + 14] as usize, class);
            }
        }
        // The first occupied record is a wall voxel at x = 2.05 m.
        let x = u16::from_le_bytes([bytes[0], bytes[1]]);
        let origin = data["origin"][0].as_f64().unwrap();
        assert!((origin + (f64::from(x) + 0.5) * 0.1 - 2.05).abs() < 1e-9);
    }

    #[test]
    fn placeholders_in_titles_and_path_names_stay_as_they_are() {
        let map = map();
        let mut options = ViewerOptions::new("/*FUZZYVOX_VIEWER_JS*/ {{TITLE}}", "fuzzy");
        options.paths.push(PagePath {
            name: "/*FUZZYVOX_VIEWER_JS*/".into(),
            kind: PathKind::Flight,
            ok: true,
            points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.5]],
        });
        let (page, _) = viewer_page(&map, &options).unwrap();
        let data = data_of(&page);
        assert_eq!(data["title"], "/*FUZZYVOX_VIEWER_JS*/ {{TITLE}}");
        assert_eq!(data["paths"][0]["name"], "/*FUZZYVOX_VIEWER_JS*/");
        // The script went where the template wants it, once.
        assert_eq!(page.matches("fuzzyvox map viewer.").count(), 1);
        assert!(!page.contains("/*FUZZYVOX_VIRIDIS*/"));
        assert!(!page.contains("/*FUZZYVOX_PATH_COLORS*/"));
    }

    #[test]
    fn the_script_uses_the_figures_viridis_stops() {
        let (page, _) = viewer_page(&map(), &ViewerOptions::new("wall", "fuzzy")).unwrap();
        let start = page.find("const VIRIDIS = [").unwrap() + "const VIRIDIS = ".len();
        let end = start + page[start..].find(';').unwrap();
        let stops: Vec<[u8; 3]> = serde_json::from_str(&page[start..end]).unwrap();
        assert_eq!(stops, VIRIDIS);
    }

    #[test]
    fn free_voxels_are_subsampled_the_same_way_every_time() {
        let map = map();
        let mut options = ViewerOptions::new("wall", "fuzzy");
        options.max_free = 50;
        let (a, sa) = viewer_page(&map, &options).unwrap();
        let (b, _) = viewer_page(&map, &options).unwrap();
        assert_eq!(a, b);
        assert!(sa.total[1] > 50);
        assert!(sa.drawn[1] <= 50 && sa.drawn[1] >= 25, "{sa:?}");
        assert_eq!(sa.drawn[0], sa.total[0]);
        options.max_free = 0;
        assert!(viewer_page(&map, &options).is_err());
    }

    #[test]
    fn an_empty_map_gives_a_page_with_no_voxels() {
        let map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let (page, summary) = viewer_page(&map, &ViewerOptions::new("empty", "fuzzy")).unwrap();
        assert_eq!(summary.drawn, [0; 4]);
        assert_eq!(data_of(&page)["voxels"], "");
    }
}
