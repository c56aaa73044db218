//! Gradient lines of a map: paths along the quantity's gradient in the plane (Multiwfn's
//! gradient lines; for the density, Bader's trajectories of ∇ρ that outline the atoms' basins),
//! traced downhill by fourth-order Runge–Kutta steps on the map's own values (central
//! differences, bilinear between points) from seeds on a small circle around each atom near the
//! plane.

/// Seeds per atom, spread evenly on their circle.
pub const SEEDS_PER_ATOM: usize = 16;
/// The seeds' circle, and how close to another atom a line ends (grid steps).
const START: f64 = 1.5;
/// Step along a line (grid steps) and the most steps one takes.
const STEP: f64 = 0.4;
const MAX_STEPS: usize = 4000;

/// The lines traced from seeds around `centres` (grid coordinates, x along the fastest index)
/// on `values` (`n` × `n`), each as grid coordinates from its seed until it leaves the map, the
/// gradient vanishes, or it reaches another centre.
pub fn gradient_lines(values: &[f64], n: usize, centres: &[[f64; 2]]) -> Vec<Vec<[f64; 2]>> {
    if n < 3 || values.len() != n * n {
        return Vec::new();
    }
    let field = Field::new(values, n);
    let mut lines = Vec::new();
    for (c, centre) in centres.iter().enumerate() {
        for k in 0..SEEDS_PER_ATOM {
            let angle = std::f64::consts::TAU * k as f64 / SEEDS_PER_ATOM as f64;
            let seed = [centre[0] + START * angle.cos(), centre[1] + START * angle.sin()];
            let line = trace(&field, seed, centres, c);
            if line.len() > 2 {
                lines.push(line);
            }
        }
    }
    lines
}

/// The map's gradient at every point (central differences, one-sided at the border).
struct Field {
    n: usize,
    gx: Vec<f64>,
    gy: Vec<f64>,
}

impl Field {
    fn new(values: &[f64], n: usize) -> Self {
        let at = |i: usize, j: usize| values[j * n + i];
        let diff = |a: f64, b: f64, span: usize| (b - a) / span as f64;
        let mut gx = vec![0.0; n * n];
        let mut gy = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                let (il, ir) = (i.saturating_sub(1), (i + 1).min(n - 1));
                let (jd, ju) = (j.saturating_sub(1), (j + 1).min(n - 1));
                gx[j * n + i] = diff(at(il, j), at(ir, j), ir - il);
                gy[j * n + i] = diff(at(i, jd), at(i, ju), ju - jd);
            }
        }
        Self { n, gx, gy }
    }

    /// The gradient at grid coordinate `p`, bilinear between points; `None` outside the map
    /// or where a value is missing.
    fn at(&self, [x, y]: [f64; 2]) -> Option<[f64; 2]> {
        let last = (self.n - 1) as f64;
        if !(0.0..=last).contains(&x) || !(0.0..=last).contains(&y) {
            return None;
        }
        let (i, j) = ((x.floor() as usize).min(self.n - 2), (y.floor() as usize).min(self.n - 2));
        let (fx, fy) = (x - i as f64, y - j as f64);
        let mix = |g: &[f64]| {
            let a = |i: usize, j: usize| g[j * self.n + i];
            (a(i, j) * (1.0 - fx) + a(i + 1, j) * fx) * (1.0 - fy)
                + (a(i, j + 1) * (1.0 - fx) + a(i + 1, j + 1) * fx) * fy
        };
        let g = [mix(&self.gx), mix(&self.gy)];
        g.iter().all(|v| v.is_finite()).then_some(g)
    }

    /// The unit direction downhill at `p`.
    fn down(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let [gx, gy] = self.at(p)?;
        let norm = gx.hypot(gy);
        (norm > 1e-12).then(|| [-gx / norm, -gy / norm])
    }
}

