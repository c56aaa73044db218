//! The electrostatic potential from wavefunction files against PySCF's (`int1e_rinv` per point,
//! scripts/make_esp_fixtures.py): cartesian and pure bases, d to h functions, restricted and
//! unrestricted, cations, a pseudopotential's core charge; Molden and fchk files of the same
//! calculations give the same potential; far away the potential is the net charge over the
//! distance. Volume arithmetic (`eval`/`cube --minus`) against PySCF's density difference.

use std::path::Path;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::esp::{Potential, Scratch};
use serde::Deserialize;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");
/// Agreement with PySCF (a.u.): the bound.
const TOL: f64 = 1e-6;

#[derive(Deserialize)]
struct Reference {
    source: String,
    charge: i32,
    points: Vec<[f64; 3]>,
    esp: Vec<f64>,
}

fn reference(name: &str) -> Reference {
    let path = format!("{FIXTURES}/esp/{name}.json");
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn potential(path: &Path) -> Potential {
    let doc = formats::load(path).unwrap_or_else(|e| panic!("{e}"));
    let wf = doc.wavefunction.as_ref().expect("a wavefunction");
    Potential::new(&doc.molecule, wf)
}

fn check(name: &str, file: &str) {
    let r = reference(name);
    let v = potential(&Path::new(FIXTURES).join(file));
    let points: Vec<DVec3> = r.points.iter().map(|p| DVec3::from_array(*p)).collect();
    let got = v.at_points(&points);
    let worst = got.iter().zip(&r.esp).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < TOL, "{file}: largest difference from PySCF {worst:.2e} a.u.");
    assert!((v.total_charge() - r.charge as f64).abs() < 1e-6, "{file}: charge {}", v.total_charge());
}

#[test]
fn molden_files_match_pyscf() {
    for name in ["h2o_cart_631gs", "h2o_ccpvtz", "h2o_cation_uhf_631gs", "h3o_cation_631gss", "benzene_631gs"] {
        let r = reference(name);
        check(name, &r.source);
    }
}

#[test]
fn fchk_files_match_pyscf() {
    for name in ["h2o_cart_631gs", "h2o_ccpvtz", "h2o_cation_uhf_631gs", "h3o_cation_631gss"] {
        check(name, &format!("wavefunctions/{name}.fchk"));
    }
}

#[test]
fn d_to_h_functions_match_pyscf() {
    check("h2_spdfgh", "wavefunctions/h2_spdfgh.molden");
}

#[test]
fn a_pseudopotential_uses_the_core_charge() {
    // Iodine's nucleus counts as +25 (fchk "Nuclear charges"), not +53: the molecule is neutral.
    check("hi_def2svp_ecp", "esp/hi_def2svp_ecp.fchk");
}

#[test]
fn far_away_the_potential_is_the_net_charge_over_the_distance() {
    for (file, charge) in [("wavefunctions/h2o_cation_uhf_631gs.molden", 1.0), ("wavefunctions/h2o_ccpvtz.fchk", 0.0)] {
        let v = potential(&Path::new(FIXTURES).join(file));
        let mut s = Scratch::default();
        for r in [200.0, 2000.0] {
            let at = v.at(DVec3::new(0.3, -0.2, 0.9).normalize() * r, &mut s);
            // The dipole term falls off as 1/r², so r·V → q to within |μ|/r.
            assert!((at * r - charge).abs() < 2.0 / r, "{file}: r·V = {} at r = {r}", at * r);
        }
    }
}

#[test]
fn eight_points_at_a_time_give_each_points_own_bits() {
    // Grids and point lists are evaluated eight neighbours at a time where the CPU allows,
    // masking the pairs a point takes as far fields; each value must be the one-point sum's,
    // bit for bit, for every angular momentum (s to h pairs), near nuclei and far out, with rows
    // whose length is not a multiple of eight and short lists of points.
    use orbcloud::model::GridSpec;
    for file in ["wavefunctions/benzene_631gs.molden", "wavefunctions/h2_spdfgh.molden", "esp/hi_def2svp_ecp.fchk"] {
        let doc = formats::load(&Path::new(FIXTURES).join(file)).unwrap();
        let v = Potential::new(&doc.molecule, doc.wavefunction.as_ref().unwrap());
        let (lo, hi) = doc.molecule.bounds().unwrap();
        let grid = GridSpec::cube(lo - DVec3::splat(4.0), hi + DVec3::splat(4.0), 19);
        let rows = v.on_grid(&grid);
        let mut s = Scratch::default();
        let mut points = Vec::new();
        for i in 0..19 {
            for j in 0..19 {
                for k in 0..19 {
                    let p = grid.point(i, j, k);
                    let one = v.at(p, &mut s);
                    let got = rows[(i * 19 + j) * 19 + k];
                    assert_eq!(got.to_bits(), one.to_bits(), "{file}: point {p}: {got:e} against {one:e}");
                    points.push(p);
                }
            }
        }
        for list in [&points[..], &points[5..16], &points[..3]] {
            for (p, got) in list.iter().zip(v.at_points(list)) {
                assert_eq!(got.to_bits(), v.at(*p, &mut s).to_bits(), "{file}: listed point {p}");
            }
        }
    }
}

