//! The cube files of the shared real-world corpus (`../shared/refdata/real-world/`), each
//! checked against what its MANIFEST.md and its own header say.

use std::path::{Path, PathBuf};

use glam::DVec3;
use orbcloud::formats::cube::{self, CubeFile};
use orbcloud::model::units::BOHR_PER_ANGSTROM;
use orbcloud::model::{Document, VolumeGrid};

mod common;

struct Expected {
    name: &'static str,
    dims: [usize; 3],
    volumes: usize,
    atoms: usize,
    /// Atomic number and position (bohr) of the first atom.
    first_atom: (u32, DVec3),
    orthogonal: bool,
}

fn expected() -> Vec<Expected> {
    vec![
        Expected {
            name: "grid20mo6-8.cube",
            dims: [20, 20, 20],
            volumes: 3,
            atoms: 7,
            first_atom: (6, DVec3::new(-5.520036, -0.133037, 3.206199)),
            orthogonal: true,
        },
        Expected {
            name: "grid20ang.cube",
            dims: [20, 20, 20],
            volumes: 1,
            atoms: 16,
            // N1 < 0: the origin and atoms are read as ångström too.
            first_atom: (29, DVec3::new(2.317035, 3.509540, -0.795570) * BOHR_PER_ANGSTROM),
            orthogonal: true,
        },
        Expected {
            name: "aelta.cube",
            dims: [12, 12, 12],
            volumes: 1,
            atoms: 72,
            first_atom: (14, DVec3::new(-26.460812, 22.351301, 8.260143)),
            orthogonal: false,
        },
        Expected {
            name: "cubegen_h2o_5points.cube",
            dims: [5, 5, 5],
            volumes: 1,
            atoms: 3,
            first_atom: (8, DVec3::new(0.010866, 0.008050, -0.005688)),
            orthogonal: true,
        },
    ]
}

/// The corpus; every test first asks `common::refdata`, which says when it is absent.
fn dir() -> PathBuf {
    common::refdata_dir()
}

fn load(path: &Path) -> Document {
    match cube::load(path) {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    }
}

/// The `range=[min,max]` the manifest prints for `name`, as written.
fn manifest_range(name: &str) -> (String, String) {
    let manifest = std::fs::read_to_string(dir().join("MANIFEST.md")).expect("MANIFEST.md");
    let block = manifest
        .split("\n\n")
        .find(|b| b.starts_with(&format!("{name} ")))
        .unwrap_or_else(|| panic!("{name} not in MANIFEST.md"));
    let range = block.split("range=[").nth(1).and_then(|r| r.split(']').next()).expect("range=[…]");
    let (lo, hi) = range.split_once(',').expect("range=[min,max]");
    (lo.trim().to_string(), hi.trim().to_string())
}

/// `value` agrees with `printed` to the significant digits `printed` shows.
fn agrees_to_printed_digits(value: f64, printed: &str) -> bool {
    let mantissa = printed.trim_start_matches(['-', '+']).split(['e', 'E']).next().unwrap_or("");
    let digits = mantissa.replace('.', "").trim_start_matches('0').len().max(1);
    let want: f64 = printed.parse().expect("a number");
    format!("{:.*e}", digits - 1, value) == format!("{:.*e}", digits - 1, want)
}

#[test]
fn every_reference_cube_loads_as_the_manifest_says() {
    if common::refdata("refdata_cubes::every_reference_cube_loads_as_the_manifest_says").is_none() {
        return;
    }
    let table = expected();
    let mut seen = 0;
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir())
        .expect("readable corpus directory")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "cube"))
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let e = table.iter().find(|e| e.name == name).unwrap_or_else(|| panic!("{name}: no expectations"));
        let d = load(&path);
        assert_eq!(d.volumes.len(), e.volumes, "{name}: volumes");
        for g in &d.volumes {
            assert_eq!(g.dims, e.dims, "{name}: dims");
            assert_eq!(g.is_orthogonal(), e.orthogonal, "{name}: orthogonality");
        }
        assert_eq!(d.molecule.atoms.len(), e.atoms, "{name}: atoms");
        let a = &d.molecule.atoms[0];
        assert_eq!(a.z, e.first_atom.0, "{name}: first atom Z");
        assert!((a.position - e.first_atom.1).length() < 1e-6, "{name}: first atom at {}", a.position);

        let min = d.volumes.iter().map(|g| g.stats.min).fold(f64::INFINITY, f64::min);
        let max = d.volumes.iter().map(|g| g.stats.max).fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = manifest_range(&name);
        assert!(agrees_to_printed_digits(min, &lo), "{name}: min {min} vs manifest {lo}");
        assert!(agrees_to_printed_digits(max, &hi), "{name}: max {max} vs manifest {hi}");
        seen += 1;
    }
    assert_eq!(seen, table.len(), "every expected cube is in the corpus");
}

