//! The progress line on standard error: after the first second of a solve, when standard error
//! is a terminal, one line redrawn at most ten times a second with the iterations so far (every
//! round and load step counted), the energy and the reduced gradient; erased when the solve
//! ends. Nothing is drawn when standard error is a file or a pipe (tests, scripts).

use std::io::{IsTerminal, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The callback for `Options::progress` and the line's state, or `None` when standard error is
/// not a terminal.
pub(crate) struct Line {
    state: Arc<Mutex<State>>,
}

struct State {
    started: Instant,
    drawn: Option<Instant>,
    iterations: usize,
}

/// Silent for this long.
const AFTER: Duration = Duration::from_secs(1);
/// Redrawn at most this often.
const EVERY: Duration = Duration::from_millis(100);

impl Line {
    /// A progress line if standard error is a terminal.
    pub(crate) fn start() -> Option<Line> {
        std::io::stderr().is_terminal().then(|| Line {
            state: Arc::new(Mutex::new(State {
                started: Instant::now(),
                drawn: None,
                iterations: 0,
            })),
        })
    }

    /// The solver's callback.
    pub(crate) fn callback(&self) -> restpose::solver::Progress {
        let state = Arc::clone(&self.state);
        restpose::solver::Progress(Some(Arc::new(move |_, energy: f64, gradient: f64| {
            let Ok(mut s) = state.lock() else { return };
            s.iterations += 1;
            let now = Instant::now();
            let due = now.duration_since(s.started) >= AFTER
                && s.drawn.is_none_or(|d| now.duration_since(d) >= EVERY);
            if due {
                s.drawn = Some(now);
                let mut err = std::io::stderr().lock();
                let _ = write!(
                    err,
                    "\r\x1b[Ksolving: {} iterations, V = {energy:.9} J, ‖∂V/∂v‖∞ = {gradient:.2e} J, {:.1} s",
                    s.iterations,
                    now.duration_since(s.started).as_secs_f64()
                );
                let _ = err.flush();
            }
        })))
    }

    /// Erases the line if it was drawn.
    pub(crate) fn finish(self) {
        if self.state.lock().is_ok_and(|s| s.drawn.is_some()) {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r\x1b[K");
            let _ = err.flush();
        }
    }
}
