//! Folders of posed camera images, the input of the one-camera depth stage on real footage.
//!
//! The layout of the RGB-D folders (7-Scenes / 3DMatch): `frame-N.color.png` or `.color.jpg`
//! (or `.jpeg`), `frame-N.pose.txt` (row-major 4×4 `world_from_camera`) and
//! `camera-intrinsics.txt` (3×3 K). Optional:
//!
//! - `color-intrinsics.txt`: K of the colour camera, read instead of `camera-intrinsics.txt`
//!   for the images when present (7-Scenes's colour and depth cameras differ);
//! - `frame-N.depth.png`: sensor depth (16-bit millimetres in the depth camera, whose K is
//!   `camera-intrinsics.txt`), used only to evaluate, never to map;
//! - a TUM trajectory instead of the pose files ([`parse_tum_trajectory`]);
//! - a colour-to-depth extrinsics file: when the poses are those of the depth camera (as in
//!   7-Scenes), the colour camera's pose is `world_from_depth · depth_from_color`.

use std::path::{Path, PathBuf};

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::geometry::{PinholeIntrinsics, validate_pose};
use fuzzyvox_core::image::Frame;
use fuzzyvox_core::integrate::DepthFrame;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use super::gray::read_gray_image;
use super::rgbd::{kinect_interval_image, read_depth_png_mm, read_intrinsics_txt, read_pose_txt};

/// Frames per second assumed for frame numbers without a trajectory's timestamps (a frame's
/// time is `N / 30` s, the rate of the Kinect that recorded 7-Scenes).
pub const DEFAULT_FRAME_RATE: f64 = 30.0;

/// The files of one posed frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PosedFrameFiles {
    /// The frame number `N` of `frame-N.*`.
    pub number: u64,
    /// `frame-N.color.png`, `.color.jpg` or `.color.jpeg`.
    pub color: PathBuf,
    /// `frame-N.depth.png`, when the folder has it (evaluation only).
    pub depth: Option<PathBuf>,
}

/// A folder of posed images: frames in order of their number, with their poses and times.
#[derive(Clone, Debug)]
pub struct PosedFolder {
    /// The folder.
    pub dir: PathBuf,
    /// The frames, by increasing number.
    pub frames: Vec<PosedFrameFiles>,
    /// Each frame's `world_from_camera` of the colour camera (extrinsics applied).
    pub poses: Vec<Isometry3<f64>>,
    /// Each frame's time in seconds.
    pub times: Vec<f64>,
    /// The colour camera's K file: `color-intrinsics.txt` when present, else
    /// `camera-intrinsics.txt`.
    pub color_intrinsics: PathBuf,
    /// `camera-intrinsics.txt`, the depth camera's K.
    pub depth_intrinsics: PathBuf,
    /// `depth_from_color`, identity unless given.
    pub depth_from_color: Isometry3<f64>,
}

