//! Several quantities of one file on the `render` command line: each quantity option
//! (`--orbital X`, `--density`, `--spin-density`, `--basis-function F`, `--volume N`, `--nci`) after the
//! first starts another quantity, and the representation options after it (`--iso`,
//! `--translucent`, `--no-volume`, transfer function, colours) are its own; `--beside` puts the
//! next quantity in a pane of its own, side by side with the same camera.

use std::ffi::OsString;

use crate::gpu::{GpuContext, OffscreenTarget, Renderer};
use crate::layers::show_scene;
use crate::model::Document;
use crate::scene::{Camera, Evaluation, IsoLevel, ObjectState, QuantityState, Source};
use anyhow::{Result, bail};
use clap::Parser;

use super::surface::IsoArgs;
use super::{Cli, Command, RenderArgs, ViewArgs, WavefunctionArgs};

/// The options that start a quantity.
const STARTS: [&str; 6] = ["--orbital", "--density", "--spin-density", "--basis-function", "--volume", "--nci"];
/// The option that puts the next quantity beside the ones before, in a pane of its own.
const BESIDE: &str = "--beside";
/// Options that belong to the whole picture or file, not to a quantity: wherever they are
/// given, they join the first part of the command line (`mesh FILE --density --iso 0.1
/// --orbital homo --iso 0.05 -o out.glb`).
const WHOLE_PICTURE: [&str; 32] = [
    "--output",
    "-o",
    "--size",
    "--view",
    "--yaw",
    "--pitch",
    "--zoom",
    "--atoms",
    "--color",
    "--depth-cue",
    "--lavapipe",
    "--pick",
    "--demo",
    "--grid-points",
    "--direct",
    "--surface",
    "--surface-resolution",
    "--surface-color",
    "--probe",
    "--smoothness",
    "--lod-px",
    "--normal-mode",
    "--phase",
    "--amplitude",
    "--arrows",
    "--ball-scale",
    "--stick-scale",
    "--scale",
    "--transparent",
    "--clip",
    "--clip-atoms",
    "--no-captions",
];
/// Those of them that take no value.
const WHOLE_PICTURE_FLAGS: [&str; 6] =
    ["--lavapipe", "--direct", "--arrows", "--transparent", "--clip-atoms", "--no-captions"];

/// A quantity given after the first, with the options that followed it.
pub struct Later {
    /// Whether `--beside` came before it: it starts a new pane.
    pub beside: bool,
    pub args: Vec<OsString>,
}

fn option_name(arg: &OsString) -> String {
    let s = arg.to_string_lossy();
    s.split('=').next().unwrap_or_default().to_string()
}

/// Splits `args` (a whole command line) of a `render` or `mesh` command at each quantity option
/// after the first one: the first part parses as that command always did; each later quantity
/// comes with its own options. Other commands are returned whole.
pub fn split(args: Vec<OsString>) -> Result<(Vec<OsString>, Vec<Later>)> {
    let Some(at) = args.iter().position(|a| a == "render" || a == "mesh") else { return Ok((args, Vec::new())) };
    let mesh = args[at] == "mesh";
    let mut first: Vec<OsString> = args[..=at].to_vec();
    let mut later: Vec<Later> = Vec::new();
    let (mut seen, mut beside) = (false, false);
    // The value of a whole-picture option moved to the first part follows it there.
    let mut moving_value = false;
    for arg in args.into_iter().skip(at + 1) {
        if moving_value {
            first.push(arg);
            moving_value = false;
            continue;
        }
        let name = option_name(&arg);
        if name == BESIDE {
            beside = true;
            continue;
        }
        if STARTS.contains(&name.as_str()) {
            if seen || beside {
                later.push(Later { beside, args: Vec::new() });
                beside = false;
            }
            seen = true;
        }
        match later.last_mut() {
            Some(_) if WHOLE_PICTURE.contains(&name.as_str()) => {
                moving_value = !WHOLE_PICTURE_FLAGS.contains(&name.as_str()) && !arg.to_string_lossy().contains('=');
                first.push(arg);
            }
            Some(l) => l.args.push(arg),
            None => first.push(arg),
        }
    }
    if beside {
        bail!("--beside must be followed by the quantity to show beside (--orbital X, --density, …)");
    }
    if mesh && later.iter().any(|l| l.beside) {
        bail!("--beside places a quantity in a picture's pane: `render` takes it, `mesh` does not");
    }
    Ok((first, later))
}

