//! Scan lists: many clouds, each seen from its own origin, as the insertion peers
//! (`../shared/peers`) and robot logs converted to text hand them over.

use std::io::BufReader;
use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::PointCloud;
use nalgebra::Point3;

use super::bounded::ContentLines;
use super::cloud_text::read_text_cloud;

/// One line of a scan list: a text cloud and the origin its rays start from.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanListEntry {
    /// The cloud's file, resolved against the list's folder when the line gives a relative
    /// path.
    pub cloud: std::path::PathBuf,
    /// The sensor's position when it took the scan, world frame, metres.
    pub origin: Point3<f64>,
}

/// Reads a scan list's lines: `CLOUD ox oy oz` per scan (separated by spaces or tabs), `CLOUD` a
/// text cloud (`x y z [confidence]`, world frame) relative to the list's folder or absolute,
/// `ox oy oz` the sensor's origin for that scan. Blank lines and lines starting with `#` are
/// ignored. A line with another number of fields, or an origin that is not a finite number, is
/// an error naming the line; a list without any scan is an error too.
pub fn read_scan_list_entries(path: &Path) -> Result<Vec<ScanListEntry>> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let parse_error = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut entries = Vec::new();
    let mut lines = ContentLines::new(BufReader::new(file), path);
    while let Some((number, line)) = lines.next_line()? {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let [cloud, x, y, z] = fields[..] else {
            return Err(parse_error(
                number,
                format!("expected `CLOUD ox oy oz`, found {} fields", fields.len()),
            ));
        };
        let mut origin = [0f64; 3];
        for (slot, field) in origin.iter_mut().zip([x, y, z]) {
            *slot = field
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    parse_error(number, format!("origin `{field}` is not a finite number"))
                })?;
        }
        entries.push(ScanListEntry {
            cloud: folder.join(cloud),
            origin: Point3::from(origin),
        });
    }
    if entries.is_empty() {
        return Err(parse_error(0, "the scan list holds no scan".into()));
    }
    Ok(entries)
}

/// Reads every scan of a scan list ([`read_scan_list_entries`]) as a cloud from its own
/// origin, in list order. A cloud that cannot be read is an error naming its file.
pub fn read_scan_list(path: &Path) -> Result<Vec<PointCloud>> {
    read_scan_list_entries(path)?
        .into_iter()
        .map(|entry| read_text_cloud(&entry.cloud, entry.origin))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("fuzzyvox-scan-list-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn scans_read_from_their_own_origins_relative_to_the_list() {
        let dir = scratch("ok");
        std::fs::write(dir.join("a.xyz"), "1 0 0\n2 0 0\n").unwrap();
        std::fs::write(dir.join("b.xyz"), "0 1 0 0.5\n").unwrap();
        let list = dir.join("scans.list");
        std::fs::write(&list, "# two scans\na.xyz 0 0 0\n\nb.xyz\t0.5 -1 2e-1\n").unwrap();
        let scans = read_scan_list(&list).unwrap();
        assert_eq!(scans.len(), 2);
        assert_eq!(scans[0].len(), 2);
        assert_eq!(scans[1].origin(), Point3::new(0.5, -1.0, 0.2));
        assert_eq!(scans[1].confidence_of(0), 0.5);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_lines_name_the_line() {
        let dir = scratch("bad");
        std::fs::write(dir.join("a.xyz"), "1 0 0\n").unwrap();
        let cases = [
            ("a.xyz 0 0\n", 1, "found 3 fields"),
            (
                "a.xyz 0 0 0\na.xyz 0 x 0\n",
                2,
                "`x` is not a finite number",
            ),
            ("a.xyz 0 0 nan\n", 1, "`nan` is not a finite number"),
            ("# nothing\n", 0, "no scan"),
        ];
        for (text, line, message) in cases {
            let list = dir.join("scans.list");
            std::fs::write(&list, text).unwrap();
            match read_scan_list(&list) {
                Err(Error::Parse {
                    line: l,
                    message: m,
                    ..
                }) => {
                    assert_eq!(l, line, "{text}");
                    assert!(m.contains(message), "{m}");
                }
                other => panic!("{text}: {other:?}"),
            }
        }
        // A cloud that is missing is an error naming its file.
        std::fs::write(dir.join("scans.list"), "missing.xyz 0 0 0\n").unwrap();
        let error = read_scan_list(&dir.join("scans.list")).unwrap_err();
        assert!(error.to_string().contains("missing.xyz"), "{error}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
