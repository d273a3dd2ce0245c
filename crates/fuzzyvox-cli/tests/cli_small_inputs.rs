//! Every command that works on files, run on small inputs made here (no data needed): `export`
//! in each variant, `info` and `stereo`, each with bad inputs.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};

use common::{Rng, fuzzyvox, insert_wall, json};

/// Runs a command that must fail with `code` and a message containing `expected`.
fn fails(args: &[&str], code: i32, expected: &str) {
    let out = fuzzyvox(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    assert!(stderr.contains(expected), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-small-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fuzzy map of a 2 × 1 m wall at x = 3 m, seen from (0, 0, 0.5), at 0.1 m.
fn wall_map(dir: &Path) -> PathBuf {
    let mut text = String::new();
    for i in 0..=40 {
        for j in 0..=20 {
            let (y, z) = (-1.0 + 0.05 * f64::from(i), 0.05 * f64::from(j));
            text.push_str(&format!("3.0 {y} {z} 0.9\n"));
        }
    }
    insert_wall(dir, &text)
}

#[test]
fn export_writes_ply_files_that_hold_the_maps_voxels() {
    let dir = scratch("ply");
    let map = wall_map(&dir);
    let m = map.to_str().unwrap();
    let info = json(&fuzzyvox(&["info", m, "--json"]));
    let occupied = info["occupied"].as_u64().unwrap();
    assert!(occupied > 100, "{info}");

    // ASCII, occupied voxels only: one line per occupied voxel, every one on the wall.
    let ascii = dir.join("occupied.ply");
    let report = json(&fuzzyvox(&[
        "export",
        m,
        "--ply",
        ascii.to_str().unwrap(),
        "--ascii",
        "--classes",
        "occupied",
        "--json",
    ]));
    assert_eq!(report["ply_vertices"].as_u64(), Some(occupied));
    assert_eq!(report["ply_format"], "ascii");
    let text = std::fs::read_to_string(&ascii).unwrap();
    let (header, body) = text.split_once("end_header\n").unwrap();
    assert!(header.starts_with("ply\nformat ascii 1.0\n"));
    assert!(header.contains(&format!("element vertex {occupied}\n")));
    for property in ["x", "y", "z", "occupied", "free", "ambiguity", "safety"] {
        assert!(header.contains(&format!("property float {property}\n")));
    }
    assert!(header.contains("property uchar class\n"));
    assert_eq!(body.lines().count() as u64, occupied);
    for line in body.lines() {
        let v: Vec<f64> = line.split(' ').map(|f| f.parse().unwrap()).collect();
        assert!(
            (2.9..3.2).contains(&v[0]),
            "occupied voxel off the wall: {line}"
        );
        assert!(
            v[3] >= 0.5 && v[3] > v[4],
            "memberships of an occupied voxel: {line}"
        );
        assert_eq!(v[7], 0.0, "class 0 is occupied: {line}");
    }

    // Binary, every observed voxel: 32 bytes per vertex after the header.
    let binary = dir.join("all.ply");
    let report = json(&fuzzyvox(&[
        "export",
        m,
        "--ply",
        binary.to_str().unwrap(),
        "--json",
    ]));
    let n = report["ply_vertices"].as_u64().unwrap();
    let counted = ["occupied", "free", "ambiguous"]
        .iter()
        .map(|k| info[k].as_u64().unwrap())
        .sum::<u64>();
    assert!(n >= counted, "{n} vertices, {counted} classified voxels");
    let bytes = std::fs::read(&binary).unwrap();
    let end = b"end_header\n";
    let start = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    assert!(String::from_utf8_lossy(&bytes[..start]).contains("format binary_little_endian 1.0\n"));
    assert_eq!((bytes.len() - start) as u64, 32 * n);

    // Text output names the file.
    let out = fuzzyvox(&["export", m, "--ply", binary.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("all.ply"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_draws_top_side_and_slice_views() {
    let dir = scratch("png");
    let map = wall_map(&dir);
    let m = map.to_str().unwrap();
    let png = |name: &str| dir.join(name);
    let cases: [(&str, &[&str]); 4] = [
        ("top.png", &[]),
        ("side.png", &["--view", "side", "--color", "occupied"]),
        (
            "slice.png",
            &["--view", "slice", "--height", "0.55", "--color", "safety"],
        ),
        ("scaled.png", &["--color", "ambiguity", "--scale", "3"]),
    ];
    let mut sizes = Vec::new();
    for (name, extra) in cases {
        let path = png(name);
        let mut args = vec!["export", m, "--png", path.to_str().unwrap(), "--json"];
        args.extend_from_slice(extra);
        let report = json(&fuzzyvox(&args));
        let image = image::open(&path).unwrap().to_rgb8();
        assert_eq!(
            (report["png_width"].as_u64(), report["png_height"].as_u64()),
            (
                Some(u64::from(image.width())),
                Some(u64::from(image.height()))
            )
        );
        sizes.push(image.dimensions());
        // Something other than background was drawn.
        assert!(image.pixels().any(|p| p.0 != [255, 255, 255]), "{name}");
    }
    // Every view is a figure at least 800 pixels wide (title, axes, scale bar, legend).
    for (w, h) in &sizes {
        assert!(*w >= 800 && *h > 0, "{w} x {h}");
    }
    assert!(sizes[3].0 >= sizes[0].0);
    // Top view by class: the wall (occupied, class colour 40, 40, 40) is drawn.
    let top = image::open(png("top.png")).unwrap().to_rgb8();
    assert!(top.pixels().filter(|p| p.0 == [40, 40, 40]).count() > 100);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_writes_several_outputs_at_once_and_rejects_bad_requests() {
    let dir = scratch("export-bad");
    let map = wall_map(&dir);
    let m = map.to_str().unwrap();
    let (bt, ply, png) = (dir.join("a.bt"), dir.join("a.ply"), dir.join("a.png"));
    let report = json(&fuzzyvox(&[
        "export",
        m,
        "--bt",
        bt.to_str().unwrap(),
        "--ply",
        ply.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--json",
    ]));
    assert!(report["occupied"].as_u64().unwrap() > 100);
    assert!(bt.is_file() && ply.is_file() && png.is_file());

    let not_a_map = dir.join("not-a-map.fvx");
    std::fs::write(&not_a_map, "hello").unwrap();
    let out = png.to_str().unwrap();
    // Usage errors (exit 2): no output, PLY options without --ply, an unknown colour.
    fails(&["export", m], 2, "--bt");
    fails(&["export", m, "--ascii", "--png", out], 2, "--ply");
    fails(&["export", m, "--png", out, "--color", "pink"], 2, "pink");
    // Failed commands (exit 1).
    fails(
        &["export", m, "--png", out, "--view", "slice"],
        1,
        "--height",
    );
    fails(
        &["export", m, "--png", out, "--height", "1"],
        1,
        "slice only",
    );
    fails(
        &[
            "export", m, "--png", out, "--view", "slice", "--height", "40",
        ],
        1,
        "empty",
    );
    fails(&["export", m, "--png", out, "--scale", "0"], 1, "scale");
    fails(
        &["export", m, "--ply", "/nonexistent-dir/a.ply"],
        1,
        "/nonexistent-dir/a.ply",
    );
    fails(
        &["export", not_a_map.to_str().unwrap(), "--png", out],
        1,
        "not a map file fuzzyvox reads",
    );
    fails(&["info", "/nonexistent/map.fvx"], 1, "/nonexistent/map.fvx");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A textured 96×64 rectified pair with a constant disparity of 8 px, a Middlebury calibration
/// and ground truth.
fn write_stereo_pair(dir: &Path) {
    let mut rng = Rng::new(7);
    let (w, h, d) = (96u32, 64u32, 8u32);
    let texture: Vec<u8> = (0..(w + d) * h)
        .map(|_| (rng.next_u64() % 256) as u8)
        .collect();
    let left = image::GrayImage::from_fn(w, h, |x, y| {
        image::Luma([texture[(y * (w + d) + x) as usize]])
    });
    // left(y, x) matches right(y, x - d).
    let right = image::GrayImage::from_fn(w, h, |x, y| {
        image::Luma([texture[(y * (w + d) + x + d) as usize]])
    });
    left.save(dir.join("im0.png")).unwrap();
    right.save(dir.join("im1.png")).unwrap();
    std::fs::write(
        dir.join("calib.txt"),
        "cam0=[100 0 48; 0 100 32; 0 0 1]\ncam1=[100 0 48; 0 100 32; 0 0 1]\n\
         doffs=0\nbaseline=100\nwidth=96\nheight=64\nndisp=16\n",
    )
    .unwrap();
    fuzzyvox::io::pfm::write_pfm(
        &dir.join("disp0GT.pfm"),
        w,
        h,
        &vec![d as f32; (w * h) as usize],
    )
    .unwrap();
}

#[test]
fn stereo_matches_a_small_synthetic_pair_and_rejects_mismatched_sizes() {
    let dir = scratch("stereo");
    write_stereo_pair(&dir);
    let out = dir.join("out");
    let report = json(&fuzzyvox(&[
        "stereo",
        "--middlebury",
        dir.to_str().unwrap(),
        "--window",
        "5",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(
        (report["width"].as_u64(), report["height"].as_u64()),
        (Some(96), Some(64))
    );
    assert!(report["density"].as_f64().unwrap() > 70.0, "{report}");
    assert!(report["bad2_matched"].as_f64().unwrap() < 5.0, "{report}");
    // Depth is baseline · f / d = 0.1 m · 100 px / 8 px = 1.25 m where matched.
    let depth = fuzzyvox::io::pfm::read_pfm(&out.join("depth.pfm")).unwrap();
    let matched: Vec<f32> = depth
        .data
        .iter()
        .copied()
        .filter(|z| z.is_finite())
        .collect();
    let close = matched.iter().filter(|z| (**z - 1.25).abs() < 0.05).count();
    assert!(
        close as f64 > 0.9 * matched.len() as f64,
        "{close} of {}",
        matched.len()
    );

    // The right image of another size.
    let small = dir.join("small.png");
    image::GrayImage::new(50, 40).save(&small).unwrap();
    fails(
        &[
            "stereo",
            "--middlebury",
            dir.to_str().unwrap(),
            "--right",
            small.to_str().unwrap(),
        ],
        1,
        "error",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every command, including ones added later, documents itself with example invocations.
#[test]
fn every_command_has_help_with_examples() {
    let top = fuzzyvox(&["--help"]);
    assert!(top.status.success());
    let text = String::from_utf8_lossy(&top.stdout).into_owned();
    assert!(text.contains("Examples:"), "{text}");
    let commands: Vec<String> = text
        .split("Commands:")
        .nth(1)
        .expect("a command list")
        .lines()
        .skip(1)
        .take_while(|line| line.starts_with("  "))
        .filter_map(|line| line.split_whitespace().next().map(str::to_string))
        .filter(|name| name != "help")
        .collect();
    for expected in ["insert", "info", "export", "plan", "stereo", "rgbd"] {
        assert!(commands.iter().any(|c| c == expected), "{commands:?}");
    }
    for command in &commands {
        let help = fuzzyvox(&[command, "--help"]);
        let text = String::from_utf8_lossy(&help.stdout);
        assert!(help.status.success(), "{command}");
        assert!(
            text.contains("Examples:\n  fuzzyvox "),
            "{command} --help:\n{text}"
        );
        assert!(text.contains("--verbose"), "{command} takes -v");
    }
}

#[test]
fn insert_reads_a_scan_list_each_scan_from_its_own_origin() {
    let dir = scratch("scan-list");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let (mut a, mut b) = (String::new(), String::new());
    for i in 0..=20 {
        for j in 0..=10 {
            let (s, z) = (-1.0 + 0.1 * f64::from(i), 0.1 * f64::from(j));
            a.push_str(&format!("3.0 {s} {z} 0.9\n"));
            b.push_str(&format!("{s} 3.0 {z} 0.8\n"));
        }
    }
    std::fs::write(dir.join("a.xyz"), &a).unwrap();
    std::fs::write(dir.join("sub").join("b.xyz"), &b).unwrap();
    let list = dir.join("scans.list");
    std::fs::write(
        &list,
        "# wall ahead, wall to the left\na.xyz 0 0 0.5\nsub/b.xyz 0.4 -0.2 0.5\n",
    )
    .unwrap();
    let list = list.to_str().unwrap();
    for model in ["logodds", "alpha", "fuzzy"] {
        let report = json(&fuzzyvox(&[
            "insert", "--cloud", list, "--res", "0.1", "--model", model, "--json",
        ]));
        assert_eq!(report["scans"], 2, "{model}");
        assert_eq!(report["points"], 2 * 21 * 11, "{model}");
        // The same clouds from the same origins, one after the other, through the library.
        let kind: fuzzyvox::MapKind = model.parse().unwrap();
        let mut map = kind.new_map(0.1).unwrap();
        for (file, origin) in [
            ("a.xyz", nalgebra::Point3::new(0.0, 0.0, 0.5)),
            ("sub/b.xyz", nalgebra::Point3::new(0.4, -0.2, 0.5)),
        ] {
            let cloud = fuzzyvox::io::read_text_cloud(&dir.join(file), origin).unwrap();
            map.as_map_mut()
                .integrate_cloud(&cloud, &Default::default())
                .unwrap();
        }
        let counts = map.as_map().counts();
        assert_eq!(report["occupied"], counts.occupied, "{model}");
        assert_eq!(report["free"], counts.free, "{model}");
        assert!(counts.occupied > 0 && counts.free > 0, "{model}");
    }
    // A bad line is an error naming it, and nothing is written.
    let bad = dir.join("bad.list");
    std::fs::write(&bad, "a.xyz 0 0 0.5\nsub/b.xyz 0 0\n").unwrap();
    let out = dir.join("out.fvx");
    fails(
        &[
            "insert",
            "--cloud",
            bad.to_str().unwrap(),
            "--res",
            "0.1",
            "--out",
            out.to_str().unwrap(),
        ],
        1,
        "bad.list:2: expected `CLOUD ox oy oz`, found 3 fields",
    );
    assert!(!out.exists(), "a failed insert wrote a map");
    std::fs::remove_dir_all(&dir).unwrap();
}
