//! The grid an orbital or density is evaluated on holds it: on every face of the box |ψ| stays
//! under 1 % of its largest value (ρ under 1e-4 a.u.), where atoms plus a fixed margin cut
//! diffuse orbitals off.

use glam::DVec3;
use orbcloud::model::extent::{DENSITY_FACE, FACE_FRACTION, quantity_box};
use orbcloud::model::gto::{GridSpec, PreparedBasis};
use orbcloud::model::orbitals::{Quantity, Spin};

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");

/// The largest |value| on the box's faces and inside it, on an `n`³ grid.
fn face_and_max(values: &[f64], n: usize) -> (f64, f64) {
    face_and_max_of(values, [n; 3])
}

/// The largest |value| on the faces of a grid of `dims` and inside it.
fn face_and_max_of(values: &[f64], dims: [usize; 3]) -> (f64, f64) {
    let (mut face, mut max) = (0.0f64, 0.0f64);
    for i in 0..dims[0] {
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                let v = values[(i * dims[1] + j) * dims[2] + k].abs();
                max = max.max(v);
                if [i, j, k].iter().zip(dims).any(|(&x, n)| x == 0 || x == n - 1) {
                    face = face.max(v);
                }
            }
        }
    }
    (face, max)
}

#[test]
fn orbitals_and_densities_decay_inside_their_box() {
    let n = 48;
    let mut cut_by_a_fixed_margin = 0;
    for file in ["h2o_ccpvtz.molden", "benzene_631gs.fchk", "h3o_cation_631gss.molden", "h2o_cation_uhf_631gs.fchk"] {
        let doc = orbcloud::formats::load(&std::path::Path::new(FIXTURES).join(file)).unwrap();
        let wf = doc.wavefunction.as_ref().unwrap();
        let prepared = PreparedBasis::new(&wf.basis);
        let homo = wf.homo(Spin::Alpha).unwrap();
        let lumo = wf.lumo(Spin::Alpha).unwrap();
        let mut quantities = vec![Quantity::Density, Quantity::Orbital(homo), Quantity::Orbital(homo - 1)];
        quantities.extend((0..4).map(|k| Quantity::Orbital(lumo + k)));
        for q in quantities {
            let eval = |lo: DVec3, hi: DVec3| {
                let step = (hi - lo) / (n - 1) as f64;
                let spec = GridSpec::new(lo, [DVec3::X * step.x, DVec3::Y * step.y, DVec3::Z * step.z], [n; 3]);
                match q {
                    Quantity::Orbital(i) => prepared.eval_grid(&wf.orbitals[i].coefficients, &spec),
                    _ => prepared.density_grid(wf, &spec),
                }
            };
            let (lo, hi) = quantity_box(wf, &doc.molecule, q).unwrap();
            let (face, max) = face_and_max(&eval(lo, hi), n);
            let limit = if q == Quantity::Density { DENSITY_FACE } else { FACE_FRACTION * max };
            assert!(face <= limit, "{file} {q:?}: faces reach {face:.2e} (max {max:.2e})");
            // The old box: the atoms plus 4.5 bohr.
            let (alo, ahi) = doc.molecule.bounds().unwrap();
            let (old_face, old_max) = face_and_max(&eval(alo - DVec3::splat(4.5), ahi + DVec3::splat(4.5)), n);
            eprintln!(
                "{file} {q:?}: faces {:.2} % of max in a {:.1}×{:.1}×{:.1} bohr box (atoms + 4.5 bohr: {:.1} %)",
                100.0 * face / max,
                (hi - lo).x,
                (hi - lo).y,
                (hi - lo).z,
                100.0 * old_face / old_max
            );
            cut_by_a_fixed_margin += usize::from(old_face > FACE_FRACTION * old_max && q != Quantity::Density);
        }
    }
    assert!(cut_by_a_fixed_margin > 0, "no orbital here needs more than a fixed margin: the test shows nothing");
}

#[test]
fn a_scans_key_grid_holds_every_key_orbital() {
    use orbcloud::model::scan::Follow;
    let file = orbcloud::sources::demo::scan().unwrap();
    let scan = &file.scan;
    let tracks = scan.track(Follow::Index).unwrap();
    let grid = scan.key_grid(&tracks, orbcloud::scene::framing::ORBITAL_MARGIN, 40);
    let mut worst: f64 = 0.0;
    for slot in 0..scan.orbitals.len() {
        for frame in 0..scan.frames.len() {
            let values: Vec<f64> = scan.key_values(&tracks, slot, frame, &grid).into_iter().map(f64::from).collect();
            let (face, max) = face_and_max_of(&values, grid.dims);
            worst = worst.max(face / max);
        }
    }
    eprintln!("PSB3 key grid {:?}: faces at most {:.2} % of max |ψ|", grid.dims, 100.0 * worst);
    assert!(worst <= FACE_FRACTION, "faces reach {:.2} % of max |ψ|", 100.0 * worst);
}
