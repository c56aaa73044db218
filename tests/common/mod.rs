//! Shared by the GPU tests: the lavapipe context, synthetic scenes and golden-image checks.
#![allow(dead_code, reason = "each test binary uses some of these helpers")]

pub mod cloud;

use std::path::PathBuf;

use glam::DVec3;
use orbcloud::gpu::{AdapterPreference, GpuContext};
use orbcloud::model::{Atom, Document, Molecule, VolumeGrid, units::BOHR_PER_ANGSTROM};

/// The test adapter: Mesa lavapipe on Vulkan. Fails loudly (never skips) when it is missing.
pub fn lavapipe() -> GpuContext {
    let ctx = GpuContext::headless(AdapterPreference::LavapipeOnly).unwrap_or_else(|e| {
        panic!("GPU tests need the Vulkan CPU adapter (lavapipe): {e}. Install: apt-get install -y mesa-vulkan-drivers libvulkan1")
    });
    assert_eq!(ctx.info.backend, wgpu::Backend::Vulkan, "tests must run on Vulkan, got {}", ctx.describe());
    eprintln!("test adapter: {}", ctx.describe());
    ctx
}

fn atom(z: u32, ang: [f64; 3]) -> Atom {
    Atom { z, charge: z as f64, position: DVec3::from(ang) * BOHR_PER_ANGSTROM, ghost: false }
}

/// Formaldehyde-like skeleton in the xy plane, C=O along x, centred near the origin.
pub fn formaldehyde() -> Molecule {
    Molecule::new(vec![
        atom(6, [-0.6, 0.0, 0.0]),
        atom(8, [0.61, 0.0, 0.0]),
        atom(1, [-1.15, 0.94, 0.0]),
        atom(1, [-1.15, -0.94, 0.0]),
    ])
}

/// A π-like orbital: ψ = z·exp(−r²/σ²) around the C=O midpoint, on an `n`³ grid, optionally
/// sheared (non-orthogonal axes).
pub fn p_orbital(n: usize, sheared: bool) -> VolumeGrid {
    let half = 4.5;
    let h = 2.0 * half / (n - 1) as f64;
    let steps = if sheared {
        [DVec3::new(h, 0.0, 0.0), DVec3::new(0.35 * h, h, 0.0), DVec3::new(0.0, 0.2 * h, h)]
    } else {
        [DVec3::new(h, 0.0, 0.0), DVec3::new(0.0, h, 0.0), DVec3::new(0.0, 0.0, h)]
    };
    let origin = DVec3::splat(-half)
        - if sheared { 0.5 * (n - 1) as f64 * (steps[1] - DVec3::new(0.0, h, 0.0)) } else { DVec3::ZERO };
    let world = VolumeGrid::affine(origin, steps);
    let mut values = Vec::with_capacity(n * n * n);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = world.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                let r2 = (p - DVec3::new(0.3, 0.0, 0.0)).length_squared();
                values.push((p.z * (-r2 / 4.0).exp()) as f32);
            }
        }
    }
    VolumeGrid::new(if sheared { "sheared p" } else { "p" }, [n, n, n], world, values)
}

pub fn scene(with_volume: Option<VolumeGrid>) -> Document {
    Document {
        source: "synthetic".into(),
        title: "formaldehyde-like test scene".into(),
        molecule: formaldehyde(),
        volumes: with_volume.into_iter().collect(),
        ..Document::default()
    }
}

/// Compares `actual` with tests/golden/NAME.png (lavapipe output). Writes NAME.actual.png and
/// NAME.diff.png on failure; `ORBCLOUD_BLESS=1` rewrites the reference.
///
/// Tolerance: lavapipe is bit-identical run to run, so the check is tight but not exact (other
/// Mesa versions round a few edge pixels differently): at most 0.5% of pixels may differ by more
/// than 8/255 in any channel, and the mean absolute difference must stay below 1/255.
pub fn assert_golden(name: &str, actual: &image::RgbaImage) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let reference = dir.join(format!("{name}.png"));
    if blessing() {
        actual.save(&reference).unwrap();
        eprintln!("blessed {}", reference.display());
        return;
    }
    let expected = image::open(&reference)
        .unwrap_or_else(|e| panic!("{}: {e} (run with ORBCLOUD_BLESS=1 to create it)", reference.display()))
        .to_rgba8();
    assert_eq!(expected.dimensions(), actual.dimensions(), "{name}: size differs from the reference");
    let mut diff = image::RgbaImage::new(actual.width(), actual.height());
    let (mut bad, mut sum) = (0usize, 0u64);
    for (x, y, a) in actual.enumerate_pixels() {
        let e = expected.get_pixel(x, y);
        let d = (0..4).map(|c| (a[c] as i32 - e[c] as i32).unsigned_abs()).max().unwrap_or(0);
        sum += d as u64;
        if d > 8 {
            bad += 1;
        }
        let v = (d * 8).min(255) as u8;
        diff.put_pixel(x, y, image::Rgba([v, v, v, 255]));
    }
    let n = (actual.width() * actual.height()) as usize;
    let mean = sum as f64 / n as f64;
    if bad * 200 > n || mean > 1.0 {
        actual.save(dir.join(format!("{name}.actual.png"))).unwrap();
        diff.save(dir.join(format!("{name}.diff.png"))).unwrap();
        panic!(
            "{name}: {bad} of {n} pixels differ by > 8/255, mean |diff| {mean:.3}/255; see tests/golden/{name}.actual.png and .diff.png"
        );
    }
}

