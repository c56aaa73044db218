//! Fortran `E13.5` fields (` -1.23456E-04`), the layout cube files use, written without
//! `format!`: a 512 000-point cube is 6.7 MB of them, and formatting them was most of the time
//! `orbcloud cube` spent.
//!
//! A field is two little-endian words, bytes 0..8 (blank, sign, first digit, point, four more
//! digits) and bytes 8..13 (the last digit, `E`, the exponent's sign and two digits), made by
//! arithmetic without branches: a row's values become words in a loop the compiler vectorises
//! (eight values at a time with AVX-512), and the words are then stored six to a line. The
//! digits are those of the previous scalar writer, bit for bit (the tests compare the two).

use std::sync::OnceLock;

/// Powers of ten 10^k for k in [`LO`]..=[`HI`]: an f32 with six digits never needs more.
const LO: i32 = -60;
const HI: i32 = 60;
type Table = [f64; (HI - LO + 1) as usize];

/// Bytes of one field.
pub const FIELD: usize = 13;

/// Fields per line.
pub const PER_LINE: usize = 6;

/// Bytes of `n` values written six to a line, each line ended by a newline.
pub fn text_len(n: usize) -> usize {
    n * FIELD + n.div_ceil(PER_LINE)
}

/// Writes `values` into `out` ([`text_len`] bytes), six fields a line; `words` is scratch.
pub fn write_lines(values: &[f32], out: &mut [u8], words: &mut Vec<[u64; 2]>) {
    words.resize(values.len(), [0; 2]);
    fill_words(values, words);
    const LINE: usize = PER_LINE * FIELD + 1;
    let full = values.len() / PER_LINE;
    let (lines, last) = out.split_at_mut(full * LINE);
    for (line, six) in lines.chunks_exact_mut(LINE).zip(words.chunks_exact(PER_LINE)) {
        // Each field's second word is stored whole (8 bytes, 3 past the field) and overwritten
        // by the next field's first; the last field's ends the line exactly.
        for (i, w) in six[..PER_LINE - 1].iter().enumerate() {
            line[FIELD * i..FIELD * i + 8].copy_from_slice(&w[0].to_le_bytes());
            line[FIELD * i + 8..FIELD * i + 16].copy_from_slice(&w[1].to_le_bytes());
        }
        let [head, tail] = six[PER_LINE - 1];
        let end = FIELD * (PER_LINE - 1);
        line[end..end + 8].copy_from_slice(&head.to_le_bytes());
        line[end + 8..LINE].copy_from_slice(&(tail | (b'\n' as u64) << 40).to_le_bytes()[..6]);
    }
    if !last.is_empty() {
        let mut buf = [0u8; PER_LINE * FIELD + 3];
        let rest = &words[full * PER_LINE..];
        for (i, w) in rest.iter().enumerate() {
            buf[FIELD * i..FIELD * i + 8].copy_from_slice(&w[0].to_le_bytes());
            buf[FIELD * i + 8..FIELD * i + 16].copy_from_slice(&w[1].to_le_bytes());
        }
        let n = rest.len() * FIELD;
        last[..n].copy_from_slice(&buf[..n]);
        last[n] = b'\n';
    }
}

/// One value's 13 bytes.
#[cfg(test)]
fn field(v: f32) -> [u8; FIELD] {
    let w = words(v, table(), |y| y as i32 as u32);
    let mut b = [0u8; 16];
    b[..8].copy_from_slice(&w[0].to_le_bytes());
    b[8..].copy_from_slice(&w[1].to_le_bytes());
    let mut out = [0u8; FIELD];
    out.copy_from_slice(&b[..FIELD]);
    out
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    // Parsed, not multiplied, so each entry is the correctly rounded power.
    TABLE.get_or_init(|| std::array::from_fn(|i| format!("1e{}", LO + i as i32).parse().unwrap_or(0.0)))
}

fn fill_words(values: &[f32], words: &mut [[u64; 2]]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512dq") {
        // SAFETY: the CPU has the features the function is compiled for.
        unsafe { fill_words_avx512(values, words) };
        return;
    }
    fill_words_inline(values, words, |y| y as i32 as u32);
}

