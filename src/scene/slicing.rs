//! Slice geometry for volume rendering: plain math, no GPU.
//!
//! The grid's box is a parallelepiped (origin + edges, possibly non-orthogonal). Slices are
//! emitted back to front as triangle lists in world space, with the plane normal and spacing the
//! shader needs to correct opacity for the distance a ray travels between slices.

use glam::Vec3;

use super::SliceMode;

/// A parallelepiped: `origin + a·edges[0] + b·edges[1] + c·edges[2]`, a, b, c ∈ [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridBox {
    pub origin: Vec3,
    pub edges: [Vec3; 3],
}

/// Triangles of all slices, back to front, and the plane family they belong to.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Slices {
    pub vertices: Vec<Vec3>,
    /// Unit normal of the slice planes.
    pub normal: Vec3,
    /// Distance between neighbouring planes along `normal`.
    pub spacing: f32,
    /// Index of each slice's first vertex, back to front (a slice ends where the next starts).
    pub starts: Vec<u32>,
    /// Each slice's plane n·p = depth, back to front.
    pub depths: Vec<f32>,
    /// Signed distance along `normal` of the nearest plane: plane j (front to back) lies at
    /// `nearest + j·spacing`, j < `starts.len()`.
    pub nearest: f32,
}

impl GridBox {
    pub fn corners(&self) -> [Vec3; 8] {
        let e = self.edges;
        std::array::from_fn(|n| {
            self.origin + e[0] * (n & 1) as f32 + e[1] * ((n >> 1) & 1) as f32 + e[2] * ((n >> 2) & 1) as f32
        })
    }

    /// The smallest box with this box's edge directions that holds both boxes (for boxes cut
    /// from one grid, whose edges are parallel).
    pub fn union(&self, other: &GridBox) -> GridBox {
        let m = glam::Mat3::from_cols(self.edges[0], self.edges[1], self.edges[2]);
        if m.determinant().abs() < 1e-12 {
            return *self;
        }
        let inv = m.inverse();
        // Both boxes' corners in this box's coordinates (0..1 spans this box).
        let (lo, hi) = self
            .corners()
            .iter()
            .chain(other.corners().iter())
            .map(|&c| inv * (c - self.origin))
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        GridBox { origin: self.origin + m * lo, edges: std::array::from_fn(|a| self.edges[a] * (hi[a] - lo[a])) }
    }

    /// The 12 edges as pairs of corner indices.
    pub(super) const EDGES: [(usize, usize); 12] =
        [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];

    pub fn slices(&self, mode: SliceMode, count: u32, eye: Vec3, view_dir: Vec3) -> Slices {
        match mode {
            SliceMode::ViewAligned => self.view_aligned(count, view_dir),
            SliceMode::AxisAligned => self.axis_aligned(count, eye, view_dir),
        }
    }