#[test]
fn far_fields_agree_with_the_exact_sum_on_a_grid() {
    // Every point of a grid around the molecule, from inside the nuclei's cusps to the box's
    // corners: the far fields change the potential by less than their stated bound.
    use orbcloud::model::GridSpec;
    use orbcloud::model::esp::FAR_FIELD_ERROR;
    for file in ["wavefunctions/benzene_631gs.molden", "wavefunctions/h2_spdfgh.molden", "esp/hi_def2svp_ecp.fchk"] {
        let doc = formats::load(&Path::new(FIXTURES).join(file)).unwrap();
        let v = Potential::new(&doc.molecule, doc.wavefunction.as_ref().unwrap());
        let (lo, hi) = doc.molecule.bounds().unwrap();
        let grid = GridSpec::cube(lo - DVec3::splat(5.0), hi + DVec3::splat(5.0), 17);
        let fast = v.on_grid(&grid);
        let mut s = Scratch::default();
        let mut worst: f64 = 0.0;
        for i in 0..17 {
            for j in 0..17 {
                for k in 0..17 {
                    let exact = v.exact_at(grid.point(i, j, k), &mut s);
                    worst = worst.max((fast[(i * 17 + j) * 17 + k] - exact).abs());
                }
            }
        }
        assert!(worst <= FAR_FIELD_ERROR, "{file}: far fields off by {worst:.2e}");
        eprintln!("{file}: far fields within {worst:.1e} of the exact sum");
    }
}

fn orbcloud(args: &[&str]) -> std::process::Output {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().expect("run orbcloud");
    assert!(out.status.success(), "orbcloud {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Vertices (bohr) and `value` of a binary PLY written by `mesh` with `--color-by`.
fn ply_values(path: &Path) -> Vec<(DVec3, f32, [u8; 3])> {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.contains("property float value\n"), "{header}");
    let n: usize = header.lines().find_map(|l| l.strip_prefix("element vertex ")).unwrap().parse().unwrap();
    let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    (0..n)
        .map(|i| {
            let o = end + i * (6 * 4 + 3 + 4);
            let angstrom = DVec3::new(f(o) as f64, f(o + 4) as f64, f(o + 8) as f64);
            let rgb = [bytes[o + 24], bytes[o + 25], bytes[o + 26]];
            (angstrom * orbcloud::model::units::BOHR_PER_ANGSTROM, f(o + 27), rgb)
        })
        .collect()
}

#[test]
fn a_density_surface_coloured_by_the_potential_carries_it_per_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("esp.ply");
    let file = format!("{FIXTURES}/wavefunctions/h2o_ccpvtz.molden");
    orbcloud(&["mesh", &file, "--density", "--iso", "0.002", "--color-by", "esp", "-o", out.to_str().unwrap()]);
    let vertices = ply_values(&out);
    assert!(vertices.len() > 1000, "{} vertices", vertices.len());
    let doc = formats::load(Path::new(&file)).unwrap();
    let wf = doc.wavefunction.as_ref().unwrap();
    let v = Potential::new(&doc.molecule, wf);
    let basis = orbcloud::model::gto::PreparedBasis::new(&wf.basis);
    let mut s = Scratch::default();
    let (mut negative, mut positive) = (0, 0);
    for (p, value, rgb) in vertices.iter().step_by(37) {
        // On the surface: the density is 0.002 to within the grid's linear interpolation.
        let rho = basis.density(wf, *p);
        assert!((rho - 0.002).abs() < 4e-4, "ρ = {rho} at a vertex");
        // The value written is the potential there (f32).
        let exact = v.exact_at(*p, &mut s);
        assert!((*value as f64 - exact).abs() < 1e-6 + 1e-6 * exact.abs(), "{value} vs {exact}");
        // Red where negative (the lone pairs), blue where positive (the hydrogens).
        if exact < -0.01 {
            negative += 1;
            assert!(rgb[0] > rgb[2], "{rgb:?} for {exact}");
        } else if exact > 0.01 {
            positive += 1;
            assert!(rgb[2] > rgb[0], "{rgb:?} for {exact}");
        }
    }
    assert!(negative > 0 && positive > 0, "{negative} negative, {positive} positive vertices");
}