/// One quantity of the file as `args` asks for it (its quantity option, cloud and isosurfaces;
/// `--nci`: the viewer's NCI surface).
pub fn quantity(args: &RenderArgs, doc: &Document) -> Result<Option<QuantityState>> {
    if args.nci {
        check_nci(args, doc)?;
        let mut q = match doc.wavefunction {
            Some(_) => QuantityState::nci_surface(&args.view.settings()),
            None => QuantityState::promolecular_nci(&args.view.settings(), args.nci_between.clone()),
        };
        for iso in &mut q.isosurfaces {
            if let Some(level) = args.nci_level {
                iso.level = IsoLevel::Absolute(level);
            }
            if let Some(range) = args.nci_range {
                iso.color_range = Some(range);
            }
        }
        return Ok(Some(q));
    }
    quantity_of(doc, &args.view, &args.wavefunction, &args.iso)
}

/// `--nci` refused for a file without a wavefunction: the surface is cut from its density's
/// derivatives.
pub fn check_nci(args: &RenderArgs, doc: &Document) -> Result<()> {
    if !args.nci {
        return Ok(());
    }
    match (&doc.wavefunction, &args.nci_between) {
        (Some(_), Some(_)) => bail!(
            "{}: --nci-between splits a structure's spherical atoms, and this file has a wavefunction: `orbcloud nci A B --intermolecular -o PREFIX` keeps what lies between the wavefunctions of two fragments' files",
            doc.source
        ),
        (Some(_), None) => Ok(()),
        // A structure's NCI comes from its spherical atoms.
        (None, between) => {
            use crate::evaluate::interaction::{self, Kind};
            let fragments = crate::scene::Fragments { selection: between.clone(), ..Default::default() };
            interaction::check(doc, Kind::Spherical, &fragments, &[]).map_err(anyhow::Error::msg)?;
            if let Some(note) = interaction::note(doc) {
                eprintln!("{note}");
            }
            Ok(())
        }
    }
}

/// The quantity `what` names (or the data set `view` picks) with `view`'s cloud and `iso`'s
/// isosurfaces.
pub fn quantity_of(
    doc: &Document,
    view: &ViewArgs,
    what: &WavefunctionArgs,
    iso: &IsoArgs,
) -> Result<Option<QuantityState>> {
    let settings = view.settings();
    let source = match &doc.wavefunction {
        Some(_) => Source::Wavefunction(what.what.resolve(doc)?),
        None => match view.volume_index(doc)? {
            Some(i) => Source::Volume(i),
            None => return Ok(None),
        },
    };
    let mut q = QuantityState::new(source, &settings);
    q.isosurfaces = vec![iso.base()];
    iso.apply_to(&mut q);
    if iso.levels().is_empty() {
        q.isosurfaces.clear();
    }
    Ok(Some(q))
}

/// An object showing the atoms as `view` asks and evaluating orbitals as `what` asks, without
/// quantities yet.
fn bare_object(view: &ViewArgs, what: &WavefunctionArgs) -> ObjectState {
    let settings = view.settings();
    ObjectState {
        atoms: crate::scene::AtomLook::of(&settings),
        clip: settings.clip,
        evaluation: Evaluation {
            direct: what.direct,
            grid_points: what.grid_points.clamp(8, 512),
            ..Evaluation::default()
        },
        ..ObjectState::default()
    }
}

