//! Bad input gives a typed error or a documented skip, never a panic, and a failed call leaves
//! the map unchanged.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::{room_scan, wall_frame};
use fuzzyvox::VoxelMapMut;
use fuzzyvox::{
    DepthFrame, Error, Family, FormatError, FuzzyConfig, FuzzyMap, IntegrationOptions,
    IntervalDepthImage, PinholeIntrinsics, PointCloud, TConorm,
};
use nalgebra::{Isometry3, Matrix4, Point3, Quaternion, Translation3, UnitQuaternion};

fn mapped() -> FuzzyMap {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    map.integrate_cloud(&room_scan(Point3::origin(), 500, 7), &Default::default())
        .unwrap();
    map
}

/// Runs `f` on a mapped map, expects an error, and checks the map's bytes are unchanged.
fn fails_unchanged(f: impl FnOnce(&mut FuzzyMap) -> fuzzyvox::Result<()>) -> Error {
    let mut map = mapped();
    let before = map.to_bytes();
    let error = f(&mut map).expect_err("the call should fail");
    assert_eq!(map.to_bytes(), before, "a failed call changed the map");
    error
}

#[test]
fn non_finite_points_are_skipped_and_counted() {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let cloud = PointCloud::new(
        Point3::origin(),
        vec![
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(f64::NAN, 0.0, 0.0),
            Point3::new(0.0, f64::INFINITY, 0.0),
            Point3::new(0.0, 0.0, f64::NEG_INFINITY),
        ],
    )
    .unwrap();
    let stats = map.integrate_cloud(&cloud, &Default::default()).unwrap();
    assert_eq!((stats.integrated, stats.skipped), (1, 3));
    let mut reference = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
    let valid = PointCloud::new(Point3::origin(), vec![Point3::new(1.0, 0.0, 0.0)]).unwrap();
    reference
        .integrate_cloud(&valid, &Default::default())
        .unwrap();
    assert_eq!(map.to_bytes(), reference.to_bytes());
}

#[test]
fn non_finite_origin_is_an_error() {
    for bad in [f64::NAN, f64::INFINITY] {
        let result = PointCloud::new(Point3::new(0.0, bad, 0.0), vec![Point3::origin()]);
        assert!(matches!(result, Err(Error::NonFinite { .. })));
    }
}

#[test]
fn points_outside_the_key_range_fail_the_whole_call() {
    let error = fails_unchanged(|map| {
        let cloud = PointCloud::new(
            Point3::origin(),
            vec![Point3::new(1.0, 0.0, 0.0), Point3::new(1e300, 0.0, 0.0)],
        )?;
        map.integrate_cloud(&cloud, &Default::default()).map(|_| ())
    });
    assert!(matches!(error, Error::OutOfKeyRange { .. }), "{error}");
    let error = fails_unchanged(|map| {
        let cloud = PointCloud::new(Point3::new(0.0, 0.0, -1e12), vec![Point3::origin()])?;
        map.integrate_cloud(&cloud, &Default::default()).map(|_| ())
    });
    assert!(matches!(error, Error::OutOfKeyRange { .. }), "{error}");
}

#[test]
fn confidence_outside_the_unit_interval_is_an_error() {
    let cloud = PointCloud::new(Point3::origin(), vec![Point3::new(1.0, 0.0, 0.0); 3]).unwrap();
    for bad in [-0.1, 1.01, f32::NAN, f32::INFINITY] {
        let result = cloud.clone().with_confidence(vec![0.5, bad, 0.5]);
        assert!(
            matches!(result, Err(Error::InvalidConfidence { index: 1, .. })),
            "{bad}"
        );
    }
    let result = cloud.with_confidence(vec![0.5; 2]);
    assert!(matches!(result, Err(Error::SizeMismatch { .. })));
}

#[test]
fn invalid_max_range_is_an_error() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let error = fails_unchanged(|map| {
            let options = IntegrationOptions {
                max_range: Some(bad),
            };
            map.integrate_cloud(&room_scan(Point3::origin(), 10, 1), &options)
                .map(|_| ())
        });
        assert!(
            matches!(
                error,
                Error::InvalidParameter { .. } | Error::NonFinite { .. }
            ),
            "{bad}: {error}"
        );
    }
}

#[test]
fn invalid_resolutions_are_errors() {
    for bad in [0.0, -0.1, f64::NAN, f64::INFINITY, 1e-7, 1e7] {
        assert!(FuzzyConfig::new(bad).is_err(), "{bad}");
    }
}

#[test]
fn operator_parameters_out_of_range_are_errors() {
    for bad in [
        Family::Hamacher { gamma: -1.0 },
        Family::Yager { p: 0.0 },
        Family::Frank { s: 1.0 },
        Family::Frank { s: -2.0 },
        Family::Dombi { lambda: f64::NAN },
        Family::AczelAlsina { p: -1.0 },
        Family::SchweizerSklar { p: f64::INFINITY },
    ] {
        assert!(
            matches!(
                TConorm::new(bad),
                Err(fuzzyvox::ops::OperatorError::InvalidParameter { .. })
            ),
            "{bad:?}"
        );
    }
    assert!("dombi".parse::<Family>().is_err());
    assert!("teleport:3".parse::<Family>().is_err());
    assert!("product:2".parse::<Family>().is_err());
}

