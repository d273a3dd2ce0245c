//! Agreement between depth images: a surface that one image alone claims counts for less in the
//! fuzzy map than one that several images agree on, and the evidence model for checked depth
//! (`EvidenceModel::confirmed`) keeps the map exact: the same images give the same file in any
//! order or split.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::{
    DepthFrame, EvidenceModel, FuzzyConfig, FuzzyMap, IntegrationOptions, IntervalDepthImage,
    PinholeIntrinsics, VoxelClass, VoxelMap, VoxelMapMut,
};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};

const W: u32 = 48;
const H: u32 = 36;

/// A camera at `x` on a line looking along +z at a wall 3 m away, every pixel at depth 3 with
/// an interval of ±1% and confidence 0.5 (about what the depth stage gives its checked pixels).
fn wall_image(x: f64) -> DepthFrame {
    let k = PinholeIntrinsics::new(W, H, 40.0, 40.0, 23.5, 17.5).unwrap();
    let n = (W * H) as usize;
    // The wall at z = 3 in the world, seen from (x, 0, 0): depth 3 along the axis everywhere.
    let depth = vec![3.0f32; n];
    let near = depth.iter().map(|d| d * 0.99).collect();
    let far = depth.iter().map(|d| d * 1.01).collect();
    let image = IntervalDepthImage::new(W, H, near, depth, far, vec![0.5; n]).unwrap();
    let pose = Isometry3::from_parts(Translation3::new(x, 0.0, 0.0), UnitQuaternion::identity());
    DepthFrame::new(k, pose, image).unwrap()
}

fn map(evidence: EvidenceModel) -> FuzzyMap {
    let mut config = FuzzyConfig::new(0.05).unwrap();
    config.evidence = evidence;
    FuzzyMap::new(config).unwrap()
}

fn integrate(map: &mut FuzzyMap, frames: &[&DepthFrame]) {
    for frame in frames {
        map.integrate_depth(frame, &IntegrationOptions::default())
            .unwrap();
    }
}

#[test]
fn a_surface_one_image_claims_counts_less_than_one_several_agree_on() {
    let frames: Vec<DepthFrame> = [-0.1, 0.0, 0.1].map(wall_image).into();
    // A point on the wall that all three cameras see.
    let on_wall = Point3::new(0.025, 0.025, 3.025);
    for evidence in [EvidenceModel::dual(), EvidenceModel::confirmed()] {
        let mut one = map(evidence);
        integrate(&mut one, &[&frames[1]]);
        let mut three = map(evidence);
        integrate(&mut three, &frames.iter().collect::<Vec<_>>());
        let (lone, agreed) = (
            one.memberships_at_point(&on_wall).unwrap(),
            three.memberships_at_point(&on_wall).unwrap(),
        );
        // One image's claim stays below the occupied threshold; three agreeing images make the
        // surface occupied.
        assert!(lone.occupied > 0.0 && lone.occupied < 0.5, "{lone:?}");
        assert!(agreed.occupied > lone.occupied, "{agreed:?} vs {lone:?}");
        assert_ne!(one.class_at_point(&on_wall).unwrap(), VoxelClass::Occupied);
        assert_eq!(
            three.class_at_point(&on_wall).unwrap(),
            VoxelClass::Occupied
        );
    }
}

#[test]
fn free_evidence_of_confirmed_depth_reaches_closer_to_the_surface() {
    // Just in front of the wall (a voxel whose centre lies 7.5 cm in front of it): the dual
    // model's free evidence stops half way into the interval, the confirmed model's reaches it.
    let frame = wall_image(0.0);
    let in_front = Point3::new(0.025, 0.025, 2.925);
    let mut dual = map(EvidenceModel::dual());
    integrate(&mut dual, &[&frame]);
    let mut confirmed = map(EvidenceModel::confirmed());
    integrate(&mut confirmed, &[&frame]);
    let (d, c) = (
        dual.memberships_at_point(&in_front).unwrap(),
        confirmed.memberships_at_point(&in_front).unwrap(),
    );
    assert!(c.free > d.free, "confirmed {c:?}, dual {d:?}");
}

#[test]
fn confirmed_evidence_merges_exactly_in_any_order_and_split() {
    let frames: Vec<DepthFrame> = (0..6).map(|i| wall_image(0.07 * f64::from(i))).collect();
    let refs: Vec<&DepthFrame> = frames.iter().collect();
    let mut all = map(EvidenceModel::confirmed());
    integrate(&mut all, &refs);
    let bytes = all.to_bytes();
    let mut reversed = map(EvidenceModel::confirmed());
    integrate(
        &mut reversed,
        &refs.iter().rev().copied().collect::<Vec<_>>(),
    );
    assert_eq!(reversed.to_bytes(), bytes);
    for cut in 1..refs.len() {
        let (a, b) = refs.split_at(cut);
        let mut left = map(EvidenceModel::confirmed());
        integrate(&mut left, a);
        let mut right = map(EvidenceModel::confirmed());
        integrate(&mut right, b);
        right.merge(&left).unwrap();
        assert_eq!(right.to_bytes(), bytes, "split at {cut}");
    }
}
