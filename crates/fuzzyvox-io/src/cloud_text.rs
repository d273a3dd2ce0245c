use std::io::{BufRead, BufReader};
use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::PointCloud;
use nalgebra::Point3;

use super::bounded::ContentLines;

/// Reads a plain text point cloud: one point per line as `x y z` or `x y z confidence`
/// (separated by spaces, tabs or commas), metres in the world frame, confidence in `[0, 1]`.
/// Blank lines and lines starting with `#` are ignored. Either every point has a confidence or
/// none does.
///
/// Coordinates written as `nan` or `inf` are kept (integration skips them); anything else that
/// is not a number is an error naming the line.
pub fn read_text_cloud(path: &Path, origin: Point3<f64>) -> Result<PointCloud> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_cloud(BufReader::new(file), path, origin)
}

/// Parses a text point cloud held in memory; see [`read_text_cloud`]. Errors name the path
/// `<memory>`.
pub fn parse_text_cloud(bytes: &[u8], origin: Point3<f64>) -> Result<PointCloud> {
    parse_cloud(bytes, Path::new("<memory>"), origin)
}

fn parse_cloud(reader: impl BufRead, path: &Path, origin: Point3<f64>) -> Result<PointCloud> {
    let parse_error = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut points = Vec::new();
    let mut confidence = Vec::new();
    let mut columns = None;
    let mut lines = ContentLines::new(reader, path);
    while let Some((line_number, line)) = lines.next_line()? {
        let mut values = [0f64; 4];
        let mut count = 0;
        for field in line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
        {
            let slot = values
                .get_mut(count)
                .ok_or_else(|| parse_error(line_number, "more than 4 values".into()))?;
            *slot = field
                .parse()
                .map_err(|_| parse_error(line_number, format!("`{field}` is not a number")))?;
            count += 1;
        }
        if count < 3 {
            return Err(parse_error(
                line_number,
                format!("expected `x y z [confidence]`, found {count} values"),
            ));
        }
        match columns {
            None => columns = Some(count),
            Some(c) if c != count => {
                return Err(parse_error(
                    line_number,
                    format!("{count} values where earlier lines had {c}"),
                ));
            }
            _ => {}
        }
        let [x, y, z, c] = values;
        points.push(Point3::new(x, y, z));
        if count == 4 {
            let confidence_f32 = c as f32;
            if !(0.0..=1.0).contains(&confidence_f32) {
                return Err(parse_error(
                    line_number,
                    format!("confidence {c} is outside [0, 1]"),
                ));
            }
            confidence.push(confidence_f32);
        }
    }
    let cloud = PointCloud::new(origin, points)?;
    if columns == Some(4) {
        cloud.with_confidence(confidence)
    } else {
        Ok(cloud)
    }
}