#[test]
fn image_sizes_must_agree() {
    let planes = |n: usize| vec![1.0_f32; n];
    let result = IntervalDepthImage::new(4, 4, planes(16), planes(15), planes(16), planes(16));
    assert!(matches!(result, Err(Error::SizeMismatch { .. })));
    let result = IntervalDepthImage::new(4, 4, planes(16), planes(16), planes(16), planes(17));
    assert!(matches!(result, Err(Error::SizeMismatch { .. })));
    let result = IntervalDepthImage::new(0, 4, vec![], vec![], vec![], vec![]);
    assert!(matches!(result, Err(Error::Empty(_))));
    let image =
        IntervalDepthImage::new(4, 4, planes(16), planes(16), planes(16), planes(16)).unwrap();
    let k = PinholeIntrinsics::new(8, 4, 4.0, 4.0, 4.0, 2.0).unwrap();
    assert!(matches!(
        DepthFrame::new(k, Isometry3::identity(), image),
        Err(Error::SizeMismatch { .. })
    ));
}

#[test]
fn out_of_order_intervals_are_errors() {
    let result = IntervalDepthImage::new(
        1,
        2,
        vec![1.0, 2.1],
        vec![1.5, 2.0],
        vec![2.0, 2.5],
        vec![1.0, 1.0],
    );
    assert!(matches!(
        result,
        Err(Error::IntervalOrder { x: 0, y: 1, .. })
    ));
    let result = IntervalDepthImage::new(1, 1, vec![1.0], vec![2.0], vec![1.5], vec![1.0]);
    assert!(matches!(result, Err(Error::IntervalOrder { .. })));
}

#[test]
fn degenerate_poses_are_errors() {
    let mut m = Matrix4::identity();
    m[(1, 1)] = 0.0;
    assert!(matches!(
        fuzzyvox::pose_from_matrix(&m),
        Err(Error::InvalidPose(_))
    ));
    let bad_rotation = UnitQuaternion::new_unchecked(Quaternion::new(2.0, 0.0, 0.0, 0.0));
    let pose = Isometry3::from_parts(Translation3::identity(), bad_rotation);
    let frame = wall_frame(Point3::origin(), 3.0);
    let result = DepthFrame::new(*frame.intrinsics(), pose, frame.image().clone());
    assert!(matches!(result, Err(Error::InvalidPose(_))));
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    let result = DepthFrame::new(*frame.intrinsics(), nan, frame.image().clone());
    assert!(matches!(result, Err(Error::InvalidPose(_))));
}

#[test]
fn absurd_depths_are_an_error_not_a_hang() {
    let k = PinholeIntrinsics::new(4, 4, 4.0, 4.0, 1.5, 1.5).unwrap();
    let image = IntervalDepthImage::from_depth(4, 4, &[1e30; 16], |z| (z, z, 1.0)).unwrap();
    let frame = DepthFrame::new(k, Isometry3::identity(), image).unwrap();
    let error = fails_unchanged(|map| map.integrate_depth(&frame, &Default::default()).map(|_| ()));
    assert!(
        matches!(
            error,
            Error::OutOfKeyRange { .. } | Error::InvalidParameter { .. }
        ),
        "{error}"
    );
    let image = IntervalDepthImage::from_depth(4, 4, &[1e5; 16], |z| (z, z, 1.0)).unwrap();
    let frame = DepthFrame::new(k, Isometry3::identity(), image).unwrap();
    let error = fails_unchanged(|map| map.integrate_depth(&frame, &Default::default()).map(|_| ()));
    assert!(matches!(error, Error::InvalidParameter { .. }), "{error}");
    // The same frame is fine with a max range: it clears up to it.
    let mut map = mapped();
    let options = IntegrationOptions {
        max_range: Some(5.0),
    };
    let stats = map.integrate_depth(&frame, &options).unwrap();
    assert_eq!(stats.clipped, 16);
}

#[test]
fn an_image_without_valid_pixels_changes_nothing() {
    let mut map = mapped();
    let before = map.to_bytes();
    let k = PinholeIntrinsics::new(4, 4, 4.0, 4.0, 1.5, 1.5).unwrap();
    let image = IntervalDepthImage::from_depth(
        4,
        4,
        &[f32::NAN, 0.0, -1.0, f32::INFINITY].repeat(4),
        |z| (z, z, 1.0),
    )
    .unwrap();
    let frame = DepthFrame::new(k, Isometry3::identity(), image).unwrap();
    let stats = map.integrate_depth(&frame, &Default::default()).unwrap();
    assert_eq!((stats.integrated, stats.skipped), (0, 16));
    assert_eq!(map.to_bytes(), before);
}

