//! Damaged, truncated, empty, oversized and foreign files of every format fuzzyvox reads: each is
//! a typed error (never a panic, never a huge allocation), and a failed save leaves the old file
//! intact. The native map's truncations, bit flips and oversized length are in `bad_input.rs`;
//! the table of every case is in `docs/robustness.md`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use fuzzyvox::VoxelMapMut;
use std::path::{Path, PathBuf};

use common::room_scan;
use fuzzyvox::io::decode_gray_image;
use fuzzyvox::io::middlebury::{parse_calib, read_calib, read_middlebury};
use fuzzyvox::io::octomap::{
    decode_bt, decode_scan_graph, encode_bt, parse_scan_log, read_bt, read_scan_graph,
    read_scan_log,
};
use fuzzyvox::io::pfm::{encode_pfm, parse_pfm};
use fuzzyvox::io::rgbd::{
    decode_depth_png_mm, parse_intrinsics_txt, parse_pose_txt, read_depth_png_mm, read_pose_txt,
};
use fuzzyvox::io::{parse_text_cloud, read_header, read_text_cloud};
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, AnyMap, Error, FormatError, FuzzyConfig, FuzzyMap, LogOddsConfig,
    LogOddsMap, VoxelKey,
};
use nalgebra::Point3;

/// A fresh folder for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-badfiles-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn fuzzy_map() -> FuzzyMap {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
    map.integrate_cloud(&room_scan(Point3::origin(), 300, 11), &Default::default())
        .unwrap();
    map
}

/// Rewrites a native map file's declared body length and CRC so that a deliberate change to
/// the header or body passes the container checks and reaches the decoder.
fn repair(bytes: &mut [u8]) {
    let body_len = (bytes.len() - 40) as u64;
    bytes[28..36].copy_from_slice(&body_len.to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..36]);
    crc.update(&bytes[40..]);
    let crc = crc.finalize();
    bytes[36..40].copy_from_slice(&crc.to_le_bytes());
}

fn format_reason(result: fuzzyvox::Result<impl std::fmt::Debug>) -> FormatError {
    match result {
        Err(Error::Format { reason, .. }) => reason,
        other => panic!("expected a format error, got {other:?}"),
    }
}

