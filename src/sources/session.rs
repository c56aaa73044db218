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

#[cfg(test)]
mod scan_tests {
    use super::*;

    #[test]
    fn a_session_written_before_scans_were_objects_opens_its_scan_as_one() {
        // The old layout: the playback's fields and the views' settings in one `[scan]` table.
        #[derive(serde::Serialize)]
        struct Old {
            scan: crate::scene::LegacyScan,
        }
        let mut settings = crate::scene::RenderSettings::default();
        settings.volume.slices = 96;
        settings.iso.visible = true;
        let state = crate::scene::ScanState {
            value: -45.0,
            mode: crate::scene::Interpolation::ThreePass,
            looping: false,
            speed: 12.0,
            orbitals: vec!["homo".into(), "lumo".into()],
            ..crate::scene::ScanState::default()
        };
        let text = toml::to_string(&Old { scan: crate::scene::LegacyScan { state, settings } }).unwrap();
        assert!(text.starts_with("[scan]\nmanifest") || text.contains("[scan]\nvalue = -45.0"), "{text}");
        assert!(text.contains("[scan.settings.volume]"), "{text}");
        let session: Session = toml::from_str(&text).unwrap();
        let legacy = session.scan.expect("the old scan table is read");
        assert_eq!((legacy.state.value, legacy.state.mode), (-45.0, crate::scene::Interpolation::ThreePass));
        let object = legacy.into_object(2);
        let scan = object.scan.as_ref().unwrap();
        assert!(!scan.looping && scan.speed == 12.0 && scan.orbitals == ["homo", "lumo"]);
        let views: Vec<(crate::scene::Source, Option<usize>)> =
            object.quantities.iter().map(|q| (q.source, q.pane)).collect();
        assert_eq!(
            views,
            [(crate::scene::Source::Scan(0), Some(0)), (crate::scene::Source::Scan(1), Some(1))],
            "each view in its pane"
        );
        assert!(object.quantities.iter().all(|q| q.cloud.slices == 96 && q.isosurfaces[0].visible));
        // Written again, the scan is the object's: no table of its own.
        let again = toml::to_string(&Session { objects: vec![object], ..Session::default() }).unwrap();
        assert!(!again.contains("[scan]") && again.contains("[objects.scan]"), "{again}");
    }
}