    /// Planes perpendicular to `view_dir` (pointing away from the eye), cut from the box.
    pub fn view_aligned(&self, count: u32, view_dir: Vec3) -> Slices {
        let n = view_dir.normalize_or(Vec3::NEG_Z);
        let corners = self.corners();
        let depths = corners.map(|c| c.dot(n));
        let (lo, hi) = depths.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &d| (l.min(d), h.max(d)));
        // Whatever asks (a session, a caller's arithmetic), the slices stay a bounded allocation.
        let count = count.clamp(*super::limits::SLICES.start(), *super::limits::SLICES.end());
        let spacing = (hi - lo) / count as f32;
        let mut vertices = Vec::with_capacity(count as usize * 12);
        let mut starts = Vec::with_capacity(count as usize);
        // Far to near: the first plane is deepest.
        let depths: Vec<f32> = (0..count).map(|s| hi - (s as f32 + 0.5) * spacing).collect();
        for &d in &depths {
            starts.push(vertices.len() as u32);
            self.cut(n, d, &mut vertices);
        }
        Slices { vertices, normal: n, spacing, starts, depths, nearest: lo + 0.5 * spacing }
    }

    /// The box's section by the plane n·p = d (n a unit vector), as triangles appended to `out`.
    pub fn cut(&self, n: Vec3, d: f32, out: &mut Vec<Vec3>) {
        let corners = self.corners();
        let mut poly: Vec<Vec3> = Vec::with_capacity(6);
        for &(a, b) in &Self::EDGES {
            let (da, db) = (corners[a].dot(n) - d, corners[b].dot(n) - d);
            if (da < 0.0) != (db < 0.0) {
                poly.push(corners[a].lerp(corners[b], da / (da - db)));
            }
        }
        triangulate_convex(&mut poly, n, out);
    }

    /// Naka et al.'s three stacks: planes of constant grid coordinate along the axis that faces the
    /// viewer most directly, ordered back to front.
    pub fn axis_aligned(&self, count: u32, eye: Vec3, view_dir: Vec3) -> Slices {
        let v = view_dir.normalize_or(Vec3::NEG_Z);
        let e = self.edges;
        let normals = [e[1].cross(e[2]), e[2].cross(e[0]), e[0].cross(e[1])].map(|c| c.normalize_or(Vec3::Z));
        let axis = (0..3).max_by(|&a, &b| normals[a].dot(v).abs().total_cmp(&normals[b].dot(v).abs())).unwrap_or(0);
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        let count = count.clamp(*super::limits::SLICES.start(), *super::limits::SLICES.end());
        let mut normal = normals[axis];
        // Orient the normal away from the eye, so "back" is the larger signed distance.
        let centre = self.origin + 0.5 * (e[0] + e[1] + e[2]);
        if normal.dot(centre - eye) < 0.0 {
            normal = -normal;
        }
        let spacing = e[axis].dot(normal).abs() / count as f32;
        // Planes at fractions t along the axis; start with the one farthest from the eye.
        let far_first = e[axis].dot(normal) > 0.0;
        let mut vertices = Vec::with_capacity(count as usize * 6);
        let mut starts = Vec::with_capacity(count as usize);
        let mut depths = Vec::with_capacity(count as usize);
        for s in 0..count {
            starts.push(vertices.len() as u32);
            let i = if far_first { count - 1 - s } else { s };
            let t = (i as f32 + 0.5) / count as f32;
            let p = self.origin + e[axis] * t;
            depths.push(normal.dot(p));
            let quad = [p, p + e[u], p + e[u] + e[w], p + e[w]];
            vertices.extend_from_slice(&[quad[0], quad[1], quad[2], quad[0], quad[2], quad[3]]);
        }
        // The planes lie at t = (i + ½)/count along the axis; the nearest is the end the
        // normal points away from.
        let along = e[axis].dot(normal);
        let nearest =
            normal.dot(self.origin) + (0.5 / count as f32 * along).min((count as f32 - 0.5) / count as f32 * along);
        Slices { vertices, normal, spacing, starts, depths, nearest }
    }
}

/// The convex hull of points on one plane (basis `bu`, `bv`) as a fan of triangles appended
/// to `out`: one slice's polygon, with no seams inside it.
pub(super) fn hull_triangles(points: &mut [Vec3], bu: Vec3, bv: Vec3, out: &mut Vec<Vec3>) {
    let hull = convex_hull(points, bu, bv);
    for t in 1..hull.len().saturating_sub(1) {
        out.extend_from_slice(&[hull[0], hull[t], hull[t + 1]]);
    }
}

/// The convex hull (counter-clockwise in the basis `bu`, `bv`) of points on one plane:
/// Andrew's monotone chain on their coordinates in that basis.
fn convex_hull(points: &mut [Vec3], bu: Vec3, bv: Vec3) -> Vec<Vec3> {
    if points.len() < 3 {
        return Vec::new();
    }
    let at = |p: Vec3| (p.dot(bu), p.dot(bv));
    points.sort_by(|&a, &b| {
        let ((ax, ay), (bx, by)) = (at(a), at(b));
        ax.total_cmp(&bx).then(ay.total_cmp(&by))
    });
    let turns_left = |o: Vec3, a: Vec3, b: Vec3| {
        let ((ox, oy), (ax, ay), (bx, by)) = (at(o), at(a), at(b));
        (ax - ox) * (by - oy) - (ay - oy) * (bx - ox) > 0.0
    };
    let mut hull: Vec<Vec3> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let floor = hull.len();
        let push = |p: Vec3, hull: &mut Vec<Vec3>| {
            while hull.len() >= floor + 2 && !turns_left(hull[hull.len() - 2], hull[hull.len() - 1], p) {
                hull.pop();
            }
            hull.push(p);
        };
        if pass == 0 {
            points.iter().for_each(|&p| push(p, &mut hull));
        } else {
            points.iter().rev().for_each(|&p| push(p, &mut hull));
        }
        // The chain's last point starts the other chain.
        hull.pop();
    }
    if hull.len() < 3 { Vec::new() } else { hull }
}

