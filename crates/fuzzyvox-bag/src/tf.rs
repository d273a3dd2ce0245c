//! The TF tree of a recording: every `parent -> child` edge with its stamped transforms, looked
//! up as tf2 does. A frame's pose in another frame at time `t` chains the edges through their
//! common ancestor; each dynamic edge is interpolated between the two samples around `t`
//! (linear in translation, spherical in rotation) and never extrapolated; static edges
//! (`/tf_static`) hold at every time.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::Serialize;

use crate::error::BagError;
use crate::messages::{Header, TransformStamped, frame_name};

/// Chains longer than this are taken for a loop.
const MAX_DEPTH: usize = 1000;

/// One edge: the child's pose in its parent over time.
#[derive(Clone, Debug, Default)]
struct Edge {
    parent: String,
    /// `(stamp ns, parent_from_child)`, sorted by stamp, one per stamp.
    samples: Vec<(i64, Isometry3<f64>)>,
    is_static: bool,
    /// Another parent seen for this child, which tf2 refuses too.
    conflict: Option<String>,
}

/// A summary of one edge, for `info`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TfEdge {
    /// The parent frame.
    pub parent: String,
    /// The child frame.
    pub child: String,
    /// Whether it came from `/tf_static`.
    pub is_static: bool,
    /// Transforms recorded for it.
    pub samples: usize,
    /// Its first and last stamps, seconds.
    pub first: f64,
    /// See `first`.
    pub last: f64,
}

/// Every edge of a recording's TF tree.
#[derive(Clone, Debug, Default)]
pub struct TfTree {
    /// By child frame.
    edges: BTreeMap<String, Edge>,
    /// Transforms refused (not a rigid transform).
    invalid: usize,
}

impl TfTree {
    /// An empty tree.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one transform (`is_static` for `/tf_static`). A transform whose quaternion is not
    /// finite or has zero length is counted and skipped; so is a second transform for the same
    /// edge and stamp (the first is kept).
    pub fn add(&mut self, t: &TransformStamped, is_static: bool) {
        let r = t.transform.rotation;
        let v = t.transform.translation;
        let q = Quaternion::new(r.w, r.x, r.y, r.z);
        let finite = [r.x, r.y, r.z, r.w, v.x, v.y, v.z]
            .iter()
            .all(|c| c.is_finite());
        if !finite || q.norm() < 1e-9 {
            self.invalid += 1;
            return;
        }
        let pose = Isometry3::from_parts(
            Translation3::new(v.x, v.y, v.z),
            UnitQuaternion::from_quaternion(q),
        );
        let parent = frame_name(&t.header.frame_id);
        let child = frame_name(&t.child_frame_id);
        let edge = self.edges.entry(child).or_insert_with(|| Edge {
            parent: parent.clone(),
            ..Edge::default()
        });
        if edge.parent != parent {
            edge.conflict.get_or_insert(parent);
            return;
        }
        edge.is_static |= is_static;
        let stamp = t.header.stamp_ns;
        match edge.samples.binary_search_by_key(&stamp, |s| s.0) {
            Ok(_) => {}
            Err(at) => edge.samples.insert(at, (stamp, pose)),
        }
    }

    /// Transforms skipped because they were not rigid.
    pub fn invalid(&self) -> usize {
        self.invalid
    }

    /// Every edge, by child frame.
    pub fn edges(&self) -> Vec<TfEdge> {
        self.edges
            .iter()
            .map(|(child, e)| TfEdge {
                parent: e.parent.clone(),
                child: child.clone(),
                is_static: e.is_static,
                samples: e.samples.len(),
                first: e.samples.first().map_or(0.0, |s| s.0 as f64 * 1e-9),
                last: e.samples.last().map_or(0.0, |s| s.0 as f64 * 1e-9),
            })
            .collect()
    }

