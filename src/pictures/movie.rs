//! Movies: a sequence of rendered frames written as numbered PNG files, an animated GIF (a
//! palette per frame, dithered), an animated PNG, or an MP4/WebM video through `ffmpeg`; and the
//! sweeps a movie is made of (a scan's coordinate, a turntable, a vibration's period).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use image::RgbaImage;

#[derive(Debug, thiserror::Error)]
pub enum MovieError {
    #[error(
        "{path}: writing .{ext} needs ffmpeg on PATH (Debian/Ubuntu: apt-get install ffmpeg); without it \
         orbcloud writes .gif, .apng or a folder of PNG frames (-o DIR/)"
    )]
    NoFfmpeg { path: String, ext: String },
    #[error(
        "{path}: unknown movie format; give a folder (DIR/, numbered PNG frames), .gif, .apng, .png (animated), .mp4 \
         or .webm"
    )]
    UnknownFormat { path: String },
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    #[error("{path}: ffmpeg failed: {message}")]
    Ffmpeg { path: String, message: String },
    #[error("frame {index} is {got:?}, the movie's frames are {want:?}")]
    FrameSize { index: usize, got: (u32, u32), want: (u32, u32) },
}

/// How a movie is written, from the output's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MovieFormat {
    /// A folder of numbered PNG files (`-o DIR/`, or a path without an extension).
    Frames,
    Gif,
    /// Animated PNG (`.apng`, or `.png`).
    Apng,
    /// Through ffmpeg: H.264 in MP4, or VP9 in WebM.
    Mp4,
    Webm,
}

impl MovieFormat {
    /// The format `path` asks for.
    pub fn of(path: &Path) -> Result<Self, MovieError> {
        let text = path.to_string_lossy();
        if text.ends_with('/') || path.is_dir() {
            return Ok(MovieFormat::Frames);
        }
        match path.extension().map(|e| e.to_string_lossy().to_lowercase()) {
            None => Ok(MovieFormat::Frames),
            Some(e) if e == "gif" => Ok(MovieFormat::Gif),
            Some(e) if e == "apng" || e == "png" => Ok(MovieFormat::Apng),
            Some(e) if e == "mp4" => Ok(MovieFormat::Mp4),
            Some(e) if e == "webm" => Ok(MovieFormat::Webm),
            Some(_) => Err(MovieError::UnknownFormat { path: text.into_owned() }),
        }
    }

    /// Whether this format can be written on this machine: the video formats need ffmpeg.
    pub fn check(self, path: &Path) -> Result<(), MovieError> {
        if matches!(self, MovieFormat::Mp4 | MovieFormat::Webm) && !ffmpeg_available() {
            let ext = if self == MovieFormat::Mp4 { "mp4" } else { "webm" };
            return Err(MovieError::NoFfmpeg { path: path.display().to_string(), ext: ext.into() });
        }
        Ok(())
    }
}

/// Whether `ffmpeg` runs.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Values swept evenly from `from` to `to`, both ends included; with `bounce` the way back
/// follows without repeating either end, so the movie loops smoothly.
pub fn sweep(from: f64, to: f64, frames: usize, bounce: bool) -> Vec<f64> {
    let n = frames.max(1);
    let forward: Vec<f64> =
        (0..n).map(|k| if n == 1 { from } else { from + (to - from) * k as f64 / (n - 1) as f64 }).collect();
    let back: Vec<f64> = if bounce && n > 2 { forward[1..n - 1].iter().rev().copied().collect() } else { Vec::new() };
    forward.into_iter().chain(back).collect()
}

/// Angles (radians) of one full turn in `frames` steps, the last one short of the first again
/// (so the movie loops without a repeated frame). A vibration's phases are the same.
pub fn full_turn(frames: usize) -> Vec<f64> {
    let n = frames.max(1);
    (0..n).map(|k| std::f64::consts::TAU * k as f64 / n as f64).collect()
}