/// [`fill_words`] compiled for AVX-512: 64-bit multiplies, gathers from the table and
/// conversions between f64 and integers eight lanes wide.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
fn fill_words_avx512(values: &[f32], words: &mut [[u64; 2]]) {
    // `as` saturates and maps NaN to 0 lane by lane; `floor` is one instruction here, and an
    // integer below 2⁵² plus 2⁵² has it in its low bits.
    fill_words_inline(values, words, |y| (y.floor() + 4_503_599_627_370_496.0).to_bits() as u32);
}

/// `truncate(y)` is ⌊y⌋ for 0 ≤ y < 2³¹ (what a field's digits need).
#[inline(always)]
fn fill_words_inline(values: &[f32], out: &mut [[u64; 2]], truncate: impl Fn(f64) -> u32) {
    let p = table();
    for (w, &v) in out.iter_mut().zip(values) {
        *w = words(v, p, &truncate);
    }
}

/// The field of `v` as two words (see the module's documentation), six significant digits
/// rounded half up: within an ulp of a tie this may differ from exact decimal rounding in the
/// sixth digit, which a cube file's precision does not notice.
#[inline(always)]
fn words(v: f32, p: &Table, truncate: impl Fn(f64) -> u32) -> [u64; 2] {
    // Non-finite values are written as 0 (below); 0 keeps their arithmetic in range meanwhile.
    let a = if v.is_finite() { v.abs() as f64 } else { 0.0 };
    let at = |k: i32| p[(k - LO).clamp(0, HI - LO) as usize];
    // The decimal exponent from the binary one, ⌊binary · log10 2⌋ with log10 2 ≈ 1233/4096 (the
    // arithmetic shift floors negatives too), then corrected by one against the table.
    let binary = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let mut e = (binary * 1233) >> 12;
    e += (a >= at(e + 1)) as i32 - (a < at(e)) as i32;
    // Six digits, 100000..=1000000 for every finite non-zero f32 (so an i32 holds them).
    let m = truncate(a * at(5 - e) + 0.5);
    // Rounding may carry into a seventh digit (9.999996 → 10.0000).
    let carry = m >= 1_000_000;
    let m = if carry { (m + 5) / 10 } else { m };
    e += carry as i32;
    let d = ascii_digits(m);
    let sign = if v < 0.0 { b'-' } else { b' ' } as u64;
    let head = b' ' as u64 | sign << 8 | (d & 0xff_0000) | (b'.' as u64) << 24 | (d >> 24) << 32;
    // f32 exponents stay within ±45: two digits always suffice.
    let x = e.unsigned_abs().min(99);
    let exponent = (b'0' as u64 + (x / 10) as u64) | (b'0' as u64 + (x % 10) as u64) << 8;
    let exponent_sign = if e < 0 { b'-' } else { b'+' } as u64;
    let tail = d >> 56 | (b'E' as u64) << 8 | exponent_sign << 16 | exponent << 24;
    if v == 0.0 || !v.is_finite() {
        [u64::from_le_bytes(*b"  0.0000"), u64::from_le_bytes(*b"0E+00\0\0\0")]
    } else {
        [head, tail]
    }
}

