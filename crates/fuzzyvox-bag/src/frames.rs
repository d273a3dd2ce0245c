//! Colour frames of a recording for the one-camera depth stage: the images of one topic
//! (`sensor_msgs/CompressedImage` or `sensor_msgs/Image`), the camera's intrinsics from its
//! `sensor_msgs/CameraInfo`, and each image's pose from the TF tree at its stamp.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use fuzzyvox_core::error::Error as CoreError;
use fuzzyvox_core::geometry::PinholeIntrinsics;
use fuzzyvox_core::image::{Frame, GrayImage};
use fuzzyvox_core::integrate::DepthFrame;
use fuzzyvox_io::decode_gray_image;
use fuzzyvox_io::posed::PosedFrames;

use crate::error::{BagError, Result};
use crate::messages::{CameraInfo, CompressedImage, Header, Image, Message};
use crate::reader::Bag;
use crate::scans::{add_tf, topics_of};
use crate::tf::TfTree;

/// One image as recorded.
#[derive(Clone, Debug)]
enum Pixels {
    /// PNG or JPEG bytes.
    Compressed(Vec<u8>),
    /// Raw pixels: 8-bit RGB, BGR, RGBA, BGRA or grey, rows `step` bytes apart.
    Raw(Image),
}

/// The posed colour frames of a recording, in stamp order.
#[derive(Clone, Debug)]
pub struct BagFrames {
    path: PathBuf,
    info_topic: String,
    images: Vec<Pixels>,
    intrinsics: PinholeIntrinsics,
    poses: Vec<Isometry3<f64>>,
    /// Seconds since the first frame.
    times: Vec<f64>,
}

/// Bytes per pixel of a raw encoding fuzzyvox reads.
fn channels(encoding: &str) -> Option<usize> {
    match encoding {
        "rgb8" | "bgr8" | "8UC3" => Some(3),
        "rgba8" | "bgra8" | "8UC4" => Some(4),
        "mono8" | "8UC1" => Some(1),
        _ => None,
    }
}

impl BagFrames {
    /// Reads the images on `image_topic`, the intrinsics on `info_topic` (by default the
    /// `camera_info` topic beside the images: `/cam/color/camera_info` for
    /// `/cam/color/image_raw/compressed`, or the recording's only camera-info topic) and each
    /// image's pose in `frame` from the TF tree at its stamp.
    ///
    /// Errors: no image on the topic (listing the image topics), no camera info, intrinsics
    /// that change, distortion or binning (the depth stage needs rectified, full images), a raw
    /// encoding other than 8-bit RGB, BGR, RGBA, BGRA or grey, a missing transform.
    pub fn open(
        bag: &Bag,
        image_topic: &str,
        info_topic: Option<&str>,
        frame: &str,
    ) -> Result<Self> {
        let mut tree = TfTree::new();
        let mut images: Vec<(Header, usize, Pixels)> = Vec::new();
        let mut infos: Vec<(String, CameraInfo)> = Vec::new();
        let mut info_topics: Vec<String> = Vec::new();
        let mut tf_index = 0;
        bag.for_each_message(&mut |m| {
            if add_tf(&mut tree, &m, tf_index)? {
                tf_index += 1;
                return Ok(());
            }
            let c = m.connection;
            let index = images.len();
            if c.topic == image_topic {
                let (header, pixels) = if CompressedImage::is_type(&c.msg_type) {
                    let image = CompressedImage::decode(&m, index)?;
                    (image.header, Pixels::Compressed(image.data.into_vec()))
                } else if Image::is_type(&c.msg_type) {
                    let image = Image::decode(&m, index)?;
                    check_raw(&image).map_err(|detail| BagError::BadMessage {
                        topic: c.topic.clone(),
                        msg_type: c.msg_type.clone(),
                        index,
                        detail,
                    })?;
                    (image.header.clone(), Pixels::Raw(image))
                } else {
                    return Err(BagError::WrongType {
                        topic: c.topic.clone(),
                        found: c.msg_type.clone(),
                        expected: "sensor_msgs/CompressedImage or sensor_msgs/Image",
                    });
                };
                images.push((header, index, pixels));
            } else if CameraInfo::is_type(&c.msg_type) {
                if !info_topics.contains(&c.topic) {
                    info_topics.push(c.topic.clone());
                }
                if info_topic.is_none_or(|wanted| wanted == c.topic) {
                    let at = infos.iter().filter(|(t, _)| *t == c.topic).count();
                    infos.push((c.topic.clone(), CameraInfo::decode(&m, at)?));
                }
            }
            Ok(())
        })?;
        if images.is_empty() {
            let mut available = topics_of::<CompressedImage>(bag)?;
            available.extend(topics_of::<Image>(bag)?);
            available.sort();
            return Err(BagError::UnknownTopic {
                topic: image_topic.to_string(),
                kind: "image",
                available,
            });
        }
        info_topics.sort();
        let info_topic = choose_info_topic(image_topic, info_topic, &info_topics)?;
        let intrinsics = intrinsics_of(bag.path(), &info_topic, &infos)?;
        images.sort_by_key(|(header, index, _)| (header.stamp_ns, *index));
        let first = images.first().map_or(0, |(h, _, _)| h.stamp_ns);
        let mut poses = Vec::with_capacity(images.len());
        let mut times = Vec::with_capacity(images.len());
        for (header, _, _) in &images {
            poses.push(tree.pose_of(frame, header)?);
            times.push((header.stamp_ns - first) as f64 * 1e-9);
        }
        Ok(Self {
            path: bag.path().to_path_buf(),
            info_topic,
            images: images.into_iter().map(|(_, _, p)| p).collect(),
            intrinsics,
            poses,
            times,
        })
    }