/// Where frames go.
enum Sink {
    Frames { dir: PathBuf, digits: usize },
    Gif(gif::Encoder<BufWriter<File>>),
    Apng(png::Writer<BufWriter<File>>),
    Video(Child),
}

/// Writes a movie frame by frame: every frame the same size, `frames` of them (the animated
/// PNG states its count up front).
pub struct MovieWriter {
    path: PathBuf,
    sink: Sink,
    size: (u32, u32),
    fps: f64,
    written: usize,
}

impl MovieWriter {
    /// Opens `path` for a movie of `frames` frames of `size` at `fps` frames per second.
    pub fn create(path: &Path, size: [u32; 2], fps: f64, frames: usize) -> Result<Self, MovieError> {
        let format = MovieFormat::of(path)?;
        format.check(path)?;
        let io = |e: std::io::Error| MovieError::Io { path: path.display().to_string(), message: e.to_string() };
        let fps = fps.clamp(0.1, 120.0);
        let (w, h) = (size[0], size[1]);
        let sink = match format {
            MovieFormat::Frames => {
                std::fs::create_dir_all(path).map_err(io)?;
                Sink::Frames { dir: path.to_path_buf(), digits: frames.max(1).to_string().len().max(4) }
            }
            MovieFormat::Gif => {
                let file = BufWriter::new(File::create(path).map_err(io)?);
                let (gw, gh) = (w.min(u16::MAX as u32) as u16, h.min(u16::MAX as u32) as u16);
                let mut encoder = gif::Encoder::new(file, gw, gh, &[]).map_err(|e| gif_error(path, e))?;
                encoder.set_repeat(gif::Repeat::Infinite).map_err(|e| gif_error(path, e))?;
                Sink::Gif(encoder)
            }
            MovieFormat::Apng => {
                let file = BufWriter::new(File::create(path).map_err(io)?);
                let mut encoder = png::Encoder::new(file, w, h);
                encoder.set_color(png::ColorType::Rgba);
                encoder.set_depth(png::BitDepth::Eight);
                let png_err =
                    |e: png::EncodingError| MovieError::Io { path: path.display().to_string(), message: e.to_string() };
                encoder.set_animated(frames.max(1) as u32, 0).map_err(png_err)?;
                let (num, den) = frame_delay(fps);
                encoder.set_frame_delay(num, den).map_err(png_err)?;
                Sink::Apng(encoder.write_header().map_err(png_err)?)
            }
            MovieFormat::Mp4 | MovieFormat::Webm => Sink::Video(spawn_ffmpeg(path, format, [w, h], fps).map_err(io)?),
        };
        Ok(Self { path: path.to_path_buf(), sink, size: (w, h), fps, written: 0 })
    }

    /// Adds the next frame.
    pub fn push(&mut self, frame: &RgbaImage) -> Result<(), MovieError> {
        if frame.dimensions() != self.size {
            return Err(MovieError::FrameSize { index: self.written, got: frame.dimensions(), want: self.size });
        }
        let path = self.path.display().to_string();
        let io = |e: std::io::Error| MovieError::Io { path: path.clone(), message: e.to_string() };
        match &mut self.sink {
            Sink::Frames { dir, digits } => {
                let name = dir.join(format!("frame_{:0width$}.png", self.written + 1, width = *digits));
                frame
                    .save(&name)
                    .map_err(|e| MovieError::Io { path: name.display().to_string(), message: e.to_string() })?;
            }
            Sink::Gif(encoder) => {
                let mut gif_frame = quantize(frame);
                gif_frame.delay = (100.0 / self.fps).round().clamp(2.0, 65535.0) as u16;
                encoder.write_frame(&gif_frame).map_err(|e| gif_error(&self.path, e))?;
            }
            Sink::Apng(writer) => {
                writer
                    .write_image_data(frame.as_raw())
                    .map_err(|e| MovieError::Io { path: path.clone(), message: e.to_string() })?;
            }
            Sink::Video(child) => {
                let stdin = child.stdin.as_mut().expect("ffmpeg's input is piped");
                stdin.write_all(frame.as_raw()).map_err(io)?;
            }
        }
        self.written += 1;
        Ok(())
    }

