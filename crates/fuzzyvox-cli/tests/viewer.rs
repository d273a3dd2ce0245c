//! `fuzzyvox view`: the page it writes, opened in a headless Chromium as a user would open it,
//! and its errors on bad input.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::browser::{Browser, changed_fraction};
use common::{fuzzyvox, json, room_scan};
use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, VoxelMapMut};
use nalgebra::Point3;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fuzzyvox-viewer-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fuzzy map of a room (walls at ±4 m) scanned from two places, saved in `dir`.
fn room_map(dir: &Path) -> PathBuf {
    let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
    for (i, origin) in [Point3::new(0.0, 0.0, 1.0), Point3::new(1.5, -1.0, 0.5)]
        .into_iter()
        .enumerate()
    {
        map.integrate_cloud(
            &room_scan(origin, 20_000, i as u64),
            &IntegrationOptions::default(),
        )
        .unwrap();
    }
    let path = dir.join("room.fvx");
    map.save(&path).unwrap();
    path
}

/// A planned flight through the room, in the `{"paths": [...]}` form.
fn flights(dir: &Path) -> PathBuf {
    let path = dir.join("flights.json");
    std::fs::write(
        &path,
        r#"{"paths": [{"name": "across", "ok": true,
            "points": [[-2.5, -2.5, 1.0], [0.0, 0.5, 1.2], [2.5, 2.5, 1.0]]}]}"#,
    )
    .unwrap();
    path
}

#[test]
fn the_page_opens_in_a_browser_draws_the_map_and_toggles_classes() {
    let dir = scratch("page");
    let map = room_map(&dir);
    let page = dir.join("room.html");
    let written = json(&fuzzyvox(&[
        "view",
        map.to_str().unwrap(),
        "--out",
        page.to_str().unwrap(),
        "--flights",
        flights(&dir).to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(written["out"], page.to_str().unwrap());
    assert!(written["voxels"]["occupied"].as_u64().unwrap() > 1000);
    let html = std::fs::read_to_string(&page).unwrap();
    // Self-contained: nothing is fetched from anywhere.
    for remote in ["http://", "https://", "<script src", "<link "] {
        assert!(!html.contains(remote), "the page refers to {remote}");
    }

    let Some(browser) = Browser::find("the_page_opens_in_a_browser") else {
        return;
    };
    let shot = dir.join("shot.png");
    let colors = browser.check_viewer_page(&page, "", &shot);
    assert!(colors >= 20, "the screenshot has only {colors} colours");

    // Hiding the occupied voxels, or colouring by height, changes the picture.
    let hidden = dir.join("hidden.png");
    browser.screenshot(&page, "#hide=occupied", (1000, 700), &hidden);
    let changed = changed_fraction(&shot, &hidden);
    assert!(
        changed > 0.02,
        "hiding occupied voxels changed {changed:.4} of the pixels"
    );
    let height = dir.join("height.png");
    browser.screenshot(&page, "#color=height", (1000, 700), &height);
    let changed = changed_fraction(&shot, &height);
    assert!(
        changed > 0.02,
        "colouring by height changed {changed:.4} of the pixels"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_gives_a_clear_error_and_no_page() {
    let dir = scratch("bad");
    let page = dir.join("out.html");
    let map = room_map(&dir);
    let damaged = dir.join("damaged.fvx");
    std::fs::write(&damaged, b"not a map at all").unwrap();
    let short = dir.join("short.json");
    std::fs::write(&short, r#"{"paths": [{"points": [[0, 0]]}]}"#).unwrap();
    let nan = dir.join("nan.json");
    std::fs::write(&nan, r#"[[0, 0, 0], [1, "NaN", 0]]"#).unwrap();
    let missing = dir.join("nope.fvx");
    let cases: [(&Path, Option<&Path>, &str); 4] = [
        (&missing, None, "nope.fvx"),
        (&damaged, None, "damaged.fvx"),
        (&map, Some(&short), "short.json"),
        (&map, Some(&nan), "nan.json"),
    ];
    for (map, flights, named) in cases {
        let mut args = vec![
            "view",
            map.to_str().unwrap(),
            "--out",
            page.to_str().unwrap(),
        ];
        if let Some(flights) = flights {
            args.extend(["--flights", flights.to_str().unwrap()]);
        }
        let run = fuzzyvox(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{named}: expected a failure");
        assert!(stderr.contains(named), "{named}: {stderr}");
        assert!(!stderr.contains("panicked"), "{named}: {stderr}");
        assert!(!page.exists(), "{named}: a failed view left a page behind");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
