//! Bad numbers at every public entry point that takes geometry: clouds, depth images, cameras,
//! poses, the depth stage, map configuration and merging, and the planner. Each case is a typed
//! error (or a documented skip) and leaves every map unchanged. The cases of `bad_input.rs` are
//! not repeated; the table of every case is in `docs/robustness.md`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{room_scan, wall_frame};
use fuzzyvox::VoxelMapMut;
use fuzzyvox::depth::{
    DepthParams, Frame, GrayImage, IntervalMethod, IntervalParams, MatchParams,
    UnrectifiableReason, depth_from_pair, match_pair,
};
use fuzzyvox::plan::{PlanError, PlannerConfig, plan_path};
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, AnyMap, DepthFrame, Error, Family, FuzzyConfig, FuzzyMap,
    IntegrationOptions, IntervalDepthImage, LogOddsConfig, LogOddsMap, PinholeIntrinsics,
    PointCloud, TConorm, VoxelMap,
};
use nalgebra::{Isometry3, Matrix4, Point3, Quaternion, Translation3, UnitQuaternion};

/// One map of each kind at 0.1 m, each holding the same room scan.
fn mapped() -> Vec<AnyMap> {
    let scan = room_scan(Point3::origin(), 400, 21);
    let mut maps = vec![
        AnyMap::Fuzzy(FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap()),
        AnyMap::LogOdds(LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap()),
        AnyMap::Alpha(AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap()),
    ];
    for map in &mut maps {
        map.as_map_mut()
            .integrate_cloud(&scan, &Default::default())
            .unwrap();
    }
    maps
}

/// Runs `f` on each mapped map, expects an error from every one, checks every map's bytes are
/// unchanged, and returns the errors.
fn fails_unchanged_in_every_map(
    mut f: impl FnMut(&mut dyn VoxelMapMut) -> fuzzyvox::Result<fuzzyvox::IntegrationStats>,
) -> Vec<Error> {
    mapped()
        .into_iter()
        .map(|mut map| {
            let before = map.to_bytes();
            let error = f(map.as_map_mut()).expect_err("the call should fail");
            assert_eq!(
                map.to_bytes(),
                before,
                "a failed call changed the {} map",
                map.kind().name()
            );
            error
        })
        .collect()
}

/// Like [`fails_unchanged_in_every_map`], for calls that succeed without changing anything.
fn succeeds_unchanged_in(
    maps: Vec<AnyMap>,
    mut f: impl FnMut(&mut dyn VoxelMapMut) -> fuzzyvox::Result<fuzzyvox::IntegrationStats>,
) -> Vec<fuzzyvox::IntegrationStats> {
    maps.into_iter()
        .map(|mut map| {
            let before = map.to_bytes();
            let stats = f(map.as_map_mut()).expect("the call should succeed");
            assert_eq!(map.to_bytes(), before, "{} map changed", map.kind().name());
            stats
        })
        .collect()
}

fn cloud(points: Vec<Point3<f64>>) -> PointCloud {
    PointCloud::new(Point3::new(0.2, 0.1, 0.3), points).unwrap()
}

fn camera() -> PinholeIntrinsics {
    PinholeIntrinsics::new(8, 6, 6.0, 6.0, 3.5, 2.5).unwrap()
}

fn image(depth: f32) -> IntervalDepthImage {
    IntervalDepthImage::from_depth(8, 6, &[depth; 48], |z| (0.9 * z, 1.1 * z, 0.8)).unwrap()
}

// ---------------------------------------------------------------------------------------------
// Point clouds
// ---------------------------------------------------------------------------------------------

#[test]
fn huge_coordinates_inside_the_key_range_are_refused_not_walked() {
    // 10^6 m is inside the key range at 0.1 m (10^7 voxels) but would walk and allocate free
    // space along ten million voxels.
    for far in [
        Point3::new(1e6, 0.0, 0.0),
        Point3::new(-3e4, 2e4, 1e4),
        Point3::new(0.0, 0.0, 6600.0),
    ] {
        let bad = cloud(vec![Point3::new(1.0, 0.0, 0.0), far]);
        for error in
            fails_unchanged_in_every_map(|map| map.integrate_cloud(&bad, &Default::default()))
        {
            assert!(
                matches!(
                    error,
                    Error::InvalidParameter {
                        name: "ray length",
                        ..
                    }
                ),
                "{far}: {error}"
            );
        }
    }
}

