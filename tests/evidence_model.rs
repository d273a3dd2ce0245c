//! The dual evidence model, part by part: a pixel without a far bound still clears up to its
//! near bound, free evidence is graded and falls monotonically through the interval, and free
//! evidence does not depend on the interval's width or the confidence; point clouds the same.
//! The paper's model, kept for comparison, is checked beside it.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::VoxelMapMut;
use fuzzyvox::integrate::depth_evidence;
use fuzzyvox::storage::Resolution;
use fuzzyvox::{
    DepthFrame, Evidence, EvidenceKind, EvidenceModel, FuzzyConfig, FuzzyMap, IntegrationOptions,
    IntervalDepthImage, Memberships, PinholeIntrinsics, PointCloud, TConorm, VoxelMap,
};
use nalgebra::{Isometry3, Point3};

const RES: f64 = 0.1;
/// Half a voxel diagonal at `RES`.
const DELTA: f64 = 0.5 * 1.732_050_8 * RES;
const SIDE: u32 = 64;

fn map(model: EvidenceModel) -> FuzzyMap {
    FuzzyMap::new(FuzzyConfig::new(RES).unwrap().with_evidence(model)).unwrap()
}

/// A camera at the origin looking along +z whose every pixel has the same interval.
fn frame(near: f32, depth: f32, far: f32, confidence: f32, reliability: Option<f32>) -> DepthFrame {
    let n = (SIDE * SIDE) as usize;
    let mut image = IntervalDepthImage::new(
        SIDE,
        SIDE,
        vec![near; n],
        vec![depth; n],
        vec![far; n],
        vec![confidence; n],
    )
    .unwrap();
    if let Some(r) = reliability {
        image = image.with_reliability(vec![r; n]).unwrap();
    }
    let k = PinholeIntrinsics::new(SIDE, SIDE, 50.0, 50.0, 31.5, 31.5).unwrap();
    DepthFrame::new(k, Isometry3::identity(), image).unwrap()
}

/// Memberships of the voxels just beside the optical axis, by the depth of their centres.
fn along_axis(map: &FuzzyMap) -> Vec<(f64, Memberships)> {
    (1..120)
        .map(|k| {
            let centre = Point3::new(-0.05, -0.05, (f64::from(k) + 0.5) * RES);
            (centre.z, map.memberships_at_point(&centre).unwrap())
        })
        .collect()
}

fn integrate(model: EvidenceModel, frame: &DepthFrame) -> FuzzyMap {
    let mut m = map(model);
    m.integrate_depth(frame, &IntegrationOptions::default())
        .unwrap();
    m
}

#[test]
fn a_pixel_without_a_far_bound_clears_up_to_its_near_bound() {
    // P+ undefined (the disparity's far end at infinity) and no confidence, but a reliable match.
    let without_far = frame(3.0, 5.0, f32::NAN, f32::NAN, Some(1.0));
    let dual = along_axis(&integrate(EvidenceModel::dual(), &without_far));
    for (z, m) in &dual {
        assert_eq!(
            m.occupied, 0.0,
            "no occupied evidence without a confidence (z = {z})"
        );
        if *z < 3.0 - DELTA {
            assert!(m.free >= 0.59, "z = {z}: free {} in front of P-", m.free);
        }
        if *z > 4.0 {
            assert_eq!(m.free, 0.0, "z = {z}: cleared past the profile's end");
        }
    }
    // The paper's model reads only pixels with all three depths and a confidence.
    let paper = integrate(EvidenceModel::paper(), &without_far);
    assert!(paper.cells().next().is_none());
    // Without reliability, the same pixel gives nothing in the dual model either.
    let unreliable = frame(3.0, 5.0, f32::NAN, f32::NAN, Some(0.0));
    assert!(
        integrate(EvidenceModel::dual(), &unreliable)
            .cells()
            .next()
            .is_none()
    );
}