impl PosedFolder {
    /// Lists the frames of `dir` with their poses: from each `frame-N.pose.txt`, or, with
    /// `trajectory`, from a TUM trajectory whose k-th pose belongs to the k-th frame (the counts
    /// must match). `depth_from_color` (the colour camera in the depth camera's frame) turns
    /// the poses, which are the depth camera's, into the colour camera's.
    ///
    /// Errors: no colour frame, a frame without its pose, a missing `camera-intrinsics.txt`,
    /// a trajectory of another length, invalid poses, two colour files for one frame number.
    pub fn open(
        dir: &Path,
        trajectory: Option<&Path>,
        depth_from_color: Option<Isometry3<f64>>,
    ) -> Result<Self> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io { path, source }
        };
        let mut frames: Vec<PosedFrameFiles> = Vec::new();
        for entry in std::fs::read_dir(dir).map_err(io(dir))? {
            let name = entry.map_err(io(dir))?.file_name();
            let Some(name) = name.to_str() else { continue };
            let Some(number) = name.strip_prefix("frame-").and_then(|rest| {
                [".color.png", ".color.jpg", ".color.jpeg"]
                    .iter()
                    .find_map(|ext| rest.strip_suffix(ext))
            }) else {
                continue;
            };
            let parsed: u64 = number.parse().map_err(|_| Error::Parse {
                path: dir.join(name),
                line: 0,
                message: format!("`{number}` is not a frame number"),
            })?;
            let depth = dir.join(format!("frame-{number}.depth.png"));
            frames.push(PosedFrameFiles {
                number: parsed,
                color: dir.join(name),
                depth: depth.is_file().then_some(depth),
            });
        }
        if frames.is_empty() {
            return Err(Error::Empty(
                "posed image folder (frame-N.color.png or .jpg files)",
            ));
        }
        frames.sort_by_key(|f| f.number);
        let twice = frames.windows(2).find_map(|pair| match pair {
            [a, b] if a.number == b.number => Some((a, b)),
            _ => None,
        });
        if let Some((a, b)) = twice {
            return Err(Error::Duplicate(format!(
                "frame {}'s colour image ({} and {})",
                a.number,
                a.color.display(),
                b.color.display()
            )));
        }
        let depth_intrinsics = dir.join("camera-intrinsics.txt");
        if !depth_intrinsics.is_file() {
            return Err(Error::Io {
                path: depth_intrinsics,
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "no camera intrinsics"),
            });
        }
        let color = dir.join("color-intrinsics.txt");
        let color_intrinsics = if color.is_file() {
            color
        } else {
            depth_intrinsics.clone()
        };
        let depth_from_color = depth_from_color.unwrap_or_else(Isometry3::identity);
        validate_pose(&depth_from_color)?;
        let (sensor_poses, times) = match trajectory {
            Some(path) => {
                let bytes = std::fs::read(path).map_err(io(path))?;
                let stamped = parse_tum_trajectory(&bytes, path)?;
                if stamped.len() != frames.len() {
                    return Err(Error::SizeMismatch {
                        what: "trajectory poses (one per colour frame, in frame order)",
                        expected: frames.len(),
                        found: stamped.len(),
                    });
                }
                stamped.into_iter().map(|(t, p)| (p, t)).unzip()
            }
            None => {
                let mut poses = Vec::with_capacity(frames.len());
                for f in &frames {
                    let path = pose_path(&f.color);
                    if !path.is_file() {
                        return Err(Error::Io {
                            path,
                            source: std::io::Error::new(
                                std::io::ErrorKind::NotFound,
                                format!("the pose of {} is missing", f.color.display()),
                            ),
                        });
                    }
                    poses.push(read_pose_txt(&path)?);
                }
                let times = frames
                    .iter()
                    .map(|f| f.number as f64 / DEFAULT_FRAME_RATE)
                    .collect();
                (poses, times)
            }
        };
        let poses = sensor_poses.iter().map(|p| p * depth_from_color).collect();
        Ok(Self {
            dir: dir.to_path_buf(),
            frames,
            poses,
            times,
            color_intrinsics,
            depth_intrinsics,
            depth_from_color,
        })
    }

    /// Frame `index` (position in [`Self::frames`]) as the depth stage reads it: the grey image,
    /// the colour camera's intrinsics and pose, and its time.
    pub fn read_frame(&self, index: usize) -> Result<Frame> {
        let (files, pose) = self.files(index)?;
        let image = read_gray_image(&files.color)?;
        let intrinsics =
            read_intrinsics_txt(&self.color_intrinsics, image.width(), image.height())?;
        let time = self.times.get(index).copied().unwrap_or_default();
        Frame::new(image, intrinsics, pose, time)
    }

    /// Frame `index`'s sensor depth in the depth camera (its pose: the colour camera's pose
    /// times `color_from_depth`), with the Kinect noise model, or `None` when the folder has no
    /// depth image for it.
    pub fn read_sensor_depth(&self, index: usize) -> Result<Option<DepthFrame>> {
        let (files, color_pose) = self.files(index)?;
        let Some(path) = &files.depth else {
            return Ok(None);
        };
        let depth = read_depth_png_mm(path)?;
        let intrinsics: PinholeIntrinsics =
            read_intrinsics_txt(&self.depth_intrinsics, depth.width, depth.height)?;
        let pose = color_pose * self.depth_from_color.inverse();
        DepthFrame::new(intrinsics, pose, kinect_interval_image(&depth)?).map(Some)
    }

    /// Frame `index`'s files and colour pose.
    fn files(&self, index: usize) -> Result<(&PosedFrameFiles, Isometry3<f64>)> {
        match (self.frames.get(index), self.poses.get(index)) {
            (Some(files), Some(pose)) => Ok((files, *pose)),
            _ => Err(Error::InvalidParameter {
                name: "frame index",
                value: index as f64,
                expected: "an index below the folder's frame count",
            }),
        }
    }
}

