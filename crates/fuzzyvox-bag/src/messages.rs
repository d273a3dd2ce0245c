//! The ROS messages fuzzyvox reads, as serde types decoded from either wire format: ROS 1's
//! serialisation (`roslibrust_serde_rosmsg`) or ROS 2's CDR (`cdr-encoding`). The two differ
//! only in the header (ROS 1's has a sequence number and unsigned seconds), so each message is
//! generic over its header and both decode into the same [`Header`].

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_bytes::ByteBuf;

use crate::error::{BagError, Result};
use crate::reader::{Encoding, RawMessage};

/// A message's stamp and frame, whatever its wire format.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// The data's time, nanoseconds since the epoch.
    pub stamp_ns: i64,
    /// The frame the data is expressed in, without a leading `/`.
    pub frame_id: String,
}

impl Header {
    /// The stamp in seconds.
    pub fn stamp_seconds(&self) -> f64 {
        self.stamp_ns as f64 * 1e-9
    }
}

/// tf2 names frames without a leading `/`; ROS 1 data often has one.
pub fn frame_name(id: &str) -> String {
    id.strip_prefix('/').unwrap_or(id).to_string()
}

/// ROS 1's `time`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros1Time {
    /// Seconds.
    pub secs: u32,
    /// Nanoseconds.
    pub nsecs: u32,
}

/// ROS 2's `builtin_interfaces/Time`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros2Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds.
    pub nanosec: u32,
}

/// ROS 1's `std_msgs/Header`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros1Header {
    /// Sequence number.
    pub seq: u32,
    /// Stamp.
    pub stamp: Ros1Time,
    /// Frame.
    pub frame_id: String,
}

/// ROS 2's `std_msgs/msg/Header`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros2Header {
    /// Stamp.
    pub stamp: Ros2Time,
    /// Frame.
    pub frame_id: String,
}

impl From<Ros1Header> for Header {
    fn from(h: Ros1Header) -> Self {
        Self {
            stamp_ns: i64::from(h.stamp.secs) * 1_000_000_000 + i64::from(h.stamp.nsecs),
            frame_id: frame_name(&h.frame_id),
        }
    }
}

impl From<Ros2Header> for Header {
    fn from(h: Ros2Header) -> Self {
        Self {
            stamp_ns: i64::from(h.stamp.sec) * 1_000_000_000 + i64::from(h.stamp.nanosec),
            frame_id: frame_name(&h.frame_id),
        }
    }
}

/// `sensor_msgs/PointField`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PointField {
    /// Field name (`x`, `y`, `z`, `intensity`, ...).
    pub name: String,
    /// Byte offset inside a point.
    pub offset: u32,
    /// Type code: 1-8 for int8, uint8, int16, uint16, int32, uint32, float32, float64.
    pub datatype: u8,
    /// Elements in the field.
    pub count: u32,
}

/// `sensor_msgs/PointCloud2`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointCloud2<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// Rows (1 for an unorganised cloud).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The layout of a point.
    pub fields: Vec<PointField>,
    /// Byte order of the data.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points.
    pub data: ByteBuf,
    /// True when no point is invalid.
    pub is_dense: bool,
}

/// `geometry_msgs/Vector3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

/// `geometry_msgs/Transform`: the child frame's pose in the parent frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation, metres.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/TransformStamped`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped<H = Header> {
    /// Stamp and parent frame.
    pub header: H,
    /// The child frame.
    pub child_frame_id: String,
    /// `parent_from_child`.
    pub transform: Transform,
}

/// `tf2_msgs/TFMessage`, and ROS 1's older `tf/tfMessage` (the same layout).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TfMessage<H = Header> {
    /// The transforms.
    pub transforms: Vec<TransformStamped<H>>,
}

/// `sensor_msgs/CompressedImage`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CompressedImage<H = Header> {
    /// Stamp and camera frame.
    pub header: H,
    /// `png`, `jpeg`, or e.g. `rgb8; png compressed`.
    pub format: String,
    /// The compressed image.
    pub data: ByteBuf,
}

/// `sensor_msgs/Image`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Image<H = Header> {
    /// Stamp and camera frame.
    pub header: H,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`rgb8`, `bgr8`, `mono8`, ...).
    pub encoding: String,
    /// Byte order of multi-byte pixels.
    pub is_bigendian: u8,
    /// Bytes per row.
    pub step: u32,
    /// The pixels.
    pub data: ByteBuf,
}

/// `sensor_msgs/RegionOfInterest`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegionOfInterest {
    /// Left column.
    pub x_offset: u32,
    /// Top row.
    pub y_offset: u32,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Whether the region should be rectified.
    pub do_rectify: bool,
}