#[test]
fn free_membership_falls_monotonically_through_the_interval() {
    let model = EvidenceModel::dual();
    let cells = along_axis(&integrate(model, &frame(3.0, 5.0, 8.0, 0.8, Some(1.0))));
    let profile_end = 3.0 + f64::from(model.free_reach) * 2.0 - DELTA;
    let mut graded = 0;
    for pair in cells.windows(2) {
        let ((z0, a), (z1, b)) = (pair[0], pair[1]);
        assert!(
            b.free <= a.free,
            "free rises from {} at z = {z0} to {} at z = {z1}",
            a.free,
            b.free
        );
        if z0 > 3.0 - DELTA && z0 < profile_end && a.free > 0.0 {
            graded += 1;
            assert!(
                a.free < cells[0].1.free,
                "z = {z0} inside the interval at full strength"
            );
        }
    }
    assert!(
        graded >= 3,
        "only {graded} voxels with graded free evidence"
    );
    for (z, m) in &cells {
        if *z >= profile_end {
            assert_eq!(m.free, 0.0, "z = {z} beyond the profile's end");
        }
    }
    // The paper's model stops at P- - δ.
    let paper = along_axis(&integrate(
        EvidenceModel::paper(),
        &frame(3.0, 5.0, 8.0, 0.8, None),
    ));
    assert!(paper.iter().all(|(z, m)| *z < 3.0 - DELTA || m.free == 0.0));
}

/// The evidence one frame gives the voxels of a map at `resolution`, before the map folds it in.
fn scan_evidence(
    model: EvidenceModel,
    frame: &DepthFrame,
    resolution: &Resolution,
) -> fuzzyvox::ScanEvidence {
    let options = IntegrationOptions::default();
    depth_evidence(frame, resolution, &model, &TConorm::default(), &options)
        .unwrap()
        .0
}

/// The evidence one frame gives the voxels beside the optical axis, before the map folds it in.
fn evidence_along_axis(model: EvidenceModel, frame: &DepthFrame) -> Vec<(f64, Evidence)> {
    let resolution = Resolution::new(RES).unwrap();
    let scan = scan_evidence(model, frame, &resolution);
    (1..120)
        .map(|k| {
            let centre = Point3::new(-0.05, -0.05, (f64::from(k) + 0.5) * RES);
            let key = resolution.key_of(&centre).unwrap();
            (centre.z, scan.cell(key).copied().unwrap_or_default())
        })
        .collect()
}

#[test]
fn free_evidence_does_not_depend_on_the_interval_width_or_the_confidence() {
    let model = EvidenceModel::dual();
    // Through the whole profile, the free evidence a frame gives is the same bit for bit.
    let narrow = evidence_along_axis(model, &frame(3.0, 5.0, 6.0, 0.9, Some(0.7)));
    let wide = evidence_along_axis(model, &frame(3.0, 5.0, 40.0, 0.05, Some(0.7)));
    let mut occupied_differs = false;
    for ((z, a), (_, b)) in narrow.iter().zip(&wide) {
        assert_eq!(a.free.to_bits(), b.free.to_bits(), "z = {z}: {a:?} {b:?}");
        occupied_differs |= a.occupied != b.occupied;
    }
    assert!(
        occupied_differs,
        "occupied evidence should follow the confidence"
    );
    assert!(narrow.iter().any(|(z, e)| *z > 3.0 && e.free > 0.0));
    // In the map, a voxel that the same frame also claims occupied keeps "free and not
    // occupied" (`FuzzyMap::apply_evidence`); in front of the interval the memberships are
    // equal bit for bit.
    let narrow = along_axis(&integrate(model, &frame(3.0, 5.0, 6.0, 0.9, Some(0.7))));
    let wide = along_axis(&integrate(model, &frame(3.0, 5.0, 40.0, 0.05, Some(0.7))));
    for ((z, a), (_, b)) in narrow.iter().zip(&wide) {
        if *z < 3.0 - DELTA {
            assert_eq!(a.free.to_bits(), b.free.to_bits(), "z = {z}");
        }
    }
    // The reliability does change it: half as reliable, half an observation.
    let half = along_axis(&integrate(model, &frame(3.0, 5.0, 6.0, 0.9, Some(0.35))));
    let (full, halved) = (narrow[5].1.free, half[5].1.free);
    assert!(
        (1.0 - halved - (1.0 - full).sqrt()).abs() < 1e-6,
        "{full} {halved}"
    );
    // In the paper's model the width does change free evidence, through the confidence.
    let paper = EvidenceModel {
        kind: EvidenceKind::Paper,
        ..EvidenceModel::paper()
    };
    let a = along_axis(&integrate(paper, &frame(3.0, 5.0, 6.0, 0.9, None)));
    let b = along_axis(&integrate(paper, &frame(3.0, 5.0, 40.0, 0.05, None)));
    assert!(a[5].1.free > b[5].1.free);
}