#[test]
fn huge_coordinates_integrate_when_max_range_cuts_them() {
    let far = cloud(vec![Point3::new(1.0, 0.0, 0.0), Point3::new(1e6, 0.0, 0.0)]);
    let options = IntegrationOptions {
        max_range: Some(20.0),
    };
    for mut map in mapped() {
        let stats = map.as_map_mut().integrate_cloud(&far, &options).unwrap();
        assert_eq!(
            (stats.integrated, stats.clipped),
            (2, 1),
            "{}",
            map.kind().name()
        );
    }
}

#[test]
fn an_empty_cloud_changes_no_map() {
    let empty = cloud(vec![]);
    for stats in succeeds_unchanged_in(mapped(), |map| {
        map.integrate_cloud(&empty, &Default::default())
    }) {
        assert_eq!((stats.integrated, stats.skipped), (0, 0));
    }
}

#[test]
fn a_cloud_of_only_non_finite_points_is_skipped_whole() {
    let bad = cloud(vec![
        Point3::new(f64::NAN, f64::NAN, f64::NAN),
        Point3::new(f64::INFINITY, 0.0, 0.0),
        Point3::new(1.0, f64::NEG_INFINITY, 2.0),
    ]);
    for stats in succeeds_unchanged_in(mapped(), |map| {
        map.integrate_cloud(&bad, &Default::default())
    }) {
        assert_eq!((stats.integrated, stats.skipped), (0, 3));
    }
}

#[test]
fn an_origin_outside_the_key_range_of_a_fine_map_is_an_error() {
    // At 0.1 mm (the finest resolution) the key range ends at ±214 km: a sensor 300 km out
    // cannot be keyed, though its coordinates are ordinary numbers.
    let mut map = FuzzyMap::new(FuzzyConfig::new(1e-4).unwrap()).unwrap();
    let scan = PointCloud::new(
        Point3::new(3e5, 0.0, 0.0),
        vec![Point3::new(3e5, 1e-3, 0.0)],
    )
    .unwrap();
    assert!(matches!(
        map.integrate_cloud(&scan, &Default::default()),
        Err(Error::OutOfKeyRange { .. })
    ));
    assert_eq!(
        map.counts(),
        FuzzyMap::new(FuzzyConfig::new(1e-4).unwrap())
            .unwrap()
            .counts()
    );
}

