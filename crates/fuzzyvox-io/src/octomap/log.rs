//! OctoMap's plain-text scan log (the input of its `log2graph` tool).
//!
//! ```text
//! # comment
//! NODE x y z roll pitch yaw     sensor pose in the world (metres, radians)
//! x y z                         a point in the sensor frame (metres)
//! x y z
//! NODE ...                      the next scan
//! ```

use std::io::{BufRead, BufReader};
use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::geometry::validate_pose;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};

use super::scan::ScanNode;
use crate::bounded::ContentLines;

/// Reads an OctoMap scan log: a `NODE x y z roll pitch yaw` line starts each scan and is followed
/// by its points, one `x y z` per line in the sensor frame. Fields are separated by whitespace;
/// blank lines and lines starting with `#` are ignored. Nodes get ids 0, 1, 2, … in file order.
///
/// The rotation is OctoMap's `Quaternion(roll, pitch, yaw)`, that is `Rz(yaw)·Ry(pitch)·Rx(roll)`.
/// Points may be `nan` or `inf` (integration skips them); a non-finite pose, a point before the
/// first `NODE`, a wrong number of fields or text that is not a number is an [`Error::Parse`]
/// naming the line. A file without any `NODE` line is [`Error::Empty`].
///
/// Unlike OctoMap, which silently skips lines that start with a space, indented lines are read.
pub fn read_scan_log(path: &Path) -> Result<Vec<ScanNode>> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_log(BufReader::new(file), path)
}

/// Parses the bytes of an OctoMap scan log held in memory; see [`read_scan_log`]. Errors name
/// the path `<memory>`.
pub fn parse_scan_log(bytes: &[u8]) -> Result<Vec<ScanNode>> {
    parse_log(bytes, Path::new("<memory>"))
}

fn parse_log(reader: impl BufRead, path: &Path) -> Result<Vec<ScanNode>> {
    let parse_error = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut nodes: Vec<ScanNode> = Vec::new();
    let mut lines = ContentLines::new(reader, path);
    while let Some((line_number, line)) = lines.next_line()? {
        let mut fields = line.split_whitespace().peekable();
        if fields.peek() == Some(&"NODE") {
            fields.next();
            let [x, y, z, roll, pitch, yaw] = numbers(fields, "NODE x y z roll pitch yaw")
                .map_err(|m| parse_error(line_number, m))?;
            let pose = Isometry3::from_parts(
                Translation3::new(x, y, z),
                UnitQuaternion::from_euler_angles(roll, pitch, yaw),
            );
            validate_pose(&pose).map_err(|e| parse_error(line_number, e.to_string()))?;
            let id = u32::try_from(nodes.len())
                .map_err(|_| parse_error(line_number, "more than 2^32 scans".into()))?;
            nodes.push(ScanNode {
                world_from_sensor: pose,
                points_in_sensor: Vec::new(),
                id,
            });
        } else {
            let [x, y, z] = numbers(fields, "x y z").map_err(|m| parse_error(line_number, m))?;
            let node = nodes.last_mut().ok_or_else(|| {
                parse_error(line_number, "a point before the first NODE line".into())
            })?;
            node.points_in_sensor.push(Point3::new(x, y, z));
        }
    }
    if nodes.is_empty() {
        return Err(Error::Empty("scan log (no NODE line)"));
    }
    Ok(nodes)
}

/// Parses exactly `N` numbers from `fields`; `form` describes the expected line in errors.
fn numbers<'a, const N: usize>(
    fields: impl Iterator<Item = &'a str>,
    form: &str,
) -> std::result::Result<[f64; N], String> {
    let mut values = [0.0; N];
    let mut count = 0;
    for field in fields {
        let slot = values
            .get_mut(count)
            .ok_or_else(|| format!("more than {N} values: expected `{form}`"))?;
        *slot = field
            .parse()
            .map_err(|_| format!("`{field}` is not a number"))?;
        count += 1;
    }
    if count < N {
        return Err(format!("{count} values: expected `{form}`"));
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Rotation3, Vector3};

    fn write(name: &str, text: &str) -> std::path::PathBuf {
        let path =
            std::env::temp_dir().join(format!("fuzzyvox-log-{}-{name}.log", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn reads_nodes_and_points() {
        let path = write(
            "ok",
            "# a log\n\nNODE 1 2 3 0.1 -0.2 0.3\n1 0 0\n  nan 0 1\nNODE 0 0 0 0 0 0\n",
        );
        let nodes = read_scan_log(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(nodes.len(), 2);
        assert_eq!((nodes[0].id, nodes[1].id), (0, 1));
        assert_eq!(nodes[0].points_in_sensor.len(), 2);
        assert!(nodes[1].points_in_sensor.is_empty());
        // Rz(yaw)·Ry(pitch)·Rx(roll), as OctoMap's Quaternion(roll, pitch, yaw).
        let expected: Matrix3<f64> = *Rotation3::from_axis_angle(&Vector3::z_axis(), 0.3).matrix()
            * Rotation3::from_axis_angle(&Vector3::y_axis(), -0.2).matrix()
            * Rotation3::from_axis_angle(&Vector3::x_axis(), 0.1).matrix();
        let got = nodes[0].world_from_sensor.rotation.to_rotation_matrix();
        assert!((got.matrix() - expected).abs().max() < 1e-12);
        assert_eq!(
            nodes[0].world_from_sensor.translation.vector,
            Vector3::new(1.0, 2.0, 3.0)
        );
    }

    #[test]
    fn errors_name_the_line() {
        for (name, text, line) in [
            ("before", "# c\n1 2 3\n", 2),
            ("short", "NODE 0 0 0 0 0 0\n1 2\n", 2),
            ("long", "NODE 0 0 0 0 0 0\n1 2 3 4\n", 2),
            ("word", "NODE 0 0 0 0 0 0\n\n1 two 3\n", 3),
            ("pose", "NODE 0 0 inf 0 0 0\n", 1),
            ("node", "NODE 0 0 0 0 0\n", 1),
        ] {
            let path = write(name, text);
            let error = read_scan_log(&path).unwrap_err();
            std::fs::remove_file(&path).unwrap();
            match error {
                Error::Parse { line: found, .. } => assert_eq!(found, line, "{name}"),
                other => panic!("{name}: {other}"),
            }
        }
        let path = write("binary", "");
        let mut bytes = b"NODE 0 0 0 0 0 0\n1 2 3\n".to_vec();
        bytes.extend([0x89, b'P', b'N', b'G', 0xff, b'\n']);
        std::fs::write(&path, &bytes).unwrap();
        let error = read_scan_log(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert!(matches!(error, Error::Parse { line: 3, .. }), "{error}");
        let path = write("empty", "# nothing\n\n");
        assert!(matches!(read_scan_log(&path), Err(Error::Empty(_))));
        std::fs::remove_file(&path).unwrap();
    }
}