#[test]
fn point_clouds_weigh_free_space_by_reliability_in_the_dual_model() {
    let points = vec![Point3::new(0.05, 0.05, 2.05)];
    let cloud = |confidence: f32, reliability: Option<f32>| {
        let c = PointCloud::new(Point3::new(0.05, 0.05, 0.05), points.clone())
            .unwrap()
            .with_confidence(vec![confidence])
            .unwrap();
        match reliability {
            Some(r) => c.with_reliability(vec![r]).unwrap(),
            None => c,
        }
    };
    let free_at = |model: EvidenceModel, cloud: &PointCloud| {
        let mut m = map(model);
        m.integrate_cloud(cloud, &IntegrationOptions::default())
            .unwrap();
        m.memberships_at_point(&Point3::new(0.05, 0.05, 1.05))
            .unwrap()
    };
    let dual = EvidenceModel::dual();
    // A point without confidence still clears its ray when it is reliable.
    let cleared = free_at(dual, &cloud(0.0, Some(1.0)));
    assert!(cleared.free > 0.59 && cleared.occupied == 0.0);
    assert_eq!(
        free_at(EvidenceModel::paper(), &cloud(0.0, Some(1.0))).free,
        0.0
    );
    // Free evidence follows the reliability, not the confidence.
    assert_eq!(
        free_at(dual, &cloud(0.2, None)).free.to_bits(),
        free_at(dual, &cloud(1.0, None)).free.to_bits()
    );
    assert!(free_at(dual, &cloud(1.0, Some(0.25))).free < free_at(dual, &cloud(1.0, None)).free);
    assert!(
        free_at(EvidenceModel::paper(), &cloud(0.2, None)).free
            < free_at(EvidenceModel::paper(), &cloud(1.0, None)).free
    );
}

#[test]
fn the_dual_model_is_the_default_and_both_models_validate() {
    assert_eq!(EvidenceModel::default(), EvidenceModel::dual());
    assert_eq!(EvidenceModel::default().kind, EvidenceKind::Dual);
    let mut bad = EvidenceModel::dual();
    bad.free_reach = 1.5;
    assert!(FuzzyMap::new(FuzzyConfig::new(RES).unwrap().with_evidence(bad)).is_err());
    bad.free_reach = f32::NAN;
    assert!(FuzzyMap::new(FuzzyConfig::new(RES).unwrap().with_evidence(bad)).is_err());
}

#[test]
fn voxels_over_unmeasured_pixels_read_their_footprint() {
    // Every other pixel has no measurement (a sparse stereo depth image); near the camera each
    // voxel spans several pixels, so it clears from its measured neighbours.
    let n = (SIDE * SIDE) as usize;
    let holes = |plane: f32| -> Vec<f32> {
        (0..n)
            .map(|i| {
                if (i + i / SIDE as usize).is_multiple_of(2) {
                    plane
                } else {
                    f32::NAN
                }
            })
            .collect()
    };
    let image = IntervalDepthImage::new(SIDE, SIDE, holes(3.0), holes(5.0), holes(8.0), holes(0.8))
        .unwrap()
        .with_reliability(holes(1.0))
        .unwrap();
    let k = PinholeIntrinsics::new(SIDE, SIDE, 50.0, 50.0, 31.5, 31.5).unwrap();
    let sparse = DepthFrame::new(k, Isometry3::identity(), image).unwrap();
    let count_free = |model: EvidenceModel| {
        let map = integrate(model, &sparse);
        map.cells()
            .filter(|(_, m)| m.free > 0.0 && m.occupied == 0.0)
            .count()
    };
    let without = EvidenceModel {
        fill_footprints: false,
        ..EvidenceModel::dual()
    };
    let (filled, sampled) = (count_free(EvidenceModel::dual()), count_free(without));
    assert!(
        filled as f64 > 1.2 * sampled as f64,
        "{filled} free voxels with footprints, {sampled} without"
    );
    // Nothing is cleared past the nearest near bound.
    for (z, m) in along_axis(&integrate(EvidenceModel::dual(), &sparse)) {
        if z > 3.0 - DELTA + 0.5 * 2.0 {
            assert_eq!(m.free, 0.0, "z = {z}");
        }
    }
}

/// A wall 3.02 m in front of a camera at the origin (0.05 m voxels, 400 px focal length, so
/// each voxel of the wall holds some 40 pixels' end points), except the pixels `short`, whose
/// depth came out 0.15 m short; every interval ±3%, confidence 0.9.
fn wall_with_short_pixels(short: &[usize]) -> DepthFrame {
    const W: u32 = 120;
    let n = (W * W) as usize;
    let mut depth = vec![3.02f32; n];
    for &i in short {
        depth[i] = 2.87;
    }
    let near = depth.iter().map(|d| d * 0.97).collect();
    let far = depth.iter().map(|d| d * 1.03).collect();
    let image = IntervalDepthImage::new(W, W, near, depth, far, vec![0.9; n]).unwrap();
    let k = PinholeIntrinsics::new(W, W, 400.0, 400.0, 59.5, 59.5).unwrap();
    DepthFrame::new(k, Isometry3::identity(), image).unwrap()
}

