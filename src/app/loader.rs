//! Loading files on a background thread, with progress, so the window stays responsive and
//! keeps what it shows until the new file has loaded.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use super::jobs::{Pending, spawn};
use crate::formats::{self, LoadError};
use crate::model::Document;
use crate::scene::objects::AddedVolume;

pub struct LoadJob {
    pub path: PathBuf,
    /// Bytes read so far and the file's size; parsing starts when they are equal.
    read: Arc<AtomicU64>,
    total: u64,
    result: Pending<Result<Document, LoadError>>,
}

impl LoadJob {
    /// Loads `path`, then makes the data sets a session's object had added to it
    /// ([`super::session::add_volume`]).
    pub fn start(path: PathBuf, added: Vec<AddedVolume>, repaint: impl Fn() + Send + Sync + 'static) -> Self {
        let total = std::fs::metadata(&path).map_or(0, |m| m.len());
        let read = Arc::new(AtomicU64::new(0));
        let (p, counter) = (path.clone(), read.clone());
        let repaint = Arc::new(repaint);
        let progress = repaint.clone();
        let result = spawn(
            &format!("loading {}", path.display()),
            move || {
                let mut doc = load_with_progress(&p, &counter, &*progress)?;
                // Those after one that fails would be numbered wrongly: they are left out.
                if let Some(e) = added.iter().find_map(|a| super::session::add_volume(&mut doc, a).err()) {
                    doc.problems.push(e);
                }
                Ok(doc)
            },
            move || repaint(),
        );
        Self { path, read, total, result }
    }

    /// Fraction of the file read (0..1), and whether it is being parsed.
    pub fn progress(&self) -> (f32, bool) {
        let read = self.read.load(Ordering::Relaxed);
        let f = if self.total == 0 { 0.0 } else { read as f32 / self.total as f32 };
        (f.min(1.0), self.total > 0 && read >= self.total)
    }

    /// The document, or why it did not load (a reader's error, or a failure of the job).
    pub fn poll(&self) -> Option<Result<Document, String>> {
        self.result.poll().map(|r| r.and_then(|loaded| loaded.map_err(|e| e.to_string())))
    }
}

fn load_with_progress(path: &Path, counter: &AtomicU64, repaint: &dyn Fn()) -> Result<Document, LoadError> {
    let io = |source| LoadError::Io { path: path.display().to_string(), source };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    let mut chunk = vec![0u8; 1 << 20];
    loop {
        let n = file.read(&mut chunk).map_err(io)?;
        if n == 0 {
            break;
        }
        bytes.extend_from_slice(&chunk[..n]);
        counter.store(bytes.len() as u64, Ordering::Relaxed);
        repaint();
    }
    formats::load_bytes(path, &bytes)
}
