//! The depth stage end to end on synthetic views with exact ground truth, rectification
//! geometry, pair selection, and bad inputs.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use fuzzyvox::VoxelMapMut;
use fuzzyvox::depth::{
    DepthParams, ForwardMotion, Frame, GrayImage, IntervalMethod, MatchMethod, MatchParams,
    PairCriteria, PairSelector, Rectification, Side, UnrectifiableReason, depth_by_plane_sweep,
    depth_from_pair, depth_from_views, match_pair,
};
use fuzzyvox::io::pfm::read_pfm;
use fuzzyvox::{
    Error, FormatError, FuzzyConfig, FuzzyMap, IntegrationOptions, PinholeIntrinsics, VoxelMap,
};
use nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};

/// The textured plane `z = 4 + 0.3 x` (world), seen by cameras near the origin looking along +z.
fn plane_hit(origin: &Point3<f64>, direction: &Vector3<f64>) -> Option<Point3<f64>> {
    // n · p = 4 with n = (-0.3, 0, 1).
    let n = Vector3::new(-0.3, 0.0, 1.0);
    let t = (4.0 - n.dot(&origin.coords)) / n.dot(direction);
    (t > 0.0).then(|| origin + direction * t)
}

/// Value noise fixed to the plane (cells of 3 cm, bilinear), so both views see the same texture.
fn texture(p: &Point3<f64>) -> f32 {
    let hash = |i: i64, j: i64| {
        let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        z = (z ^ (z >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        ((z >> 40) & 0xff) as f64
    };
    let (u, v) = (p.x / 0.03, p.y / 0.03);
    let (i, j) = (u.floor(), v.floor());
    let (fu, fv) = (u - i, v - j);
    let (i, j) = (i as i64, j as i64);
    let top = hash(i, j) * (1.0 - fu) + hash(i + 1, j) * fu;
    let bottom = hash(i, j + 1) * (1.0 - fu) + hash(i + 1, j + 1) * fu;
    (top * (1.0 - fv) + bottom * fv) as f32
}

fn camera() -> PinholeIntrinsics {
    PinholeIntrinsics::new(320, 240, 300.0, 300.0, 159.5, 119.5).unwrap()
}

fn render(k: &PinholeIntrinsics, pose: &Isometry3<f64>) -> GrayImage {
    let origin = Point3::from(pose.translation.vector);
    let mut pixels = Vec::new();
    for v in 0..k.height() {
        for u in 0..k.width() {
            let ray = pose.rotation * k.back_project(f64::from(u), f64::from(v), 1.0).coords;
            pixels.push(plane_hit(&origin, &ray).map_or(0.0, |p| texture(&p)));
        }
    }
    GrayImage::new(k.width(), k.height(), pixels).unwrap()
}

/// The textured plane seen from `pose` at `time`.
fn view(k: &PinholeIntrinsics, pose: Isometry3<f64>, time: f64) -> Frame {
    Frame::new(render(k, &pose), *k, pose, time).unwrap()
}

fn pose(position: [f64; 3], yaw_degrees: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(position[0], position[1], position[2]),
        UnitQuaternion::from_euler_angles(0.02, yaw_degrees.to_radians(), 0.01),
    )
}

#[test]
fn forward_motion_is_matched_by_plane_sweep_with_honest_intervals() {
    let k = camera();
    let reference_pose = pose([0.0, 0.0, 0.0], 0.0);
    // Half a metre back along the view: the epipole sits near the image centre.
    let other_pose = pose([0.01, 0.0, -0.5], 0.0);
    let reference = view(&k, reference_pose, 0.0);
    let other = view(&k, other_pose, 0.5);
    let mut params = DepthParams {
        depth_range: Some((2.0, 12.0)),
        ..DepthParams::default()
    };
    assert!(matches!(
        depth_from_pair(&reference, &other, &params),
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::EpipoleInImage { .. }
        })
    ));
    params.forward_motion = ForwardMotion::PlaneSweep;
    let result = depth_from_pair(&reference, &other, &params).unwrap();
    assert_eq!(result.method, MatchMethod::PlaneSweep);
    assert!(result.quality < 0.1, "Q_ABD = {}", result.quality);
    // The output lives in the original reference camera.
    assert_eq!(result.frame.world_from_camera(), &reference_pose);
    let image = result.frame.image();
    let origin = Point3::origin();
    let (mut bounded, mut inside) = (0usize, 0usize);
    // Interval widths near the epipole (centre) and near the image border.
    let (mut centre, mut border) = (Vec::new(), Vec::new());
    for i in 0..image.depth().len() {
        let (near, depth, far) = (image.near()[i], image.depth()[i], image.far()[i]);
        if !depth.is_finite() {
            continue;
        }
        assert!(near <= depth, "P- > P0 at {i}");
        if !far.is_finite() {
            continue;
        }
        assert!(depth <= far, "P0 > P+ at {i}");
        let (u, v) = ((i % 320) as f64, (i / 320) as f64);
        let ray = reference_pose.rotation * k.back_project(u, v, 1.0).coords;
        let truth = (reference_pose.inverse() * plane_hit(&origin, &ray).unwrap()).z as f32;
        bounded += 1;
        inside += usize::from(near <= truth && truth <= far);
        let radius = ((u - 159.5).powi(2) + (v - 119.5).powi(2)).sqrt();
        if radius < 30.0 {
            centre.push(far - near);
        } else if radius > 120.0 {
            border.push(far - near);
        }
    }
    assert!(bounded > 320 * 240 / 4, "{bounded} pixels with an interval");
    let share = inside as f64 / bounded as f64;
    assert!(share > 0.9, "truth inside the interval for {share:.3}");
    let median = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f32::INFINITY)
    };
    // Near the epipole the image barely moves: wider intervals (or none at all).
    assert!(median(&mut border) < median(&mut centre) || centre.is_empty());
    // Confidence carries the pair's poor geometry.
    assert!(
        image
            .confidence()
            .iter()
            .all(|c| c.is_nan() || *c <= result.quality as f32 + 1e-6)
    );
    // The sweep works for a sideways pair too, and needs a depth range.
    let sideways = Frame::new(
        render(&k, &pose([0.35, 0.0, 0.0], 0.0)),
        k,
        pose([0.35, 0.0, 0.0], 0.0),
        1.0,
    )
    .unwrap();
    let swept = depth_by_plane_sweep(&reference, &sideways, 1.0, &params).unwrap();
    assert!(swept.frame.image().valid_pixels() > 320 * 240 / 2);
    params.depth_range = None;
    assert!(matches!(
        depth_by_plane_sweep(&reference, &sideways, 1.0, &params),
        Err(Error::InvalidParameter { .. })
    ));
}