#[test]
fn zero_confidence_points_add_no_occupied_evidence_and_unreliable_ones_nothing() {
    // Documented: a point of confidence 0 gives no occupied evidence to the fuzzy map and falls
    // in no cut of the alpha-cut map; the log-odds map ignores confidence by design. In the
    // fuzzy map's dual evidence model such a point still clears its ray when it is reliable
    // (its reliability defaults to 1); with reliability 0, or in the paper's model, it changes
    // nothing.
    let doubtful = cloud(vec![
        Point3::new(2.0, 0.5, 0.0),
        Point3::new(-1.0, 2.0, 1.0),
    ])
    .with_confidence(vec![0.0, 0.0])
    .unwrap();
    let alpha: Vec<_> = mapped()
        .into_iter()
        .filter(|m| matches!(m, AnyMap::Alpha(_)))
        .collect();
    succeeds_unchanged_in(alpha, |map| {
        map.integrate_cloud(&doubtful, &Default::default())
    });
    let unreliable = doubtful.clone().with_reliability(vec![0.0, 0.0]).unwrap();
    let fuzzy = || {
        mapped()
            .into_iter()
            .filter(|m| matches!(m, AnyMap::Fuzzy(_)))
            .collect::<Vec<_>>()
    };
    succeeds_unchanged_in(fuzzy(), |map| {
        map.integrate_cloud(&unreliable, &Default::default())
    });
    let paper = |map: AnyMap| match map {
        AnyMap::Fuzzy(m) => {
            let config = m.config().with_evidence(fuzzyvox::EvidenceModel::paper());
            let mut fresh = FuzzyMap::new(config).unwrap();
            fresh.merge(&m).unwrap();
            AnyMap::Fuzzy(fresh)
        }
        other => other,
    };
    succeeds_unchanged_in(fuzzy().into_iter().map(paper).collect(), |map| {
        map.integrate_cloud(&doubtful, &Default::default())
    });
    // Reliable, it clears: free memberships rise, occupied ones do not.
    for mut map in fuzzy() {
        let before: Vec<_> = map.as_map().cells().collect();
        map.as_map_mut()
            .integrate_cloud(&doubtful, &Default::default())
            .unwrap();
        let after = map.as_map();
        assert!(
            before
                .iter()
                .all(|(k, m)| after.memberships_at(*k).occupied == m.occupied)
        );
        assert!(
            after.cells().count() > before.len()
                || before
                    .iter()
                    .any(|(k, m)| after.memberships_at(*k).free > m.free)
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Depth images, cameras and poses
// ---------------------------------------------------------------------------------------------

#[test]
fn invalid_max_range_for_depth_images_is_an_error_in_every_map() {
    let frame = wall_frame(Point3::new(0.0, 0.0, 0.5), 3.0);
    for bad in [f64::NAN, -2.0, 0.0, f64::NEG_INFINITY] {
        let options = IntegrationOptions {
            max_range: Some(bad),
        };
        for error in fails_unchanged_in_every_map(|map| map.integrate_depth(&frame, &options)) {
            assert!(
                matches!(
                    error,
                    Error::InvalidParameter { .. } | Error::NonFinite { .. }
                ),
                "{bad}: {error}"
            );
        }
    }
}

#[test]
fn pixel_confidence_outside_the_unit_interval_is_an_error() {
    for bad in [1.5, -0.25, f32::INFINITY, f32::NEG_INFINITY] {
        let result = IntervalDepthImage::new(
            2,
            1,
            vec![1.0; 2],
            vec![2.0; 2],
            vec![3.0; 2],
            vec![0.5, bad],
        );
        assert!(
            matches!(result, Err(Error::InvalidConfidence { index: 1, .. })),
            "{bad}"
        );
        let result = IntervalDepthImage::from_depth(2, 1, &[2.0, 2.0], |z| (z, z, bad));
        assert!(matches!(
            result,
            Err(Error::InvalidConfidence { index: 0, .. })
        ));
    }
}

#[test]
fn empty_depth_images_are_errors() {
    for (w, h) in [(0, 0), (5, 0)] {
        assert!(matches!(
            IntervalDepthImage::from_depth(w, h, &[], |z| (z, z, 1.0)),
            Err(Error::Empty(_))
        ));
    }
    // A depth plane shorter than width × height.
    assert!(matches!(
        IntervalDepthImage::from_depth(4, 4, &[1.0; 15], |z| (z, z, 1.0)),
        Err(Error::SizeMismatch { .. })
    ));
}

#[test]
fn non_finite_or_non_unit_rotations_are_invalid_poses() {
    let rotations = [
        Quaternion::new(f64::NAN, 0.0, 0.0, 0.0),
        Quaternion::new(1.0, f64::INFINITY, 0.0, 0.0),
        Quaternion::new(0.0, 0.0, 0.0, 0.0),
        Quaternion::new(1.0, 1e-2, 0.0, 0.0),
    ];
    for q in rotations {
        let pose = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 1.0),
            UnitQuaternion::new_unchecked(q),
        );
        assert!(
            matches!(
                DepthFrame::new(camera(), pose, image(2.0)),
                Err(Error::InvalidPose(_))
            ),
            "{q:?}"
        );
        let gray = GrayImage::new(8, 6, vec![0.5; 48]).unwrap();
        assert!(matches!(
            Frame::new(gray, camera(), pose, 0.0),
            Err(Error::InvalidPose(_))
        ));
        assert!(matches!(
            fuzzyvox::validate_pose(&pose),
            Err(Error::InvalidPose(_))
        ));
    }
}

#[test]
fn pose_matrices_that_are_not_rigid_are_invalid_poses() {
    let mut reflection = Matrix4::identity();
    reflection[(2, 2)] = -1.0;
    let mut sheared = Matrix4::identity();
    sheared[(0, 1)] = 0.2;
    let mut scaled = Matrix4::identity();
    scaled[(0, 0)] = 1.01;
    let mut nan = Matrix4::identity();
    nan[(1, 3)] = f64::NAN;
    let mut projective = Matrix4::identity();
    projective[(3, 0)] = 0.1;
    for (name, m) in [
        ("reflection", reflection),
        ("sheared", sheared),
        ("scaled", scaled),
        ("nan", nan),
        ("projective", projective),
    ] {
        assert!(
            matches!(fuzzyvox::pose_from_matrix(&m), Err(Error::InvalidPose(_))),
            "{name}"
        );
    }
}

#[test]
fn invalid_intrinsics_are_errors() {
    assert!(matches!(
        PinholeIntrinsics::new(0, 480, 500.0, 500.0, 320.0, 240.0),
        Err(Error::Empty(_))
    ));
    assert!(matches!(
        PinholeIntrinsics::new(640, 480, f64::NAN, 500.0, 320.0, 240.0),
        Err(Error::NonFinite { what: "fx", .. })
    ));
    assert!(matches!(
        PinholeIntrinsics::new(640, 480, 500.0, -500.0, 320.0, 240.0),
        Err(Error::InvalidParameter { name: "fy", .. })
    ));
    assert!(matches!(
        PinholeIntrinsics::new(640, 480, 500.0, 500.0, f64::INFINITY, 240.0),
        Err(Error::NonFinite { what: "cx", .. })
    ));
    assert!(matches!(
        PinholeIntrinsics::new(640, 480, 500.0, 500.0, 320.0, f64::NAN),
        Err(Error::NonFinite { what: "cy", .. })
    ));
}

#[test]
fn a_camera_outside_the_key_range_is_an_error_in_every_map() {
    let pose = Isometry3::translation(1e12, 0.0, 0.0);
    let frame = DepthFrame::new(camera(), pose, image(2.0)).unwrap();
    for error in
        fails_unchanged_in_every_map(|map| map.integrate_depth(&frame, &Default::default()))
    {
        assert!(matches!(error, Error::OutOfKeyRange { .. }), "{error}");
    }
}

/// Integrates a frame whose pixels all lie at 3 m (interval 2.98–3.03 m), seen by a skewed
/// camera, into a new fuzzy map at 0.05 m. The five-second bound (the work takes about 12 ms)
/// only guards against a hang; the culling test in `crates/fuzzyvox-core/src/integrate/frustum.rs` checks how many
/// blocks such frustums keep.
fn integrate_skewed(
    k: PinholeIntrinsics,
    pose: Isometry3<f64>,
) -> (fuzzyvox::IntegrationStats, FuzzyMap) {
    let n = (k.width() * k.height()) as usize;
    let image = IntervalDepthImage::new(
        k.width(),
        k.height(),
        vec![2.98; n],
        vec![3.0; n],
        vec![3.03; n],
        vec![0.78; n],
    )
    .unwrap();
    let frame = DepthFrame::new(k, pose, image).unwrap();
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.05).unwrap()).unwrap();
    let started = std::time::Instant::now();
    let stats = map.integrate_depth(&frame, &Default::default()).unwrap();
    let seconds = started.elapsed().as_secs_f64();
    assert!(seconds < 5.0, "{n} pixels took {seconds:.1} s");
    (stats, map)
}

