//! Work off the UI thread. Every background job (loading a file, building a scan's key volumes)
//! starts through [`spawn`], which turns a panic in the job into an error message, so the window
//! reports it and goes on instead of showing a progress bar forever.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
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

/// The work of a [`Latest`] job: it may look at the flag and stop early when it is raised.
type Work<T> = Box<dyn FnOnce(&AtomicBool) -> T + Send>;

/// A series of jobs of one kind where the newest request is what matters (an object's orbital,
/// its isosurfaces while a slider moves): at most one runs; a request made while it runs waits,
/// and a newer request replaces the waiting one, so a dragged slider never piles up threads.
/// Results arrive in the order requested; the intermediate ones are still worth showing.
pub struct Latest<T> {
    name: String,
    running: Option<(Pending<T>, Arc<AtomicBool>)>,
    waiting: Option<Work<T>>,
    repaint: Arc<dyn Fn() + Send + Sync>,
}

impl<T: Send + 'static> Latest<T> {
    /// Jobs named `name` (a panic reads "`name` failed: …"); `repaint` is called whenever one
    /// ends.
    pub fn new(name: &str, repaint: impl Fn() + Send + Sync + 'static) -> Self {
        Self { name: name.into(), running: None, waiting: None, repaint: Arc::new(repaint) }
    }

    /// Runs `work` now, or after the running job (replacing any request still waiting).
    pub fn request(&mut self, work: impl FnOnce(&AtomicBool) -> T + Send + 'static) {
        if self.running.is_some() {
            self.waiting = Some(Box::new(work));
        } else {
            self.start(Box::new(work));
        }
    }

    fn start(&mut self, work: Work<T>) {
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = cancel.clone();
        let repaint = self.repaint.clone();
        self.running = Some((spawn(&self.name, move || work(&flag), move || repaint()), cancel));
    }

    /// The result of the job that ended, if one did; the waiting request starts then.
    pub fn poll(&mut self) -> Option<Result<T, String>> {
        let result = self.running.as_ref()?.0.poll()?;
        self.running = None;
        if let Some(next) = self.waiting.take() {
            self.start(next);
        }
        Some(result)
    }

    /// Whether a job runs or waits.
    pub fn is_busy(&self) -> bool {
        self.running.is_some() || self.waiting.is_some()
    }

    /// Drops the waiting request and the running job's result, and asks the running job to stop.
    pub fn cancel(&mut self) {
        self.waiting = None;
        if let Some((_, flag)) = self.running.take() {
            flag.store(true, Ordering::Relaxed);
        }
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(std::string::ToString::to_string)
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
    fn the_latest_request_runs_after_the_running_one_and_replaces_the_waiting_one() {
        let (go, gate) = std::sync::mpsc::channel::<()>();
        let gate = std::sync::Mutex::new(gate);
        let mut jobs = Latest::new("isosurfaces", || {});
        jobs.request(move |_| {
            gate.lock().unwrap().recv().ok();
            1
        });
        jobs.request(|_| 2);
        jobs.request(|_| 3);
        assert!(jobs.is_busy());
        assert_eq!(jobs.poll(), None, "the first is still running");
        go.send(()).unwrap();
        let mut results = Vec::new();
        for _ in 0..500 {
            if let Some(r) = jobs.poll() {
                results.push(r.unwrap());
            }
            if !jobs.is_busy() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert_eq!(results, vec![1, 3], "2 was replaced while it waited");
        // Cancelling drops the result and raises the job's flag.
        let seen = Arc::new(AtomicBool::new(false));
        let s = seen.clone();
        jobs.request(move |stop| {
            while !stop.load(Ordering::Relaxed) {
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            s.store(true, Ordering::Relaxed);
            4
        });
        jobs.cancel();
        assert!(!jobs.is_busy() && jobs.poll().is_none());
        for _ in 0..500 {
            if seen.load(Ordering::Relaxed) {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert!(seen.load(Ordering::Relaxed), "the job saw the flag and stopped");
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
