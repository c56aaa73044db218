//! Coarser versions of a big surface's mesh for the level of detail: the same vertices, fewer
//! triangles, each version within a known distance of the original (meshoptimizer's quadric
//! edge collapse). Where a frame shows that distance under a fraction of a pixel, drawing the
//! coarser version looks the same and costs less: a marching-cubes surface has triangles of a
//! fraction of a pixel at the scale a big molecule is framed, and a rasteriser pays per
//! triangle.

use super::isosurface::Mesh;

/// One coarser version: its triangles (indices into the original mesh's vertices) and how far
/// at most it lies from the original (the sum of the simplifier's errors on the way, in the
/// mesh's units).
#[derive(Debug, Clone, PartialEq)]
pub struct Simplified {
    pub indices: Vec<u32>,
    pub error: f32,
}

/// A version is kept only if it drops at least this share of the previous one's triangles.
const MIN_DROP: f32 = 0.15;

/// Up to `count` coarser versions of `mesh`, each from the previous one with the error bound
/// doubled, starting at `first_error` (mesh units); a bound whose version would not drop
/// enough triangles to pay for itself is skipped (doubled again).
pub fn levels(mesh: &Mesh, first_error: f32, count: usize) -> Vec<Simplified> {
    let bytes: &[u8] = bytemuck::cast_slice(&mesh.positions);
    let Ok(vertices) = meshopt::VertexDataAdapter::new(bytes, size_of::<glam::Vec3>(), 0) else {
        return Vec::new();
    };
    let mut out: Vec<Simplified> = Vec::new();
    let mut bound = first_error / 2.0;
    for _ in 0..2 * count {
        bound *= 2.0;
        if out.len() == count {
            break;
        }
        let previous = out.last().map_or(&mesh.indices, |s| &s.indices);
        let mut error = 0.0f32;
        let indices = meshopt::simplify(
            previous,
            &vertices,
            0,
            bound,
            meshopt::SimplifyOptions::ErrorAbsolute,
            Some(&mut error),
        );
        if (indices.len() as f32) > (1.0 - MIN_DROP) * previous.len() as f32 {
            continue;
        }
        let error = out.last().map_or(0.0, |s| s.error) + error;
        out.push(Simplified { indices, error });
    }
    out
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicBool;

    use glam::{DVec3, Vec3};

    use super::*;
    use crate::model::surface::{self, Sphere, SurfaceKind, SurfaceParams};

    /// Distance from `p` to the triangle a, b, c.
    fn to_triangle(p: Vec3, [a, b, c]: [Vec3; 3]) -> f32 {
        let n = (b - a).cross(c - a).normalize_or_zero();
        let q = p - n * n.dot(p - a);
        let inside = [(a, b), (b, c), (c, a)].iter().all(|&(u, v)| (v - u).cross(q - u).dot(n) >= 0.0);
        if inside {
            return (p - q).length();
        }
        let to_edge = |u: Vec3, v: Vec3| {
            let t = ((p - u).dot(v - u) / (v - u).length_squared().max(1e-12)).clamp(0.0, 1.0);
            (p - (u + t * (v - u))).length()
        };
        to_edge(a, b).min(to_edge(b, c)).min(to_edge(c, a))
    }

    /// The solvent-excluded surface of a small cluster of atoms: fewer triangles each level,
    /// every original vertex within each level's error bound of its triangles (checked by brute
    /// force on a sample), the area kept, and only the original vertices used.
    #[test]
    fn each_level_has_fewer_triangles_within_its_error() {
        let spheres: Vec<Sphere> = (0..27)
            .map(|k| Sphere {
                centre: DVec3::new((k % 3) as f64 * 2.8, (k / 3 % 3) as f64 * 2.6, (k / 9) as f64 * 3.0),
                radius: 3.2,
            })
            .collect();
        let mut params = SurfaceParams::auto(SurfaceKind::SolventExcluded, &spheres);
        params.resolution = 0.4;
        let mesh = surface::build(&spheres, &params, &AtomicBool::new(false)).unwrap().mesh;
        let levels = levels(&mesh, 0.05, 3);
        assert!(levels.len() >= 2, "{} levels", levels.len());
        let mut previous = mesh.indices.len();
        for level in &levels {
            assert!(level.indices.len() < previous, "fewer triangles each level");
            previous = level.indices.len();
            assert!(level.indices.iter().all(|&i| (i as usize) < mesh.positions.len()));
            let triangles: Vec<[Vec3; 3]> = level
                .indices
                .chunks_exact(3)
                .map(|t| [0, 1, 2].map(|k| mesh.positions[t[k] as usize]))
                .collect();
            for p in mesh.positions.iter().step_by(97) {
                let d = triangles.iter().map(|&t| to_triangle(*p, t)).fold(f32::INFINITY, f32::min);
                // The quadric error is a squared-distance sum; the distance to the nearest
                // triangle stays within the bound.
                assert!(d <= level.error * 1.01 + 1e-4, "vertex {p} is {d} from the level of error {}", level.error);
            }
            let area: f32 = triangles.iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).sum();
            let rel = area as f64 / mesh.area() - 1.0;
            assert!(rel.abs() < 0.02, "area off by {rel}");
        }
        assert!(levels[0].indices.len() * 10 < mesh.indices.len() * 9, "the first level drops a tenth");
    }
}