impl Slices {
    /// The triangles of the same planes taken `k` at a time (back to front): slab s holds planes
    /// s·k … s·k + k − 1 from the front, and its polygon, on its front plane, is the convex hull
    /// of its planes' slices projected there from `eye`, so every pixel whose ray meets one of
    /// them is covered. None where some plane does not lie wholly beyond the eye (the eye among
    /// the planes): no projection from it covers what lies behind it.
    pub fn slabs(&self, k: usize, eye: Vec3) -> Option<Vec<Vec3>> {
        let planes = self.starts.len();
        let n = self.normal;
        let eye_depth = n.dot(eye);
        let beyond = |p: &Vec3| n.dot(*p) - eye_depth > 1e-3 * self.spacing.max(1e-6);
        if k < 2 || planes == 0 || !self.vertices.iter().all(beyond) {
            return None;
        }
        let (bu, bv) = n.any_orthonormal_pair();
        let plane = |back: usize| {
            let end = self.starts.get(back + 1).map_or(self.vertices.len(), |&e| e as usize);
            &self.vertices[self.starts[back] as usize..end]
        };
        let mut vertices = Vec::with_capacity(self.vertices.len() / k + 12);
        let mut points = Vec::new();
        for s in (0..planes.div_ceil(k)).rev() {
            let front = s * k;
            let depth = self.nearest + front as f32 * self.spacing - eye_depth;
            points.clear();
            for j in front..(front + k).min(planes) {
                let back = planes - 1 - j;
                points.extend(plane(back).iter().map(|&p| eye + (p - eye) * (depth / (n.dot(p) - eye_depth))));
            }
            hull_triangles(&mut points, bu, bv, &mut vertices);
        }
        Some(vertices)
    }
}