/// The eight decimal digits of `n` < 10⁸ as ASCII, most significant in the lowest byte: the
/// two halves of four digits, then pairs, then digits, split in the lanes of one word.
#[inline(always)]
fn ascii_digits(n: u32) -> u64 {
    let n = n as u64;
    let x = (n / 10_000) | ((n % 10_000) << 32);
    // ⌊q / 100⌋ = (q · 10486) >> 20 for q < 10⁴, in both 32-bit lanes at once.
    let hundreds = ((x * 10486) >> 20) & 0x0000_007f_0000_007f;
    let x = hundreds | (x - hundreds * 100) << 16;
    // ⌊q / 10⌋ = (q · 103) >> 10 for q < 100, in the four 16-bit lanes.
    let tens = ((x * 103) >> 10) & 0x000f_000f_000f_000f;
    let x = tens | (x - tens * 10) << 8;
    x | 0x3030_3030_3030_3030
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The previous writer's field, kept to show the words give the same bytes.
    fn reference(v: f32) -> [u8; 13] {
        if v == 0.0 || !v.is_finite() {
            return *b"  0.00000E+00";
        }
        let p = table();
        let a = v.abs() as f64;
        let at = |k: i32| p[(k - LO).clamp(0, HI - LO) as usize];
        let binary = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
        let mut e = (binary * 1233) >> 12;
        e += (a >= at(e + 1)) as i32 - (a < at(e)) as i32;
        let mut m = (a * at(5 - e) + 0.5) as i64 as u32;
        if m >= 1_000_000 {
            m = (m + 5) / 10;
            e += 1;
        }
        let text = format!("  {}.{:05}E{}{:02}", m / 100_000, m % 100_000, if e < 0 { '-' } else { '+' }, e.abs());
        let mut b: [u8; 13] = text.as_bytes().try_into().unwrap();
        b[1] = if v < 0.0 { b'-' } else { b' ' };
        b
    }

    fn xorshift(s: &mut u64) -> u64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        *s
    }

    #[test]
    fn digits_are_correctly_rounded() {
        let mut s = 0x2545F4914F6CDD1Du64;
        for i in 0..20_000 {
            let r = xorshift(&mut s);
            let exp = (r % 70) as i32 - 40;
            let mantissa = (r >> 11) as f64 / (1u64 << 53) as f64 * 9.0 + 1.0;
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let v = (sign * mantissa * 10f64.powi(exp)) as f32;
            let text = String::from_utf8(field(v).to_vec()).unwrap();
            // Exact decimal rounding may differ in the last digit when the value sits within an
            // ulp of a tie; anything more is a bug.
            let expected: f64 = format!("{:.5E}", v as f64).parse().unwrap();
            let got: f64 = text.trim().parse().unwrap();
            assert!((got - expected).abs() <= 1.01e-5 * expected.abs(), "{v:e} → {text}");
        }
        for (v, text) in [
            (1.0f32, "  1.00000E+00"),
            (-0.000123456, " -1.23456E-04"),
            (9.999996e-3, "  1.00000E-02"),
            (0.0, "  0.00000E+00"),
            (-0.0, "  0.00000E+00"),
            (f32::NAN, "  0.00000E+00"),
            (f32::NEG_INFINITY, "  0.00000E+00"),
            (f32::MAX, "  3.40282E+38"),
            (-f32::from_bits(1), " -1.40130E-45"),
        ] {
            assert_eq!(String::from_utf8(field(v).to_vec()).unwrap(), text);
        }
    }

    /// Every bit pattern tried (random ones, and all around powers of ten and rounding
    /// carries) gives the previous writer's bytes; lines hold six fields and a newline.
    #[test]
    fn same_bytes_as_before() {
        let mut s = 0x9E3779B97F4A7C15u64;
        let mut values: Vec<f32> = (0..200_000).map(|_| f32::from_bits(xorshift(&mut s) as u32)).collect();
        for k in -45..=38 {
            let p = 10f32.powi(k);
            for d in -3i32..=3 {
                for q in [p, p * 9.99999, p * 9.999995, p * 9.999996] {
                    values.push(f32::from_bits((q.to_bits() as i32 + d) as u32));
                    values.push(-f32::from_bits((q.to_bits() as i32 + d) as u32));
                }
            }
        }
        for &v in &values {
            assert_eq!(field(v), reference(v), "{v:e} ({:#x})", v.to_bits());
        }
        let mut out = vec![0u8; text_len(values.len())];
        write_lines(&values, &mut out, &mut Vec::new());
        let expected: Vec<u8> = values
            .chunks(PER_LINE)
            .flat_map(|six| six.iter().flat_map(|&v| reference(v)).chain([b'\n']).collect::<Vec<_>>())
            .collect();
        assert!(out == expected);
    }
}
