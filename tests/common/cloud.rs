//! An independent CPU compositor of the slice pass: the same slice polygons, ray–triangle
//! intersection per pixel, trilinear sampling in f64 and the same opacity law.

use glam::DVec3;
use orbcloud::model::VolumeGrid;
use orbcloud::model::grid::ValueKind;
use orbcloud::scene::slicing::GridBox;
use orbcloud::scene::{Camera, RenderSettings, Shape, TransferKind, VolumeSettings};

pub fn srgb_encode(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let v = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (v * 255.0).round() as u8
}

fn ray_triangle(o: DVec3, d: DVec3, t: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-14 {
        return None;
    }
    let s = o - t[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then(|| e2.dot(q) / det)
}

/// Jang & Varetto's transfer function shapes on the signed value `s` (a fraction of max|ψ|),
/// placed at the signed centre `c` with width `w`, written out from the paper (not the
/// renderer's code): a box, the bell e^(−((s − c)/w)²), the bell's half left of its peak (s ≤ c)
/// and right of it (s ≥ c), and contours (½ + ½ cos 2π(s − c)/w)^8 from half a period inside c
/// outwards, towards the lobe's sign `outward`.
pub fn paper_shape(shape: Shape, s: f64, c: f64, w: f64, outward: f64) -> f64 {
    let w = w.max(1e-4);
    let bell = (-((s - c) / w).powi(2)).exp();
    match shape {
        Shape::Uniform if (s - c).abs() <= w / 2.0 => 1.0,
        Shape::Uniform => 0.0,
        Shape::Gaussian => bell,
        Shape::LeftHalfGaussian if s <= c => bell,
        Shape::RightHalfGaussian if s >= c => bell,
        Shape::LeftHalfGaussian | Shape::RightHalfGaussian => 0.0,
        Shape::Sinusoidal if (s - c) * outward < -w / 2.0 => 0.0,
        Shape::Sinusoidal => (0.5 + 0.5 * (std::f64::consts::TAU * (s - c) / w).cos()).powi(8),
    }
}

/// One sample of a ray: its distance from the eye, colour and opacity.
pub struct Sample {
    pub t: f64,
    pub color: [f64; 3],
    pub alpha: f64,
}

/// The slices of one frame of a cloud, sampled along rays as the GPU's slice pass does.
pub struct CloudReference<'a> {
    grid: &'a VolumeGrid,
    vs: VolumeSettings,
    tris: Vec<[DVec3; 3]>,
    spacing: f64,
    normal: DVec3,
    grid_from_world: glam::DMat4,
    /// The clipping plane (unit n, d): points with n·p > d are cut away.
    clip: Option<glam::DVec4>,
    pub eye: DVec3,
    /// The grid's mean spacing: the step the opacity law's extinction refers to.
    step: f64,
    /// Each grid point's signed extinction and colour, made by the first `classified_samples`.
    classified: std::cell::OnceCell<(VolumeGrid, VolumeGrid)>,
}

impl<'a> CloudReference<'a> {
    pub fn new(grid: &'a VolumeGrid, cam: &Camera, s: &RenderSettings) -> Self {
        let e = grid.box_edges();
        let gbox = GridBox {
            origin: grid.origin().as_vec3(),
            edges: [e.x_axis.as_vec3(), e.y_axis.as_vec3(), e.z_axis.as_vec3()],
        };
        let eye = cam.eye();
        let view_dir = (cam.target - eye).normalize();
        let slices = gbox.slices(s.volume.mode, s.volume.slices, eye, view_dir);
        let tris = slices.vertices.chunks(3).map(|t| [t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3()]).collect();
        let vs = s.volume;
        // The test scenes' atoms lie inside their grid: the object's centre is the grid's.
        let centre = gbox.origin + 0.5 * (gbox.edges[0] + gbox.edges[1] + gbox.edges[2]);
        let plane = s.clip.plane(centre).map(glam::Vec4::as_dvec4);
        Self {
            grid,
            vs,
            tris,
            spacing: slices.spacing as f64,
            normal: slices.normal.as_dvec3(),
            grid_from_world: grid.world_from_grid.inverse(),
            clip: plane,
            eye: eye.as_dvec3(),
            step: grid.voxel_volume().cbrt(),
            classified: std::cell::OnceCell::new(),
        }
    }

    /// The unit direction of the ray through the centre of pixel (px, py) of a `size` frame.
    pub fn ray(&self, cam: &Camera, size: [u32; 2], px: u32, py: u32) -> DVec3 {
        let aspect = size[0] as f32 / size[1] as f32;
        let world_from_clip = cam.clip_from_world(aspect, 20.0).inverse().as_dmat4();
        let ndc_x = (px as f64 + 0.5) / size[0] as f64 * 2.0 - 1.0;
        let ndc_y = 1.0 - (py as f64 + 0.5) / size[1] as f64 * 2.0;
        let far = world_from_clip.project_point3(DVec3::new(ndc_x, ndc_y, 0.9));
        (far - self.eye).normalize()
    }

