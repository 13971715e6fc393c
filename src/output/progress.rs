//! Progress bar with ETA on stderr, drawn only when stderr is a terminal.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Bar resolution: the simulated time is mapped onto this many ticks.
const TICKS: u64 = 10_000;
/// Minimum wall time between two updates of the bar's state.
const MIN_INTERVAL: Duration = Duration::from_millis(100);

/// Progress of a run from t = 0 to `end_time`, drawn on stderr with simulated time, step
/// count, elapsed time and ETA; hidden (and nearly free) when stderr is not a terminal.
pub struct Progress {
    bar: ProgressBar,
    end_time: f64,
    start: Instant,
    /// Nanoseconds after `start` of the last accepted update (`u64::MAX` = none yet).
    last_update: AtomicU64,
}

impl Progress {
    /// A bar for a run ending at simulated time `end_time`.
    pub fn new(end_time: f64) -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        Self::with_target(end_time, target)
    }

    fn with_target(end_time: f64, target: ProgressDrawTarget) -> Self {
        let bar = ProgressBar::with_draw_target(Some(TICKS), target);
        let style = ProgressStyle::with_template(
            "{wide_bar} {percent:>3}% {msg} [{elapsed_precise} elapsed, ETA {eta_precise}]",
        )
        .expect("valid progress template");
        bar.set_style(style);
        Self {
            bar,
            end_time,
            start: Instant::now(),
            last_update: AtomicU64::new(u64::MAX),
        }
    }

    /// Report that step `step` reached simulated time `t`. Cheap: the bar's state is
    /// updated at most every 100 ms, and not at all when hidden.
    pub fn set(&self, t: f64, step: usize) {
        if self.bar.is_hidden() {
            return;
        }
        let now = self.start.elapsed().as_nanos() as u64;
        let last = self.last_update.load(Ordering::Relaxed);
        if last != u64::MAX && now.saturating_sub(last) < MIN_INTERVAL.as_nanos() as u64 {
            return;
        }
        self.last_update.store(now, Ordering::Relaxed);
        // Message first: setting the position may redraw.
        self.bar
            .set_message(format!("t = {t:.4e} / {:.4e}, step {step}", self.end_time));
        self.bar.set_position(self.ticks(t));
    }

    /// Fill the bar and leave it on screen, followed by a newline (idempotent).
    pub fn finish(&self) {
        if self.bar.is_finished() {
            return;
        }
        self.bar.set_position(TICKS);
        self.bar.finish();
        if !self.bar.is_hidden() {
            // indicatif leaves the cursor at the end of the bar's line.
            eprintln!();
        }
    }

    fn ticks(&self, t: f64) -> u64 {
        if self.end_time > 0.0 && t.is_finite() {
            ((t / self.end_time).clamp(0.0, 1.0) * TICKS as f64).round() as u64
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_bar_is_silent_and_safe() {
        // Tests never run with a terminal on stderr in CI; force the hidden target anyway.
        let p = Progress::with_target(2.0, ProgressDrawTarget::hidden());
        for step in 0..1000 {
            p.set(step as f64 * 0.002, step);
        }
        p.finish();
        assert!(p.bar.is_finished());
    }

    #[test]
    fn time_maps_to_ticks() {
        let p = Progress::with_target(2.0, ProgressDrawTarget::hidden());
        assert_eq!(p.ticks(0.0), 0);
        assert_eq!(p.ticks(1.0), TICKS / 2);
        assert_eq!(p.ticks(5.0), TICKS);
        assert_eq!(p.ticks(f64::NAN), 0);
        let zero = Progress::with_target(0.0, ProgressDrawTarget::hidden());
        assert_eq!(zero.ticks(1.0), 0);
    }
}
