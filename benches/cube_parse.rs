//! Cube parsing throughput on a synthetic 128³ orbital written the way Gaussian writes it.

use std::fmt::Write;
use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};

/// `-1.23456E-03` in a 13-character field, as Fortran's `E13.5` writes it.
fn push_e13_5(out: &mut String, v: f64) {
    if v == 0.0 {
        out.push_str("  0.00000E+00");
        return;
    }
    let mut exp = v.abs().log10().floor() as i32;
    let mut mantissa = v.abs() / 10f64.powi(exp);
    if format!("{mantissa:.5}").starts_with("10") {
        mantissa /= 10.0;
        exp += 1;
    }
    let sign = if v < 0.0 { '-' } else { ' ' };
    let esign = if exp < 0 { '-' } else { '+' };
    let _ = write!(out, " {sign}{mantissa:.5}E{esign}{:02}", exp.abs());
}

/// A 2p-like orbital on an n³ grid: values from 1e-12 to 1e-1, both signs.
fn synthetic_cube(n: usize) -> String {
    let step = 0.2;
    let origin = -(n as f64 - 1.0) * step / 2.0;
    let mut s = String::with_capacity(n * n * n * 14 + 1024);
    s.push_str(" Synthetic orbital\n MO 1\n");
    let _ = writeln!(s, "    2 {origin:11.6} {origin:11.6} {origin:11.6}");
    for a in 0..3 {
        let v = [0, 1, 2].map(|b| if a == b { step } else { 0.0 });
        let _ = writeln!(s, "  {n:3} {:11.6} {:11.6} {:11.6}", v[0], v[1], v[2]);
    }
    s.push_str("    6    6.000000    0.000000    0.000000   -1.200000\n");
    s.push_str("    8    8.000000    0.000000    0.000000    1.200000\n");
    for i in 0..n {
        let x = origin + i as f64 * step;
        for j in 0..n {
            let y = origin + j as f64 * step;
            for k in 0..n {
                let z = origin + k as f64 * step;
                let r2 = x * x + y * y + z * z;
                push_e13_5(&mut s, z * (-0.9 * r2.sqrt()).exp() * 0.1 + 1e-12 * x);
                if k % 6 == 5 || k == n - 1 {
                    s.push('\n');
                }
            }
        }
    }
    s
}

fn bench(c: &mut Criterion) {
    let text = synthetic_cube(128);
    let doc = orbcloud::formats::cube::parse("synthetic.cube", &text).expect("synthetic cube parses");
    assert_eq!(doc.volumes[0].values.len(), 128 * 128 * 128);
    let mut group = c.benchmark_group("cube");
    group.throughput(Throughput::Bytes(text.len() as u64));
    group.sample_size(20);
    group.bench_function("parse_128^3", |b| {
        b.iter(|| orbcloud::formats::cube::parse("synthetic.cube", black_box(&text)).expect("parses"));
    });
    group.bench_function("read_128^3", |b| {
        b.iter(|| orbcloud::formats::cube::CubeFile::parse("synthetic.cube", black_box(&text)).expect("parses"));
    });
    // Baseline: the standard library's tokenizer and float parser, one thread, data section only.
    let data = &text[text.match_indices('\n').nth(7).map_or(0, |(i, _)| i + 1)..];
    group.throughput(Throughput::Bytes(data.len() as u64));
    group.bench_function("std_split_parse_f32_128^3", |b| {
        b.iter(|| {
            black_box(data).split_ascii_whitespace().map(|t| t.parse::<f32>().expect("a number")).collect::<Vec<f32>>()
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
