//! A headless Chromium for the tests of the viewer page and the report.
//!
//! The browser is `FUZZYVOX_CHROMIUM` when set, else the first of `chromium`,
//! `chromium-browser`, `google-chrome` on the `PATH`. Without one, a test prints that it skipped;
//! with `FUZZYVOX_REQUIRE_BROWSER=1` (which `.ci/run` sets after installing Debian's `chromium`)
//! a missing browser fails the test instead. WebGL2 runs on SwiftShader, Chromium's software
//! renderer, so no GPU is needed.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The longest a page may take before the browser is killed and the test fails.
const TIMEOUT: Duration = Duration::from_secs(120);

/// A browser found on this machine.
pub struct Browser {
    program: PathBuf,
}

/// What one headless run of a page left behind.
pub struct PageRun {
    /// `--dump-dom`: the page's DOM after load (empty for a screenshot run).
    pub dom: String,
    /// The console messages the page logged, one per line, as the browser reported them.
    pub console: Vec<String>,
}

impl PageRun {
    /// The value of `data-NAME` on the page's `<body>`.
    pub fn body_data(&self, name: &str) -> Option<String> {
        let start = self.dom.find("<body")?;
        let tag = &self.dom[start..start + self.dom[start..].find('>')?];
        let key = format!("data-{name}=\"");
        let at = tag.find(&key)? + key.len();
        Some(tag[at..at + tag[at..].find('"')?].to_string())
    }

    /// Console messages that report an error: an uncaught exception, a failed load, or the
    /// viewer's own error message.
    pub fn console_errors(&self) -> Vec<&String> {
        self.console
            .iter()
            .filter(|line| {
                ["Uncaught", "Failed to load", "Not allowed to load", "error"]
                    .iter()
                    .any(|word| line.contains(word))
            })
            .collect()
    }
}

impl Browser {
    /// The browser, or `None` after printing that `test` skipped.
    pub fn find(test: &str) -> Option<Browser> {
        let candidates: Vec<PathBuf> = match std::env::var_os("FUZZYVOX_CHROMIUM") {
            Some(program) => vec![PathBuf::from(program)],
            None => ["chromium", "chromium-browser", "google-chrome"]
                .iter()
                .map(PathBuf::from)
                .collect(),
        };
        for program in candidates {
            let works = Command::new(&program)
                .arg("--version")
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .is_ok_and(|status| status.success());
            if works {
                return Some(Browser { program });
            }
        }
        let required = std::env::var("FUZZYVOX_REQUIRE_BROWSER").is_ok_and(|v| v == "1");
        assert!(
            !required,
            "FUZZYVOX_REQUIRE_BROWSER=1 but no chromium was found (set FUZZYVOX_CHROMIUM)"
        );
        eprintln!(
            "SKIPPED {test}: no chromium on the PATH (install Debian's chromium, or set \
             FUZZYVOX_CHROMIUM; FUZZYVOX_REQUIRE_BROWSER=1 makes this a failure)"
        );
        None
    }

    /// Opens `page` (a file, with an optional `#fragment`) and returns its DOM after load.
    pub fn dump_dom(&self, page: &Path, fragment: &str) -> PageRun {
        self.run(page, fragment, &["--dump-dom".to_string()], "dom")
    }

    /// Opens `page` in a `width` × `height` window and writes a PNG screenshot to `png`.
    pub fn screenshot(
        &self,
        page: &Path,
        fragment: &str,
        (width, height): (u32, u32),
        png: &Path,
    ) -> PageRun {
        let _ = std::fs::remove_file(png);
        let run = self.run(
            page,
            fragment,
            &[
                format!("--window-size={width},{height}"),
                format!("--screenshot={}", png.display()),
            ],
            "shot",
        );
        assert!(
            png.is_file(),
            "chromium wrote no screenshot of {}",
            page.display()
        );
        run
    }

    /// Opens a viewer page written by `fuzzyvox view`, checks that it reports ready with no
    /// console error, takes a `1000 × 700` screenshot to `png` and returns its number of
    /// distinct colours.
    pub fn check_viewer_page(&self, page: &Path, fragment: &str, png: &Path) -> usize {
        let run = self.dump_dom(page, fragment);
        let shown = || format!("{}: {:#?}", page.display(), run.console);
        assert_eq!(
            run.body_data("status").as_deref(),
            Some("ready"),
            "{}",
            shown()
        );
        assert_eq!(run.body_data("errors").as_deref(), Some("0"), "{}", shown());
        assert!(run.console_errors().is_empty(), "{}", shown());
        assert!(
            run.console
                .iter()
                .any(|line| line.contains("fuzzyvox-view ready")),
            "the page did not log that it is ready: {}",
            shown()
        );
        let shot = self.screenshot(page, fragment, (1000, 700), png);
        assert!(shot.console_errors().is_empty(), "{:#?}", shot.console);
        distinct_colors(png)
    }

    fn run(&self, page: &Path, fragment: &str, extra: &[String], tag: &str) -> PageRun {
        let page = page.canonicalize().expect("the page exists");
        let url = format!("file://{}{fragment}", page.display());
        // A profile folder of its own, so that tests running at once do not share one.
        let profile = std::env::temp_dir().join(format!(
            "fuzzyvox-chromium-{}-{tag}-{}",
            std::process::id(),
            page.file_name().unwrap().to_string_lossy()
        ));
        let mut child = Command::new(&self.program)
            .args([
                "--headless=new",
                "--no-sandbox",
                "--disable-gpu-sandbox",
                "--no-first-run",
                "--disable-extensions",
                "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader",
                "--enable-logging=stderr",
                "--v=0",
                "--virtual-time-budget=10000",
            ])
            .arg(format!("--user-data-dir={}", profile.display()))
            .args(extra)
            .arg(&url)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starting chromium");
        // Read both pipes on threads so that a full pipe never stalls the browser.
        let mut stdout = child.stdout.take().unwrap();
        let mut stderr = child.stderr.take().unwrap();
        let out = std::thread::spawn(move || {
            let mut text = String::new();
            std::io::Read::read_to_string(&mut stdout, &mut text).ok();
            text
        });
        let err = std::thread::spawn(move || {
            let mut text = String::new();
            std::io::Read::read_to_string(&mut stderr, &mut text).ok();
            text
        });
        let started = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().expect("waiting for chromium") {
                break status;
            }
            if started.elapsed() > TIMEOUT {
                let _ = child.kill();
                let _ = child.wait();
                panic!("chromium did not finish {url} within {TIMEOUT:?}");
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        let dom = out.join().unwrap();
        let log = err.join().unwrap();
        let _ = std::fs::remove_dir_all(&profile);
        assert!(status.success(), "chromium failed on {url}: {log}");
        let console = log
            .lines()
            .filter(|line| line.contains(":CONSOLE"))
            .map(str::to_string)
            .collect();
        PageRun { dom, console }
    }
}

/// The number of distinct colours in a PNG image.
pub fn distinct_colors(png: &Path) -> usize {
    let image = image::open(png).expect("a readable screenshot").to_rgb8();
    let mut colors: Vec<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    colors.sort_unstable();
    colors.dedup();
    colors.len()
}

/// The fraction of pixels that differ between two images of the same size.
pub fn changed_fraction(a: &Path, b: &Path) -> f64 {
    let a = image::open(a).expect("a readable screenshot").to_rgb8();
    let b = image::open(b).expect("a readable screenshot").to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions(), "screenshots differ in size");
    let changed = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    changed as f64 / (a.width() * a.height()) as f64
}