/// A surface straight ahead of a camera moving along its view: pixels a few degrees from the
/// epipole move only a few pixels over the whole depth range (many planes per pixel of
/// motion). The sweep measures them, with intervals that hold the truth, instead of dropping
/// them as not unique; the epipole itself, which does not move, gets no depth.
#[test]
fn forward_motion_measures_pixels_near_the_epipole() {
    let k = camera();
    let reference_pose = pose([0.0, 0.0, 0.0], 0.0);
    let other_pose = pose([0.0, 0.0, -0.5], 0.0);
    let reference = view(&k, reference_pose, 0.0);
    let other = view(&k, other_pose, 0.5);
    let params = DepthParams {
        depth_range: Some((1.0, 60.0)),
        forward_motion: ForwardMotion::PlaneSweep,
        ..DepthParams::default()
    };
    let result = depth_from_pair(&reference, &other, &params).unwrap();
    assert_eq!(result.method, MatchMethod::PlaneSweep);
    let image = result.frame.image();
    // The epipole: the other camera's centre seen from the reference camera.
    let behind = reference_pose.inverse() * Point3::from(other_pose.translation.vector);
    let epipole = k.project(&Point3::from(-behind.coords)).unwrap();
    let (mut annulus, mut measured, mut inside, mut at_epipole) = (0usize, 0usize, 0usize, 0usize);
    for i in 0..image.depth().len() {
        let (u, v) = ((i % 320) as f64, (i / 320) as f64);
        let radius = (u - epipole.x).hypot(v - epipole.y);
        let depth = image.depth()[i];
        if radius < 1.0 {
            at_epipole += usize::from(depth.is_finite());
        }
        if !(8.0..30.0).contains(&radius) {
            continue;
        }
        annulus += 1;
        if !depth.is_finite() {
            continue;
        }
        measured += 1;
        inside += usize::from(interval_holds_truth(image, &reference_pose, i));
    }
    let share = measured as f64 / annulus as f64;
    assert!(
        share > 0.5,
        "{measured} of {annulus} pixels 8-30 px from the epipole measured"
    );
    let held = inside as f64 / measured as f64;
    assert!(
        held > 0.9,
        "truth inside the interval for {held:.3} near the epipole"
    );
    assert_eq!(at_epipole, 0, "the epipole itself has no depth");
}