#[test]
fn a_skewed_camera_whose_frustum_box_is_huge_integrates_quickly() {
    // Found by fuzzing: one pixel, a principal point 8,000 px off the image and fy = 5e46 make a
    // sliver of a frustum 780 m long whose bounding box holds 19 million blocks, all near the
    // camera plane. Culling used to test every block (7 s for one pixel); whole groups of blocks
    // beside the frustum's side planes are now skipped.
    let (stats, _) = integrate_skewed(
        PinholeIntrinsics::new(1, 1, 31.875, 5.03e46, 8191.875, 8164.875).unwrap(),
        Isometry3::from_parts(
            Translation3::new(0.06, -241.59, -20.49),
            UnitQuaternion::from_euler_angles(-1e-3, -1e-3, 10.239),
        ),
    );
    assert_eq!(stats.integrated, 1);

    // Found by fuzzing later: six pixels whose frustum is a needle grazing the camera plane,
    // 860 m long. The side planes are then nearly one plane, and the blocks of a whole sheet
    // around the needle passed them (680,000 blocks, 1.5 s); the separating-axis test keeps
    // the needle's own blocks.
    let (stats, map) = integrate_skewed(
        PinholeIntrinsics::new(2, 3, 64.125, 31.875, 8191.875, 8165.375).unwrap(),
        Isometry3::from_parts(
            Translation3::new(0.0, -0.01, -241.59),
            UnitQuaternion::from_euler_angles(-1e-3, -1e-3, -0.768),
        ),
    );
    assert_eq!(stats.integrated, 6);
    assert!(
        map.counts().occupied > 0,
        "the six surface points are mapped"
    );
}

