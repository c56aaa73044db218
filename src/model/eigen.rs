//! Eigenvalues and eigenvectors of small symmetric matrices by Jacobi rotations: the principal
//! axes of a molecule (3×3) and the rotation that superposes two shapes (4×4, Horn's method).

/// The eigenvalues (the diagonal left) and eigenvectors (columns: `v[row][k]` belongs to
/// eigenvalue k) of the symmetric matrix `a`, by Jacobi rotations of its largest off-diagonal
/// element (the first of equals, pairs in row order) until every one is below 1e-14, at most
/// `rotations` of them.
pub fn symmetric_eigen<const N: usize>(mut a: [[f64; N]; N], rotations: usize) -> ([f64; N], [[f64; N]; N]) {
    let mut v = [[0.0; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let pairs: Vec<(usize, usize)> = (0..N).flat_map(|p| (p + 1..N).map(move |q| (p, q))).collect();
    for _ in 0..rotations {
        let Some(&(p, q)) = pairs.iter().max_by(|x, y| a[x.0][x.1].abs().total_cmp(&a[y.0][y.1].abs())) else { break };
        if a[p][q].abs() < 1e-14 {
            break;
        }
        let theta = 0.5 * (2.0 * a[p][q]).atan2(a[q][q] - a[p][p]);
        let (s, c) = theta.sin_cos();
        for row in &mut a {
            let (akp, akq) = (row[p], row[q]);
            row[p] = c * akp - s * akq;
            row[q] = s * akp + c * akq;
        }
        let (rp, rq) = (a[p], a[q]);
        a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
        a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
        for row in &mut v {
            let (vp, vq) = (row[p], row[q]);
            row[p] = c * vp - s * vq;
            row[q] = s * vp + c * vq;
        }
    }
    (std::array::from_fn(|i| a[i][i]), v)
}