#[test]
fn multi_orbital_cube_has_its_dataset_ids() {
    if common::refdata("refdata_cubes::multi_orbital_cube_has_its_dataset_ids").is_none() {
        return;
    }
    let text = std::fs::read_to_string(dir().join("grid20mo6-8.cube")).unwrap();
    let file = CubeFile::parse("grid20mo6-8.cube", &text).unwrap();
    assert_eq!(file.natoms, -7);
    assert_eq!(file.dataset_ids, Some(vec![6, 7, 8]));
    let d = load(&dir().join("grid20mo6-8.cube"));
    let labels: Vec<&str> = d.volumes.iter().map(|g| g.label.as_str()).collect();
    assert_eq!(labels, ["MO 6", "MO 7", "MO 8"]);
    // The first values of the file belong to point (0, 0, 0) of MO 6, 7, 8 in turn.
    let first = &file.values[..6];
    assert_eq!([d.volumes[0].values[0], d.volumes[1].values[0], d.volumes[2].values[0]], first[..3]);
    assert_eq!([d.volumes[0].values[1], d.volumes[1].values[1], d.volumes[2].values[1]], first[3..6]);
}

/// Header numbers of lines 3-6: the origin and the three axis vectors.
fn header_vectors(text: &str) -> (DVec3, [DVec3; 3]) {
    let num = |line: &str, skip: usize| -> DVec3 {
        let v: Vec<f64> = line.split_whitespace().skip(skip).take(3).map(|t| t.parse().unwrap()).collect();
        DVec3::new(v[0], v[1], v[2])
    };
    let lines: Vec<&str> = text.lines().collect();
    (num(lines[2], 1), [num(lines[3], 1), num(lines[4], 1), num(lines[5], 1)])
}

#[test]
fn non_orthogonal_voxels_sit_where_the_header_says() {
    if common::refdata("refdata_cubes::non_orthogonal_voxels_sit_where_the_header_says").is_none() {
        return;
    }
    let path = dir().join("aelta.cube");
    let (origin, v) = header_vectors(&std::fs::read_to_string(&path).unwrap());
    let g = &load(&path).volumes[0];
    assert!(!g.is_orthogonal());
    for i in 0..12 {
        for j in 0..12 {
            for k in 0..12 {
                let want = origin + v[0] * i as f64 + v[1] * j as f64 + v[2] * k as f64;
                assert!((g.point(i, j, k) - want).length() < 1e-9, "({i},{j},{k})");
            }
        }
    }
}

#[test]
fn angstrom_flagged_axis_is_converted() {
    if common::refdata("refdata_cubes::angstrom_flagged_axis_is_converted").is_none() {
        return;
    }
    let g: VolumeGrid = load(&dir().join("grid20ang.cube")).volumes.remove(0);
    assert!((g.step(0) - DVec3::X * 1.151300 * BOHR_PER_ANGSTROM).length() < 1e-9, "{}", g.step(0));
    // Axes 2 and 3 carry positive counts: bohr.
    assert!((g.step(1) - DVec3::Y * 1.215025).length() < 1e-9);
    assert!((g.step(2) - DVec3::Z * 1.239406).length() < 1e-9);
}

#[test]
fn cubegen_density_integrates_to_something_positive() {
    if common::refdata("refdata_cubes::cubegen_density_integrates_to_something_positive").is_none() {
        return;
    }
    let g = load(&dir().join("cubegen_h2o_5points.cube")).volumes.remove(0);
    let integral: f64 = g.values.iter().map(|&v| v as f64).sum::<f64>() * g.voxel_volume();
    println!(
        "cubegen_h2o_5points: sum(rho) * dV = {integral:.4} electrons on a 5x5x5 grid (10 expected on a fine one)"
    );
    assert!(integral > 0.0 && integral.is_finite());
}