    /// The camera's intrinsics.
    pub fn intrinsics(&self) -> &PinholeIntrinsics {
        &self.intrinsics
    }

    /// Each frame's time, seconds since the first.
    pub fn times(&self) -> &[f64] {
        &self.times
    }
}

/// The camera-info topic for `image_topic`: the one asked for, else `camera_info` beside the
/// images (under the image topic's parents, nearest first), else the only one there is.
fn choose_info_topic(image_topic: &str, asked: Option<&str>, topics: &[String]) -> Result<String> {
    let missing = |topic: &str| BagError::UnknownTopic {
        topic: topic.to_string(),
        kind: "camera info",
        available: topics.to_vec(),
    };
    if let Some(asked) = asked {
        return if topics.iter().any(|t| t == asked) {
            Ok(asked.to_string())
        } else {
            Err(missing(asked))
        };
    }
    let mut prefix = image_topic;
    while let Some((parent, _)) = prefix.rsplit_once('/') {
        let beside = format!("{parent}/camera_info");
        if topics.contains(&beside) {
            return Ok(beside);
        }
        prefix = parent;
    }
    match topics {
        [only] => Ok(only.clone()),
        _ => {
            let (parent, _) = image_topic.rsplit_once('/').unwrap_or_default();
            Err(missing(&format!("{parent}/camera_info")))
        }
    }
}

