//! Writing an 80³ cube (6.7 MB of text): formatting into memory, writing a file, and what the
//! machine allows for bytes of that size (copying them in memory, writing them to a file
//! unformatted). Threads follow RAYON_NUM_THREADS.

use std::hint::black_box;
use std::io::Write;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use orbcloud::formats::cube_write;
use orbcloud::model::{Atom, GridSpec, Molecule};

/// A 2p-like orbital on an n³ grid: values from about 1e-12 to 1e-1, both signs.
fn orbital(n: usize) -> (GridSpec, Vec<f32>) {
    let step = 0.2;
    let origin = DVec3::splat(-(n as f64 - 1.0) * step / 2.0);
    let spec = GridSpec::new(origin, [DVec3::X * step, DVec3::Y * step, DVec3::Z * step], [n; 3]);
    let mut values = Vec::with_capacity(n * n * n);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = spec.point(i, j, k);
                values.push((p.z * (-0.9 * p.length()).exp() * 0.1 + 1e-12 * p.x) as f32);
            }
        }
    }
    (spec, values)
}

fn bench(c: &mut Criterion) {
    let (spec, values) = orbital(80);
    let molecule = Molecule::new(vec![Atom { z: 6, charge: 6.0, position: DVec3::ZERO, ghost: false }]);
    let mut text = Vec::new();
    cube_write::write_values_to(&mut text, "t", "d", &molecule, &spec, &[(&values, 1)]).expect("memory");
    let dir = std::env::temp_dir().join(format!("orbcloud-cube-write-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let path = dir.join("bench.cube");
    let mut group = c.benchmark_group("cube_write");
    group.sample_size(30);
    group.throughput(Throughput::Bytes(text.len() as u64));
    let mut memory = Vec::with_capacity(text.len() + 4096);
    group.bench_function("format_80cubed_to_memory", |b| {
        b.iter(|| {
            memory.clear();
            cube_write::write_values_to(&mut memory, "t", "d", &molecule, &spec, &[(black_box(&values), 1)])
                .expect("memory");
        });
    });
    // A new file each time (the old one removed outside the timing): truncating the file just
    // written would wait for the kernel to write it back.
    let remove = || {
        let _ = std::fs::remove_file(&path);
    };
    group.bench_function("format_80cubed_to_file", |b| {
        b.iter_batched(
            remove,
            |()| {
                let file = std::fs::File::create(&path).expect("file");
                let mut w = std::io::BufWriter::with_capacity(cube_write::BLOCK / 4, file);
                cube_write::write_values_to(&mut w, "t", "d", &molecule, &spec, &[(black_box(&values), 1)])
                    .expect("file");
            },
            BatchSize::PerIteration,
        );
    });
    // The limits: the same bytes copied in memory, and written to the file as they are.
    let mut copy = vec![0u8; text.len()];
    group.bench_function("copy_same_bytes_in_memory", |b| b.iter(|| copy.copy_from_slice(black_box(&text))));
    group.bench_function("write_same_bytes_to_file", |b| {
        b.iter_batched(
            remove,
            |()| {
                let mut file = std::fs::File::create(&path).expect("file");
                for block in black_box(&text).chunks(cube_write::BLOCK) {
                    file.write_all(block).expect("file");
                }
            },
            BatchSize::PerIteration,
        );
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