    /// Frames written so far.
    pub fn written(&self) -> usize {
        self.written
    }

    /// Finishes the file (waits for ffmpeg); returns where it went.
    pub fn finish(self) -> Result<PathBuf, MovieError> {
        let path = self.path.display().to_string();
        match self.sink {
            Sink::Frames { .. } => {}
            Sink::Gif(encoder) => {
                let mut file = encoder.into_inner().map_err(|e| gif_error(&self.path, e))?;
                file.flush().map_err(|e| MovieError::Io { path: path.clone(), message: e.to_string() })?;
            }
            Sink::Apng(writer) => {
                writer.finish().map_err(|e| MovieError::Io { path: path.clone(), message: e.to_string() })?;
            }
            Sink::Video(mut child) => {
                drop(child.stdin.take());
                let out = child
                    .wait_with_output()
                    .map_err(|e| MovieError::Io { path: path.clone(), message: e.to_string() })?;
                if !out.status.success() {
                    let message = String::from_utf8_lossy(&out.stderr).trim().lines().last().unwrap_or("").to_string();
                    return Err(MovieError::Ffmpeg { path, message });
                }
            }
        }
        Ok(self.path)
    }
}

fn gif_error(path: &Path, e: gif::EncodingError) -> MovieError {
    MovieError::Io { path: path.display().to_string(), message: e.to_string() }
}

/// A frame delay as a fraction of a second, as APNG states it.
fn frame_delay(fps: f64) -> (u16, u16) {
    if (fps - fps.round()).abs() < 1e-6 { (1, fps.round() as u16) } else { ((1000.0 / fps).round() as u16, 1000) }
}

fn spawn_ffmpeg(path: &Path, format: MovieFormat, size: [u32; 2], fps: f64) -> std::io::Result<Child> {
    let mut command = Command::new("ffmpeg");
    command.args(["-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba"]);
    command.args(["-s", &format!("{}x{}", size[0], size[1]), "-r", &format!("{fps}"), "-i", "-"]);
    // 4:2:0 video needs even sides: pad by a pixel where a side is odd.
    command.args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"]);
    match format {
        MovieFormat::Webm => command.args(["-c:v", "libvpx-vp9", "-b:v", "0", "-crf", "32", "-pix_fmt", "yuv420p"]),
        _ => command.args(["-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", "18", "-movflags", "+faststart"]),
    };
    command.arg(path).stdin(Stdio::piped()).stdout(Stdio::null()).stderr(Stdio::piped()).spawn()
}