    /// Extinction of one reference step for a value: Naka et al.'s k1·ρ^k2 or Jang and Varetto's shapes.
    fn extinction(&self, v: f64) -> f64 {
        let vs = &self.vs;
        let signed = self.grid.kind == ValueKind::Signed;
        let t = if signed { (v / self.grid.stats.max_abs).abs() } else { self.density_t(v) };
        let (k1, k2) = (vs.k1 as f64, vs.k2 as f64);
        match vs.transfer.kind {
            TransferKind::PowerLaw if signed => k1 * (t * t).powf(k2),
            TransferKind::PowerLaw => k1 * t.powf(k2),
            TransferKind::Shaped => {
                let (lobe, sign) =
                    if v >= 0.0 || !signed { (vs.transfer.positive, 1.0) } else { (vs.transfer.negative, -1.0) };
                lobe.opacity as f64
                    * paper_shape(lobe.shape, sign * t, sign * lobe.center as f64, lobe.width as f64, sign)
            }
        }
    }

    /// A density's t: on its scale (log by default), the shader's `transfer_value`.
    fn density_t(&self, v: f64) -> f64 {
        self.vs.density_scale.t(v as f32, self.grid.stats.max_abs as f32) as f64
    }

    /// The samples along the ray from the eye in direction `d`, back to front.
    pub fn samples(&self, d: DVec3) -> Vec<Sample> {
        let (pos, neg) = (self.vs.positive_color.map(|c| c as f64), self.vs.negative_color.map(|c| c as f64));
        let signed = self.grid.kind == ValueKind::Signed;
        self.points(d)
            .map(|(t, p)| {
                let v = self.grid.sample(self.grid_from_world.transform_point3(p));
                let alpha = self.opacity(self.extinction(v), d);
                let color = match (signed, v >= 0.0) {
                    (true, true) => pos,
                    (true, false) => neg,
                    // A density's colour runs from the thin to the dense end.
                    (false, _) => {
                        let w = self.density_t(v).min(1.0).sqrt();
                        [0, 1, 2].map(|i| neg[i] + (pos[i] - neg[i]) * w)
                    }
                };
                Sample { t, color, alpha }
            })
            .collect()
    }

    /// The samples as α-mix and three-pass take them from classified key volumes: each grid
    /// point's extinction (with its value's sign for an orbital) and colour first, those
    /// interpolated at the sample (the signed extinction's sign picks an orbital's colour).
    pub fn classified_samples(&self, d: DVec3) -> Vec<Sample> {
        let signed = self.grid.kind == ValueKind::Signed;
        let (extinction, hue) = self.classified.get_or_init(|| {
            let classified = |f: &dyn Fn(f64) -> f64| {
                let values = self.grid.values.iter().map(|&v| f(v as f64) as f32).collect();
                VolumeGrid::new("classified", self.grid.dims, self.grid.world_from_grid, values)
            };
            let extinction = classified(&|v| if signed && v < 0.0 { -self.extinction(v) } else { self.extinction(v) });
            (extinction, classified(&|v| self.density_t(v).min(1.0).sqrt()))
        });
        let (pos, neg) = (self.vs.positive_color.map(|c| c as f64), self.vs.negative_color.map(|c| c as f64));
        self.points(d)
            .map(|(t, p)| {
                let g = self.grid_from_world.transform_point3(p);
                let e = extinction.sample(g);
                let w = match signed {
                    true => f64::from(u8::from(e >= 0.0)),
                    false => hue.sample(g),
                };
                let color = [0, 1, 2].map(|i| neg[i] + (pos[i] - neg[i]) * w);
                Sample { t, color, alpha: self.opacity(e.abs(), d) }
            })
            .collect()
    }

    /// Where the ray from the eye in direction `d` meets the slices and is not clipped, back to
    /// front: its distance and the point.
    fn points(&self, d: DVec3) -> impl Iterator<Item = (f64, DVec3)> + '_ {
        let mut hits: Vec<f64> = self.tris.iter().filter_map(|&t| ray_triangle(self.eye, d, t)).collect();
        hits.sort_by(|a, b| b.total_cmp(a));
        hits.into_iter()
            .map(move |t| (t, self.eye + d * t))
            .filter(|(_, p)| !self.clip.is_some_and(|c| c.truncate().dot(*p) > c.w))
    }

    /// The opacity of `extinction` (per reference step, the grid spacing) over the path between
    /// two slices along `d`.
    fn opacity(&self, extinction: f64, d: DVec3) -> f64 {
        let path = self.spacing / d.dot(self.normal).abs().max(0.05);
        1.0 - (-extinction * path / self.step).exp()
    }
}
