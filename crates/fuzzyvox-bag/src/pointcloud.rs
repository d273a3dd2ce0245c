//! The points of a `sensor_msgs/PointCloud2`: `x`, `y` and `z` found by name at their offsets,
//! float32 or float64, either byte order, any point step and row padding, organised or not.
//! Other fields are skipped; points with a non-finite coordinate (the "not dense" clouds' gaps)
//! are dropped and counted.

use nalgebra::Point3;

use crate::messages::{PointCloud2, PointField};

/// `PointField` type codes.
const FLOAT32: u8 = 7;
const FLOAT64: u8 = 8;

/// The points of a cloud in its own frame, and how many were dropped as not finite.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CloudPoints {
    /// Every point with three finite coordinates, in the cloud's order.
    pub points: Vec<Point3<f64>>,
    /// Points with a NaN or infinite coordinate.
    pub dropped: usize,
}

/// One coordinate's place in a point.
#[derive(Clone, Copy)]
struct Coordinate {
    offset: usize,
    double: bool,
}

/// Reads the `x`, `y` and `z` of every point of `cloud`. Errors (in words) when a coordinate
/// field is missing or not floating point, when a field does not fit in the point step, or when
/// the data is shorter than `height × row_step` says.
pub fn cloud_points(cloud: &PointCloud2) -> Result<CloudPoints, String> {
    let point_step = cloud.point_step as usize;
    let row_step = cloud.row_step as usize;
    let (width, height) = (cloud.width as usize, cloud.height as usize);
    let count = width
        .checked_mul(height)
        .ok_or_else(|| format!("{width} × {height} points overflow"))?;
    if count == 0 {
        return Ok(CloudPoints::default());
    }
    let [x, y, z] = ["x", "y", "z"].map(|name| coordinate(&cloud.fields, name, point_step));
    let (x, y, z) = (x?, y?, z?);
    let row_bytes = width
        .checked_mul(point_step)
        .filter(|&b| b <= row_step)
        .ok_or_else(|| {
            format!(
                "a row of {width} points of {point_step} bytes does not fit in row_step {row_step}"
            )
        })?;
    let needed = (height - 1)
        .checked_mul(row_step)
        .and_then(|b| b.checked_add(row_bytes))
        .ok_or_else(|| "the cloud's size overflows".to_string())?;
    let data = cloud.data.as_slice();
    if data.len() < needed {
        return Err(format!(
            "{} bytes of data, but {height} rows of {width} points need {needed}",
            data.len()
        ));
    }
    let big = cloud.is_bigendian;
    let mut points = Vec::with_capacity(count);
    let mut dropped = 0;
    for row in data.chunks(row_step.max(1)).take(height) {
        for point in row.chunks_exact(point_step).take(width) {
            let p = [x, y, z].map(|c| read(point, c, big));
            match p {
                [Some(px), Some(py), Some(pz)]
                    if px.is_finite() && py.is_finite() && pz.is_finite() =>
                {
                    points.push(Point3::new(px, py, pz));
                }
                _ => dropped += 1,
            }
        }
    }
    Ok(CloudPoints { points, dropped })
}

/// Where field `name` sits, checked to be one float32 or float64 inside the point.
fn coordinate(fields: &[PointField], name: &str, point_step: usize) -> Result<Coordinate, String> {
    let field = fields.iter().find(|f| f.name == name).ok_or_else(|| {
        let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
        format!("no `{name}` field (fields: {})", names.join(" "))
    })?;
    let (double, size) = match field.datatype {
        FLOAT32 => (false, 4),
        FLOAT64 => (true, 8),
        other => {
            return Err(format!(
                "field `{name}` has point type {other} ({}); coordinates must be float32 or \
                 float64",
                type_name(other)
            ));
        }
    };
    let offset = field.offset as usize;
    if offset + size > point_step {
        return Err(format!(
            "field `{name}` at byte {offset} does not fit in a point of {point_step} bytes"
        ));
    }
    Ok(Coordinate { offset, double })
}

/// One coordinate of one point (`None` only if the point is shorter than checked).
fn read(point: &[u8], c: Coordinate, big: bool) -> Option<f64> {
    let bytes = point.get(c.offset..)?;
    Some(if c.double {
        let b = *bytes.first_chunk::<8>()?;
        if big {
            f64::from_be_bytes(b)
        } else {
            f64::from_le_bytes(b)
        }
    } else {
        let b = *bytes.first_chunk::<4>()?;
        f64::from(if big {
            f32::from_be_bytes(b)
        } else {
            f32::from_le_bytes(b)
        })
    })
}