fn parse_line(result: fuzzyvox::Result<impl std::fmt::Debug>) -> usize {
    match result {
        Err(Error::Parse { line, .. }) => line,
        other => panic!("expected a parse error, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Native map files
// ---------------------------------------------------------------------------------------------

#[test]
fn map_of_another_kind_is_wrong_kind() {
    let fuzzy = fuzzy_map().to_bytes();
    let reason = format_reason(LogOddsMap::from_bytes(&fuzzy));
    assert!(
        matches!(reason, FormatError::WrongKind { expected: "logodds", ref found } if found == "fuzzy"),
        "{reason}"
    );
    let mut logodds = LogOddsMap::new(LogOddsConfig::new(0.2).unwrap()).unwrap();
    logodds
        .integrate_cloud(&room_scan(Point3::origin(), 50, 1), &Default::default())
        .unwrap();
    let reason = format_reason(AlphaCutMap::from_bytes(&logodds.to_bytes()));
    assert!(matches!(reason, FormatError::WrongKind { .. }), "{reason}");
    let reason = format_reason(FuzzyMap::from_bytes(&logodds.to_bytes()));
    assert!(matches!(reason, FormatError::WrongKind { .. }), "{reason}");
}

#[test]
fn map_of_a_newer_version_is_unsupported() {
    let mut bytes = fuzzy_map().to_bytes();
    bytes[8..10].copy_from_slice(&6u16.to_le_bytes());
    // Version is checked before the CRC, so no repair is needed; repair anyway to be sure it is
    // the version that is refused.
    repair(&mut bytes);
    assert_eq!(
        format_reason(FuzzyMap::from_bytes(&bytes)),
        FormatError::UnsupportedVersion(6)
    );
}

#[test]
fn map_whose_header_and_body_disagree_is_invalid() {
    let mut bytes = fuzzy_map().to_bytes();
    bytes[20..28].copy_from_slice(&0.25f64.to_le_bytes());
    repair(&mut bytes);
    assert!(matches!(
        format_reason(FuzzyMap::from_bytes(&bytes)),
        FormatError::Invalid(_)
    ));
}

#[test]
fn map_with_unknown_kind_or_operator_code_is_invalid() {
    for (at, code) in [(10, 9u8), (11, 77u8)] {
        let mut bytes = fuzzy_map().to_bytes();
        bytes[at] = code;
        repair(&mut bytes);
        assert!(
            matches!(
                format_reason(FuzzyMap::from_bytes(&bytes)),
                FormatError::Invalid(_)
            ),
            "byte {at} = {code}"
        );
    }
    // A valid code with an invalid parameter (Dombi with λ = -1).
    let mut bytes = fuzzy_map().to_bytes();
    bytes[11] = 9;
    bytes[12..20].copy_from_slice(&(-1.0f64).to_le_bytes());
    repair(&mut bytes);
    assert!(matches!(
        format_reason(FuzzyMap::from_bytes(&bytes)),
        FormatError::Invalid(_)
    ));
}

#[test]
fn map_body_of_garbage_behind_a_valid_checksum_is_invalid() {
    let mut bytes = fuzzy_map().to_bytes();
    for (i, b) in bytes[40..].iter_mut().enumerate() {
        *b = (i as u8).wrapping_mul(151) ^ 0x5a;
    }
    repair(&mut bytes);
    assert!(matches!(
        format_reason(FuzzyMap::from_bytes(&bytes)),
        FormatError::Invalid(_)
    ));
    // An empty map's body ends with its block count, 0. Declaring four billion blocks there
    // (with no bytes behind them) is refused without reserving memory for them.
    let mut bytes = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap())
        .unwrap()
        .to_bytes();
    assert_eq!(bytes.pop(), Some(0), "the block count ends an empty map");
    bytes.extend_from_slice(&[0xff, 0xff, 0xff, 0xff, 0x0f]);
    repair(&mut bytes);
    assert!(matches!(
        format_reason(FuzzyMap::from_bytes(&bytes)),
        FormatError::Invalid(_)
    ));
    // A body with nothing after the header.
    let mut bytes = fuzzy_map().to_bytes();
    bytes.truncate(40);
    repair(&mut bytes);
    assert!(matches!(
        format_reason(FuzzyMap::from_bytes(&bytes)),
        FormatError::Invalid(_)
    ));
}

#[test]
fn baseline_map_files_detect_truncation_and_bit_flips() {
    let scan = room_scan(Point3::origin(), 200, 4);
    let mut logodds = LogOddsMap::new(LogOddsConfig::new(0.2).unwrap()).unwrap();
    logodds.integrate_cloud(&scan, &Default::default()).unwrap();
    let mut alpha = AlphaCutMap::new(AlphaConfig::new(0.2).unwrap()).unwrap();
    alpha.integrate_cloud(&scan, &Default::default()).unwrap();
    for (name, bytes, load) in [
        (
            "logodds",
            logodds.to_bytes(),
            (|b: &[u8]| LogOddsMap::from_bytes(b).map(|_| ())) as fn(&[u8]) -> _,
        ),
        ("alpha", alpha.to_bytes(), |b: &[u8]| {
            AlphaCutMap::from_bytes(b).map(|_| ())
        }),
    ] {
        for len in [0, 7, 20, 40, bytes.len() / 3, bytes.len() - 1] {
            assert!(
                matches!(load(&bytes[..len]), Err(Error::Format { .. })),
                "{name} truncated to {len}"
            );
        }
        for at in (8..bytes.len()).step_by(bytes.len() / 61 + 1) {
            let mut flipped = bytes.clone();
            flipped[at] ^= 0x81;
            assert!(
                matches!(load(&flipped), Err(Error::Format { .. })),
                "{name}: flip at {at}"
            );
        }
    }
}

#[test]
fn empty_and_foreign_files_are_not_maps() {
    let dir = scratch("foreign-maps");
    let empty = write(&dir, "empty.fvx", b"");
    let bt = write(
        &dir,
        "tree.fvx",
        encode_bt(0.1, [(VoxelKey::new(0, 0, 0), true)]).unwrap(),
    );
    let folder = dir.join("folder.fvx");
    std::fs::create_dir_all(&folder).unwrap();
    for path in [&empty, &bt] {
        assert_eq!(
            format_reason(AnyMap::load(path)),
            FormatError::BadMagic,
            "{path:?}"
        );
        assert_eq!(format_reason(read_header(path)), FormatError::BadMagic);
    }
    assert!(matches!(AnyMap::load(&folder), Err(Error::Io { .. })));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_save_leaves_the_old_file_intact() {
    let dir = scratch("failed-save");
    let path = dir.join("map.fvx");
    let old = fuzzy_map();
    old.save(&path).unwrap();
    let before = std::fs::read(&path).unwrap();
    // Inject a failure mid-save: the temporary file's name is taken by a folder, so the save
    // cannot create it.
    let temporary = dir.join(format!(".map.fvx.tmp-{}", std::process::id()));
    std::fs::create_dir_all(temporary.join("occupied")).unwrap();
    let mut new = fuzzy_map();
    new.integrate_cloud(
        &room_scan(Point3::new(0.5, 0.0, 0.0), 100, 2),
        &Default::default(),
    )
    .unwrap();
    assert!(matches!(new.save(&path), Err(Error::Io { .. })));
    assert_eq!(std::fs::read(&path).unwrap(), before, "the old map changed");
    assert_eq!(FuzzyMap::load(&path).unwrap().to_bytes(), old.to_bytes());
    // Saving into a folder that does not exist creates nothing.
    let missing = dir.join("missing/map.fvx");
    assert!(matches!(new.save(&missing), Err(Error::Io { .. })));
    assert!(!missing.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// OctoMap .bt
// ---------------------------------------------------------------------------------------------

fn small_bt() -> Vec<u8> {
    let voxels = (0..6).map(|i| (VoxelKey::new(i, -i, 2 * i), i % 2 == 0));
    encode_bt(0.1, voxels).unwrap()
}

#[test]
fn bt_truncated_anywhere_is_an_error() {
    let bytes = small_bt();
    assert!(decode_bt(&bytes).is_ok());
    for len in 0..bytes.len() {
        assert!(decode_bt(&bytes[..len]).is_err(), "truncated to {len}");
    }
}

#[test]
fn bt_of_another_tree_type_is_wrong_kind() {
    let text = String::from_utf8_lossy(&small_bt()).into_owned();
    let colour = text.replacen("id OcTree", "id ColorOcTree", 1);
    assert!(matches!(
        decode_bt(colour.as_bytes()),
        Err(FormatError::WrongKind {
            expected: "OcTree",
            ..
        })
    ));
}

#[test]
fn bt_declaring_more_nodes_than_its_bytes_hold_is_refused_before_allocating() {
    let bytes = small_bt();
    let text = String::from_utf8_lossy(&bytes);
    let size_line = text.lines().find(|l| l.starts_with("size ")).unwrap();
    for size in ["99999999999", "18446744073709551615"] {
        let damaged = text.replacen(size_line, &format!("size {size}"), 1);
        let error = decode_bt(damaged.as_bytes()).unwrap_err();
        assert!(matches!(error, FormatError::Invalid(_)), "{error}");
    }
    let damaged = text.replacen(size_line, "size -4", 1);
    assert!(matches!(
        decode_bt(damaged.as_bytes()),
        Err(FormatError::Invalid(_))
    ));
}

#[test]
fn bt_with_a_bad_resolution_is_invalid() {
    let text = String::from_utf8_lossy(&small_bt()).into_owned();
    for res in ["-0.1", "0", "nan", "inf", "1e400", "ten"] {
        let damaged = text.replacen("res 0.1", &format!("res {res}"), 1);
        assert!(
            matches!(decode_bt(damaged.as_bytes()), Err(FormatError::Invalid(_))),
            "res {res}"
        );
    }
}

#[test]
fn bt_empty_foreign_and_missing_files_are_errors() {
    let dir = scratch("bt");
    let empty = write(&dir, "empty.bt", b"");
    let map = write(&dir, "map.bt", fuzzy_map().to_bytes());
    let png = write(&dir, "image.bt", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR");
    for path in [&empty, &map, &png] {
        assert!(
            matches!(format_reason(read_bt(path)), FormatError::Invalid(_)),
            "{path:?}"
        );
    }
    assert!(matches!(
        read_bt(&dir.join("missing.bt")),
        Err(Error::Io { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bt_bit_flips_give_an_error_or_another_consistent_tree() {
    // `.bt` has no checksum: a flipped bit in the tree data can describe another valid tree.
    // Either way the reader never panics, and a tree it accepts has the declared node count.
    let bytes = small_bt();
    let data_start = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    let mut accepted = 0;
    for at in 0..bytes.len() {
        for bit in [0x01, 0x02, 0x40, 0x80] {
            let mut flipped = bytes.clone();
            flipped[at] ^= bit;
            if let Ok(tree) = decode_bt(&flipped) {
                accepted += 1;
                let text = String::from_utf8_lossy(&flipped[..data_start.min(flipped.len())]);
                if let Some(size) = text
                    .split_whitespace()
                    .skip_while(|t| *t != "size")
                    .nth(1)
                    .and_then(|s| s.parse::<usize>().ok())
                {
                    assert_eq!(tree.node_count, size, "flip {bit:#x} at {at}");
                }
            }
        }
    }
    assert!(accepted < bytes.len() * 4, "every flip was accepted");
}

// ---------------------------------------------------------------------------------------------
// OctoMap .graph
// ---------------------------------------------------------------------------------------------

fn put_vector(out: &mut Vec<u8>, v: [f64; 3]) {
    out.extend(3i32.to_le_bytes());
    v.iter().for_each(|x| out.extend(x.to_le_bytes()));
}

/// One node (id 3) with `points` points at `translation`, and no edges.
fn graph(points: u32, translation: [f64; 3]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend(1u32.to_le_bytes());
    out.extend(points.to_le_bytes());
    for i in 0..points {
        put_vector(&mut out, [f64::from(i), 1.0, 0.5]);
    }
    put_vector(&mut out, translation);
    out.extend(4i32.to_le_bytes());
    [1.0f64, 0.0, 0.0, 0.0]
        .iter()
        .for_each(|x| out.extend(x.to_le_bytes()));
    out.extend(3u32.to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out
}

#[test]
fn graph_truncated_anywhere_is_an_error() {
    let bytes = graph(3, [0.0, 0.0, 1.0]);
    assert_eq!(decode_scan_graph(&bytes).unwrap().len(), 1);
    for len in 0..bytes.len() {
        assert!(decode_scan_graph(&bytes[..len]).is_err(), "length {len}");
    }
}

#[test]
fn graph_counts_beyond_the_file_are_refused_before_allocating() {
    // Node count u32::MAX in a 4-byte file.
    assert!(matches!(
        decode_scan_graph(&u32::MAX.to_le_bytes()),
        Err(FormatError::Invalid(_))
    ));
    // A node whose point count is u32::MAX.
    let mut bytes = graph(2, [0.0; 3]);
    bytes[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
    let error = decode_scan_graph(&bytes).unwrap_err();
    assert!(error.to_string().contains("cannot fit"), "{error}");
    // An edge count far beyond the bytes left.
    let mut bytes = graph(1, [0.0; 3]);
    let n = bytes.len();
    bytes[n - 4..].copy_from_slice(&0x0fff_ffffu32.to_le_bytes());
    assert!(decode_scan_graph(&bytes).is_err());
}

#[test]
fn graph_with_a_non_finite_pose_is_invalid() {
    for bad in [f64::NAN, f64::INFINITY] {
        let bytes = graph(1, [0.0, bad, 0.0]);
        assert!(matches!(
            decode_scan_graph(&bytes),
            Err(FormatError::Invalid(_))
        ));
    }
}

#[test]
fn graph_empty_and_foreign_files_are_errors() {
    let dir = scratch("graph");
    let empty = write(&dir, "empty.graph", b"");
    let text = write(&dir, "text.graph", "NODE 0 0 0 0 0 0\n1 2 3\n");
    let map = write(&dir, "map.graph", fuzzy_map().to_bytes());
    for path in [&empty, &text, &map] {
        assert!(
            matches!(read_scan_graph(path), Err(Error::Format { .. })),
            "{path:?}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// OctoMap .log and text clouds
// ---------------------------------------------------------------------------------------------

#[test]
fn log_with_a_non_finite_rotation_names_the_line() {
    for angle in ["nan", "inf", "-inf"] {
        let text = format!("NODE 0 0 0 0 0 0\n1 0 0\nNODE 1 0 0 0 {angle} 0\n");
        assert_eq!(parse_line(parse_scan_log(text.as_bytes())), 3, "{angle}");
    }
}

#[test]
fn log_empty_and_foreign_files_are_errors() {
    let dir = scratch("log");
    let empty = write(&dir, "empty.log", b"");
    assert!(matches!(read_scan_log(&empty), Err(Error::Empty(_))));
    let binary = write(&dir, "scan.log", graph(2, [0.0; 3]));
    assert_eq!(parse_line(read_scan_log(&binary)), 1);
    let png = write(&dir, "image.log", b"\x89PNG\r\n\x1a\n");
    assert_eq!(parse_line(read_scan_log(&png)), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn text_cloud_empty_file_is_an_empty_cloud() {
    // Documented: an empty file (or one of comments only) is a cloud of no points, and
    // integrating it changes nothing.
    for text in ["", "# x y z\n\n   \n"] {
        let cloud = parse_text_cloud(text.as_bytes(), Point3::origin()).unwrap();
        assert!(cloud.is_empty());
        let mut map = fuzzy_map();
        let before = map.to_bytes();
        let stats = map.integrate_cloud(&cloud, &Default::default()).unwrap();
        assert_eq!((stats.integrated, stats.skipped), (0, 0));
        assert_eq!(map.to_bytes(), before);
    }
}

#[test]
fn text_cloud_of_binary_bytes_is_a_parse_error_naming_the_line() {
    let dir = scratch("cloud");
    let mut bytes = b"1 2 3\n4 5 6\n".to_vec();
    bytes.extend_from_slice(&fuzzy_map().to_bytes()[..64]);
    let path = write(&dir, "cloud.xyz", &bytes);
    assert_eq!(parse_line(read_text_cloud(&path, Point3::origin())), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn text_cloud_with_a_nan_or_infinite_confidence_is_an_error() {
    for c in ["nan", "inf", "-0.5"] {
        let text = format!("1 2 3 0.5\n1 2 3 {c}\n");
        assert_eq!(
            parse_line(parse_text_cloud(text.as_bytes(), Point3::origin())),
            2
        );
    }
}

// ---------------------------------------------------------------------------------------------
// PFM
// ---------------------------------------------------------------------------------------------

#[test]
fn pfm_longer_than_declared_is_a_length_error() {
    let mut bytes = encode_pfm(2, 2, &[1.0; 4]).unwrap();
    bytes.extend_from_slice(&[0; 4]);
    assert!(matches!(
        parse_pfm(&bytes),
        Err(FormatError::Length {
            declared: 16,
            actual: 20
        })
    ));
}

#[test]
fn pfm_with_a_bad_scale_or_size_is_invalid() {
    for header in [
        "Pf\n1 1\nnan\n",
        "Pf\n1 1\ninf\n",
        "Pf\n-3 1\n-1\n",
        "Pf\n1 1.5\n-1\n",
        "Pf\n1\n",
        "Pf\n1 1\n",
    ] {
        let mut bytes = header.as_bytes().to_vec();
        bytes.extend_from_slice(&[0; 4]);
        assert!(
            matches!(parse_pfm(&bytes), Err(FormatError::Invalid(_))),
            "{header:?}"
        );
    }
}

#[test]
fn pfm_empty_and_foreign_files_are_errors() {
    assert!(matches!(parse_pfm(b""), Err(FormatError::Invalid(_))));
    // A map file's first "token" runs past the header's token limit before the magic is
    // compared: still a format error, never a read of the whole file as a header.
    assert!(matches!(
        parse_pfm(&fuzzy_map().to_bytes()),
        Err(FormatError::BadMagic | FormatError::Invalid(_))
    ));
    assert!(matches!(
        parse_pfm(b"P6\n2 2\n255\n"),
        Err(FormatError::BadMagic)
    ));
    assert!(matches!(
        parse_pfm(b"\x89PNG\r\n\x1a\n"),
        Err(FormatError::BadMagic)
    ));
}

// ---------------------------------------------------------------------------------------------
// PNG (RGB-D depth and stereo images)
// ---------------------------------------------------------------------------------------------

fn png_bytes(image: image::DynamicImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A PNG whose header claims `width × height` 16-bit gray pixels, with a tiny data chunk.
fn png_claiming(width: u32, height: u32) -> Vec<u8> {
    fn chunk(out: &mut Vec<u8>, kind: &[u8], body: &[u8]) {
        out.extend((body.len() as u32).to_be_bytes());
        let mut crc = crc32fast::Hasher::new();
        crc.update(kind);
        crc.update(body);
        out.extend(kind);
        out.extend(body);
        out.extend(crc.finalize().to_be_bytes());
    }
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut header = Vec::new();
    header.extend(width.to_be_bytes());
    header.extend(height.to_be_bytes());
    header.extend([16, 0, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &header);
    // zlib stream of a few zero bytes.
    chunk(
        &mut out,
        b"IDAT",
        &[0x78, 0x9c, 0x63, 0x60, 0x60, 0, 0, 0, 3, 0, 1],
    );
    chunk(&mut out, b"IEND", &[]);
    out
}

#[test]
fn depth_png_of_the_wrong_pixel_type_is_a_parse_error() {
    let eight = image::DynamicImage::ImageLuma8(image::GrayImage::new(4, 3));
    let rgb16 = image::DynamicImage::ImageRgb16(image::ImageBuffer::new(4, 3));
    for image in [eight, rgb16] {
        let message = match decode_depth_png_mm(&png_bytes(image)) {
            Err(Error::Parse { message, .. }) => message,
            other => panic!("{other:?}"),
        };
        assert!(message.contains("16-bit grayscale"), "{message}");
    }
}

#[test]
fn png_truncated_or_bit_flipped_is_a_parse_error() {
    let depth = image::DynamicImage::ImageLuma16(image::ImageBuffer::from_fn(8, 6, |x, y| {
        image::Luma([(1000 + 10 * x + 100 * y) as u16])
    }));
    let bytes = png_bytes(depth);
    assert_eq!(decode_depth_png_mm(&bytes).unwrap().depth.len(), 48);
    for len in [0, 8, 20, 33, bytes.len() / 2, bytes.len() - 13] {
        assert!(
            matches!(decode_depth_png_mm(&bytes[..len]), Err(Error::Parse { .. })),
            "truncated to {len}"
        );
        assert!(matches!(
            decode_gray_image(&bytes[..len]),
            Err(Error::Parse { .. })
        ));
    }
    // A flipped bit inside a chunk breaks its CRC.
    let mut flipped = bytes.clone();
    let inside_the_data = bytes.len() - 16;
    flipped[inside_the_data] ^= 0x10;
    assert!(matches!(
        decode_depth_png_mm(&flipped),
        Err(Error::Parse { .. })
    ));
}

#[test]
fn png_claiming_a_huge_size_is_refused_without_allocating_it() {
    // 100,000 × 100,000 16-bit pixels would be 20 GB.
    for (w, h) in [(100_000, 100_000), (1 << 30, 4), (0, 5)] {
        let bytes = png_claiming(w, h);
        assert!(
            matches!(decode_depth_png_mm(&bytes), Err(Error::Parse { .. })),
            "{w}×{h}"
        );
        assert!(matches!(
            decode_gray_image(&bytes),
            Err(Error::Parse { .. })
        ));
    }
}

#[test]
fn png_empty_foreign_and_missing_files_are_errors() {
    let dir = scratch("png");
    let pfm = write(&dir, "depth.png", encode_pfm(1, 1, &[1.0]).unwrap());
    let empty = write(&dir, "empty.png", b"");
    for path in [&pfm, &empty] {
        assert!(
            matches!(read_depth_png_mm(path), Err(Error::Parse { .. })),
            "{path:?}"
        );
    }
    assert!(matches!(
        read_depth_png_mm(&dir.join("missing.png")),
        Err(Error::Io { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// Middlebury calib.txt and folders
// ---------------------------------------------------------------------------------------------

const CALIB: &str = "cam0=[40 0 15.5; 0 40 11.5; 0 0 1]\ncam1=[40 0 15.5; 0 40 11.5; 0 0 1]\n\
                     doffs=0\nbaseline=100\nwidth=32\nheight=24\nndisp=16\n";

#[test]
fn calib_missing_a_key_is_a_parse_error() {
    assert!(parse_calib(CALIB.as_bytes()).is_ok());
    for key in [
        "cam0", "cam1", "doffs", "baseline", "width", "height", "ndisp",
    ] {
        let text: String = CALIB
            .lines()
            .filter(|l| !l.starts_with(&format!("{key}=")))
            .map(|l| format!("{l}\n"))
            .collect();
        let message = match parse_calib(text.as_bytes()) {
            Err(Error::Parse { message, .. }) => message,
            other => panic!("{key}: {other:?}"),
        };
        assert!(message.contains(key), "{message}");
    }
}

#[test]
fn calib_with_bad_numbers_names_the_line() {
    for (from, to, line) in [
        ("doffs=0", "doffs=nan", 3),
        ("baseline=100", "baseline=inf", 4),
        ("width=32", "width=-5", 5),
        ("height=24", "height=2.5", 6),
        ("ndisp=16", "ndisp=1e20", 7),
        (
            "cam0=[40 0 15.5; 0 40 11.5; 0 0 1]",
            "cam0=[40 0 15.5; 0 40 11.5; 0 0]",
            1,
        ),
        (
            "cam1=[40 0 15.5; 0 40 11.5; 0 0 1]",
            "cam1=[40 0 x; 0 40 11.5; 0 0 1]",
            2,
        ),
    ] {
        let text = CALIB.replacen(from, to, 1);
        assert_eq!(parse_line(parse_calib(text.as_bytes())), line, "{to}");
    }
}

#[test]
fn calib_with_a_zero_focal_length_has_no_geometry() {
    let text = CALIB.replacen("cam0=[40 0", "cam0=[0 0", 1);
    let calib = parse_calib(text.as_bytes()).unwrap();
    assert!(matches!(
        calib.geometry(),
        Err(Error::InvalidParameter { name: "fx", .. })
    ));
    let text = CALIB.replacen("width=32", "width=0", 1);
    let calib = parse_calib(text.as_bytes()).unwrap();
    assert!(matches!(calib.geometry(), Err(Error::Empty(_))));
}

#[test]
fn calib_binary_and_missing_files_are_errors() {
    let dir = scratch("calib");
    let binary = write(&dir, "calib.txt", fuzzy_map().to_bytes());
    assert!(matches!(read_calib(&binary), Err(Error::Parse { .. })));
    assert!(matches!(
        read_calib(&dir.join("none.txt")),
        Err(Error::Io { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn middlebury_folder_with_images_of_the_wrong_size_is_a_size_mismatch() {
    let dir = scratch("middlebury");
    write(&dir, "calib.txt", CALIB);
    let image = |w, h| png_bytes(image::DynamicImage::ImageLuma8(image::GrayImage::new(w, h)));
    write(&dir, "im0.png", image(32, 24));
    write(&dir, "im1.png", image(31, 24));
    assert!(matches!(
        read_middlebury(&dir),
        Err(Error::SizeMismatch {
            what: "im1.png pixels",
            ..
        })
    ));
    write(&dir, "im1.png", image(32, 24));
    write(&dir, "disp0GT.pfm", encode_pfm(2, 2, &[1.0; 4]).unwrap());
    assert!(matches!(
        read_middlebury(&dir),
        Err(Error::SizeMismatch {
            what: "disp0GT.pfm pixels",
            ..
        })
    ));
    write(&dir, "disp0GT.pfm", b"Pf\n32 24\n-1\n");
    assert!(matches!(read_middlebury(&dir), Err(Error::Format { .. })));
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// RGB-D pose and intrinsics text
// ---------------------------------------------------------------------------------------------

const POSE: &str = "1 0 0 0.5\n0 1 0 -0.25\n0 0 1 1\n0 0 0 1\n";

#[test]
fn pose_that_is_not_a_rigid_transform_is_an_invalid_pose() {
    assert!(parse_pose_txt(POSE.as_bytes()).is_ok());
    for (name, text) in [
        ("non-finite", POSE.replacen("0.5", "nan", 1)),
        ("-inf", POSE.replacen("-0.25", "-inf", 1)),
        ("scaled", POSE.replacen("1 0 0 0.5", "2 0 0 0.5", 1)),
        ("sheared", POSE.replacen("0 1 0 -0.25", "0.3 1 0 -0.25", 1)),
        ("reflection", POSE.replacen("0 0 1 1", "0 0 -1 1", 1)),
        ("last row", POSE.replacen("0 0 0 1", "0 0 1 1", 1)),
        ("projective", POSE.replacen("0 0 0 1", "0 0 0 2", 1)),
    ] {
        assert!(
            matches!(parse_pose_txt(text.as_bytes()), Err(Error::InvalidPose(_))),
            "{name}"
        );
    }
}

#[test]
fn pose_with_the_wrong_count_of_numbers_is_a_parse_error() {
    let short = POSE.replacen(" 1\n", "\n", 1);
    let long = format!("{POSE}7\n");
    for text in ["", short.as_str(), long.as_str(), "1 0 0 0\n0 1 0 x\n"] {
        assert!(
            matches!(parse_pose_txt(text.as_bytes()), Err(Error::Parse { .. })),
            "{text:?}"
        );
    }
    let dir = scratch("pose");
    let binary = write(&dir, "frame.pose.txt", b"\xff\xfe1 0 0 0\n");
    assert_eq!(parse_line(read_pose_txt(&binary)), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn intrinsics_with_skew_or_bad_focal_lengths_are_errors() {
    let k = "585 0 320\n0 585 240\n0 0 1\n";
    assert!(parse_intrinsics_txt(k.as_bytes(), 640, 480).is_ok());
    for skew in ["585 3 320", "585 nan 320"] {
        let text = k.replacen("585 0 320", skew, 1);
        assert!(
            matches!(
                parse_intrinsics_txt(text.as_bytes(), 640, 480),
                Err(Error::Parse { .. })
            ),
            "{skew}"
        );
    }
    let zero = k.replacen("585 0 320", "0 0 320", 1);
    assert!(matches!(
        parse_intrinsics_txt(zero.as_bytes(), 640, 480),
        Err(Error::InvalidParameter { name: "fx", .. })
    ));
    let nan = k.replacen("0 585 240", "0 nan 240", 1);
    assert!(matches!(
        parse_intrinsics_txt(nan.as_bytes(), 640, 480),
        Err(Error::NonFinite { what: "fy", .. })
    ));
    assert!(matches!(
        parse_intrinsics_txt(k.as_bytes(), 0, 480),
        Err(Error::Empty(_))
    ));
    assert!(matches!(
        parse_intrinsics_txt(b"585 0 320\n0 585 240\n", 640, 480),
        Err(Error::Parse { .. })
    ));
}

// ---------------------------------------------------------------------------------------------
// Every text format, cut or flipped anywhere
// ---------------------------------------------------------------------------------------------

/// Whether an error is one a text reader may give for damaged text.
fn text_error(error: &Error) -> bool {
    matches!(
        error,
        Error::Parse { .. }
            | Error::Empty(_)
            | Error::InvalidPose(_)
            | Error::InvalidParameter { .. }
            | Error::NonFinite { .. }
            | Error::InvalidConfidence { .. }
    )
}

#[test]
fn text_files_cut_or_flipped_anywhere_are_errors_or_still_valid() {
    // Text formats have no checksum: a cut at a line end, or a flipped digit, can leave a valid
    // file. Whatever the damage, the reader returns a value or one of the typed text errors.
    let log = "# log\nNODE 1 2 3 0.1 -0.2 0.3\n1 0 0\n  nan 0 1\nNODE 0 0 0 0 0 0\n2 2 2\n";
    let cloud = "# x y z c\n1 2 3 0.5\n4,5,6,1\n\n-1.5e2 0 2 0.25\n";
    let k = "585 0 320\n0 585 240\n0 0 1\n";
    type Reader = fn(&[u8]) -> Result<(), Error>;
    let readers: [(&str, &str, Reader); 5] = [
        ("log", log, |b| parse_scan_log(b).map(|_| ())),
        ("cloud", cloud, |b| {
            parse_text_cloud(b, Point3::origin()).map(|_| ())
        }),
        ("calib", CALIB, |b| parse_calib(b).map(|_| ())),
        ("pose", POSE, |b| parse_pose_txt(b).map(|_| ())),
        ("intrinsics", k, |b| {
            parse_intrinsics_txt(b, 640, 480).map(|_| ())
        }),
    ];
    for (name, text, read) in readers {
        let bytes = text.as_bytes();
        assert!(read(bytes).is_ok(), "{name}: the undamaged file reads");
        let mut errors = 0;
        for len in 0..bytes.len() {
            if let Err(error) = read(&bytes[..len]) {
                assert!(text_error(&error), "{name} cut to {len}: {error:?}");
                errors += 1;
            }
        }
        for at in 0..bytes.len() {
            for bit in [0x01, 0x08, 0x20, 0x80] {
                let mut flipped = bytes.to_vec();
                flipped[at] ^= bit;
                if let Err(error) = read(&flipped) {
                    assert!(
                        text_error(&error),
                        "{name}: flip {bit:#x} at {at}: {error:?}"
                    );
                    errors += 1;
                }
            }
        }
        assert!(errors > bytes.len(), "{name}: damage went unnoticed");
    }
}

#[test]
fn graph_and_pfm_bit_flips_give_an_error_or_a_consistent_result() {
    // Neither format has a checksum: a flipped bit in a coordinate or a sample is another valid
    // file. A flipped count, tag or header is an error; nothing panics or allocates wildly.
    let graph_bytes = graph(3, [0.5, -1.0, 2.0]);
    let mut refused = 0;
    for at in 0..graph_bytes.len() {
        for bit in [0x01, 0x10, 0x80] {
            let mut flipped = graph_bytes.clone();
            flipped[at] ^= bit;
            match decode_scan_graph(&flipped) {
                Ok(nodes) => {
                    for node in nodes {
                        assert!(node.to_cloud().is_ok(), "flip {bit:#x} at {at}");
                    }
                }
                Err(_) => refused += 1,
            }
        }
    }
    assert!(refused > 0);
    let pfm = encode_pfm(3, 2, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    let header_len = pfm.len() - 24;
    for at in 0..pfm.len() {
        for bit in [0x01, 0x10, 0x80] {
            let mut flipped = pfm.clone();
            flipped[at] ^= bit;
            match parse_pfm(&flipped) {
                Ok(image) => {
                    assert_eq!(
                        image.data.len(),
                        image.width as usize * image.height as usize
                    );
                }
                Err(_) => assert!(at < header_len, "a flipped sample at {at} was refused"),
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Inputs that never end, and files far larger than their header says
// ---------------------------------------------------------------------------------------------

#[test]
fn endless_inputs_are_errors_not_endless_reads() {
    let zero = Path::new("/dev/zero");
    if !zero.exists() {
        eprintln!("SKIPPED endless_inputs_are_errors_not_endless_reads: no /dev/zero here");
        return;
    }
    // Each of these would read forever (and exhaust memory) if it trusted the input to end.
    assert_eq!(format_reason(AnyMap::load(zero)), FormatError::BadMagic);
    assert_eq!(format_reason(read_header(zero)), FormatError::BadMagic);
    assert_eq!(parse_line(read_text_cloud(zero, Point3::origin())), 1);
    assert_eq!(parse_line(read_scan_log(zero)), 1);
    assert!(matches!(
        read_calib(zero),
        Err(Error::Parse { line: 0, .. })
    ));
    assert!(matches!(
        read_pose_txt(zero),
        Err(Error::Parse { line: 0, .. })
    ));
    for result in [
        read_bt(zero).map(|_| ()),
        read_scan_graph(zero).map(|_| ()),
        fuzzyvox::io::pfm::read_pfm(zero).map(|_| ()),
    ] {
        assert!(matches!(result, Err(Error::Io { .. })), "{result:?}");
    }
    assert!(matches!(read_depth_png_mm(zero), Err(Error::Parse { .. })));
}

#[test]
fn a_map_file_larger_than_its_header_says_is_refused_before_reading_it() {
    // A valid header declaring this map's body, then a gigabyte (a sparse file: no disk used).
    let dir = scratch("huge-map");
    let path = dir.join("map.fvx");
    let bytes = fuzzy_map().to_bytes();
    std::fs::write(&path, &bytes).unwrap();
    let file = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
    file.set_len(1 << 30).unwrap();
    drop(file);
    let declared = (bytes.len() - 40) as u64;
    let started = std::time::Instant::now();
    let reason = format_reason(FuzzyMap::load(&path));
    assert_eq!(
        reason,
        FormatError::Length {
            declared,
            actual: (1 << 30) - 40
        }
    );
    assert_eq!(format_reason(read_header(&path)), reason);
    let seconds = started.elapsed().as_secs_f64();
    assert!(seconds < 1.0, "took {seconds:.2} s: the body was read");
    // A text line of more than a megabyte is refused at the limit.
    let long = write(&dir, "long.xyz", vec![b'1'; (1 << 20) + 10]);
    let message = match read_text_cloud(&long, Point3::origin()) {
        Err(Error::Parse {
            line: 1, message, ..
        }) => message,
        other => panic!("{other:?}"),
    };
    assert!(message.contains("line longer"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
}
