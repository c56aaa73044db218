//! Movies and figures end to end: `movie` frames are the pictures `scan render --at`, `render
//! --yaw` and `render --phase` draw; a GIF holds every frame; videos go through ffmpeg or say
//! what to install; `render --scale` and `--transparent` make figures.

use std::path::{Path, PathBuf};
use std::process::Command;

use orbcloud::scene::objects::AddedVolume;
use orbcloud::scene::{ObjectState, QuantityState, RenderSettings, Session, Source};

mod common;

fn orbcloud(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).env("NODEVICE_SELECT", "1").output().expect("run orbcloud")
}

fn ok(args: &[&str]) {
    let out = orbcloud(args);
    assert!(out.status.success(), "orbcloud {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

fn asset(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path).display().to_string()
}

fn png(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Pixels that differ by more than one level in some channel.
fn differing(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 1)).count()
}

const SCAN: &str = "assets/psb3/psb3.scan.toml";
/// The bundled scan's range (degrees).
const RANGE: (f64, f64) = (-180.0, 0.0);

#[test]
fn a_scan_sweep_is_scan_render_frame_by_frame() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames/");
    let common = ["--size", "160x120", "--points", "32", "--lavapipe"];
    ok(&[&["movie", &asset(SCAN), "--frames", "12", "-o", s(&frames)][..], &common].concat());
    let mut names: Vec<PathBuf> = std::fs::read_dir(&frames).unwrap().map(|e| e.unwrap().path()).collect();
    names.sort();
    assert_eq!(names.len(), 12, "{names:?}");
    assert!(names[0].ends_with("frame_0001.png") && names[11].ends_with("frame_0012.png"));
    for k in [0usize, 5, 11] {
        let at = RANGE.0 + (RANGE.1 - RANGE.0) * k as f64 / 11.0;
        let single = dir.path().join(format!("at{k}.png"));
        ok(&[&["scan", "render", &asset(SCAN), "--at", &at.to_string(), "-o", s(&single)][..], &common].concat());
        let (frame, still) = (png(&names[k]), png(&single));
        assert_eq!(frame.dimensions(), (320, 120), "both views side by side");
        assert_eq!(frame, still, "frame {k} is `scan render --at {at}`");
    }
    // Frames of a sweep differ (the orbitals morph), and each carries its caption.
    assert!(common::mean_difference(&png(&names[0]), &png(&names[6])) > 0.5);
    let uncaptioned = dir.path().join("bare.png");
    ok(&[&["scan", "render", &asset(SCAN), "--at", "-180", "--no-captions", "-o", s(&uncaptioned)][..], &common]
        .concat());
    let captioned = png(&names[0]);
    let bare = png(&uncaptioned);
    let corner = |img: &image::RgbaImage| image::imageops::crop_imm(img, 0, 0, 60, 12).to_image();
    assert!(common::mean_difference(&corner(&captioned), &corner(&bare)) > 5.0, "the caption is drawn");
}

#[test]
fn a_gif_holds_every_frame_and_bounces() {
    let dir = tempfile::tempdir().unwrap();
    let gif_path = dir.path().join("sweep.gif");
    let common = ["--size", "96x72", "--points", "24", "--lavapipe", "--fps", "10"];
    ok(&[&["movie", &asset(SCAN), "--frames", "12", "-o", s(&gif_path)][..], &common].concat());
    let count = |path: &Path| {
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(std::fs::File::open(path).unwrap()).unwrap();
        assert_eq!((decoder.width(), decoder.height()), (192, 72));
        let mut n = 0;
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!(frame.delay, 10, "1/10 s per frame");
            n += 1;
        }
        n
    };
    assert_eq!(count(&gif_path), 12);
    // There and back without repeating either end: 12 + 10 frames.
    ok(&[&["movie", &asset(SCAN), "--frames", "12", "--bounce", "-o", s(&gif_path)][..], &common].concat());
    assert_eq!(count(&gif_path), 22);
}

#[test]
fn a_turntable_is_render_with_yaw() {
    let dir = tempfile::tempdir().unwrap();
    let cube = asset("assets/demo.cube.gz");
    let view = ["--size", "120x90", "--iso", "0.05", "--lavapipe"];
    let apng = dir.path().join("turn.apng");
    ok(&[&["movie", &cube, "--turntable", "--frames", "8", "-o", s(&apng)][..], &view].concat());
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&apng).unwrap()));
    let reader = decoder.read_info().unwrap();
    let animation = reader.info().animation_control.expect("an animated PNG");
    assert_eq!(animation.num_frames, 8);
    let frames = dir.path().join("turn/");
    ok(&[&["movie", &cube, "--turntable", "--frames", "8", "-o", s(&frames)][..], &view].concat());
    for (k, yaw) in [(0, "0"), (3, "135")] {
        let still = dir.path().join(format!("yaw{yaw}.png"));
        ok(&[&["render", &cube, "--yaw", yaw, "-o", s(&still)][..], &view].concat());
        let frame = png(&frames.join(format!("frame_{:04}.png", k + 1)));
        assert_eq!(differing(&frame, &png(&still)), 0, "frame {k} is `render --yaw {yaw}`");
    }
}