// ---------------------------------------------------------------------------------------------
// Depth stage
// ---------------------------------------------------------------------------------------------

fn gray(width: u32, height: u32) -> GrayImage {
    let pixels = (0..width * height)
        .map(|i| ((i * 37 + i / width * 11) % 23) as f32 / 23.0)
        .collect();
    GrayImage::new(width, height, pixels).unwrap()
}

fn stereo_camera() -> PinholeIntrinsics {
    PinholeIntrinsics::new(32, 24, 30.0, 30.0, 15.5, 11.5).unwrap()
}

fn frame_at(pose: Isometry3<f64>, time: f64) -> Frame {
    Frame::new(gray(32, 24), stereo_camera(), pose, time).unwrap()
}

#[test]
fn gray_images_whose_pixels_do_not_fill_them_are_size_mismatches() {
    assert!(matches!(
        GrayImage::new(4, 4, vec![0.5; 15]),
        Err(Error::SizeMismatch { .. })
    ));
    assert!(matches!(
        GrayImage::from_luma8(4, 4, &[7; 17]),
        Err(Error::SizeMismatch { .. })
    ));
    assert!(matches!(
        GrayImage::from_rgb8(4, 4, &[7; 47]),
        Err(Error::SizeMismatch { .. })
    ));
}

#[test]
fn a_baseline_below_a_nanometre_is_a_zero_baseline() {
    let reference = frame_at(Isometry3::identity(), 0.0);
    let other = frame_at(Isometry3::translation(1e-10, 0.0, 0.0), 1.0);
    assert!(matches!(
        depth_from_pair(&reference, &other, &DepthParams::default()),
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::ZeroBaseline { .. }
        })
    ));
}

#[test]
fn pure_forward_and_backward_motion_are_unrectifiable() {
    let reference = frame_at(Isometry3::identity(), 0.0);
    for dz in [0.5, -0.5] {
        let other = frame_at(Isometry3::translation(0.0, 0.0, dz), 1.0);
        assert!(
            matches!(
                depth_from_pair(&reference, &other, &DepthParams::default()),
                Err(Error::Unrectifiable {
                    reason: UnrectifiableReason::EpipoleInImage { .. }
                })
            ),
            "dz = {dz}"
        );
    }
}

