//! The rigid motion that lays one set of points on another best (least squares), by Horn's
//! quaternion method: the rotation is the eigenvector of the largest eigenvalue of a symmetric
//! 4×4 matrix built from the two sets' cross-covariance. Scans use it to blend two key frames'
//! shapes whatever orientation each file was written in.

use glam::{DQuat, DVec3};

use super::eigen::symmetric_eigen;

/// The rotation `r` and translation `t` minimising Σ|r·mobile + t − target|² (equal weights).
/// Fewer than two points, or a degenerate set, give the identity rotation.
pub fn superpose(mobile: &[DVec3], target: &[DVec3]) -> (DQuat, DVec3) {
    let n = mobile.len().min(target.len());
    if n == 0 {
        return (DQuat::IDENTITY, DVec3::ZERO);
    }
    let cm = mobile[..n].iter().copied().sum::<DVec3>() / n as f64;
    let ct = target[..n].iter().copied().sum::<DVec3>() / n as f64;
    // Cross-covariance S[a][b] = Σ m_a · t_b of the centred points.
    let mut s = [[0.0f64; 3]; 3];
    for (m, t) in mobile[..n].iter().zip(&target[..n]) {
        let (m, t) = ((*m - cm).to_array(), (*t - ct).to_array());
        for a in 0..3 {
            for b in 0..3 {
                s[a][b] += m[a] * t[b];
            }
        }
    }
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = s;
    let k = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let (values, vectors) = symmetric_eigen(k, 200);
    let best = (0..4).max_by(|&a, &b| values[a].total_cmp(&values[b])).unwrap_or(0);
    let [w, x, y, z] = std::array::from_fn(|i| vectors[i][best]);
    let q = DQuat::from_xyzw(x, y, z, w);
    let rotation = if q.length() > 1e-12 { q.normalize() } else { DQuat::IDENTITY };
    (rotation, ct - rotation * cm)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moved_copy_is_laid_back_exactly() {
        let points = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.8, 0.0, 0.0),
            DVec3::new(-0.5, 1.7, 0.0),
            DVec3::new(0.3, 0.4, 1.1),
        ];
        let r = DQuat::from_euler(glam::EulerRot::XYZ, 0.7, -1.2, 2.5);
        let t = DVec3::new(3.0, -1.0, 0.5);
        let moved: Vec<DVec3> = points.iter().map(|p| r * *p + t).collect();
        let (rot, shift) = superpose(&moved, &points);
        for (m, p) in moved.iter().zip(&points) {
            assert!((rot * *m + shift).distance(*p) < 1e-10);
        }
        // Three collinear points: any rotation about their line fits; the fit is still exact.
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        let turned: Vec<DVec3> = line.iter().map(|p| r * *p).collect();
        let (rot, shift) = superpose(&turned, &line);
        assert!(turned.iter().zip(&line).all(|(m, p)| (rot * *m + shift).distance(*p) < 1e-9));
        assert_eq!(superpose(&[], &[]).0, DQuat::IDENTITY);
    }
}