/// Whether pixel `i` of a depth image in the camera at `pose` (at the origin) holds the
/// textured plane's true depth in `[P-, P+]` (an undefined `P+` holds everything beyond `P-`).
fn interval_holds_truth(
    image: &fuzzyvox::IntervalDepthImage,
    pose: &Isometry3<f64>,
    i: usize,
) -> bool {
    let k = camera();
    let (u, v) = ((i % 320) as f64, (i / 320) as f64);
    let ray = pose.rotation * k.back_project(u, v, 1.0).coords;
    let truth = (pose.inverse() * plane_hit(&Point3::origin(), &ray).unwrap()).z;
    let (near, far) = (f64::from(image.near()[i]), f64::from(image.far()[i]));
    near <= truth && (truth <= far || far.is_nan())
}

#[test]
fn a_pair_with_the_epipole_just_outside_the_image_is_swept() {
    let k = camera();
    let reference_pose = pose([0.0, 0.0, 0.0], 0.0);
    // Behind and above the reference (y points down): the other camera's centre projects 80 px
    // below the 240 px image, so the views look nearly along the baseline.
    let other_pose = pose([0.0, -0.2, -0.3], 0.0);
    let reference = view(&k, reference_pose, 0.0);
    let other = view(&k, other_pose, 0.5);
    let params = |forward_motion| DepthParams {
        depth_range: Some((1.0, 60.0)),
        forward_motion,
        ..DepthParams::default()
    };
    // Rectification accepts the pair (the epipole is outside the image) ...
    let rectified = depth_from_pair(&reference, &other, &params(ForwardMotion::Reject)).unwrap();
    assert_eq!(rectified.method, MatchMethod::Rectified);
    // ... but where the plane sweep is allowed, the pair goes to it.
    let result = depth_from_pair(&reference, &other, &params(ForwardMotion::PlaneSweep)).unwrap();
    assert_eq!(result.method, MatchMethod::PlaneSweep);
    let image = result.frame.image();
    let (mut measured, mut inside) = (0usize, 0usize);
    for i in 0..image.depth().len() {
        if !image.depth()[i].is_finite() {
            continue;
        }
        measured += 1;
        inside += usize::from(interval_holds_truth(image, &reference_pose, i));
    }
    assert!(measured > 320 * 240 / 2, "{measured} pixels measured");
    let held = inside as f64 / measured as f64;
    assert!(held > 0.9, "truth inside the interval for {held:.3}");
}

/// Median `|P0 - truth|` and median interval width over the pixels with a bounded interval,
/// and the share of those whose interval holds the true depth, for a depth frame in the
/// camera `pose` looking at the textured plane.
fn depth_errors(image: &fuzzyvox::IntervalDepthImage, pose: &Isometry3<f64>) -> (f32, f32, f64) {
    let k = camera();
    let origin = Point3::from(pose.translation.vector);
    let (mut errors, mut widths, mut inside) = (Vec::new(), Vec::new(), 0usize);
    for i in 0..image.depth().len() {
        let (near, depth, far) = (image.near()[i], image.depth()[i], image.far()[i]);
        if !(depth.is_finite() && far.is_finite()) {
            continue;
        }
        let (u, v) = ((i % 320) as f64, (i / 320) as f64);
        let ray = pose.rotation * k.back_project(u, v, 1.0).coords;
        let truth = (pose.inverse() * plane_hit(&origin, &ray).unwrap()).z as f32;
        errors.push((depth - truth).abs());
        widths.push(far - near);
        inside += usize::from(near <= truth && truth <= far);
    }
    assert!(errors.len() > 320 * 240 / 2, "{} pixels", errors.len());
    let share = inside as f64 / errors.len() as f64;
    let median = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    (median(&mut errors), median(&mut widths), share)
}