#[test]
fn matching_parameters_out_of_range_are_errors() {
    let image = gray(32, 24);
    let defaults = MatchParams::default();
    for (name, params) in [
        (
            "window 17",
            MatchParams {
                window_width: 17,
                ..defaults.clone()
            },
        ),
        (
            "window 0",
            MatchParams {
                window_height: 0,
                ..defaults.clone()
            },
        ),
        (
            "1025 disparities",
            MatchParams {
                num_disparities: 1025,
                ..defaults.clone()
            },
        ),
        (
            "uniqueness 100",
            MatchParams {
                uniqueness_ratio: 100,
                ..defaults.clone()
            },
        ),
        (
            "NaN tolerance",
            MatchParams {
                range_tolerance: f32::NAN,
                ..defaults.clone()
            },
        ),
        (
            "negative tolerance",
            MatchParams {
                range_tolerance: -0.1,
                ..defaults.clone()
            },
        ),
        (
            "NaN contrast",
            MatchParams {
                min_contrast: f32::NAN,
                ..defaults.clone()
            },
        ),
        (
            "negative contrast",
            MatchParams {
                min_contrast: -0.01,
                ..defaults.clone()
            },
        ),
    ] {
        assert!(
            matches!(
                match_pair(&image, &image, &params),
                Err(Error::InvalidParameter { .. })
            ),
            "{name}"
        );
    }
}

#[test]
fn interval_parameters_out_of_range_are_errors() {
    let reference = frame_at(Isometry3::identity(), 0.0);
    let other = frame_at(Isometry3::translation(0.3, 0.0, 0.0), 1.0);
    for (name, interval) in [
        (
            "NaN delta",
            IntervalParams {
                method: IntervalMethod::FixedDelta { delta: f32::NAN },
                ..IntervalParams::default()
            },
        ),
        (
            "negative delta",
            IntervalParams {
                method: IntervalMethod::CostCurve { delta: -1.0 },
                ..IntervalParams::default()
            },
        ),
        (
            "infinite delta",
            IntervalParams {
                method: IntervalMethod::CostCurve {
                    delta: f32::INFINITY,
                },
                ..IntervalParams::default()
            },
        ),
        (
            "negative slope",
            IntervalParams {
                confidence_slope: -5.0,
                ..IntervalParams::default()
            },
        ),
        (
            "NaN slope",
            IntervalParams {
                confidence_slope: f64::NAN,
                ..IntervalParams::default()
            },
        ),
    ] {
        let params = DepthParams {
            interval,
            ..DepthParams::default()
        };
        assert!(
            matches!(
                depth_from_pair(&reference, &other, &params),
                Err(Error::InvalidParameter { .. })
            ),
            "{name}"
        );
    }
}

