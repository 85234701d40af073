//! Long work off the GIL. The work runs on a worker thread while the calling thread waits with
//! the GIL released, waking every [`TICK`] to check for signals (Ctrl-C raises
//! `KeyboardInterrupt`) and to call the optional progress callback with the time reached. A
//! signal or a callback that raises stops the integration through its hook
//! ([`TransientOptions::hook`](jointrom::integrate::TransientOptions::hook)); the work's own
//! result is then dropped, and nothing it would have written exists (jointrom writes files
//! atomically, and only after a run).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use jointrom::integrate::RunHook;
use pyo3::prelude::*;

use crate::errors::to_py;

/// How often the waiting thread checks for signals and reports progress.
const TICK: Duration = Duration::from_millis(50);

/// Stack of the worker thread: the CLI's main thread's 8 MiB, with room to spare.
const STACK_BYTES: usize = 16 << 20;

/// What the worker and the waiting thread share: the time reached (f64 bits), the stop, and
/// whether the work is done (with its condition variable).
#[derive(Default)]
struct Shared {
    t_bits: AtomicU64,
    stop: AtomicBool,
    done: Mutex<bool>,
    woken: Condvar,
}

impl Shared {
    /// Waits up to [`TICK`] for the work to end; whether it has.
    fn wait(&self) -> bool {
        let done = self.done.lock().unwrap_or_else(|p| p.into_inner());
        let (done, _) = self
            .woken
            .wait_timeout_while(done, TICK, |d| !*d)
            .unwrap_or_else(|p| p.into_inner());
        *done
    }
}

/// Marks the work done when dropped: at its end, also by a panic.
struct Done<'a>(&'a Shared);

impl Drop for Done<'_> {
    fn drop(&mut self) {
        *self.0.done.lock().unwrap_or_else(|p| p.into_inner()) = true;
        self.0.woken.notify_all();
    }
}

/// Runs `work(hook)` on a worker thread with the GIL released; `hook` goes into the run's
/// transient options. `progress(t, end)` is called from the waiting thread (with the GIL) at
/// every tick, `end` the run's end time (s).
pub fn run<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    end: f64,
    work: impl FnOnce(RunHook) -> Result<T, jointrom::Error> + Send,
) -> PyResult<T> {
    let shared = Arc::new(Shared::default());
    let hook = {
        let s = Arc::clone(&shared);
        RunHook(Arc::new(move |t: f64| {
            s.t_bits.store(t.to_bits(), Ordering::Relaxed);
            !s.stop.load(Ordering::Relaxed)
        }))
    };
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("jointrom".into())
            .stack_size(STACK_BYTES)
            .spawn_scoped(scope, {
                let shared = &shared;
                move || {
                    let _done = Done(shared);
                    work(hook)
                }
            })
            .map_err(|e| crate::errors::Error::new_err(format!("cannot start a thread: {e}")))?;
        let mut interrupted: Option<PyErr> = None;
        loop {
            if py.detach(|| shared.wait()) {
                break;
            }
            if interrupted.is_some() {
                continue;
            }
            let checked = py.check_signals().and_then(|()| match progress {
                Some(cb) => {
                    let t = f64::from_bits(shared.t_bits.load(Ordering::Relaxed));
                    cb.call1((t, end)).map(|_| ())
                }
                None => Ok(()),
            });
            if let Err(e) = checked {
                shared.stop.store(true, Ordering::Relaxed);
                interrupted = Some(e);
            }
        }
        let joined = py.detach(|| worker.join());
        if let Some(e) = interrupted {
            return Err(e);
        }
        match joined {
            Ok(out) => out.map_err(to_py),
            Err(panic) => Err(crate::errors::Error::new_err(format!(
                "internal error (a panic in jointrom): {}",
                panic_text(&panic)
            ))),
        }
    })
}

/// The text of a panic payload.
fn panic_text(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}