/// The occupied evidence one image gives the voxels of two points.
fn occupied_at(model: EvidenceModel, frame: &DepthFrame, points: [Point3<f64>; 2]) -> [f32; 2] {
    let resolution = Resolution::new(0.05).unwrap();
    let evidence = scan_evidence(model, frame, &resolution);
    points.map(|p| {
        let key = resolution.key_of(&p).unwrap();
        evidence.cell(key).map_or(0.0, |e: &Evidence| e.occupied)
    })
}

#[test]
fn an_end_point_the_images_other_rays_pass_through_counts_little() {
    // One pixel (u = 70, v = 60) came out 0.15 m short: its end point lies three voxels in
    // front of the wall, in a voxel that its neighbours' rays cross on their way to the wall.
    let pixel = 60 * 120 + 70;
    let frame = wall_with_short_pixels(&[pixel]);
    let lone = Point3::new(10.5 / 400.0 * 2.87, 0.5 / 400.0 * 2.87, 2.87);
    let wall = Point3::new(10.5 / 400.0 * 3.02, 0.5 / 400.0 * 3.02, 3.02);
    // Counted in full, the lone end point is as strong as the wall.
    let [lone_full, wall_full] = occupied_at(EvidenceModel::dual(), &frame, [lone, wall]);
    assert!(wall_full > 0.6, "{wall_full}");
    assert_eq!(lone_full, wall_full);
    // Weighed by the share of the image's rays that end there, it counts for little; the wall,
    // where the rays end, keeps the full hit.
    let confirmed = EvidenceModel::confirmed();
    assert!(confirmed.end_point_share > 0.0);
    let [lone_weighed, wall_weighed] = occupied_at(confirmed, &frame, [lone, wall]);
    assert_eq!(wall_weighed, wall_full);
    assert!(
        lone_weighed < 0.2 * wall_weighed,
        "{lone_weighed} {wall_weighed}"
    );
    // A whole patch of short pixels is a surface of its own: most rays through its voxel end
    // there, so it keeps the full hit.
    let patch: Vec<usize> = (50..70)
        .flat_map(|v| (60..80).map(move |u| v * 120 + u))
        .collect();
    let frame = wall_with_short_pixels(&patch);
    let [patch_weighed, _] = occupied_at(confirmed, &frame, [lone, wall]);
    assert_eq!(patch_weighed, wall_full);
}

#[test]
fn a_surface_seen_by_one_image_counts_less_than_one_seen_by_several() {
    let mut once = map(EvidenceModel::confirmed());
    let mut thrice = map(EvidenceModel::confirmed());
    let frame = frame(2.95, 3.04, 3.13, 0.5, None);
    once.integrate_depth(&frame, &IntegrationOptions::default())
        .unwrap();
    for _ in 0..3 {
        thrice
            .integrate_depth(&frame, &IntegrationOptions::default())
            .unwrap();
    }
    let surface = Point3::new(-0.05, -0.05, 3.05);
    let (one, three) = (
        once.memberships_at_point(&surface).unwrap(),
        thrice.memberships_at_point(&surface).unwrap(),
    );
    assert!(
        one.occupied > 0.0 && three.occupied > one.occupied,
        "{one:?} {three:?}"
    );
    // One image of confidence 0.5 does not make the voxel occupied; three do.
    let class = |m: &FuzzyMap| m.class_at_point(&surface).unwrap();
    assert_ne!(class(&once), fuzzyvox::VoxelClass::Occupied);
    assert_eq!(class(&thrice), fuzzyvox::VoxelClass::Occupied);
}

#[test]
fn an_end_point_share_outside_zero_to_one_is_refused() {
    for share in [-0.1, 1.5, f32::NAN] {
        let model = EvidenceModel {
            end_point_share: share,
            ..EvidenceModel::confirmed()
        };
        assert!(model.validate().is_err(), "{share}");
        assert!(
            FuzzyConfig::new(RES)
                .unwrap()
                .with_evidence(model)
                .validate()
                .is_err()
        );
    }
}