#[test]
fn several_views_sharpen_depth_beyond_one_pair() {
    let k = camera();
    // Four cameras 10 cm apart along a line, looking at the plane 4 m away: the reference and
    // three earlier views with baselines of 0.1, 0.2 and 0.3 m.
    let reference_pose = pose([0.3, 0.0, 0.0], 0.0);
    let reference = Frame::new(render(&k, &reference_pose), k, reference_pose, 3.0).unwrap();
    let others: Vec<Frame> = (0..3)
        .map(|i| {
            let p = pose([0.2 - 0.1 * f64::from(i), 0.0, 0.0], 0.0);
            Frame::new(render(&k, &p), k, p, 2.0 - f64::from(i)).unwrap()
        })
        .collect();
    let params = DepthParams {
        depth_range: Some((2.0, 12.0)),
        ..DepthParams::default()
    };
    let pair = depth_by_plane_sweep(&reference, &others[0], 1.0, &params).unwrap();
    let views: Vec<&Frame> = others.iter().collect();
    let multi = depth_from_views(&reference, &views, &params).unwrap();
    assert_eq!(multi.method, MatchMethod::MultiView);
    assert_eq!(multi.frame.world_from_camera(), &reference_pose);
    assert!(multi.quality > 0.99, "Q_ABD {}", multi.quality);
    let (pair_error, pair_width, pair_inside) = depth_errors(pair.frame.image(), &reference_pose);
    let (multi_error, multi_width, multi_inside) =
        depth_errors(multi.frame.image(), &reference_pose);
    // Three times the baseline: the planes are three times finer, and so are the intervals.
    assert!(
        multi_error * 2.0 < pair_error,
        "median error {multi_error} m with four views, {pair_error} m with one pair"
    );
    assert!(
        multi_width * 2.0 < pair_width,
        "median width {multi_width} m, {pair_width} m"
    );
    assert!(
        pair_inside > 0.9 && multi_inside > 0.9,
        "{pair_inside} {multi_inside}"
    );
    // One other view is the two-view sweep.
    let single = depth_from_views(&reference, &views[..1], &params).unwrap();
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(
        bits(&single.disparity.disparity),
        bits(&pair.disparity.disparity)
    );
    assert_eq!(
        bits(&single.disparity.range_high),
        bits(&pair.disparity.range_high)
    );
    // The same views in another order give the same depth.
    let reversed: Vec<&Frame> = others.iter().rev().collect();
    let again = depth_from_views(&reference, &reversed, &params).unwrap();
    assert_eq!(
        bits(again.frame.image().depth()),
        bits(multi.frame.image().depth())
    );

    // No view, too many views, a view without baseline, no depth range: typed errors.
    assert!(matches!(
        depth_from_views(&reference, &[], &params),
        Err(Error::Empty(_))
    ));
    let crowd = vec![&others[0]; fuzzyvox::depth::MAX_SWEEP_VIEWS + 1];
    assert!(matches!(
        depth_from_views(&reference, &crowd, &params),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        depth_from_views(&reference, &[&others[0], &reference], &params),
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::ZeroBaseline { .. }
        })
    ));
    let unbounded = DepthParams {
        depth_range: None,
        ..params.clone()
    };
    assert!(matches!(
        depth_from_views(&reference, &views, &unbounded),
        Err(Error::InvalidParameter { .. })
    ));
}