fn type_name(code: u8) -> &'static str {
    match code {
        1 => "int8",
        2 => "uint8",
        3 => "int16",
        4 => "uint16",
        5 => "int32",
        6 => "uint32",
        FLOAT32 => "float32",
        FLOAT64 => "float64",
        _ => "unknown",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::Header;
    use serde_bytes::ByteBuf;

    fn field(name: &str, offset: u32, datatype: u8) -> PointField {
        PointField {
            name: name.into(),
            offset,
            datatype,
            count: 1,
        }
    }

    fn cloud(
        fields: Vec<PointField>,
        step: u32,
        width: u32,
        height: u32,
        row_step: u32,
        data: Vec<u8>,
        big: bool,
    ) -> PointCloud2 {
        PointCloud2 {
            header: Header::default(),
            height,
            width,
            fields,
            is_bigendian: big,
            point_step: step,
            row_step,
            data: ByteBuf::from(data),
            is_dense: false,
        }
    }

    #[test]
    fn float32_little_endian_with_other_fields_and_nan_points() {
        // intensity first, then z y x out of order, 4 bytes of padding: 20-byte points.
        let fields = vec![
            field("intensity", 0, 7),
            field("z", 4, 7),
            field("y", 8, 7),
            field("x", 12, 7),
        ];
        let mut data = Vec::new();
        for (x, y, z) in [(1.0f32, 2.0, 3.0), (f32::NAN, 0.0, 0.0), (-4.0, 5.5, 6.25)] {
            data.extend(9f32.to_le_bytes());
            for v in [z, y, x] {
                data.extend(v.to_le_bytes());
            }
            data.extend([0; 4]);
        }
        let got = cloud_points(&cloud(fields, 20, 3, 1, 60, data, false)).unwrap();
        assert_eq!(
            got.points,
            vec![Point3::new(1.0, 2.0, 3.0), Point3::new(-4.0, 5.5, 6.25)]
        );
        assert_eq!(got.dropped, 1);
    }

    #[test]
    fn float64_big_endian_organised_with_row_padding() {
        let fields = vec![field("x", 0, 8), field("y", 8, 8), field("z", 16, 8)];
        let mut data = Vec::new();
        for row in 0..2 {
            for col in 0..2 {
                for v in [f64::from(col), f64::from(row), 0.5] {
                    data.extend(v.to_be_bytes());
                }
            }
            data.extend([0xAB; 8]);
        }
        let got = cloud_points(&cloud(fields, 24, 2, 2, 56, data, true)).unwrap();
        assert_eq!(got.points.len(), 4);
        assert_eq!(got.points[3], Point3::new(1.0, 1.0, 0.5));
    }

    #[test]
    fn bad_layouts_are_errors() {
        let xyz = || vec![field("x", 0, 7), field("y", 4, 7), field("z", 8, 7)];
        let short = cloud_points(&cloud(xyz(), 12, 2, 1, 24, vec![0; 20], false)).unwrap_err();
        assert!(short.contains("20 bytes of data"), "{short}");
        let ints = vec![field("x", 0, 5), field("y", 4, 7), field("z", 8, 7)];
        let ints = cloud_points(&cloud(ints, 12, 1, 1, 12, vec![0; 12], false)).unwrap_err();
        assert!(ints.contains("int32"), "{ints}");
        let no_z = vec![field("x", 0, 7), field("y", 4, 7)];
        let no_z = cloud_points(&cloud(no_z, 12, 1, 1, 12, vec![0; 12], false)).unwrap_err();
        assert!(no_z.contains("no `z` field"), "{no_z}");
        let outside = vec![field("x", 0, 7), field("y", 4, 7), field("z", 10, 7)];
        let outside = cloud_points(&cloud(outside, 12, 1, 1, 12, vec![0; 12], false)).unwrap_err();
        assert!(outside.contains("does not fit"), "{outside}");
        let rows = cloud_points(&cloud(xyz(), 12, 2, 1, 16, vec![0; 24], false)).unwrap_err();
        assert!(rows.contains("row_step 16"), "{rows}");
        let huge = cloud_points(&cloud(
            xyz(),
            12,
            u32::MAX,
            u32::MAX,
            u32::MAX,
            vec![],
            false,
        ));
        assert!(huge.is_err());
        let empty = cloud_points(&cloud(vec![], 0, 0, 1, 0, vec![], false)).unwrap();
        assert!(empty.points.is_empty());
    }
}
