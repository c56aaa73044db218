//! Normal modes on the command line: `modes` writes one period of a mode as a multi-frame XYZ
//! file (for other programs), and `render --normal-mode N --phase φ` draws the displaced
//! geometry.

use crate::scene::limits::{self, within};
use std::io::Write;
use std::path::PathBuf;

use crate::model::Document;
use crate::model::arrow::{Arrow, mode_arrows};
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::model::vibrations::Vibrations;
use anyhow::{Context, Result, bail};
use clap::Args;

/// Which mode to show, where in its oscillation and how far.
#[derive(Args, Clone)]
pub struct ModeArgs {
    /// A normal mode of the file, 1-based as `info` lists them: the atoms are drawn displaced
    /// along it (the orbitals stay at the file's geometry). (`--mode` is the slicing's.)
    #[arg(long)]
    pub normal_mode: Option<usize>,
    /// Where in the oscillation, degrees (90: the largest displacement one way, 270 the other).
    #[arg(long, default_value_t = 90.0, allow_hyphen_values = true, value_parser = within(limits::wide(limits::ANGLE_DEG)))]
    pub phase: f64,
    /// The largest atom's displacement at the turning points, bohr (0 to 10).
    #[arg(long, default_value_t = 0.4, value_parser = within(limits::wide(limits::AMPLITUDE)))]
    pub amplitude: f64,
    /// Draw each atom's displacement along the mode as an arrow from the file's geometry.
    #[arg(long, requires = "normal_mode")]
    pub arrows: bool,
}

/// The file's modes and the 0-based index of `mode` (1-based), or an error saying what there is.
fn chosen(doc: &Document, mode: usize) -> Result<(&Vibrations, usize)> {
    let Some(v) = &doc.vibrations else {
        let why = doc.problems.first().map_or(String::new(), |p| format!(" ({p})"));
        bail!("{}: no normal modes in this file{why}", doc.source);
    };
    if mode == 0 || mode > v.modes.len() {
        bail!("mode {mode} is out of range: the file has modes 1 to {}", v.modes.len());
    }
    Ok((v, mode - 1))
}

impl ModeArgs {
    /// Moves `doc`'s atoms to mode `--normal-mode` at `--phase`, when one is asked for; the bonds stay
    /// those of the file's geometry.
    pub fn apply(&self, doc: &mut Document) -> Result<()> {
        let Some(mode) = self.normal_mode else { return Ok(()) };
        let (v, k) = chosen(doc, mode)?;
        let moved = v.displaced(k, self.phase.to_radians(), self.amplitude).context("the mode is there")?;
        let m = &v.modes[k];
        eprintln!(
            "mode {mode}: {:.2}{} cm⁻¹ at {:.0}°, largest displacement {:.3} bohr",
            m.frequency_cm1.abs(),
            if m.is_imaginary() { "i" } else { "" },
            self.phase,
            self.amplitude * self.phase.to_radians().sin().abs()
        );
        for (atom, p) in doc.molecule.atoms.iter_mut().zip(moved) {
            atom.position = p;
        }
        Ok(())
    }
}

impl ModeArgs {
    /// The mode's arrows, when `--arrows` asks for them (none otherwise).
    pub fn arrows(&self, doc: &Document) -> Result<Vec<Arrow>> {
        let (Some(mode), true) = (self.normal_mode, self.arrows) else { return Ok(Vec::new()) };
        let (v, k) = chosen(doc, mode)?;
        Ok(mode_arrows(v, k, self.amplitude).unwrap_or_default())
    }
}

/// `modes`: one period of a mode as a multi-frame XYZ file.
#[derive(Args)]
pub struct ModesArgs {
    /// A Molden or fchk file with normal modes.
    file: PathBuf,
    /// The mode, 1-based as `info` lists them.
    #[arg(long)]
    mode: usize,
    /// Frames over one period.
    #[arg(long, default_value_t = 20, value_parser = within(limits::FRAMES))]
    frames: usize,
    /// The largest atom's displacement at the turning points, bohr (0 to 10).
    #[arg(long, default_value_t = 0.4, value_parser = within(limits::wide(limits::AMPLITUDE)))]
    amplitude: f64,
    /// Output XYZ file (Å), one frame after another.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn write_xyz(args: &ModesArgs) -> Result<()> {
    let doc = crate::formats::load(&args.file)?;
    let (v, k) = chosen(&doc, args.mode)?;
    let frames = args.frames.clamp(2, 10_000);
    let file = std::fs::File::create(&args.output).with_context(|| format!("creating {}", args.output.display()))?;
    let mut w = std::io::BufWriter::new(file);
    let m = &v.modes[k];
    for f in 0..frames {
        let phase = std::f64::consts::TAU * f as f64 / frames as f64;
        let moved = v.displaced(k, phase, args.amplitude).context("the mode is there")?;
        writeln!(w, "{}", moved.len())?;
        writeln!(
            w,
            "mode {} {:.2} cm-1 frame {}/{frames} phase {:.1} deg",
            args.mode,
            m.frequency_cm1,
            f + 1,
            phase.to_degrees()
        )?;
        for (atom, p) in doc.molecule.atoms.iter().zip(&moved) {
            let a = *p * ANGSTROM_PER_BOHR;
            writeln!(w, "{:<2} {:>14.8} {:>14.8} {:>14.8}", atom.element().symbol, a.x, a.y, a.z)?;
        }
    }
    w.flush().with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!("wrote {} ({frames} frames of mode {}, {:.2} cm⁻¹)", args.output.display(), args.mode, m.frequency_cm1);
    Ok(())
}