    /// `target_from_source` at `stamp_ns`: the pose of frame `source` in frame `target`.
    /// Errors (in words) name the frame that is unknown or unconnected, or the edge whose
    /// samples do not reach the stamp, with the times they cover.
    pub fn lookup(
        &self,
        target: &str,
        source: &str,
        stamp_ns: i64,
    ) -> Result<Isometry3<f64>, String> {
        let (target, source) = (frame_name(target), frame_name(source));
        if target == source {
            return Ok(Isometry3::identity());
        }
        let up_source = self.chain(&source)?;
        let up_target = self.chain(&target)?;
        // The lowest common ancestor: the first frame of the source's chain on the target's.
        let Some((i, j)) = up_source.iter().enumerate().find_map(|(i, frame)| {
            up_target
                .iter()
                .position(|other| other == frame)
                .map(|j| (i, j))
        }) else {
            return Err(format!(
                "`{source}` and `{target}` are in unconnected trees (roots `{}` and `{}`)",
                up_source.last().map_or("", String::as_str),
                up_target.last().map_or("", String::as_str)
            ));
        };
        let ancestor_from_source =
            self.compose(up_source.get(..=i).unwrap_or_default(), stamp_ns)?;
        let ancestor_from_target =
            self.compose(up_target.get(..=j).unwrap_or_default(), stamp_ns)?;
        Ok(ancestor_from_target.inverse() * ancestor_from_source)
    }

    /// The pose in `frame` of the data stamped by `header` (its frame at its stamp), or
    /// [`BagError::NoTransform`] naming both frames, the stamp and why.
    pub fn pose_of(&self, frame: &str, header: &Header) -> crate::Result<Isometry3<f64>> {
        self.lookup(frame, &header.frame_id, header.stamp_ns)
            .map_err(|detail| BagError::NoTransform {
                source_frame: header.frame_id.clone(),
                target_frame: frame_name(frame),
                stamp: header.stamp_seconds(),
                detail,
            })
    }

    /// `frame`, its parent, its parent's parent, ... up to the root.
    fn chain(&self, frame: &str) -> Result<Vec<String>, String> {
        let mut chain = vec![frame.to_string()];
        let mut at = frame;
        while let Some(edge) = self.edges.get(at) {
            if let Some(other) = &edge.conflict {
                return Err(format!(
                    "frame `{at}` has two parents, `{}` and `{other}`",
                    edge.parent
                ));
            }
            if chain.len() > MAX_DEPTH || chain.contains(&edge.parent) {
                return Err(format!("the TF tree loops through `{at}`"));
            }
            chain.push(edge.parent.clone());
            at = &edge.parent;
        }
        if chain.len() == 1 && !self.edges.values().any(|e| e.parent == frame) {
            let mut known: Vec<&str> = self
                .edges
                .iter()
                .flat_map(|(c, e)| [c.as_str(), e.parent.as_str()])
                .collect();
            known.sort_unstable();
            known.dedup();
            return Err(if known.is_empty() {
                format!("no frame `{frame}`: the recording has no transforms")
            } else {
                format!(
                    "no frame `{frame}` in the TF tree (frames: {})",
                    known.join(", ")
                )
            });
        }
        Ok(chain)
    }

    /// `chain[last]_from_chain[0]` at `stamp_ns`, for a chain of child-to-parent frames.
    fn compose(&self, chain: &[String], stamp_ns: i64) -> Result<Isometry3<f64>, String> {
        let mut pose = Isometry3::identity();
        for child in chain.iter().take(chain.len().saturating_sub(1)) {
            let edge = self
                .edges
                .get(child)
                .ok_or_else(|| format!("no parent of `{child}`"))?;
            pose = edge.at(child, stamp_ns)? * pose;
        }
        Ok(pose)
    }
}