/// The object a movie of one file shows: its atoms as `view` asks, and the quantity `what` names
/// (or the file's data set) with `iso`'s isosurfaces.
pub fn object_of(doc: &Document, view: &ViewArgs, what: &WavefunctionArgs, iso: &IsoArgs) -> Result<ObjectState> {
    let mut object = bare_object(view, what);
    object.quantities.extend(quantity_of(doc, view, what, iso)?);
    Ok(object)
}

/// The later quantities' own options, parsed as `render` parses them.
pub fn parse_later(later: &[Later]) -> Result<Vec<(bool, RenderArgs)>> {
    later
        .iter()
        .map(|l| {
            let line = ["orbcloud", "render", "-o", "unused.png"].map(OsString::from).into_iter().chain(l.args.clone());
            match Cli::try_parse_from(line) {
                Ok(Cli { command: Some(Command::Render(args)), .. }) => Ok((l.beside, args)),
                Ok(_) => bail!("expected the options of a quantity"),
                Err(e) => bail!("{}", e.to_string().trim()),
            }
        })
        .collect()
}

/// The later quantities' own options, parsed as `mesh` parses them.
pub fn parse_later_meshes(later: &[Later]) -> Result<Vec<super::surface::MeshArgs>> {
    later
        .iter()
        .map(|l| {
            let head = ["orbcloud", "mesh", "unused", "-o", "unused.obj"].map(OsString::from);
            match Cli::try_parse_from(head.into_iter().chain(l.args.clone())) {
                Ok(Cli { command: Some(Command::Mesh(args)), .. }) => Ok(args),
                Ok(_) => bail!("expected the options of a quantity"),
                Err(e) => bail!("{}", e.to_string().trim()),
            }
        })
        .collect()
}

/// Renders `doc`'s quantities, the first from `first` and the rest from `later`, each pane side
/// by side (a quantity after `--beside` starts a pane) with one camera; the image is `size`
/// whole, its width shared by the panes. Each pane's quantities are said on stderr.
pub fn render(
    ctx: &GpuContext,
    doc: &Document,
    first: &RenderArgs,
    later: &[(bool, RenderArgs)],
    camera: &Camera,
    size: [u32; 2],
    background: [f32; 3],
) -> Result<image::RgbaImage> {
    let mut object = bare_object(&first.view, &first.wavefunction);
    // Which pane each quantity is drawn in.
    let mut panes = Vec::new();
    let mut pane = 0;
    for (beside, args) in std::iter::once((false, first)).chain(later.iter().map(|(b, a)| (*b, a))) {
        pane += beside as usize;
        if let Some(q) = quantity(args, doc)? {
            object.quantities.push(q);
            panes.push(pane);
        }
    }
    let count = pane + 1;
    let [width, height] = size;
    let pane_width = (width / count as u32).max(1);
    let mut image = image::RgbaImage::new(pane_width * count as u32, height);
    for p in 0..count {
        let mut state = object.clone();
        let mut k = 0;
        state.quantities.retain(|_| {
            k += 1;
            panes[k - 1] == p
        });
        let names: Vec<String> = state.quantities.iter().map(|q| describe(doc, q.source)).collect();
        let lines: Vec<String> = state.quantities.iter().map(|q| caption(doc, q.source)).collect();
        eprintln!("pane {}: {}", p + 1, if names.is_empty() { "atoms".into() } else { names.join(" + ") });
        let pane_scene = [(doc, state)];
        let mut renderer = Renderer::new(ctx);
        let points = first.wavefunction.grid_points.clamp(8, 512);
        let shown = show_scene(ctx, &mut renderer, &pane_scene, points)?;
        let target = OffscreenTarget::new(&ctx.device, [pane_width, height]);
        // A lone picture with a colour bar is framed left of it, as the window frames maps.
        let mut camera = *camera;
        if let (Some((map, name)), 1) = (&shown.color_map, count) {
            let room = crate::pictures::shots::value_bar_width(height, map, name);
            camera.leave_room_right(room, [pane_width as f32, height as f32], false);
        }
        let (mut picture, _) =
            crate::pictures::headless::picture(ctx, &mut renderer, &target, &camera, background, &shown.clouds)?;
        if let Some((map, name)) = &shown.color_map {
            crate::pictures::shots::value_bar(&mut picture, map, name);
        }
        // Panes side by side say what each shows, as the window's panes do.
        if count > 1 && !first.no_captions {
            crate::pictures::figure::caption(&mut picture, 0, pane_width, &lines);
        }
        image::imageops::replace(&mut image, &picture, (p as u32 * pane_width) as i64, 0);
    }
    Ok(image)
}