/// `sensor_msgs/CameraInfo`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraInfo<H = Header> {
    /// Stamp and camera frame.
    pub header: H,
    /// Image rows.
    pub height: u32,
    /// Image columns.
    pub width: u32,
    /// `plumb_bob`, `rational_polynomial`, ...
    pub distortion_model: String,
    /// Distortion coefficients.
    pub d: Vec<f64>,
    /// Row-major 3×3 intrinsics of the raw images.
    pub k: [f64; 9],
    /// Rectification rotation.
    pub r: [f64; 9],
    /// Row-major 3×4 projection of the rectified images.
    pub p: [f64; 12],
    /// Horizontal binning.
    pub binning_x: u32,
    /// Vertical binning.
    pub binning_y: u32,
    /// Region of interest.
    pub roi: RegionOfInterest,
}

/// A message type fuzzyvox decodes from either wire format.
pub trait Message: Sized {
    /// The type names it answers to (ROS 1 and ROS 2 spellings).
    const TYPES: &'static [&'static str];
    /// What the message is, for errors.
    const WHAT: &'static str;
    /// Decodes ROS 1 bytes.
    fn from_ros1(data: &[u8]) -> std::result::Result<Self, String>;
    /// Decodes CDR bytes (after the encapsulation header).
    fn from_cdr(data: &[u8], little_endian: bool) -> std::result::Result<Self, String>;

    /// Whether a connection's type is this message.
    fn is_type(msg_type: &str) -> bool {
        Self::TYPES.contains(&msg_type)
    }

    /// Decodes `message`, the `index`-th on its topic.
    fn decode(message: &RawMessage<'_>, index: usize) -> Result<Self> {
        let decoded = match message.connection.encoding {
            Encoding::Ros1 => Self::from_ros1(message.data),
            Encoding::Cdr => {
                cdr_body(message.data).and_then(|(little, body)| Self::from_cdr(body, little))
            }
        };
        decoded.map_err(|detail| BagError::BadMessage {
            topic: message.connection.topic.clone(),
            msg_type: message.connection.msg_type.clone(),
            index,
            detail,
        })
    }
}

/// The byte order CDR's encapsulation header gives, and the bytes after it.
fn cdr_body(data: &[u8]) -> std::result::Result<(bool, &[u8]), String> {
    match data.split_first_chunk::<4>() {
        Some(([0, 1, _, _], body)) => Ok((true, body)),
        Some(([0, 0, _, _], body)) => Ok((false, body)),
        Some(([a, b, _, _], _)) => Err(format!(
            "encapsulation {a:#04x} {b:#04x} is not plain CDR (ROS 2 writes 0x00 0x01)"
        )),
        None => Err("shorter than CDR's 4-byte header".into()),
    }
}

fn ros1<T: DeserializeOwned>(data: &[u8]) -> std::result::Result<T, String> {
    let len = u32::try_from(data.len()).map_err(|_| "longer than 4 GiB".to_string())?;
    roslibrust_serde_rosmsg::from_slice_known_length(data, len).map_err(|e| e.to_string())
}

fn cdr<T: DeserializeOwned>(data: &[u8], little_endian: bool) -> std::result::Result<T, String> {
    let decoded = if little_endian {
        cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(data)
    } else {
        cdr_encoding::from_bytes::<T, byteorder::BigEndian>(data)
    };
    decoded.map(|(value, _)| value).map_err(|e| e.to_string())
}

/// Implements [`Message`] for a message generic over its header.
macro_rules! message {
    ($name:ident, $what:literal, [$($types:literal),+], |$m:ident| $convert:expr) => {
        impl Message for $name<Header> {
            const TYPES: &'static [&'static str] = &[$($types),+];
            const WHAT: &'static str = $what;

            fn from_ros1(data: &[u8]) -> std::result::Result<Self, String> {
                ros1::<$name<Ros1Header>>(data).map(|$m| $convert)
            }

            fn from_cdr(data: &[u8], little_endian: bool) -> std::result::Result<Self, String> {
                cdr::<$name<Ros2Header>>(data, little_endian).map(|$m| $convert)
            }
        }
    };
}

message!(
    PointCloud2,
    "point cloud",
    ["sensor_msgs/PointCloud2", "sensor_msgs/msg/PointCloud2"],
    |m| PointCloud2 {
        header: m.header.into(),
        height: m.height,
        width: m.width,
        fields: m.fields,
        is_bigendian: m.is_bigendian,
        point_step: m.point_step,
        row_step: m.row_step,
        data: m.data,
        is_dense: m.is_dense,
    }
);