/// The intrinsics of every `CameraInfo` on `topic`, which must agree and describe rectified,
/// full-resolution images.
fn intrinsics_of(
    path: &Path,
    topic: &str,
    infos: &[(String, CameraInfo)],
) -> Result<PinholeIntrinsics> {
    let unsupported = |detail: String| BagError::Unsupported {
        path: path.to_path_buf(),
        detail: format!("camera info on `{topic}`: {detail}"),
    };
    let mut on_topic = infos.iter().filter(|(t, _)| t == topic).map(|(_, i)| i);
    let Some(first) = on_topic.next() else {
        return Err(unsupported("no message".into()));
    };
    if on_topic.any(|i| {
        i.k != first.k || i.d != first.d || (i.width, i.height) != (first.width, first.height)
    }) {
        return Err(unsupported(
            "the intrinsics change during the recording".into(),
        ));
    }
    if first.d.iter().any(|&d| d != 0.0) {
        return Err(unsupported(format!(
            "{} distortion {:?}: the depth stage needs undistorted images",
            first.distortion_model, first.d
        )));
    }
    if first.binning_x > 1 || first.binning_y > 1 || first.roi.width != 0 || first.roi.height != 0 {
        return Err(unsupported(
            "binning or a region of interest is not supported".into(),
        ));
    }
    let [fx, skew, cx, zero_10, fy, cy, zero_20, zero_21, _] = first.k;
    if ![skew, zero_10, zero_20, zero_21]
        .iter()
        .all(|v| v.abs() <= 1e-9)
    {
        return Err(unsupported("K must be [fx 0 cx; 0 fy cy; 0 0 1]".into()));
    }
    Ok(PinholeIntrinsics::new(
        first.width,
        first.height,
        fx,
        fy,
        cx,
        cy,
    )?)
}

/// Checks a raw image's encoding and size against its data.
fn check_raw(image: &Image) -> std::result::Result<(), String> {
    let channels = channels(&image.encoding).ok_or_else(|| {
        format!(
            "encoding `{}`: fuzzyvox reads 8-bit rgb8, bgr8, rgba8, bgra8 and mono8",
            image.encoding
        )
    })?;
    let (width, height, step) = (
        image.width as usize,
        image.height as usize,
        image.step as usize,
    );
    let row = width.saturating_mul(channels);
    let needed = height
        .checked_sub(1)
        .map_or(0, |h| h.saturating_mul(step).saturating_add(row));
    if step < row || image.data.len() < needed {
        return Err(format!(
            "{width} × {height} {} pixels with rows of {step} bytes do not fit in {} bytes",
            image.encoding,
            image.data.len()
        ));
    }
    Ok(())
}

/// A checked raw image as RGB bytes, then grey as a decoded PNG becomes grey.
fn gray_of_raw(image: &Image) -> fuzzyvox_core::error::Result<GrayImage> {
    let channels = channels(&image.encoding).unwrap_or(3);
    let (width, step) = (image.width as usize, (image.step as usize).max(1));
    let bgr = image.encoding.starts_with("bgr");
    let mut rgb = Vec::with_capacity(width * image.height as usize * 3);
    for row in image.data.chunks(step).take(image.height as usize) {
        for pixel in row.chunks_exact(channels).take(width) {
            match (pixel, bgr) {
                ([g], _) => rgb.extend([*g, *g, *g]),
                ([b, g, r, ..], true) => rgb.extend([*r, *g, *b]),
                ([r, g, b, ..], false) => rgb.extend([*r, *g, *b]),
                _ => {}
            }
        }
    }
    GrayImage::from_rgb8(image.width, image.height, &rgb)
}

impl PosedFrames for BagFrames {
    fn source(&self) -> &Path {
        &self.path
    }

    fn intrinsics_source(&self) -> PathBuf {
        PathBuf::from(format!("{}:{}", self.path.display(), self.info_topic))
    }

    fn poses(&self) -> &[Isometry3<f64>] {
        &self.poses
    }

    fn read_frame(&self, index: usize) -> fuzzyvox_core::error::Result<Frame> {
        let (Some(pixels), Some(pose), Some(time)) = (
            self.images.get(index),
            self.poses.get(index),
            self.times.get(index),
        ) else {
            return Err(CoreError::InvalidParameter {
                name: "frame index",
                value: index as f64,
                expected: "an index below the recording's frame count",
            });
        };
        let image = match pixels {
            Pixels::Compressed(bytes) => decode_gray_image(bytes)?,
            Pixels::Raw(image) => gray_of_raw(image)?,
        };
        Frame::new(image, self.intrinsics, *pose, *time)
    }

    fn read_sensor_depth(&self, _index: usize) -> fuzzyvox_core::error::Result<Option<DepthFrame>> {
        Ok(None)
    }
}
