//! End-to-end checks on real data from `FUZZYVOX_DATA`: OctoMap's laser scan and 7-Scenes
//! Kinect frames. Each test says it skipped when the variable is unset and fails when it is set
//! but the data is missing.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::data_dir;
use fuzzyvox::VoxelMapMut;
use fuzzyvox::io::read_text_cloud;
use fuzzyvox::io::rgbd::{
    kinect_interval_image, read_depth_png_mm, read_intrinsics_txt, read_pose_txt,
};
use fuzzyvox::{DepthFrame, FuzzyConfig, FuzzyMap, IntegrationOptions, VoxelClass, VoxelMap};
use nalgebra::Point3;

/// OctoMap 1.9.7's counts for `scan.dat` at 0.2 m (`../shared/REFERENCE.md`).
const OCTOMAP_OCCUPIED_0_2: f64 = 9_378.0;
const OCTOMAP_FREE_0_2: f64 = 117_825.0;

#[test]
fn laser_scan_classes_match_the_standard_method_at_full_confidence() {
    let Some(dir) = data_dir("laser_scan_classes_match_the_standard_method_at_full_confidence")
    else {
        return;
    };
    let cloud = read_text_cloud(&dir.join("octomap-samples/scan.dat"), Point3::origin()).unwrap();
    assert_eq!(cloud.len(), 88_206);
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
    let stats = map
        .integrate_cloud(&cloud, &IntegrationOptions::default())
        .unwrap();
    assert_eq!(stats.integrated, 88_206);
    let counts = map.counts();
    // One scan at full confidence carries no conflict, so the fuzzy classes should agree with
    // OctoMap's occupied / free split to within the kernel's few extra voxels.
    let occupied = counts.occupied as f64;
    let free = counts.free as f64;
    assert!(
        (occupied / OCTOMAP_OCCUPIED_0_2 - 1.0).abs() < 0.02,
        "occupied {occupied} vs OctoMap {OCTOMAP_OCCUPIED_0_2}"
    );
    assert!(
        (free / OCTOMAP_FREE_0_2 - 1.0).abs() < 0.01,
        "free {free} vs OctoMap {OCTOMAP_FREE_0_2}"
    );
    assert_eq!(counts.ambiguous, 0);
    // Every end point's voxel is occupied.
    let resolution = map.resolution();
    let missed = cloud
        .points()
        .iter()
        .filter(|p| map.class_at(resolution.key_of(p).unwrap()) != VoxelClass::Occupied)
        .count();
    assert_eq!(missed, 0);
}

fn kitchen_frame(dir: &std::path::Path, index: usize) -> DepthFrame {
    let scene = dir.join("rgbd-7scenes-redkitchen");
    let depth = read_depth_png_mm(&scene.join(format!("frame-{index:06}.depth.png"))).unwrap();
    assert_eq!((depth.width, depth.height), (640, 480));
    let k = read_intrinsics_txt(&scene.join("camera-intrinsics.txt"), 640, 480).unwrap();
    let pose = read_pose_txt(&scene.join(format!("frame-{index:06}.pose.txt"))).unwrap();
    DepthFrame::new(k, pose, kinect_interval_image(&depth).unwrap()).unwrap()
}

#[test]
fn kinect_frames_map_surfaces_occupied_and_the_space_before_them_free() {
    let Some(dir) = data_dir("kinect_frames_map_surfaces_occupied_and_the_space_before_them_free")
    else {
        return;
    };
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.05).unwrap()).unwrap();
    // Frames 150..170 except 160, which is held out as the probe.
    for index in (150..170).filter(|&i| i != 160) {
        let stats = map
            .integrate_depth(&kitchen_frame(&dir, index), &IntegrationOptions::default())
            .unwrap();
        assert!(stats.integrated > 200_000, "frame {index}: {stats:?}");
    }
    // Check against a frame the map has not seen.
    let probe = kitchen_frame(&dir, 160);
    let (k, pose, image) = (probe.intrinsics(), probe.world_from_camera(), probe.image());
    let (mut surface_hits, mut free_before, mut checked) = (0, 0, 0);
    let mut halfway_classes = [0usize; 4];
    for v in (0..480).step_by(8) {
        for u in (0..640).step_by(8) {
            let z = image.depth()[v * 640 + u];
            if !(z.is_finite() && z > 0.4) {
                continue;
            }
            checked += 1;
            let on_surface = pose * k.back_project(u as f64, v as f64, f64::from(z));
            let halfway = pose * k.back_project(u as f64, v as f64, 0.5 * f64::from(z));
            let class = |p: &Point3<f64>| map.class_at_point(p).unwrap();
            surface_hits += usize::from(class(&on_surface) == VoxelClass::Occupied);
            free_before += usize::from(class(&halfway) == VoxelClass::Free);
            halfway_classes[class(&halfway).index()] += 1;
        }
    }
    let surface = surface_hits as f64 / checked as f64;
    let before = free_before as f64 / checked as f64;
    eprintln!(
        "{checked} probe pixels: surface occupied {surface:.3}, halfway free {before:.3} (halfway classes occupied/free/ambiguous/unknown: {halfway_classes:?})"
    );
    assert!(checked > 3000);
    assert!(surface > 0.8, "surface voxels occupied: {surface:.3}");
    assert!(before > 0.95, "halfway voxels free: {before:.3}");
}