impl Edge {
    /// `parent_from_child` at `stamp_ns`.
    fn at(&self, child: &str, stamp_ns: i64) -> Result<Isometry3<f64>, String> {
        if let (true, Some((_, pose))) = (self.is_static, self.samples.last()) {
            return Ok(*pose);
        }
        let after = self.samples.partition_point(|s| s.0 < stamp_ns);
        match (
            after.checked_sub(1).and_then(|i| self.samples.get(i)),
            self.samples.get(after),
        ) {
            (_, Some((t, pose))) if *t == stamp_ns => Ok(*pose),
            (Some((t0, a)), Some((t1, b))) => {
                let s = (stamp_ns - t0) as f64 / (t1 - t0) as f64;
                Ok(a.lerp_slerp(b, s))
            }
            _ => Err(format!(
                "`{}` -> `{child}` has {} transform(s) from {:.9} to {:.9} s, and tf never \
                 extrapolates",
                self.parent,
                self.samples.len(),
                self.samples.first().map_or(0.0, |s| s.0 as f64 * 1e-9),
                self.samples.last().map_or(0.0, |s| s.0 as f64 * 1e-9),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{Quaternion as Q, Transform, Vector3};
    use nalgebra::{Point3, Vector3 as V};

    fn t(parent: &str, child: &str, ns: i64, xyz: [f64; 3], yaw: f64) -> TransformStamped {
        let q = UnitQuaternion::from_axis_angle(&V::z_axis(), yaw);
        TransformStamped {
            header: Header {
                stamp_ns: ns,
                frame_id: parent.into(),
            },
            child_frame_id: child.into(),
            transform: Transform {
                translation: Vector3 {
                    x: xyz[0],
                    y: xyz[1],
                    z: xyz[2],
                },
                rotation: Q {
                    x: q.i,
                    y: q.j,
                    z: q.k,
                    w: q.w,
                },
            },
        }
    }

    #[test]
    fn chains_interpolate_and_meet_at_the_common_ancestor() {
        let mut tree = TfTree::new();
        tree.add(&t("/map", "odom", 0, [1.0, 0.0, 0.0], 0.0), true);
        tree.add(&t("odom", "base", 100, [0.0, 0.0, 0.0], 0.0), false);
        tree.add(
            &t(
                "odom",
                "base",
                300,
                [2.0, 0.0, 0.0],
                std::f64::consts::FRAC_PI_2,
            ),
            false,
        );
        tree.add(&t("base", "/camera", 0, [0.0, 0.0, 1.0], 0.0), true);
        tree.add(&t("odom", "arm", 0, [0.0, 5.0, 0.0], 0.0), true);
        // Halfway: base at x = 1 in odom, turned by 45 degrees; the camera a metre above it.
        let pose = tree.lookup("map", "camera", 200).unwrap();
        assert!((pose.translation.vector - V::new(2.0, 0.0, 1.0)).norm() < 1e-12);
        let turned = pose.rotation * V::x();
        assert!((turned - V::new(1.0, 1.0, 0.0).normalize()).norm() < 1e-12);
        // An exact stamp takes its sample; frames with a leading slash are the same frames.
        let exact = tree.lookup("/map", "/base", 300).unwrap();
        assert!((exact * Point3::origin() - Point3::new(3.0, 0.0, 0.0)).norm() < 1e-12);
        // Sibling branches meet at odom: the arm seen from the camera at time 100.
        let arm = tree.lookup("camera", "arm", 100).unwrap();
        assert!((arm * Point3::origin() - Point3::new(0.0, 5.0, -1.0)).norm() < 1e-12);
        assert_eq!(tree.lookup("map", "map", 7).unwrap(), Isometry3::identity());
    }

    #[test]
    fn gaps_in_time_or_tree_name_what_is_missing() {
        let mut tree = TfTree::new();
        tree.add(&t("map", "base", 100, [0.0; 3], 0.0), false);
        tree.add(&t("map", "base", 200, [0.0; 3], 0.0), false);
        tree.add(&t("world", "other", 0, [0.0; 3], 0.0), true);
        let early = tree.lookup("map", "base", 50).unwrap_err();
        assert!(early.contains("from 0.000000100 to 0.000000200"), "{early}");
        assert!(tree.lookup("map", "base", 201).is_err());
        let unknown = tree.lookup("map", "lidar", 150).unwrap_err();
        assert!(
            unknown.contains("no frame `lidar`") && unknown.contains("base"),
            "{unknown}"
        );
        let apart = tree.lookup("map", "other", 150).unwrap_err();
        assert!(apart.contains("unconnected"), "{apart}");
        let empty = TfTree::new().lookup("map", "lidar", 0).unwrap_err();
        assert!(empty.contains("no transforms"), "{empty}");
    }

    #[test]
    fn bad_quaternions_and_second_parents_are_refused() {
        let mut tree = TfTree::new();
        let mut bad = t("map", "base", 0, [0.0; 3], 0.0);
        bad.transform.rotation = Q::default();
        tree.add(&bad, false);
        bad.transform.rotation.w = f64::NAN;
        tree.add(&bad, false);
        assert_eq!(tree.invalid(), 2);
        tree.add(&t("map", "base", 0, [0.0; 3], 0.0), true);
        tree.add(&t("odom", "base", 0, [0.0; 3], 0.0), true);
        let two = tree.lookup("map", "base", 0).unwrap_err();
        assert!(two.contains("two parents"), "{two}");
        let mut looped = TfTree::new();
        looped.add(&t("a", "b", 0, [0.0; 3], 0.0), true);
        looped.add(&t("b", "a", 0, [0.0; 3], 0.0), true);
        assert!(looped.lookup("a", "c", 0).is_err());
        assert!(looped.lookup("b", "a", 0).unwrap_err().contains("loops"));
    }
}