#[test]
fn synthetic_plane_depth_lies_in_the_interval() {
    let k = camera();
    let reference_pose = pose([0.0, 0.0, 0.0], 0.0);
    let other_pose = pose([0.35, 0.02, 0.03], -2.0);
    let reference = view(&k, reference_pose, 0.0);
    let other = view(&k, other_pose, 0.5);
    for method in [
        IntervalMethod::FixedDelta { delta: 1.0 },
        IntervalMethod::CostCurve { delta: 1.0 },
    ] {
        let mut params = DepthParams {
            depth_range: Some((2.0, 12.0)),
            ..DepthParams::default()
        };
        params.interval.method = method;
        let result = depth_from_pair(&reference, &other, &params).unwrap();
        let frame = &result.frame;
        let image = frame.image();
        let rect = frame.intrinsics();
        let origin = Point3::from(frame.world_from_camera().translation.vector);
        let (mut confident, mut inside) = (0usize, 0usize);
        for i in 0..image.depth().len() {
            let (near, depth, far) = (image.near()[i], image.depth()[i], image.far()[i]);
            if near.is_finite() && depth.is_finite() {
                assert!(near <= depth, "P- > P0 at {i}");
            }
            if depth.is_finite() && far.is_finite() {
                assert!(depth <= far, "P0 > P+ at {i}");
            }
            if image.confidence()[i].is_nan() || image.confidence()[i] <= 0.0 {
                continue;
            }
            let (u, v) = (
                (i % rect.width() as usize) as f64,
                (i / rect.width() as usize) as f64,
            );
            let ray = frame.world_from_camera().rotation * rect.back_project(u, v, 1.0).coords;
            let hit = plane_hit(&origin, &ray).unwrap();
            // Depth along the rectified optical axis.
            let truth = (frame.world_from_camera().inverse() * hit).z as f32;
            confident += 1;
            inside += usize::from(near <= truth && truth <= far);
        }
        let share = inside as f64 / confident as f64;
        assert!(
            confident > 320 * 240 / 2,
            "{method:?}: only {confident} confident pixels"
        );
        assert!(
            share >= 0.95,
            "{method:?}: {:.1}% of confident pixels contain the truth",
            100.0 * share
        );
        assert!(result.quality > 0.9, "strafe quality {}", result.quality);
        eprintln!(
            "{method:?}: {confident} confident pixels, {:.2}% contain the truth",
            100.0 * share
        );
        // The output goes straight into a map.
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.1).unwrap()).unwrap();
        let stats = map
            .integrate_depth(frame, &IntegrationOptions::default())
            .unwrap();
        assert!(
            stats.integrated > 0 && stats.voxels_updated > 0,
            "{stats:?}"
        );
        // The centre pixel's P0 lands in a voxel with occupied evidence; halfway there is free.
        let centre =
            (rect.height() as usize / 2) * rect.width() as usize + rect.width() as usize / 2;
        let z = f64::from(image.depth()[centre]);
        let (u, v) = (f64::from(rect.width() / 2), f64::from(rect.height() / 2));
        let at = |depth: f64| frame.world_from_camera() * rect.back_project(u, v, depth);
        let surface = map.measures_at_point(&at(z)).unwrap();
        let halfway = map.measures_at_point(&at(0.5 * z)).unwrap();
        assert!(surface.occupied > 0.0, "{surface:?}");
        assert!(halfway.free > 0.0 && halfway.occupied == 0.0, "{halfway:?}");
    }
}

#[test]
fn rectified_rows_agree_to_a_tenth_of_a_pixel() {
    let k_ref = PinholeIntrinsics::new(640, 480, 520.0, 515.0, 330.0, 238.0).unwrap();
    let k_other = PinholeIntrinsics::new(600, 450, 480.0, 485.0, 290.0, 230.0).unwrap();
    let world_from_ref = pose([0.1, -0.2, 0.05], 3.0);
    let world_from_other = Isometry3::from_parts(
        Translation3::new(0.6, -0.1, 0.15),
        UnitQuaternion::from_euler_angles(-0.05, -0.1, 0.04),
    );
    let rect = Rectification::new(&k_ref, &world_from_ref, &k_other, &world_from_other).unwrap();
    let geometry = rect.geometry();
    let mut rng = common::Rng::new(7);
    let mut checked = 0;
    for _ in 0..500 {
        let p_ref = Point3::new(
            rng.uniform(-2.0, 2.0),
            rng.uniform(-1.5, 1.5),
            rng.uniform(2.0, 20.0),
        );
        let world = world_from_ref * p_ref;
        let (Some(a), Some(b)) = (
            k_ref.project(&p_ref),
            k_other.project(&(world_from_other.inverse() * world)),
        ) else {
            continue;
        };
        let ra = rect.rectify_point(Side::Reference, a).unwrap();
        let rb = rect.rectify_point(Side::Other, b).unwrap();
        assert!((ra.y - rb.y).abs() < 0.1, "rows {} vs {}", ra.y, rb.y);
        // The disparity gives back the depth along the rectified axis.
        let z = (geometry.world_from_reference().inverse() * world).z;
        let depth = geometry.depth(ra.x - rb.x).unwrap();
        assert!((depth - z).abs() < 1e-6 * z, "depth {depth} vs {z}");
        checked += 1;
    }
    assert!(checked > 300);
}