#[test]
fn depth_ranges_that_make_no_sense_are_errors() {
    let reference = frame_at(Isometry3::identity(), 0.0);
    let other = frame_at(Isometry3::translation(0.3, 0.0, 0.0), 1.0);
    for (near, far) in [
        (f64::NAN, 10.0),
        (0.0, 10.0),
        (-1.0, 10.0),
        (f64::INFINITY, f64::INFINITY),
        (2.0, 2.0),
        // 0.3 m × 30 px / 1e-4 m = 90,000 disparities: far more than 1024.
        (1e-4, 10.0),
    ] {
        let params = DepthParams {
            depth_range: Some((near, far)),
            ..DepthParams::default()
        };
        assert!(
            matches!(
                depth_from_pair(&reference, &other, &params),
                Err(Error::InvalidParameter { .. })
            ),
            "({near}, {far})"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Map configuration, merging and queries
// ---------------------------------------------------------------------------------------------

#[test]
fn operator_names_with_bad_parameters_are_errors() {
    for text in [
        "dombi:nan",
        "yager:inf",
        "hamacher:",
        "frank:1:2",
        "",
        "schweizer-sklar:nan",
        "aczel-alsina:0",
    ] {
        assert!(text.parse::<Family>().is_err(), "{text:?}");
    }
}

#[test]
fn baseline_configurations_out_of_range_are_errors() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(LogOddsConfig::new(bad).is_err(), "{bad}");
        assert!(AlphaConfig::new(bad).is_err(), "{bad}");
    }
    for cuts in [1001, u32::MAX] {
        let mut config = AlphaConfig::new(0.1).unwrap();
        config.cuts = cuts;
        assert!(matches!(
            AlphaCutMap::new(config),
            Err(Error::InvalidParameter { name: "cuts", .. })
        ));
    }
}

#[test]
fn merging_incompatible_maps_is_an_error_and_changes_nothing() {
    let scan = room_scan(Point3::origin(), 200, 8);
    let build = |config: FuzzyConfig| {
        let mut map = FuzzyMap::new(config).unwrap();
        map.integrate_cloud(&scan, &Default::default()).unwrap();
        map
    };
    let mut map = build(FuzzyConfig::new(0.1).unwrap());
    let before = map.to_bytes();
    let coarse = build(FuzzyConfig::new(0.2).unwrap());
    let other_operator = build(
        FuzzyConfig::new(0.1)
            .unwrap()
            .with_operator(TConorm::new(Family::Minimum).unwrap()),
    );
    for other in [&coarse, &other_operator] {
        assert!(matches!(map.merge(other), Err(Error::Incompatible(_))));
        assert_eq!(map.to_bytes(), before);
    }
}

#[test]
fn point_queries_outside_the_key_range_are_errors() {
    let map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    for p in [
        Point3::new(f64::NAN, 0.0, 0.0),
        Point3::new(0.0, 1e300, 0.0),
        Point3::new(0.0, 0.0, -f64::INFINITY),
    ] {
        assert!(map.measures_at_point(&p).is_err(), "{p}");
        assert!(map.class_at_point(&p).is_err(), "{p}");
        assert!(map.memberships_at_point(&p).is_err(), "{p}");
    }
}

// ---------------------------------------------------------------------------------------------
// Planner
// ---------------------------------------------------------------------------------------------

fn planning_map() -> FuzzyMap {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
    for x in [-0.5, 0.0, 0.5] {
        map.integrate_cloud(
            &room_scan(Point3::new(x, 0.0, 0.5), 3000, 5),
            &Default::default(),
        )
        .unwrap();
    }
    map
}

#[test]
fn planning_between_bad_points_is_an_error() {
    let map = planning_map();
    let config = PlannerConfig::default();
    let inside = Point3::new(0.0, 0.0, 0.5);
    for (name, from, to) in [
        ("NaN start", Point3::new(f64::NAN, 0.0, 0.5), inside),
        (
            "infinite goal",
            inside,
            Point3::new(0.0, f64::INFINITY, 0.5),
        ),
        ("goal 50 km away", inside, Point3::new(5e4, 0.0, 0.5)),
    ] {
        assert!(
            matches!(plan_path(&map, &from, &to, &config), Err(PlanError::Map(_))),
            "{name}"
        );
    }
    // A goal in unknown space behind the wall, with unknown space forbidden.
    assert!(matches!(
        plan_path(&map, &inside, &Point3::new(6.0, 0.0, 0.5), &config),
        Err(PlanError::GoalUnsafe(_))
    ));
    // A start inside the wall.
    assert!(matches!(
        plan_path(&map, &Point3::new(4.0, 0.0, 0.5), &inside, &config),
        Err(PlanError::StartUnsafe(_))
    ));
}

#[test]
fn planner_parameters_out_of_range_are_errors() {
    let map = planning_map();
    let (a, b) = (Point3::new(0.0, 0.0, 0.5), Point3::new(1.0, 0.5, 0.5));
    for (name, config) in [
        (
            "NaN threshold",
            PlannerConfig {
                safety_threshold: f32::NAN,
                ..PlannerConfig::default()
            },
        ),
        (
            "negative clearance",
            PlannerConfig {
                preferred_clearance: -0.5,
                ..PlannerConfig::default()
            },
        ),
        (
            "infinite radius",
            PlannerConfig {
                vehicle_radius: f64::INFINITY,
                ..PlannerConfig::default()
            },
        ),
        (
            "negative weight",
            PlannerConfig {
                clearance_weight: -1.0,
                ..PlannerConfig::default()
            },
        ),
    ] {
        assert!(
            matches!(plan_path(&map, &a, &b, &config), Err(PlanError::Map(_))),
            "{name}"
        );
    }
}