#[test]
fn damaged_map_files_are_typed_errors() {
    let bytes = mapped().to_bytes();
    // Truncated anywhere.
    for len in [0, 3, 8, 39, 40, 41, bytes.len() / 2, bytes.len() - 1] {
        let result = FuzzyMap::from_bytes(&bytes[..len]);
        assert!(
            matches!(result, Err(Error::Format { .. })),
            "truncated to {len}"
        );
    }
    // A flipped bit anywhere past the magic.
    for at in (8..bytes.len()).step_by(bytes.len() / 97 + 1) {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x04;
        assert!(FuzzyMap::from_bytes(&damaged).is_err(), "bit flip at {at}");
    }
    // Another format.
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
    assert!(matches!(
        FuzzyMap::from_bytes(png),
        Err(Error::Format {
            reason: FormatError::BadMagic,
            ..
        })
    ));
    // An oversized declared length.
    let mut long = bytes.clone();
    long[28..36].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(
        FuzzyMap::from_bytes(&long),
        Err(Error::Format {
            reason: FormatError::Length { .. },
            ..
        })
    ));
    // Missing file.
    assert!(matches!(
        FuzzyMap::load("/nonexistent/map.fvx"),
        Err(Error::Io { .. })
    ));
}

#[test]
fn text_clouds_report_the_bad_line() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-badcloud-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, usize); 5] = [
        ("1 2 3\n4 5 x\n", 2),
        ("1 2\n", 1),
        ("# header\n1 2 3 0.5\n1 2 3\n", 3),
        ("1 2 3 1.5\n", 1),
        ("1 2 3 4 5\n", 1),
    ];
    for (i, (text, line)) in cases.iter().enumerate() {
        let path = dir.join(format!("cloud{i}.xyz"));
        std::fs::write(&path, text).unwrap();
        match fuzzyvox::io::read_text_cloud(&path, Point3::origin()) {
            Err(Error::Parse { line: l, .. }) => assert_eq!(l, *line, "{text:?}"),
            other => panic!("{text:?}: expected a parse error, got {other:?}"),
        }
    }
    let path = dir.join("ok.xyz");
    std::fs::write(&path, "# x y z c\n1 2 3 0.5\n\n4,5,6,1\nnan 0 0 0.2\n").unwrap();
    let cloud = fuzzyvox::io::read_text_cloud(&path, Point3::origin()).unwrap();
    assert_eq!(cloud.len(), 3);
    assert_eq!(cloud.confidence().unwrap(), &[0.5, 1.0, 0.2]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn baseline_and_planner_parameters_are_validated() {
    use fuzzyvox::plan::{PlannerConfig, PlanningRegion, UnknownPolicy};
    use fuzzyvox::{AlphaConfig, AlphaCutMap, LogOddsConfig, LogOddsMap, VoxelKey};
    let mut c = LogOddsConfig::new(0.1).unwrap();
    c.prob_hit = 1.0;
    assert!(LogOddsMap::new(c).is_err());
    let mut c = LogOddsConfig::new(0.1).unwrap();
    c.clamp_min = 0.99;
    assert!(LogOddsMap::new(c).is_err());
    let mut c = LogOddsConfig::new(0.1).unwrap();
    c.prob_miss = f64::NAN;
    assert!(LogOddsMap::new(c).is_err());
    let mut a = AlphaConfig::new(0.1).unwrap();
    a.cuts = 0;
    assert!(AlphaCutMap::new(a).is_err());
    for bad in [
        PlannerConfig {
            vehicle_radius: -1.0,
            ..PlannerConfig::default()
        },
        PlannerConfig {
            safety_threshold: 1.5,
            ..PlannerConfig::default()
        },
        PlannerConfig {
            safety_weight: f32::NAN,
            ..PlannerConfig::default()
        },
        PlannerConfig {
            unknown: UnknownPolicy::Cost(f32::INFINITY),
            ..PlannerConfig::default()
        },
    ] {
        assert!(bad.validate().is_err(), "{bad:?}");
    }
    assert!(
        PlanningRegion::new(
            VoxelKey::new(0, 0, 0),
            VoxelKey::new(10_000, 10_000, 10_000)
        )
        .is_err()
    );
}

#[test]
fn baseline_maps_are_unchanged_by_failed_calls() {
    use fuzzyvox::{AlphaConfig, AlphaCutMap, LogOddsConfig, LogOddsMap};
    let bad = PointCloud::new(
        Point3::origin(),
        vec![Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1e300, 0.0)],
    )
    .unwrap();
    let scan = room_scan(Point3::origin(), 300, 3);
    let mut logodds = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
    logodds.integrate_cloud(&scan, &Default::default()).unwrap();
    let before = logodds.to_bytes();
    assert!(matches!(
        logodds.integrate_cloud(&bad, &Default::default()),
        Err(Error::OutOfKeyRange { .. })
    ));
    assert_eq!(logodds.to_bytes(), before);
    let mut alpha = AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap();
    alpha.integrate_cloud(&scan, &Default::default()).unwrap();
    let before = alpha.to_bytes();
    let options = IntegrationOptions {
        max_range: Some(-2.0),
    };
    assert!(alpha.integrate_cloud(&scan, &options).is_err());
    assert!(alpha.integrate_cloud(&bad, &Default::default()).is_err());
    assert_eq!(alpha.to_bytes(), before);
}