message!(
    TfMessage,
    "transform",
    [
        "tf2_msgs/TFMessage",
        "tf2_msgs/msg/TFMessage",
        "tf/tfMessage"
    ],
    |m| TfMessage {
        transforms: m
            .transforms
            .into_iter()
            .map(|t| TransformStamped {
                header: t.header.into(),
                child_frame_id: frame_name(&t.child_frame_id),
                transform: t.transform,
            })
            .collect(),
    }
);

message!(
    CompressedImage,
    "compressed image",
    [
        "sensor_msgs/CompressedImage",
        "sensor_msgs/msg/CompressedImage"
    ],
    |m| CompressedImage {
        header: m.header.into(),
        format: m.format,
        data: m.data,
    }
);

message!(
    Image,
    "image",
    ["sensor_msgs/Image", "sensor_msgs/msg/Image"],
    |m| Image {
        header: m.header.into(),
        height: m.height,
        width: m.width,
        encoding: m.encoding,
        is_bigendian: m.is_bigendian,
        step: m.step,
        data: m.data,
    }
);

message!(
    CameraInfo,
    "camera info",
    ["sensor_msgs/CameraInfo", "sensor_msgs/msg/CameraInfo"],
    |m| CameraInfo {
        header: m.header.into(),
        height: m.height,
        width: m.width,
        distortion_model: m.distortion_model,
        d: m.d,
        k: m.k,
        r: m.r,
        p: m.p,
        binning_x: m.binning_x,
        binning_y: m.binning_y,
        roi: m.roi,
    }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reader::Connection;

    fn cloud<H>(header: H) -> PointCloud2<H> {
        PointCloud2 {
            header,
            height: 1,
            width: 2,
            fields: vec![PointField {
                name: "x".into(),
                offset: 0,
                datatype: 7,
                count: 1,
            }],
            is_bigendian: false,
            point_step: 4,
            row_step: 8,
            data: ByteBuf::from(vec![0, 0, 128, 63, 0, 0, 0, 64]),
            is_dense: true,
        }
    }

    fn raw<'a>(connection: &'a Connection, data: &'a [u8]) -> RawMessage<'a> {
        RawMessage {
            connection,
            log_time: 0,
            data,
        }
    }

    #[test]
    fn both_wire_formats_decode_to_the_same_message() {
        let ros1_bytes = roslibrust_serde_rosmsg::to_vec(&cloud(Ros1Header {
            seq: 7,
            stamp: Ros1Time { secs: 2, nsecs: 5 },
            frame_id: "/lidar".into(),
        }))
        .unwrap();
        // `to_vec` writes the total length first, which bag records leave out.
        let ros1_bytes = &ros1_bytes[4..];
        let ros2 = cloud(Ros2Header {
            stamp: Ros2Time { sec: 2, nanosec: 5 },
            frame_id: "lidar".into(),
        });
        let mut le = vec![0, 1, 0, 0];
        le.extend(cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&ros2).unwrap());
        let mut be = vec![0, 0, 0, 0];
        be.extend(cdr_encoding::to_vec::<_, byteorder::BigEndian>(&ros2).unwrap());
        let c1 = Connection {
            topic: "/points".into(),
            msg_type: "sensor_msgs/PointCloud2".into(),
            encoding: Encoding::Ros1,
        };
        let c2 = Connection {
            encoding: Encoding::Cdr,
            ..c1.clone()
        };
        let a = PointCloud2::decode(&raw(&c1, ros1_bytes), 0).unwrap();
        let b = PointCloud2::decode(&raw(&c2, &le), 0).unwrap();
        let c = PointCloud2::decode(&raw(&c2, &be), 0).unwrap();
        assert_eq!(a, b);
        assert_eq!(b, c);
        assert_eq!(a.header.frame_id, "lidar");
        assert_eq!(a.header.stamp_ns, 2_000_000_005);
    }

    #[test]
    fn cut_or_foreign_bytes_are_errors_naming_the_message() {
        let c = Connection {
            topic: "/points".into(),
            msg_type: "sensor_msgs/msg/PointCloud2".into(),
            encoding: Encoding::Cdr,
        };
        let mut bytes = vec![0, 1, 0, 0];
        bytes.extend(
            cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&cloud(Ros2Header::default()))
                .unwrap(),
        );
        for cut in [0, 3, 10, bytes.len() - 3] {
            let error = PointCloud2::decode(&raw(&c, &bytes[..cut]), 4).unwrap_err();
            assert!(
                error.to_string().contains("message 4 on `/points`"),
                "{error}"
            );
        }
        let mut xcdr2 = bytes.clone();
        xcdr2[1] = 7;
        let error = PointCloud2::decode(&raw(&c, &xcdr2), 0).unwrap_err();
        assert!(error.to_string().contains("not plain CDR"), "{error}");
    }
}