/// A pane's caption line: the quantity, with an orbital's energy ("HOMO  −0.2467 Eh").
fn caption(doc: &Document, source: Source) -> String {
    let name = source.name(doc);
    match (source.orbital(), &doc.wavefunction) {
        (Some(i), Some(wf)) => match wf.energy(i) {
            Some(e) => format!("{name}  {e:.4} Eh").replace('-', "−"),
            None => name,
        },
        _ => name,
    }
}

/// A quantity in words, with an orbital's energy: "HOMO: E = -0.24666 Eh, occupation 2.00"
/// ("HOMO β" for a beta orbital of an unrestricted wavefunction).
fn describe(doc: &Document, source: Source) -> String {
    let name = source.name(doc);
    match (source.orbital(), &doc.wavefunction) {
        (Some(i), Some(wf)) => {
            format!("{name}: {}, occupation {:.2}", wf.energy_text(i), wf.orbitals[i].occupation)
        }
        _ => name,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(s: &str) -> Vec<OsString> {
        s.split_whitespace().map(OsString::from).collect()
    }

    #[test]
    fn quantity_options_split_the_command_line() {
        let (first, later) =
            split(line("orbcloud render f.molden -o x.png --density --iso 0.05 --orbital homo --iso 0.02")).unwrap();
        assert_eq!(first, line("orbcloud render f.molden -o x.png --density --iso 0.05"));
        assert_eq!(later.len(), 1);
        assert_eq!(later[0].args, line("--orbital homo --iso 0.02"));
        assert!(!later[0].beside);
        let (_, later) = split(line("orbcloud render f -o x.png --orbital homo --beside --orbital lumo")).unwrap();
        assert!(later[0].beside && later[0].args == line("--orbital lumo"));
        // One quantity: today's command line, whole.
        let (first, later) = split(line("orbcloud render f -o x.png --orbital=homo --iso 0.1")).unwrap();
        assert!(later.is_empty() && first.len() == 8);
        // Options of the whole picture join the first part wherever they are given.
        let (first, later) =
            split(line("orbcloud mesh f --density --iso 0.1 --orbital homo --iso 0.05 -o x.obj --lavapipe")).unwrap();
        assert_eq!(first, line("orbcloud mesh f --density --iso 0.1 -o x.obj --lavapipe"));
        assert_eq!(later[0].args, line("--orbital homo --iso 0.05"));
        let (first, _) = split(line("orbcloud render f --orbital homo --orbital lumo --size=10x10")).unwrap();
        assert_eq!(first.last().unwrap(), "--size=10x10");
        assert!(split(line("orbcloud render f --orbital homo --beside")).is_err());
        // `--beside` before any quantity option: the default quantity, then the next beside it.
        let (_, later) = split(line("orbcloud render f -o x.png --beside --orbital lumo")).unwrap();
        assert!(later.len() == 1 && later[0].beside);
        // `--nci` starts a quantity too: the NCI surface with its own level, then the density.
        let (first, later) =
            split(line("orbcloud render f -o x.png --nci --nci-level 0.3 --density --iso 0.05")).unwrap();
        assert_eq!(first, line("orbcloud render f -o x.png --nci --nci-level 0.3"));
        assert_eq!(later[0].args, line("--density --iso 0.05"));
        let (whole, later) = split(line("orbcloud info f --density")).unwrap();
        assert!(later.is_empty() && whole.len() == 4);
    }
}