/// Whether golden images are to be rewritten: `ORBCLOUD_BLESS=1` (or `true`); any other value,
/// `0` included, compares.
pub fn blessing() -> bool {
    bless_value(std::env::var_os("ORBCLOUD_BLESS").as_deref())
}

pub fn bless_value(v: Option<&std::ffi::OsStr>) -> bool {
    v.and_then(|v| v.to_str()).is_some_and(|v| matches!(v.trim().to_ascii_lowercase().as_str(), "1" | "true"))
}

/// The shared real-world corpus: `../shared/refdata/real-world` beside the checkout, or
/// `ORBCLOUD_REFDATA`.
pub fn refdata_dir() -> PathBuf {
    std::env::var_os("ORBCLOUD_REFDATA")
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/refdata/real-world"), PathBuf::from)
}

/// [`refdata_dir`] when it exists. `None` when it is absent: the test prints one line saying it
/// did not run and why, and passes, unless `ORBCLOUD_REQUIRE_REFDATA=1` (CI), where a missing
/// corpus fails.
pub fn refdata(test: &str) -> Option<PathBuf> {
    let dir = refdata_dir();
    let required = std::env::var_os("ORBCLOUD_REQUIRE_REFDATA").is_some_and(|v| v == "1");
    refdata_in(test, dir, required)
}

pub fn refdata_in(test: &str, dir: PathBuf, required: bool) -> Option<PathBuf> {
    if dir.is_dir() {
        return Some(dir);
    }
    let why = format!("{test}: not run: the reference corpus {} is absent", dir.display());
    assert!(!required, "{why} and ORBCLOUD_REQUIRE_REFDATA=1 requires it");
    // Straight to the stream: the test harness would hide a println! of a passing test.
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{why}");
    None
}

/// Fraction of pixels that differ from the background colour by more than a few counts.
pub fn coverage(img: &image::RgbaImage, background: [u8; 3]) -> f64 {
    let covered = img.pixels().filter(|p| (0..3).any(|c| (p[c] as i32 - background[c] as i32).abs() > 6)).count();
    covered as f64 / (img.width() * img.height()) as f64
}

/// Mean absolute difference of two pictures per colour channel, 0..255.
/// Mean and largest per-channel difference (RGB, /255) between two pictures of one size.
pub fn mean_max_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u8) {
    let (mut sum, mut max) = (0u64, 0u8);
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = p[c].abs_diff(q[c]);
            sum += d as u64;
            max = max.max(d);
        }
    }
    (sum as f64 / (a.width() * a.height() * 3) as f64, max)
}

pub fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: u64 =
        a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum::<u64>()).sum();
    sum as f64 / (3 * a.width() * a.height()) as f64
}

/// A p orbital ψ = p[axis]·exp(−r²/2) (axis 2: p_z) in a box of ±4.5 bohr: beyond r ≈ 3 bohr
/// |ψ| is under 5 % of its maximum, so the box holds plenty of empty space.
pub fn compact_p_orbital(n: usize, axis: usize) -> orbcloud::model::VolumeGrid {
    let h = 9.0 / (n - 1) as f64;
    let world = orbcloud::model::VolumeGrid::affine(
        glam::DVec3::splat(-4.5),
        [glam::DVec3::X * h, glam::DVec3::Y * h, glam::DVec3::Z * h],
    );
    let values = (0..n * n * n)
        .map(|m| {
            let p =
                world.transform_point3(glam::DVec3::new((m / (n * n)) as f64, ((m / n) % n) as f64, (m % n) as f64));
            (p[axis] * (-p.length_squared() / 2.0).exp()) as f32
        })
        .collect();
    orbcloud::model::VolumeGrid::new("compact p", [n, n, n], world, values)
}

/// `count` deterministic points (xorshift) in the box of `doc`'s atoms padded by 3 bohr: where
/// two readers' wavefunctions are compared value by value.
pub fn points_around(doc: &Document, count: usize) -> Vec<DVec3> {
    let (lo, hi) =
        doc.molecule.atoms.iter().fold((DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)), |(lo, hi), a| {
            (lo.min(a.position), hi.max(a.position))
        });
    let (lo, hi) = (lo - 3.0, hi + 3.0);
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count).map(|_| lo + (hi - lo) * DVec3::new(next(), next(), next())).collect()
}
