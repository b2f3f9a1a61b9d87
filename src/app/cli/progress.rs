//! Progress on stderr for work that takes a while: a bar or a spinner on a terminal; where
//! stderr is not a terminal (a batch job, a pipe, a log file), plain lines — a counted
//! job every tenth of the way with the time left, a job of unknown length every so often
//! — once it has run for longer than [`QUIET_FOR`], so that quick commands stay silent
//! in scripts; nothing at all with `--quiet`.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, mpsc};
use std::time::{Duration, Instant};

/// How long work runs before a log line is written where stderr is not a terminal.
const QUIET_FOR: Duration = Duration::from_secs(2);

/// How often a job of unknown length says it is still working, in log lines.
const BUSY_EVERY: Duration = Duration::from_secs(30);

/// Whether progress goes to a terminal (`Some(true)`: a bar or spinner), to log lines
/// (`Some(false)`), or nowhere (--quiet, `None`).
pub(crate) fn shown(quiet: bool) -> Option<bool> {
    (!quiet).then(|| std::io::stderr().is_terminal())
}

/// Progress over a counted job of `len` items.
pub(crate) struct Progress {
    bar: indicatif::ProgressBar,
    lines: Option<Lines>,
}

/// The log-line form of [`Progress`].
struct Lines {
    what: String,
    total: u64,
    start: Instant,
    done: AtomicU64,
    /// The next tenth of the way (1–9) that may write a line, and when the last line
    /// was written (since `start`).
    next: Mutex<(u64, Option<Duration>)>,
}

impl Progress {
    /// Progress of `what` (e.g. "map") over `len` items.
    pub(crate) fn counted(what: &str, len: usize, quiet: bool) -> Self {
        let len = len as u64;
        match shown(quiet) {
            Some(true) => {
                let bar = indicatif::ProgressBar::new(len);
                bar.set_style(
                    indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len}, {eta} left")
                        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
                );
                Self { bar, lines: None }
            }
            Some(false) => Self {
                bar: indicatif::ProgressBar::hidden(),
                lines: Some(Lines {
                    what: what.to_string(),
                    total: len.max(1),
                    start: Instant::now(),
                    done: AtomicU64::new(0),
                    next: Mutex::new((1, None)),
                }),
            },
            None => Self {
                bar: indicatif::ProgressBar::hidden(),
                lines: None,
            },
        }
    }

    /// `n` more items done.
    pub(crate) fn inc(&self, n: u64) {
        self.bar.inc(n);
        if let Some(lines) = &self.lines {
            let done = lines.done.fetch_add(n, Ordering::Relaxed) + n;
            lines.reached(done);
        }
    }

    /// `done` items done in all.
    pub(crate) fn set_position(&self, done: u64) {
        self.bar.set_position(done);
        if let Some(lines) = &self.lines {
            lines.done.fetch_max(done, Ordering::Relaxed);
            lines.reached(done);
        }
    }

    /// The job ended: the bar cleared; in log lines, the time it took, if a line was
    /// written before.
    pub(crate) fn finish_and_clear(&self) {
        self.bar.finish_and_clear();
        if let Some(lines) = &self.lines
            && lines.next.lock().is_ok_and(|next| next.1.is_some())
        {
            let done = lines.done.load(Ordering::Relaxed).min(lines.total);
            eprintln!(
                "{}: {done}/{} done in {:.1} s",
                lines.what,
                lines.total,
                lines.start.elapsed().as_secs_f64()
            );
        }
    }
}

impl Lines {
    /// Write a line where `done` passes the next tenth of the way, once past [`QUIET_FOR`]
    /// and [`QUIET_FOR`] after the last line.
    fn reached(&self, done: u64) {
        let tenth = (done.min(self.total) * 10 / self.total).min(9);
        let Ok(mut next) = self.next.lock() else {
            return;
        };
        let elapsed = self.start.elapsed();
        let since = next.1.map_or(elapsed, |at| elapsed.saturating_sub(at));
        if tenth < next.0 || elapsed < QUIET_FOR || since < QUIET_FOR {
            return;
        }
        *next = (tenth + 1, Some(elapsed));
        drop(next);
        let fraction = done.min(self.total) as f64 / self.total as f64;
        let left = elapsed.as_secs_f64() * (1.0 - fraction) / fraction.max(1e-9);
        eprintln!(
            "{}: {done}/{} ({:.0} %) in {:.1} s, about {left:.0} s left",
            self.what,
            self.total,
            100.0 * fraction,
            elapsed.as_secs_f64()
        );
    }
}

/// A spinner on stderr saying `what`, ticking every half second.
pub(crate) fn spinner(what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_message(what.to_string());
    bar.enable_steady_tick(Duration::from_millis(500));
    bar
}

/// Progress of a job of unknown length: a spinner saying what runs on a terminal; in log
/// lines, that it still runs, first after [`QUIET_FOR`] and then every [`BUSY_EVERY`].
pub(crate) struct Busy {
    bar: indicatif::ProgressBar,
    stop: Option<(mpsc::Sender<()>, std::thread::JoinHandle<()>)>,
}

impl Busy {
    /// `what` runs (e.g. "tap: averaging the state over a thermal record").
    pub(crate) fn new(what: &str, quiet: bool) -> Self {
        match shown(quiet) {
            Some(true) => Self {
                bar: spinner(what),
                stop: None,
            },
            Some(false) => {
                let (tell, told) = mpsc::channel::<()>();
                let what = what.to_string();
                let start = Instant::now();
                let watcher = std::thread::spawn(move || {
                    let mut wait = QUIET_FOR;
                    while let Err(mpsc::RecvTimeoutError::Timeout) = told.recv_timeout(wait) {
                        eprintln!(
                            "{what}: still working after {:.0} s",
                            start.elapsed().as_secs_f64()
                        );
                        wait = BUSY_EVERY;
                    }
                });
                Self {
                    bar: indicatif::ProgressBar::hidden(),
                    stop: Some((tell, watcher)),
                }
            }
            None => Self {
                bar: indicatif::ProgressBar::hidden(),
                stop: None,
            },
        }
    }

    /// The job ended.
    pub(crate) fn finish_and_clear(mut self) {
        self.end();
    }

    fn end(&mut self) {
        self.bar.finish_and_clear();
        if let Some((tell, watcher)) = self.stop.take() {
            // The watcher ends on the message or on the sender dropped.
            let _ = tell.send(());
            let _ = watcher.join();
        }
    }
}

impl Drop for Busy {
    fn drop(&mut self) {
        self.end();
    }
}