fn trace(field: &Field, seed: [f64; 2], centres: &[[f64; 2]], own: usize) -> Vec<[f64; 2]> {
    let mut line = vec![seed];
    let mut p = seed;
    let add = |p: [f64; 2], d: [f64; 2], h: f64| [p[0] + h * d[0], p[1] + h * d[1]];
    for _ in 0..MAX_STEPS {
        let Some(k1) = field.down(p) else { break };
        let Some(k2) = field.down(add(p, k1, 0.5 * STEP)) else { break };
        let Some(k3) = field.down(add(p, k2, 0.5 * STEP)) else { break };
        let Some(k4) = field.down(add(p, k3, STEP)) else { break };
        let d = [(k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]) / 6.0, (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]) / 6.0];
        let next = add(p, d, STEP);
        // A line turning back on itself sits at a minimum or a saddle: it ends there.
        if line.len() > 2 && {
            let q = line[line.len() - 2];
            (next[0] - q[0]).hypot(next[1] - q[1]) < 0.5 * STEP
        } {
            break;
        }
        p = next;
        line.push(p);
        let near_other = centres.iter().enumerate().any(|(c, q)| c != own && (p[0] - q[0]).hypot(p[1] - q[1]) < START);
        if near_other {
            break;
        }
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_leave_a_maximum_straight_down_its_slope_to_the_border() {
        // A spherical maximum at (30, 20) on a 61-point map: every line runs radially outward.
        let n = 61;
        let c = [30.0, 20.0];
        let values: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = ((k % n) as f64, (k / n) as f64);
                (-((x - c[0]).powi(2) + (y - c[1]).powi(2)) / 200.0).exp()
            })
            .collect();
        let lines = gradient_lines(&values, n, &[c]);
        assert_eq!(lines.len(), SEEDS_PER_ATOM);
        for line in &lines {
            let (seed, end) = (line[0], *line.last().unwrap());
            let out = [seed[0] - c[0], seed[1] - c[1]];
            let last = (n - 1) as f64;
            // Within the map (its border's one-sided differences bend the last steps).
            for p in line.iter().filter(|p| p.iter().all(|&x| (2.0..=last - 2.0).contains(&x))) {
                let d = [p[0] - c[0], p[1] - c[1]];
                let sideways = (out[0] * d[1] - out[1] * d[0]).abs() / out[0].hypot(out[1]);
                assert!(sideways < 0.25, "off the radius by {sideways} at {p:?}");
            }
            let at_border = end[0] < 1.0 || end[1] < 1.0 || end[0] > last - 1.0 || end[1] > last - 1.0;
            assert!(at_border, "the line ends at the map's border: {end:?}");
        }
    }

    #[test]
    fn a_line_stops_at_another_atom() {
        // Two maxima: the lines from the first that head for the second end beside it (the
        // valley between them is a saddle, so they stop there or at the other atom).
        let n = 81;
        let (a, b) = ([25.0, 40.0], [55.0, 40.0]);
        let bump = |x: f64, y: f64, c: [f64; 2]| (-((x - c[0]).powi(2) + (y - c[1]).powi(2)) / 60.0).exp();
        let values: Vec<f64> =
            (0..n * n).map(|k| ((k % n) as f64, (k / n) as f64)).map(|(x, y)| bump(x, y, a) + bump(x, y, b)).collect();
        let lines = gradient_lines(&values, n, &[a, b]);
        assert!(lines.iter().all(|l| l.len() < MAX_STEPS), "no line wanders");
        let towards_b: Vec<_> =
            lines.iter().filter(|l| (l[0][0] - a[0] - START).abs() < 1e-9 && (l[0][1] - a[1]).abs() < 1e-9).collect();
        assert_eq!(towards_b.len(), 1, "one seed of a points straight at b");
        let end = *towards_b[0].last().unwrap();
        assert!(end[0] > a[0] && end[0] < b[0] - START + STEP, "it ends between the atoms, short of b: {end:?}");
    }
}
