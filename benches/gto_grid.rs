//! One orbital on an 80³ grid: benzene B3LYP/6-31G* HOMO (96 basis functions), the box PySCF's
//! cubegen uses (atoms + 3 bohr on each side). Compare with scripts/bench_cube_vs_pyscf.py.
//! Threads follow RAYON_NUM_THREADS.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use orbcloud::model::basis::{Basis, Shell, ShellKind};
use orbcloud::model::gto::{GridSpec, PreparedBasis};
use serde_json::Value;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/gto/benzene_631gs.json");

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
}

/// The basis, the HOMO's coefficients and the atom positions of the fixture.
fn benzene() -> (Basis, Vec<f64>, Vec<DVec3>) {
    let fx: Value = serde_json::from_str(&std::fs::read_to_string(FIXTURE).expect("fixture")).expect("json");
    let atoms: Vec<DVec3> = fx["atoms"]
        .as_array()
        .expect("atoms")
        .iter()
        .map(|a| {
            let p = floats(&a["xyz"]);
            DVec3::new(p[0], p[1], p[2])
        })
        .collect();
    let shells = fx["shells"]
        .as_array()
        .expect("shells")
        .iter()
        .map(|s| {
            let atom = s["atom"].as_u64().expect("atom") as usize;
            Shell {
                atom,
                center: atoms[atom],
                l: s["l"].as_u64().expect("l") as u32,
                kind: if s["pure"].as_bool().expect("pure") { ShellKind::Pure } else { ShellKind::Cartesian },
                exponents: floats(&s["exponents"]),
                coefficients: floats(&s["coefficients"]),
            }
        })
        .collect();
    let homo = fx["homo"].as_u64().expect("homo");
    let orbital = fx["orbitals"]
        .as_array()
        .expect("orbitals")
        .iter()
        .find(|o| o["index"].as_u64() == Some(homo) && o["spin"] == "alpha")
        .expect("HOMO");
    (Basis { shells }, floats(&orbital["coefficients"]), atoms)
}

fn cubegen_grid(atoms: &[DVec3], n: usize) -> GridSpec {
    let margin = 3.0;
    let lo = atoms.iter().fold(DVec3::splat(f64::INFINITY), |a, p| a.min(*p));
    let hi = atoms.iter().fold(DVec3::splat(f64::NEG_INFINITY), |a, p| a.max(*p));
    let step = (hi - lo + 2.0 * margin) / (n - 1) as f64;
    GridSpec::new(lo - DVec3::splat(margin), [DVec3::X * step.x, DVec3::Y * step.y, DVec3::Z * step.z], [n; 3])
}

fn bench(c: &mut Criterion) {
    let (basis, homo, atoms) = benzene();
    let grid = cubegen_grid(&atoms, 80);
    let prepared = PreparedBasis::new(&basis);
    let mut group = c.benchmark_group("gto_grid");
    group.sample_size(20);
    group.throughput(Throughput::Elements(grid.len() as u64));
    group.bench_function("benzene_homo_80cubed", |b| {
        b.iter(|| black_box(prepared.eval_grid_f32(black_box(&homo), &grid)));
    });
    group.bench_function("prepare_basis", |b| b.iter(|| black_box(PreparedBasis::new(black_box(&basis)))));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
