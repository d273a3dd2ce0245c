//! PLY export of a map's voxels: one vertex per voxel centre with its memberships, measures and
//! class, for point-cloud viewers (MeshLab, CloudCompare, Open3D, Blender).
//!
//! The file follows the PLY format (Turk, 1994; as read by the tools above): an ASCII header,
//! then the vertices as ASCII lines or packed little-endian binary records. Each vertex has
//! `float x, y, z` (the voxel centre, metres), `float occupied, free, ambiguity, safety`,
//! `uchar class` (0 occupied, 1 free, 2 ambiguous, 3 unknown; [`VoxelClass::index`]) and
//! `uchar red, green, blue` (the class colour of [`class_color`], so viewers show classes at
//! once).

use std::io::{BufWriter, Write};
use std::path::Path;

pub use fuzzyvox_core::class::class_color;
use fuzzyvox_core::error::Result;
use fuzzyvox_core::file::write_atomic_with;
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;

/// How the vertices are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlyEncoding {
    /// One text line per vertex: readable, about three times larger.
    Ascii,
    /// Packed little-endian records of 32 bytes (seven `f32`, four `u8`).
    BinaryLittleEndian,
}

/// Writes every observed voxel of `map` whose class is in `classes` to a PLY file at `path`
/// (atomically: a failed write leaves no half file) and returns the number of vertices.
///
/// ```
/// use fuzzyvox_io::ply::{PlyEncoding, write_ply};
/// use fuzzyvox_core::{FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, VoxelClass, VoxelMap, VoxelMapMut};
/// use nalgebra::Point3;
///
/// let mut map = FuzzyMap::new(FuzzyConfig::new(0.1)?)?;
/// let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(1.05, 0.05, 0.05)])?;
/// map.integrate_cloud(&cloud, &IntegrationOptions::default())?;
/// let path = std::env::temp_dir().join("fuzzyvox-doc-example.ply");
/// let written = write_ply(&map, &[VoxelClass::Occupied], PlyEncoding::Ascii, &path)?;
/// assert_eq!(written, 1);
/// assert!(std::fs::read_to_string(&path).unwrap().starts_with("ply\n"));
/// # std::fs::remove_file(&path).unwrap();
/// # Ok::<(), fuzzyvox_core::Error>(())
/// ```
pub fn write_ply(
    map: &dyn VoxelMap,
    classes: &[VoxelClass],
    encoding: PlyEncoding,
    path: &Path,
) -> Result<usize> {
    let config = map.measure_config();
    let selected = || {
        map.cells()
            .map(|(key, m)| (key, config.measures(m)))
            .filter(|(_, m)| classes.contains(&m.class))
    };
    // Two passes over the cells (the header needs the count first) instead of a copy of them.
    let count = selected().count();
    let resolution = map.resolution();
    write_atomic_with(path, |file| {
        let mut out = BufWriter::new(file);
        let format = match encoding {
            PlyEncoding::Ascii => "ascii",
            PlyEncoding::BinaryLittleEndian => "binary_little_endian",
        };
        write!(
            out,
            "ply\nformat {format} 1.0\ncomment fuzzyvox voxel centres, resolution {} m\n\
             comment class: 0 occupied, 1 free, 2 ambiguous, 3 unknown\n\
             element vertex {count}\n\
             property float x\nproperty float y\nproperty float z\n\
             property float occupied\nproperty float free\n\
             property float ambiguity\nproperty float safety\n\
             property uchar class\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\n\
             end_header\n",
            resolution.size()
        )?;
        for (key, m) in selected() {
            let c = resolution.center(key);
            let (x, y, z) = (c.x as f32, c.y as f32, c.z as f32);
            let class = m.class.index() as u8;
            let [r, g, b] = class_color(m.class);
            match encoding {
                PlyEncoding::Ascii => writeln!(
                    out,
                    "{x} {y} {z} {} {} {} {} {class} {r} {g} {b}",
                    m.occupied, m.free, m.ambiguity, m.safety
                )?,
                PlyEncoding::BinaryLittleEndian => {
                    for value in [x, y, z, m.occupied, m.free, m.ambiguity, m.safety] {
                        out.write_all(&value.to_le_bytes())?;
                    }
                    out.write_all(&[class, r, g, b])?;
                }
            }
        }
        out.flush()
    })?;
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzyvox_core::integrate::{IntegrationOptions, PointCloud};
    use fuzzyvox_core::map::VoxelMapMut;
    use fuzzyvox_core::map::{FuzzyConfig, FuzzyMap};
    use nalgebra::Point3;

    fn small_map() -> FuzzyMap {
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let points = (0..5)
            .map(|i| Point3::new(1.05, 0.05 + 0.1 * f64::from(i), 0.05))
            .collect();
        let cloud = PointCloud::new(Point3::origin(), points).unwrap();
        map.integrate_cloud(&cloud, &IntegrationOptions::default())
            .unwrap();
        map
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("fuzzyvox-ply-{}-{name}", std::process::id()))
    }

    #[test]
    fn ascii_vertices_match_the_map() {
        let map = small_map();
        let path = scratch("ascii.ply");
        let all = [
            VoxelClass::Occupied,
            VoxelClass::Free,
            VoxelClass::Ambiguous,
            VoxelClass::Unknown,
        ];
        let n = write_ply(&map, &all, PlyEncoding::Ascii, &path).unwrap();
        assert_eq!(n, map.cells().count());
        let text = std::fs::read_to_string(&path).unwrap();
        let (header, body) = text.split_once("end_header\n").unwrap();
        assert!(header.contains(&format!("element vertex {n}\n")));
        let lines: Vec<&str> = body.lines().collect();
        assert_eq!(lines.len(), n);
        let mut occupied = 0;
        for line in lines {
            let v: Vec<f32> = line.split(' ').map(|f| f.parse().unwrap()).collect();
            assert_eq!(v.len(), 11);
            let key = map
                .resolution()
                .key_of(&Point3::new(
                    f64::from(v[0]),
                    f64::from(v[1]),
                    f64::from(v[2]),
                ))
                .unwrap();
            let m = map.measures_at(key);
            assert_eq!(
                (v[3], v[4], v[5], v[6]),
                (m.occupied, m.free, m.ambiguity, m.safety)
            );
            assert_eq!(v[7] as usize, m.class.index());
            occupied += usize::from(m.class == VoxelClass::Occupied);
        }
        assert_eq!(occupied, 5);
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn binary_records_are_packed_little_endian() {
        let map = small_map();
        let path = scratch("binary.ply");
        let n = write_ply(
            &map,
            &[VoxelClass::Occupied],
            PlyEncoding::BinaryLittleEndian,
            &path,
        )
        .unwrap();
        assert_eq!(n, 5);
        let bytes = std::fs::read(&path).unwrap();
        let end = b"end_header\n";
        let start = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        assert_eq!(bytes.len() - start, 5 * 32);
        let f = |i: usize| {
            f32::from_le_bytes(bytes[start + 4 * i..start + 4 * i + 4].try_into().unwrap())
        };
        assert!(
            (f(0) - 1.05).abs() < 1e-6,
            "x of the first vertex: {}",
            f(0)
        );
        assert!(f(3) >= 0.5, "occupied membership {}", f(3));
        assert_eq!(bytes[start + 28], 0, "class occupied");
        assert_eq!(
            &bytes[start + 29..start + 32],
            &class_color(VoxelClass::Occupied)
        );
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn an_unwritable_path_is_an_error_and_leaves_nothing() {
        let map = small_map();
        let path = std::path::Path::new("/nonexistent-dir/map.ply");
        assert!(write_ply(&map, &[VoxelClass::Occupied], PlyEncoding::Ascii, path).is_err());
        assert!(!path.exists());
    }
}