/// Posed colour frames from any source, as the one-camera depth stage and its checks read
/// them: a folder ([`PosedFolder`]) or a robot recording (`fuzzyvox-bag`'s `BagFrames`).
pub trait PosedFrames: Sync {
    /// Where the frames come from (a folder, a recording), for reports.
    fn source(&self) -> &Path;
    /// Where the colour camera's intrinsics come from (a file, or a recording's topic), for
    /// reports.
    fn intrinsics_source(&self) -> PathBuf;
    /// Each frame's `world_from_camera` of the colour camera, in frame order.
    fn poses(&self) -> &[Isometry3<f64>];
    /// Frame `index` as the depth stage reads it: the grey image, the colour camera's
    /// intrinsics and pose, and its time.
    fn read_frame(&self, index: usize) -> Result<Frame>;
    /// Frame `index`'s sensor depth with its noise model, or `None` when the source has none
    /// for it (used to evaluate, never to map).
    fn read_sensor_depth(&self, index: usize) -> Result<Option<DepthFrame>>;
    /// The number of frames.
    fn len(&self) -> usize {
        self.poses().len()
    }
    /// Whether there is no frame.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl PosedFrames for PosedFolder {
    fn source(&self) -> &Path {
        &self.dir
    }

    fn intrinsics_source(&self) -> PathBuf {
        self.color_intrinsics.clone()
    }

    fn poses(&self) -> &[Isometry3<f64>] {
        &self.poses
    }

    fn read_frame(&self, index: usize) -> Result<Frame> {
        PosedFolder::read_frame(self, index)
    }

    fn read_sensor_depth(&self, index: usize) -> Result<Option<DepthFrame>> {
        PosedFolder::read_sensor_depth(self, index)
    }
}

/// `frame-N.pose.txt` beside a `frame-N.color.*` file, keeping the number's own digits.
fn pose_path(color: &Path) -> PathBuf {
    let name = color
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    let stem = name.split(".color.").next().unwrap_or(name);
    color.with_file_name(format!("{stem}.pose.txt"))
}

/// Parses a TUM trajectory: one `timestamp tx ty tz qx qy qz qw` line per pose
/// (`world_from_camera`, metres and a unit quaternion; `#` lines and blank lines skipped).
/// Timestamps must be finite and non-decreasing; the quaternion is normalised when within 1e-3
/// of unit length, else refused. `path` names the file in errors.
pub fn parse_tum_trajectory(bytes: &[u8], path: &Path) -> Result<Vec<(f64, Isometry3<f64>)>> {
    let text = std::str::from_utf8(bytes).map_err(|_| Error::Parse {
        path: path.to_path_buf(),
        line: 0,
        message: "not UTF-8 text".into(),
    })?;
    let mut poses: Vec<(f64, Isometry3<f64>)> = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let error = |message: String| Error::Parse {
            path: path.to_path_buf(),
            line: index + 1,
            message,
        };
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let values: Vec<f64> = line
            .split_whitespace()
            .map(|v| v.parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| error(format!("not a number: {e}")))?;
        let &[t, x, y, z, qx, qy, qz, qw] = values.as_slice() else {
            return Err(error(format!(
                "expected `timestamp tx ty tz qx qy qz qw`, found {} values",
                values.len()
            )));
        };
        if !values.iter().all(|v| v.is_finite()) {
            return Err(error("every value must be finite".into()));
        }
        if poses.last().is_some_and(|(last, _)| t < *last) {
            return Err(error(format!("timestamp {t} goes back in time")));
        }
        let q = Quaternion::new(qw, qx, qy, qz);
        if (q.norm() - 1.0).abs() > 1e-3 {
            return Err(error(format!(
                "the rotation quaternion has length {:.4}, not 1",
                q.norm()
            )));
        }
        let pose = Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_quaternion(q),
        );
        poses.push((t, pose));
    }
    if poses.is_empty() {
        return Err(Error::Empty("trajectory"));
    }
    Ok(poses)
}
