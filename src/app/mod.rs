//! The eframe viewer.

use std::path::PathBuf;

pub fn run(_files: Vec<PathBuf>) -> eframe::Result<()> {
    Ok(())
}