#[test]
fn pair_selector_prefers_the_best_quality() {
    let k = camera();
    let image = GrayImage::new(320, 240, vec![0.0; 320 * 240]).unwrap();
    let mut selector = PairSelector::new(PairCriteria::default()).unwrap();
    let frame =
        |t: f64, position: [f64; 3]| Frame::new(image.clone(), k, pose(position, 0.0), t).unwrap();
    assert!(
        selector
            .push(frame(0.0, [0.0, 0.0, 0.0]))
            .unwrap()
            .is_none()
    );
    // Forward motion: Q ≈ 0, but a valid partner.
    let forward = selector.push(frame(0.1, [0.0, 0.0, 0.3])).unwrap().unwrap();
    assert!(forward.quality.q < 0.2);
    // Sideways from the first frame, forward-ish from the second: the first wins.
    let pair = selector.push(frame(0.2, [0.3, 0.0, 0.0])).unwrap().unwrap();
    assert_eq!(pair.other.timestamp(), 0.0);
    assert!(pair.quality.q > 0.99);
    // Out of the time window: nothing to pair with.
    assert!(
        selector
            .push(frame(10.0, [0.6, 0.0, 0.0]))
            .unwrap()
            .is_none()
    );
    assert_eq!(selector.len(), 1);
    // Time must not run backwards.
    assert!(selector.push(frame(5.0, [0.6, 0.0, 0.0])).is_err());
    assert!(
        PairSelector::new(PairCriteria {
            time_window: f64::NAN,
            ..PairCriteria::default()
        })
        .is_err()
    );
}

#[test]
fn bad_inputs_are_typed_errors() {
    let k = camera();
    let image = GrayImage::new(320, 240, vec![1.0; 320 * 240]).unwrap();
    let small = GrayImage::new(160, 240, vec![1.0; 160 * 240]).unwrap();
    // Different image sizes.
    assert!(matches!(
        match_pair(&image, &small, &MatchParams::default()),
        Err(Error::SizeMismatch { .. })
    ));
    assert!(matches!(
        Frame::new(small.clone(), k, Isometry3::identity(), 0.0),
        Err(Error::SizeMismatch { .. })
    ));
    // Tiny and odd images match without panicking (nothing to match in most of them).
    for (w, h) in [(1u32, 1u32), (3, 2), (2, 9), (17, 1)] {
        let tiny = GrayImage::new(w, h, (0..w * h).map(|i| (i * 7 % 5) as f32).collect()).unwrap();
        let map = match_pair(&tiny, &tiny, &MatchParams::default()).unwrap();
        assert_eq!(map.disparity.len(), (w * h) as usize);
    }
    let nan = GrayImage::new(4, 4, vec![f32::NAN; 16]).unwrap();
    assert_eq!(
        match_pair(&nan, &nan, &MatchParams::default())
            .unwrap()
            .density(),
        0.0
    );
    // Empty images.
    assert!(matches!(GrayImage::new(0, 0, vec![]), Err(Error::Empty(_))));
    assert!(matches!(GrayImage::new(4, 0, vec![]), Err(Error::Empty(_))));
    // ndisp 0 and other bad parameters.
    let zero = MatchParams {
        num_disparities: 0,
        ..MatchParams::default()
    };
    assert!(matches!(
        match_pair(&image, &image, &zero),
        Err(Error::InvalidParameter { .. })
    ));
    let even = MatchParams {
        window_width: 8,
        ..MatchParams::default()
    };
    assert!(matches!(
        match_pair(&image, &image, &even),
        Err(Error::InvalidParameter { .. })
    ));
    // NaN pose.
    let mut nan = Isometry3::identity();
    nan.translation.vector.x = f64::NAN;
    assert!(matches!(
        Frame::new(image.clone(), k, nan, 0.0),
        Err(Error::InvalidPose(_))
    ));
    assert!(matches!(
        Frame::new(image.clone(), k, Isometry3::identity(), f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        Rectification::new(&k, &nan, &k, &Isometry3::identity()),
        Err(Error::InvalidPose(_))
    ));
    let a = Frame::new(image.clone(), k, Isometry3::identity(), 0.0).unwrap();
    // Zero baseline.
    let same = Frame::new(image.clone(), k, Isometry3::identity(), 1.0).unwrap();
    assert!(matches!(
        depth_from_pair(&a, &same, &DepthParams::default()),
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::ZeroBaseline { .. }
        })
    ));
    // Forward motion: the epipole is inside the image.
    let ahead = Frame::new(image.clone(), k, pose([0.05, 0.0, 1.0], 0.0), 1.0).unwrap();
    assert!(matches!(
        depth_from_pair(&a, &ahead, &DepthParams::default()),
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::EpipoleInImage { .. }
        })
    ));
    // Opposite views, sideways: no overlap.
    let behind = Frame::new(
        image.clone(),
        k,
        Isometry3::from_parts(
            Translation3::new(1.0, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, std::f64::consts::PI, 0.0),
        ),
        1.0,
    )
    .unwrap();
    assert!(matches!(
        depth_from_pair(&a, &behind, &DepthParams::default()),
        Err(Error::Unrectifiable {
            reason: UnrectifiableReason::OppositeViews
        })
    ));
    // A depth range that makes no sense.
    let sideways = Frame::new(image, k, pose([0.3, 0.0, 0.0], 0.0), 1.0).unwrap();
    let params = DepthParams {
        depth_range: Some((5.0, 1.0)),
        ..DepthParams::default()
    };
    assert!(matches!(
        depth_from_pair(&a, &sideways, &params),
        Err(Error::InvalidParameter { .. })
    ));
    let _ = Point2::new(0.0, 0.0);
}

