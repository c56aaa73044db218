//! Work off the UI thread. Every background job (loading a file, building a scan's key volumes)
//! starts through [`spawn`], which turns a panic in the job into an error message, so the window
//! reports it and goes on instead of showing a progress bar forever.

use std::sync::mpsc::{Receiver, TryRecvError, channel};

/// The result of a job, once it is there.
pub struct Pending<T> {
    result: Receiver<Result<T, String>>,
}

impl<T> Pending<T> {
    /// The result when the job has finished; `Err` with a message when it panicked.
    pub fn poll(&self) -> Option<Result<T, String>> {
        match self.result.try_recv() {
            Ok(r) => Some(r),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(Err("the job ended without a result".into())),
        }
    }
}

/// Runs `work` on its own thread named `name`; calls `repaint` when it ends, however it ends.
pub fn spawn<T: Send + 'static>(
    name: &str,
    work: impl FnOnce() -> T + Send + 'static,
    repaint: impl Fn() + Send + 'static,
) -> Pending<T> {
    let (tx, result) = channel();
    let label = name.to_string();
    let spawned = std::thread::Builder::new().name(label.clone()).spawn(move || {
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
            .map_err(|payload| format!("{label} failed: {}", panic_message(payload.as_ref())));
        let _ = tx.send(outcome);
        repaint();
    });
    if let Err(e) = spawned {
        // No thread: the receiver's sender is gone, and poll says so; keep the reason too.
        log::error!("could not start {name}: {e}");
    }
    Pending { result }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "an internal error".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait<T>(p: &Pending<T>) -> Result<T, String> {
        for _ in 0..500 {
            if let Some(r) = p.poll() {
                return r;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        panic!("the job did not finish");
    }

    #[test]
    fn results_arrive_and_panics_become_errors() {
        assert_eq!(wait(&spawn("sum", || 2 + 2, || {})), Ok(4));
        let failed = wait(&spawn("loading x.cube", || -> u32 { panic!("index out of range") }, || {}));
        assert_eq!(failed, Err("loading x.cube failed: index out of range".into()));
        let formatted = wait(&spawn("scan", || -> u32 { panic!("frame {} is broken", 3) }, || {}));
        assert_eq!(formatted, Err("scan failed: frame 3 is broken".into()));
    }
}