#[test]
fn eval_and_cube_print_the_potential() {
    let r = reference("h2o_cart_631gs");
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("points.txt");
    let text: String = r.points.iter().map(|p| format!("{} {} {}\n", p[0], p[1], p[2])).collect();
    std::fs::write(&points, text).unwrap();
    let file = format!("{FIXTURES}/{}", r.source);
    let out = orbcloud(&["eval", &file, "--esp", "--points", points.to_str().unwrap()]);
    let printed: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect();
    assert_eq!(printed.len(), r.esp.len());
    for (a, b) in printed.iter().zip(&r.esp) {
        assert!((a - b).abs() < TOL, "eval --esp {a} vs PySCF {b}");
    }
    // The cube holds the same potential at its grid points.
    let cube = dir.path().join("esp.cube");
    orbcloud(&["cube", &file, "--esp", "--grid", "12", "--margin", "3", "-o", cube.to_str().unwrap()]);
    let grid = formats::load(&cube).unwrap().volumes.remove(0);
    let v = potential(Path::new(&file));
    let mut s = Scratch::default();
    for (i, j, k) in [(0, 0, 0), (5, 6, 7), (11, 11, 11), (3, 9, 1)] {
        let want = v.exact_at(grid.point(i, j, k), &mut s);
        let got = grid.value(i, j, k) as f64;
        assert!((got - want).abs() < 1e-5 * want.abs().max(1.0), "cube {got} vs {want}");
    }
}

/// Volume arithmetic: water's density in cc-pVTZ minus the same in 6-31G*, by PySCF at points.
#[derive(Deserialize)]
struct Difference {
    a: String,
    b: String,
    points: Vec<[f64; 3]>,
    difference: Vec<f64>,
}

#[test]
fn eval_and_cube_subtract_another_files_quantity() {
    let r: Difference =
        serde_json::from_str(&std::fs::read_to_string(format!("{FIXTURES}/esp/density_difference.json")).unwrap())
            .unwrap();
    let (a, b) = (format!("{FIXTURES}/{}", r.a), format!("{FIXTURES}/{}", r.b));
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("points.txt");
    std::fs::write(&points, r.points.iter().map(|p| format!("{} {} {}\n", p[0], p[1], p[2])).collect::<String>())
        .unwrap();
    let out = orbcloud(&["eval", &a, "--density", "--minus", &b, "--points", points.to_str().unwrap()]);
    let printed: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect();
    assert_eq!(printed.len(), r.difference.len());
    for (got, want) in printed.iter().zip(&r.difference) {
        assert!((got - want).abs() < 1e-8 + 1e-7 * want.abs(), "Δρ {got} vs PySCF {want}");
    }

    // On a grid: A's cube minus B's equals the difference cube; B as a cube file on another
    // grid is resampled onto A's (trilinear: close where the density is smooth).
    let path = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let grid = ["--grid", "16", "--margin", "3"];
    let run = |file: &str, extra: &[&str], out: &str| {
        let mut args = vec!["cube", file, "--density"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out]);
        orbcloud(&args);
        formats::load(Path::new(out)).unwrap().volumes.remove(0)
    };
    let ga = run(&a, &grid, &path("a.cube"));
    let gb = run(&b, &grid, &path("b.cube"));
    let diff = run(&a, &[&grid[..], &["--minus", &b]].concat(), &path("diff.cube"));
    for ((d, x), y) in diff.values.iter().zip(&ga.values).zip(&gb.values) {
        assert!((d - (x - y)).abs() <= 1e-5 * x.abs().max(y.abs()).max(1e-3), "{d} vs {x} − {y}");
    }
    let fine_b = run(&b, &["--grid", "61", "--margin", "4"], &path("b_fine.cube"));
    assert_ne!(fine_b.dims, diff.dims);
    let resampled = run(&a, &[&grid[..], &["--minus", &path("b_fine.cube")]].concat(), &path("resampled.cube"));
    let mut compared = 0;
    for ((r, d), y) in resampled.values.iter().zip(&diff.values).zip(&gb.values) {
        // Where B's density is low and smooth, far from the nuclei's cusps: there a trilinear
        // sample of its 0.2-bohr grid holds to a few per cent.
        if *y < 0.02 {
            assert!((r - d).abs() < 5e-4 + 0.05 * y, "resampled {r} vs {d} (ρ_B {y})");
            compared += 1;
        }
    }
    assert!(compared > 3000, "{compared} points compared");

    // A cube that does not overlap the grid is refused, saying so.
    let text = std::fs::read_to_string(path("b.cube")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let words: Vec<&str> = lines[2].split_whitespace().collect();
    lines[2] = format!("{} 500.0 500.0 500.0", words[0]);
    std::fs::write(path("far.cube"), lines.join("\n") + "\n").unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_orbcloud"))
        .args(["cube", &a, "--density", "--grid", "16", "--minus", &path("far.cube"), "-o", &path("x.cube")])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(said.contains("far.cube") && said.contains("does not overlap"), "{said}");
}