/// A frame as a GIF frame: a palette of its own (NeuQuant), Floyd–Steinberg dithered against
/// it, so smooth clouds do not band; pixels less than half opaque become the transparent
/// index.
fn quantize(frame: &RgbaImage) -> gif::Frame<'static> {
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let opaque: Vec<u8> = frame.pixels().flat_map(|p| [p.0[0], p.0[1], p.0[2], 255]).collect();
    let has_clear = frame.pixels().any(|p| p.0[3] < 128);
    let colors = if has_clear { 255 } else { 256 };
    let quant = color_quant::NeuQuant::new(10, colors, &opaque);
    let palette_rgb = quant.color_map_rgb();
    let mut palette = palette_rgb.clone();
    let clear = has_clear.then(|| {
        palette.extend_from_slice(&[0, 0, 0]);
        (palette.len() / 3 - 1) as u8
    });
    // Floyd–Steinberg: each pixel's quantisation error spread to its unvisited neighbours.
    let mut work: Vec<[f32; 3]> = frame.pixels().map(|p| [p.0[0] as f32, p.0[1] as f32, p.0[2] as f32]).collect();
    let mut indices = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if let (Some(c), true) = (clear, frame.as_raw()[4 * i + 3] < 128) {
                indices[i] = c;
                continue;
            }
            // Clamped before the error is taken, so an unreachable colour cannot run away.
            let v = work[i].map(|c| c.clamp(0.0, 255.0));
            let k = nearest(&palette_rgb, v);
            indices[i] = k as u8;
            let got = &palette_rgb[3 * k..3 * k + 3];
            let err = [v[0] - got[0] as f32, v[1] - got[1] as f32, v[2] - got[2] as f32];
            let mut spread = |dx: isize, dy: usize, weight: f32| {
                let (nx, ny) = (x as isize + dx, y + dy);
                if nx >= 0 && (nx as usize) < w && ny < h {
                    let n = &mut work[ny * w + nx as usize];
                    for c in 0..3 {
                        n[c] += err[c] * weight;
                    }
                }
            };
            spread(1, 0, 7.0 / 16.0);
            spread(-1, 1, 3.0 / 16.0);
            spread(0, 1, 5.0 / 16.0);
            spread(1, 1, 1.0 / 16.0);
        }
    }
    let mut out = gif::Frame::from_palette_pixels(w as u16, h as u16, indices, palette, clear);
    out.dispose = gif::DisposalMethod::Background;
    out
}

/// The palette entry nearest `c` (squared distance in RGB).
fn nearest(palette: &[u8], c: [f32; 3]) -> usize {
    let mut best = (f32::INFINITY, 0);
    for (k, p) in palette.chunks_exact(3).enumerate() {
        let d = (p[0] as f32 - c[0]).powi(2) + (p[1] as f32 - c[1]).powi(2) + (p[2] as f32 - c[2]).powi(2);
        if d < best.0 {
            best = (d, k);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_include_both_ends_and_bounce_without_repeats() {
        assert_eq!(sweep(0.0, 180.0, 5, false), [0.0, 45.0, 90.0, 135.0, 180.0]);
        assert_eq!(sweep(0.0, 180.0, 5, true), [0.0, 45.0, 90.0, 135.0, 180.0, 135.0, 90.0, 45.0]);
        assert_eq!(sweep(10.0, 20.0, 1, true), [10.0]);
        let turn = full_turn(4);
        assert_eq!(turn.len(), 4);
        assert!((turn[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn formats_follow_the_name() {
        assert_eq!(MovieFormat::of(Path::new("out/")).unwrap(), MovieFormat::Frames);
        assert_eq!(MovieFormat::of(Path::new("a.GIF")).unwrap(), MovieFormat::Gif);
        assert_eq!(MovieFormat::of(Path::new("a.apng")).unwrap(), MovieFormat::Apng);
        assert_eq!(MovieFormat::of(Path::new("a.webm")).unwrap(), MovieFormat::Webm);
        assert!(MovieFormat::of(Path::new("a.avi")).unwrap_err().to_string().contains(".gif"));
    }

    #[test]
    fn dithering_keeps_a_smooth_ramp_smooth() {
        // A grey ramp with more shades than a palette could name exactly: dithered, each
        // column's mean stays near its true value.
        let img = RgbaImage::from_fn(64, 32, |x, _| {
            let v = (x * 4) as u8;
            image::Rgba([v, v / 2, 255 - v, 255])
        });
        let f = quantize(&img);
        let palette = f.palette.as_ref().unwrap();
        // Means over 8-column blocks (error diffuses sideways as well as down).
        for x0 in [0usize, 24, 56] {
            let mut sum = 0.0;
            for y in 0..32 {
                for x in x0..x0 + 8 {
                    sum += palette[3 * f.buffer[y * 64 + x] as usize] as f32;
                }
            }
            let (mean, truth) = (sum / 256.0, (x0 * 4 + 14) as f32);
            assert!((mean - truth).abs() < 3.0, "columns {x0}..: {mean} vs {truth}");
        }
    }
}
