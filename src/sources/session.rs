//! Session files (`*.orbcloud.toml`: the scene's files, representations, placements, camera):
//! read with every value brought into range, written, and the session kept between runs; and
//! the data sets a session adds to its files, made again. The viewer, `movie` and `bench scene`
//! all read sessions here.

use std::path::{Path, PathBuf};

use crate::model::Document;
use crate::scene::Session;
use crate::scene::objects::{AddedVolume, SESSION_SUFFIX};

/// `path` ending in `.orbcloud.toml` (a dialog may have dropped the double suffix).
pub fn with_suffix(path: PathBuf) -> PathBuf {
    let name = path.to_string_lossy();
    if name.ends_with(SESSION_SUFFIX) {
        return path;
    }
    let stem = name.strip_suffix(".toml").unwrap_or(&name);
    PathBuf::from(format!("{stem}{SESSION_SUFFIX}"))
}

/// Where the session is kept between runs: `$XDG_CONFIG_HOME/orbcloud` or `~/.config/orbcloud`.
pub fn last_session_path() -> Option<PathBuf> {
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))?;
    Some(config.join("orbcloud").join(format!("last{SESSION_SUFFIX}")))
}

/// A session read, its values brought into range.
#[derive(Debug, Clone, PartialEq)]
pub struct Read {
    pub session: Session,
    /// One line per value that was out of range or no finite number, naming the file and the
    /// key, and what was used instead.
    pub notes: Vec<String>,
}

/// Reads a session file; the error names the file (and the line, for TOML errors).
pub fn read(path: &Path) -> Result<Read, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&path.display().to_string(), &text)
}

/// Parses the text of session `name` and brings its values into range
/// ([`Session::sanitize`]): a session that parses always opens, whatever its numbers.
pub fn parse(name: &str, text: &str) -> Result<Read, String> {
    let mut session: Session = toml::from_str(text).map_err(|e| format!("{name}: not an orbcloud session: {e}"))?;
    let notes = session.sanitize().into_iter().map(|note| format!("{name}: {note}")).collect();
    Ok(Read { session, notes })
}

/// Writes a session file.
pub fn write(path: &Path, session: &Session) -> Result<(), String> {
    let text = toml::to_string_pretty(session).map_err(|e| format!("{}: {e}", path.display()))?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Appends the data set(s) `added` names to `doc`: a joined file's, or a difference with
/// another file made again.
pub fn add_volume(doc: &mut Document, added: &AddedVolume) -> Result<(), String> {
    match added {
        AddedVolume::Joined { path } => {
            let other = crate::formats::load(path).map_err(|e| e.to_string())?;
            doc.join(other).map(|_| ())
        }
        AddedVolume::Difference { of, minus, points } => {
            let other = crate::formats::load(minus).map_err(|e| e.to_string())?;
            let grid = crate::evaluate::arithmetic::difference(doc, *of, *points, &other)?;
            doc.volumes.push(grid);
            Ok(())
        }
    }
}
