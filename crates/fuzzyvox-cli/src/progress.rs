//! Progress bars and log lines on standard error, shared by every command.
//!
//! Log lines go through `tracing` (`-v` for info, `-vv` for debug, `-vvv` for trace; warnings
//! and errors always). Progress bars come from [`bar`] and are hidden when standard error is not
//! a terminal or when the command prints JSON, so scripts and pipes see clean output. While a
//! bar is drawn, log lines are printed above it instead of through it.
//!
//! In a command (`run(args)`), with `args.json` its `--json` flag:
//!
//! ```text
//! let bar = super::progress::bar(pairs.len() as u64, "matching", args.json);
//! for pair in &pairs {
//!     // ... the work ...
//!     tracing::debug!("pair {}: {} pixels", pair.id, pixels); // shown with -vv
//!     bar.inc(1);
//! }
//! bar.finish_and_clear();
//! tracing::info!("{} pairs matched", pairs.len()); // shown with -v
//! ```
//!
//! `spinner(what, args.json)` does the same for one step of unknown length (loading a map);
//! change its label with `set_message` between steps. `init_logging` is called once, in
//! `cli::run`, from the global `-v` count.

use std::io::{IsTerminal, Write};
use std::sync::OnceLock;
use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressFinish, ProgressStyle};
use tracing::Level;

/// Every visible bar belongs to this one group, so that log lines can suspend them all.
fn bars() -> &'static MultiProgress {
    static BARS: OnceLock<MultiProgress> = OnceLock::new();
    BARS.get_or_init(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr()))
}

/// Starts logging to standard error at the level that `-v` flags ask for (`verbosity` is their
/// count): warnings by default, info, debug, trace.
pub fn init_logging(verbosity: u8) {
    let level = match verbosity {
        0 => Level::WARN,
        1 => Level::INFO,
        2 => Level::DEBUG,
        _ => Level::TRACE,
    };
    // `try_init` fails only when a subscriber exists already (a second call): keep that one.
    let _ = tracing_subscriber::fmt()
        .with_max_level(level)
        .with_target(false)
        .with_ansi(std::io::stderr().is_terminal())
        .with_writer(|| LogWriter)
        .try_init();
}

/// Writes log lines to standard error above any progress bar.
struct LogWriter;

impl Write for LogWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        bars().suspend(|| std::io::stderr().write_all(buf))?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        std::io::stderr().flush()
    }
}

/// A progress bar over `total` steps labelled `what`, or a hidden one (every call on it does
/// nothing) when `quiet` is set (pass the command's `--json`) or standard error is not a
/// terminal. Call `inc(1)` per step and `finish_and_clear()` at the end (dropping the bar, e.g.
/// when an error returns early, clears it too).
pub fn bar(total: u64, what: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template(
        "{msg:>14} [{bar:30}] {pos}/{len} ({elapsed}, about {eta} left)",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    // Cleared also when dropped early, by an error: the error message then stands alone.
    let bar = bars().add(
        ProgressBar::new(total)
            .with_style(style)
            .with_finish(ProgressFinish::AndClear),
    );
    bar.set_message(what.to_string());
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

/// A spinner labelled `what` for work of unknown length, hidden like [`bar`].
pub fn spinner(what: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
        .unwrap_or_else(|_| ProgressStyle::default_spinner());
    let spinner = bars().add(
        ProgressBar::new_spinner()
            .with_style(style)
            .with_finish(ProgressFinish::AndClear),
    );
    spinner.set_message(what.to_string());
    spinner.enable_steady_tick(Duration::from_millis(120));
    spinner
}