#[test]
fn damaged_pfm_files_are_typed_errors() {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-pfm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &[u8]); 3] = [
        ("truncated.pfm", b"Pf\n2 2\n-1.0\n\0\0\0\0\0\0"),
        ("header.pfm", b"P5\n2 2\n255\n"),
        ("huge.pfm", b"Pf\n99999999 99999999\n-1.0\n"),
    ];
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        match read_pfm(&path) {
            Err(Error::Format { reason, .. }) => {
                assert!(matches!(
                    reason,
                    FormatError::Length { .. } | FormatError::BadMagic | FormatError::Invalid(_)
                ));
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    assert!(matches!(
        read_pfm(&dir.join("missing.pfm")),
        Err(Error::Io { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A camera 2 m above textured ground, looking level: the lower half of its image is ground, the
/// upper half a clear sky. A sideways pair measures the ground and, with the texture test, none
/// of the sky beyond the windows that reach the horizon; without it, the matcher puts sky
/// pixels at confident false depths.
#[test]
fn a_clear_sky_gives_no_depth() {
    use fuzzyvox::sim::{Scene, render, trajectory::look_at};
    let mut scene = Scene::new();
    scene.add_ground(0.0, 400.0);
    let k = PinholeIntrinsics::new(320, 240, 277.0, 277.0, 159.5, 119.5).unwrap();
    let frame = |y: f64, seed: u64| {
        let pose = look_at(Point3::new(0.0, y, 2.0), Vector3::new(1.0, 0.0, 0.0));
        render(&scene, &k, &pose, seed, 240.0).to_frame(k, pose, y)
    };
    let (reference, other) = (frame(0.0, 40).unwrap(), frame(-0.5, 41).unwrap());
    let sky = |params: &DepthParams| {
        let result = depth_from_pair(&reference, &other, params).unwrap();
        let image = result.frame.image();
        let pose = result.frame.world_from_camera();
        let intrinsics = result.frame.intrinsics();
        let (mut sky, mut confident_sky, mut ground) = (0, 0, 0);
        for v in 0..image.height() {
            for u in 0..image.width() {
                let i = (v * image.width() + u) as usize;
                if !image.depth()[i].is_finite() {
                    continue;
                }
                let ray = pose.rotation * intrinsics.back_project(f64::from(u), f64::from(v), 1.0);
                let elevation = ray.coords.z.atan2(ray.coords.x.hypot(ray.coords.y));
                if elevation < 0.0 {
                    ground += 1;
                } else if elevation > 2f64.to_radians() {
                    // Sky further from the horizon than a matching window reaches.
                    sky += 1;
                    confident_sky += usize::from(image.confidence()[i] > 0.2);
                }
            }
        }
        (sky, confident_sky, ground)
    };
    let range = Some((1.0, 60.0));
    let with = DepthParams {
        depth_range: range,
        ..DepthParams::default()
    };
    let mut without = with.clone();
    without.matching.min_contrast = 0.0;
    let (sky_off, confident_off, ground_off) = sky(&without);
    let (sky_on, confident_on, ground_on) = sky(&with);
    // The premise: without the test, the sky is "measured", some of it confidently.
    assert!(
        sky_off > 100 && confident_off > 0,
        "{sky_off} {confident_off}"
    );
    assert_eq!(
        (sky_on, confident_on),
        (0, 0),
        "the sky, with the texture test"
    );
    // The ground keeps its depth.
    assert!(
        ground_on > 10_000 && ground_on * 10 > ground_off * 9,
        "{ground_on} {ground_off}"
    );
}