/// Orders the points of a convex planar polygon by angle around its centroid and emits a fan.
fn triangulate_convex(poly: &mut [Vec3], normal: Vec3, out: &mut Vec<Vec3>) {
    if poly.len() < 3 {
        return;
    }
    let centroid = poly.iter().copied().sum::<Vec3>() / poly.len() as f32;
    let (bu, bv) = normal.any_orthonormal_pair();
    poly.sort_by(|a, b| {
        let (da, db) = (*a - centroid, *b - centroid);
        da.dot(bv).atan2(da.dot(bu)).total_cmp(&db.dot(bv).atan2(db.dot(bu)))
    });
    for i in 1..poly.len() - 1 {
        out.extend_from_slice(&[poly[0], poly[i], poly[i + 1]]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> GridBox {
        GridBox { origin: Vec3::ZERO, edges: [Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0] }
    }

    fn area(tris: &[Vec3]) -> f32 {
        tris.chunks(3).map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()).sum()
    }

    #[test]
    fn view_aligned_slices_of_a_cube_along_an_axis_are_full_squares() {
        let s = unit_cube().view_aligned(10, Vec3::NEG_Z);
        assert_eq!(s.vertices.len(), 10 * 2 * 3);
        assert!((s.spacing - 0.2).abs() < 1e-6);
        assert!((area(&s.vertices) - 10.0 * 4.0).abs() < 1e-3);
        // Back to front: looking down −z, the first slice has the smallest z.
        assert!(s.vertices[0].z < s.vertices.last().unwrap().z);
    }

    #[test]
    fn absurd_slice_counts_stay_a_bounded_allocation() {
        let most = *crate::scene::limits::SLICES.end() as usize;
        let view = unit_cube().view_aligned(4_000_000_000, Vec3::NEG_Z);
        let axis = unit_cube().axis_aligned(u32::MAX, Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
        assert_eq!((view.starts.len(), axis.starts.len()), (most, most));
        assert_eq!(unit_cube().view_aligned(0, Vec3::NEG_Z).starts.len(), 1);
    }

    #[test]
    fn diagonal_view_gives_hexagons_inside_the_box() {
        let b = unit_cube();
        let s = b.view_aligned(9, Vec3::new(1.0, 1.0, 1.0));
        for v in &s.vertices {
            assert!(v.cmpge(Vec3::splat(-1e-4)).all() && v.cmple(Vec3::splat(2.0 + 1e-4)).all(), "{v}");
        }
        // The middle slice through the centre of a cube perpendicular to a diagonal is a regular
        // hexagon of side √2·(edge/2): area (3√3/2)·2.
        let mid: Vec<Vec3> = s.vertices.iter().copied().filter(|v| (v.dot(Vec3::ONE) - 3.0).abs() < 1e-3).collect();
        assert_eq!(mid.len(), 4 * 3);
        assert!((area(&mid) - 3.0 * 3f32.sqrt()).abs() < 1e-3);
        // All triangles wind consistently (no inverted fan).
        for t in s.vertices.chunks(3) {
            assert!((t[1] - t[0]).cross(t[2] - t[0]).dot(Vec3::ONE) > 0.0);
        }
    }

    #[test]
    fn axis_aligned_picks_the_facing_stack_back_to_front() {
        let b = GridBox { origin: Vec3::ZERO, edges: [Vec3::X * 4.0, Vec3::new(1.0, 2.0, 0.0), Vec3::Z * 3.0] };
        let eye = Vec3::new(2.0, 1.0, 20.0);
        let s = b.axis_aligned(6, eye, Vec3::new(0.1, 0.0, -1.0));
        assert!((s.normal - Vec3::NEG_Z).length() < 1e-6);
        assert!((s.spacing - 0.5).abs() < 1e-6);
        assert!(s.vertices[0].z < s.vertices[6].z);
        // Looking along x instead picks the stack spanned by the other two edges.
        let s = b.axis_aligned(4, Vec3::new(-20.0, 1.0, 1.5), Vec3::X);
        assert!(s.normal.z.abs() < 1e-6 && s.normal.x > 0.5);
        assert!(s.vertices[0].x > s.vertices[6].x);
    }

    #[test]
    fn plane_j_from_the_front_lies_at_nearest_plus_j_spacings() {
        let b = GridBox {
            origin: Vec3::new(-1.0, 0.5, 0.0),
            edges: [Vec3::X * 4.0, Vec3::new(1.0, 2.0, 0.0), Vec3::Z * 3.0],
        };
        let eye = Vec3::new(2.0, 1.0, 20.0);
        for s in [
            b.view_aligned(7, Vec3::new(0.2, -0.3, -1.0)),
            b.axis_aligned(6, eye, Vec3::new(0.1, 0.0, -1.0)),
            b.axis_aligned(5, Vec3::new(2.0, 1.0, -20.0), Vec3::new(0.1, 0.0, 1.0)),
        ] {
            let count = s.starts.len();
            for (back_to_front, &start) in s.starts.iter().enumerate() {
                let j = count - 1 - back_to_front;
                let d = s.normal.dot(s.vertices[start as usize]);
                assert!((d - (s.nearest + j as f32 * s.spacing)).abs() < 1e-4, "plane {j}: {d} vs {}", s.nearest);
            }
        }
    }

    /// Whether `p` (on the plane of the triangles, normal `n`) lies in one of them.
    fn covered(tris: &[Vec3], p: Vec3, n: Vec3) -> bool {
        tris.chunks(3).any(|t| {
            let side = |a: Vec3, b: Vec3| (b - a).cross(p - a).dot(n);
            let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
            s.iter().all(|&v| v >= -1e-4) || s.iter().all(|&v| v <= 1e-4)
        })
    }

    #[test]
    fn a_slab_covers_every_ray_that_meets_one_of_its_planes() {
        let b = GridBox {
            origin: Vec3::new(-1.0, 0.5, 0.0),
            edges: [Vec3::X * 4.0, Vec3::new(1.0, 2.0, 0.0), Vec3::Z * 3.0],
        };
        let eye = Vec3::new(9.0, -4.0, 14.0);
        let centre = b.origin + 0.5 * (b.edges[0] + b.edges[1] + b.edges[2]);
        for (s, k) in [(b.view_aligned(21, centre - eye), 8), (b.axis_aligned(13, eye, centre - eye), 4)] {
            let tris = s.slabs(k, eye).expect("the eye is before every plane");
            let planes = s.starts.len();
            // Fewer, larger polygons; each slab's on its front plane.
            assert!(tris.len() < s.vertices.len());
            for (j, &start) in s.starts.iter().rev().enumerate() {
                let back = planes - 1 - j;
                let end = s.starts.get(back + 1).map_or(s.vertices.len(), |&e| e as usize);
                let front_depth = s.nearest + (j / k * k) as f32 * s.spacing;
                let slab: Vec<Vec3> =
                    tris.iter().copied().filter(|v| (s.normal.dot(*v) - front_depth).abs() < 1e-4).collect();
                assert!(!slab.is_empty(), "plane {j}'s slab");
                // Every point of plane j's slice, seen from the eye, falls inside its slab.
                let tri = &s.vertices[start as usize..end];
                let points = tri.chunks(3).flat_map(|t| [t[0], t[1], t[2], (t[0] + t[1] + t[2]) / 3.0]);
                for p in points {
                    let q = eye + (p - eye) * ((front_depth - s.normal.dot(eye)) / s.normal.dot(p - eye));
                    assert!(covered(&slab, q, s.normal), "plane {j}: {p} seen at {q}");
                }
            }
        }
        // The eye among the planes: no slabs.
        assert!(b.view_aligned(21, Vec3::Z).slabs(8, centre).is_none());
    }
}