#[test]
fn a_vibration_movie_is_render_at_each_phase() {
    let dir = tempfile::tempdir().unwrap();
    let file = asset("tests/fixtures/modes/nh3_planar_rhf_sto3g.molden");
    let view = ["--size", "120x90", "--no-volume", "--lavapipe", "--view", "y", "--arrows"];
    let frames = dir.path().join("mode/");
    ok(&[&["movie", &file, "--normal-mode", "2", "--frames", "8", "-o", s(&frames)][..], &view].concat());
    let frame = |k: usize| png(&frames.join(format!("frame_{:04}.png", k + 1)));
    for (k, phase) in [(2, "90"), (6, "270")] {
        let still = dir.path().join(format!("p{phase}.png"));
        ok(&[&["render", &file, "--normal-mode", "2", "--phase", phase, "-o", s(&still)][..], &view].concat());
        // The frame's atoms are moved in place of the file's; the picture is the same to a
        // pixel or two of rounding.
        let off = differing(&frame(k), &png(&still));
        assert!(off <= 4, "frame {k} is `render --phase {phase}` ({off} pixels differ)");
    }
    assert!(common::mean_difference(&frame(2), &frame(6)) > 0.2, "the atoms move both ways");
}

#[test]
fn videos_need_ffmpeg_and_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let mp4 = dir.path().join("sweep.mp4");
    let out = orbcloud(&[
        "movie",
        &asset("assets/demo.cube.gz"),
        "--turntable",
        "--frames",
        "4",
        "--size",
        "64x48",
        "--lavapipe",
        "-o",
        s(&mp4),
    ]);
    let has_ffmpeg = Command::new("ffmpeg").arg("-version").output().is_ok_and(|o| o.status.success());
    if has_ffmpeg {
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let probe = Command::new("ffprobe")
            .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
            .args(["-show_entries", "stream=nb_read_frames,codec_name", "-of", "csv=p=0", s(&mp4)])
            .output()
            .expect("ffprobe comes with ffmpeg");
        let said = String::from_utf8_lossy(&probe.stdout);
        assert!(said.contains("h264") && said.contains(",4"), "ffprobe: {said}");
    } else {
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("apt-get install ffmpeg") && err.contains(".gif"), "{err}");
        eprintln!("ffmpeg is not installed: checked the message that says so instead of an MP4");
    }
    // Refused before any frame is drawn.
    for (args, says) in [
        (&["-o", "x.avi"][..], "unknown movie format"),
        (&["--normal-mode", "1", "-o", "x.gif"][..], "scan sweeps"),
        (&["--frames", "0", "-o", "x.gif"][..], "'0' for '--frames <FRAMES>': 0 is outside 1..=100000"),
    ] {
        let out = orbcloud(&[&["movie", &asset(SCAN)][..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
    }
    let out = orbcloud(&["movie", &asset("assets/demo.cube.gz"), "-o", "x.gif"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("--turntable or --normal-mode"));
}

#[test]
fn figures_are_supersampled_and_transparent() {
    let dir = tempfile::tempdir().unwrap();
    let cube = asset("assets/demo.cube.gz");
    let view = ["--size", "120x90", "--iso", "0.05", "--lavapipe"];
    let plain = dir.path().join("plain.png");
    let fine = dir.path().join("fine.png");
    let clear = dir.path().join("clear.png");
    ok(&[&["render", &cube, "-o", s(&plain)][..], &view].concat());
    ok(&[&["render", &cube, "--scale", "3", "-o", s(&fine)][..], &view].concat());
    ok(&[&["render", &cube, "--transparent", "-o", s(&clear)][..], &view].concat());
    let (plain, fine, clear) = (png(&plain), png(&fine), png(&clear));
    assert_eq!(fine.dimensions(), (120, 90), "--scale keeps the size asked for");
    // Same picture, smoother: close on average, but edges differ.
    let d = common::mean_difference(&plain, &fine);
    assert!(d > 0.05 && d < 8.0, "mean difference {d}");
    // The background is see-through, the molecule is not.
    assert_eq!(clear.get_pixel(0, 0).0[3], 0, "a corner is background");
    let opaque = clear.pixels().filter(|p| p.0[3] == 255).count();
    assert!(opaque > 200, "the surfaces stay opaque ({opaque} pixels)");
    // Where the background was, the opaque picture's colours come back.
    let (x, y) = (60, 45);
    if clear.get_pixel(x, y).0[3] == 255 {
        let (a, b) = (clear.get_pixel(x, y).0, plain.get_pixel(x, y).0);
        assert!((0..3).all(|c| a[c].abs_diff(b[c]) <= 2), "{a:?} vs {b:?}");
    }
    let out = orbcloud(&["render", &cube, "--scale", "9", "-o", "x.png"]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--scale"));
}

#[test]
fn a_surface_coloured_by_a_volume_carries_its_colour_bar() {
    let dir = tempfile::tempdir().unwrap();
    let file = asset("tests/fixtures/modes/nh3_planar_rhf_sto3g.molden");
    let out = dir.path().join("map.png");
    let args = ["render", &file, "--orbital", "homo", "--no-volume", "--surface", "ses", "--lavapipe"];
    ok(&[&args[..], &["--surface-color", "volume", "--size", "240x180", "-o", s(&out)]].concat());
    let img = png(&out);
    // Down a column through the bar: the map's positive end (blue) above its negative end (red).
    let column: Vec<[u8; 4]> = (0..180).map(|y| img.get_pixel(240 - 16, y).0).collect();
    let blue = column.iter().position(|p| p[2] > 150 && p[0] < 120).expect("the bar's blue end");
    let red = column.iter().rposition(|p| p[0] > 150 && p[2] < 120).expect("the bar's red end");
    assert!(blue < red, "blue at {blue}, red at {red}");
}

/// Down the column `x` of `img`: the map's positive end (blue) above its negative end (red).
fn bar_in_column(img: &image::RgbaImage, x: u32) -> bool {
    let column: Vec<[u8; 4]> = (0..img.height()).map(|y| img.get_pixel(x, y).0).collect();
    let blue = column.iter().position(|p| p[2] > 150 && p[0] < 120);
    let red = column.iter().rposition(|p| p[0] > 150 && p[2] < 120);
    matches!((blue, red), (Some(b), Some(r)) if b < r)
}

#[test]
fn every_frame_of_a_movie_of_an_esp_map_carries_its_colour_bar() {
    let dir = tempfile::tempdir().unwrap();
    let density = asset("tests/fixtures/esp/h2o_density.cube");
    let potential = asset("tests/fixtures/esp/h2o_potential.cube");
    let frames = dir.path().join("turn/");
    let args = ["movie", &density, "--turntable", "--frames", "2", "--size", "240x180", "--lavapipe", "--no-volume"];
    ok(&[&args[..], &["--iso", "0.002", "--color-by", &potential, "-o", s(&frames)]].concat());
    for k in 1..=2 {
        let img = png(&frames.join(format!("frame_000{k}.png")));
        assert!(bar_in_column(&img, 240 - 16), "frame {k} carries the bar");
    }
    // A session of the pair opened in the viewer (the potential joined the density's object)
    // turns with its bar too.
    let session = dir.path().join("pair.orbcloud.toml");
    let map = QuantityState::esp_map(Source::Volume(0), Source::Volume(1), &RenderSettings::default());
    let object = ObjectState {
        path: Some(density.clone().into()),
        added: vec![AddedVolume::Joined { path: potential.clone().into() }],
        quantities: vec![map],
        ..Default::default()
    };
    let saved = Session { objects: vec![object], ..Default::default() };
    orbcloud::sources::session::write(&session, &saved).unwrap();
    let frames = dir.path().join("session/");
    ok(&["movie", s(&session), "--turntable", "--frames", "2", "--size", "240x180", "--lavapipe", "-o", s(&frames)]);
    assert!(bar_in_column(&png(&frames.join("frame_0001.png")), 240 - 16), "the session's movie carries the bar");
}

#[test]
fn a_session_turns_as_saved() {
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("scene.orbcloud.toml");
    let cube = asset("assets/demo.cube.gz");
    std::fs::write(
        &session,
        format!("background = [0.9, 0.9, 0.9]\n[[objects]]\npath = {cube:?}\n[[objects.quantities]]\nsource = {{ Volume = 0 }}\n"),
    )
    .unwrap();
    let frames = dir.path().join("turn/");
    ok(&["movie", s(&session), "--turntable", "--frames", "3", "--size", "64x48", "--lavapipe", "-o", s(&frames)]);
    let first = png(&frames.join("frame_0001.png"));
    assert_eq!(std::fs::read_dir(&frames).unwrap().count(), 3);
    // The session's light background, not the default dark one.
    assert!(first.get_pixel(0, 0).0[0] > 200, "{:?}", first.get_pixel(0, 0));
    assert!(common::mean_difference(&first, &png(&frames.join("frame_0002.png"))) > 0.1, "it turns");
    let broken = dir.path().join("none.orbcloud.toml");
    std::fs::write(&broken, "[[objects]]\npath = \"/nonexistent.cube\"\n").unwrap();
    let out = orbcloud(&["movie", s(&broken), "--turntable", "-o", "x.gif"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("/nonexistent.cube"), "{err}");
}
