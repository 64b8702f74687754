//! Long calls that Ctrl-C stops and that report progress, and panics kept out of Python.
//!
//! A heavy call runs its work on a worker thread while the calling thread, with the GIL
//! released, waits for it in short slices. Between slices it takes the GIL back to run
//! Python's signal handlers (`Python::check_signals`: the handlers only run on the main
//! thread, and only when some code asks for them while the GIL is released for long) and
//! to call the progress callback. On Ctrl-C the work's cancel flag is set, and the call
//! raises `KeyboardInterrupt` within one slice: work that watches the flag (renders, the
//! evaluation loops, validation between checks) stops on its own; what does not finishes
//! in the background and its result is dropped. A panic of the work (a bug) becomes a
//! `RuntimeError` naming the call instead of pyo3's `PanicException`, which `except
//! Exception` does not catch.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often the waiting thread looks for signals: well under the 0.5 s a user may wait
/// for Ctrl-C to act, and rare enough to cost nothing (each look takes the GIL once).
const POLL: Duration = Duration::from_millis(40);
/// How often the progress callback is called.
const PROGRESS_EVERY: Duration = Duration::from_millis(250);

/// What the work and the waiting thread share: the cancel flag, and the progress
/// counters the work advances (`done` of `total` units, any unit).
#[derive(Default)]
pub struct Control {
    cancel: AtomicBool,
    done: AtomicU64,
    total: AtomicU64,
}

impl Control {
    /// Whether the work should stop now.
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// The flag itself, for the render crate's `cancel` arguments.
    pub fn flag(&self) -> &AtomicBool {
        &self.cancel
    }

    /// Reports `done` of `total` units.
    pub fn progress(&self, done: u64, total: u64) {
        self.total.store(total, Ordering::Relaxed);
        self.done.store(done, Ordering::Relaxed);
    }

    /// Adds `n` done units (of a total set with `set_total`).
    pub fn advance(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }

    pub fn set_total(&self, total: u64) {
        self.total.store(total, Ordering::Relaxed);
    }
}

/// How a watched call ended.
pub enum Outcome<T> {
    Done(T),
    /// Interrupted by a signal handler's exception (`KeyboardInterrupt`) or by an
    /// exception of the progress callback; the work's result when it stopped within the
    /// settle time (a partial render), or None.
    Interrupted(PyErr, Option<T>),
}

/// A panic payload's message.
fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".into()
    }
}

/// The `RuntimeError` a panic of `call` becomes.
pub fn panic_error(call: &str, p: &(dyn std::any::Any + Send)) -> PyErr {
    PyRuntimeError::new_err(format!(
        "{call}: internal error (a bug in facette; please report it): {}",
        panic_message(p)
    ))
}

/// Runs `f` on this thread, turning a panic into a `RuntimeError` naming `call`: for the
/// short work done with the GIL held (argument checks, building a material).
pub fn guard<T>(call: &str, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| Err(panic_error(call, p.as_ref())))
}

/// Runs `work` on a worker thread, watching for signals and reporting progress to
/// `progress` (a callable `(done, total)`, or None) from the calling thread. After an
/// interruption, waits up to `settle` for the work to stop and hand back what it has.
pub fn run<T: Send + 'static>(
    py: Python<'_>,
    call: &'static str,
    progress: Option<Py<PyAny>>,
    settle: Duration,
    work: impl FnOnce(&Control) -> T + Send + 'static,
) -> PyResult<Outcome<T>> {
    let control = Arc::new(Control::default());
    let (tx, rx) = mpsc::channel();
    let worker_control = control.clone();
    std::thread::Builder::new()
        .name(call.into())
        .spawn(move || {
            let r = catch_unwind(AssertUnwindSafe(|| work(&worker_control)));
            // The receiver is gone when the call was interrupted and did not wait.
            let _ = tx.send(r);
        })
        .map_err(|e| PyRuntimeError::new_err(format!("{call}: cannot start a thread: {e}")))?;
    let report = |py: Python<'_>, cb: &Py<PyAny>| -> PyResult<()> {
        let (d, t) = (
            control.done.load(Ordering::Relaxed),
            control.total.load(Ordering::Relaxed),
        );
        cb.call1(py, (d, t)).map(|_| ())
    };
    let mut last_report = Instant::now();
    let (control_ref, progress_ref, report_ref) = (&control, &progress, &report);
    let outcome = py.detach(move || loop {
        match rx.recv_timeout(POLL) {
            Ok(Ok(v)) => return Ok(Outcome::Done(v)),
            Ok(Err(p)) => return Err(panic_error(call, p.as_ref())),
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(format!(
                    "{call}: the worker thread ended without a result"
                )))
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        let stop = Python::attach(|py| -> PyResult<()> {
            py.check_signals()?;
            if let Some(cb) = progress_ref {
                if last_report.elapsed() >= PROGRESS_EVERY {
                    last_report = Instant::now();
                    report_ref(py, cb)?;
                }
            }
            Ok(())
        });
        if let Err(e) = stop {
            control_ref.cancel.store(true, Ordering::SeqCst);
            let partial = match rx.recv_timeout(settle) {
                Ok(Ok(v)) => Some(v),
                _ => None,
            };
            return Ok(Outcome::Interrupted(e, partial));
        }
    })?;
    // The last report: 100 % when done.
    if let (Outcome::Done(_), Some(cb)) = (&outcome, &progress) {
        report(py, cb)?;
    }
    Ok(outcome)
}

/// [`run_all`], or for `small` work without a progress callback, the work itself on this
/// thread with the GIL released: a call on a few rows (a Python loop over directions)
/// should not pay for a thread, and is over before a Ctrl-C would matter.
pub fn run_small_or_all<T: Send + 'static>(
    py: Python<'_>,
    call: &'static str,
    progress: Option<Py<PyAny>>,
    small: bool,
    work: impl FnOnce(&Control) -> T + Send + 'static,
) -> PyResult<T> {
    if small && progress.is_none() {
        return py.detach(|| {
            catch_unwind(AssertUnwindSafe(|| work(&Control::default())))
                .map_err(|p| panic_error(call, p.as_ref()))
        });
    }
    run_all(py, call, progress, work)
}

/// [`run`] for work whose partial result is of no use: an interruption is an error.
pub fn run_all<T: Send + 'static>(
    py: Python<'_>,
    call: &'static str,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&Control) -> T + Send + 'static,
) -> PyResult<T> {
    match run(py, call, progress, Duration::ZERO, work)? {
        Outcome::Done(v) => Ok(v),
        Outcome::Interrupted(e, _) => Err(e),
    }
}
