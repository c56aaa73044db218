//! Atoms as sphere impostors and bonds as cylinder impostors (seed 001's P4 point sprites,
//! done as instanced quads with exact per-pixel intersection and depth).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::GpuContext;
use super::frame::{Draw, ObjectView, Phase, PickId, opaque_depth, opaque_targets};
use crate::model::{Molecule, units::BOHR_PER_ANGSTROM};
use crate::scene::AtomStyle;

/// Mirror of `Globals` in atoms.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AtomGlobals {
    pub clip_from_world: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub light: [f32; 4],
    pub up: [f32; 4],
    /// x: the high bits of this object's atom pick ids ([`PickId::atom_base`]).
    pub pick: [u32; 4],
}
const _: () = assert!(std::mem::size_of::<AtomGlobals>() == 128);

#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SphereInstance {
    pub center: [f32; 3],
    pub radius: f32,
    pub color: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<SphereInstance>() == 32);

#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct CylinderInstance {
    pub p0: [f32; 3],
    pub radius: f32,
    pub p1: [f32; 3],
    /// The atom this half-bond belongs to: picking it picks the atom.
    pub atom: u32,
    pub color: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<CylinderInstance>() == 48);

/// Ball radius as a fraction of the van der Waals radius in ball-and-stick.
const BALL_FRACTION: f32 = 0.24;
/// Stick radius in ball-and-stick, ångström.
const STICK_RADIUS_ANG: f32 = 0.13;

fn attribute(shader_location: u32, format: wgpu::VertexFormat, offset: u64) -> wgpu::VertexAttribute {
    wgpu::VertexAttribute { format, offset, shader_location }
}

fn linear_color(srgb: [u8; 3]) -> [f32; 4] {
    let lin = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    };
    [lin(srgb[0]), lin(srgb[1]), lin(srgb[2]), 1.0]
}

/// The impostor instances for a molecule in a style: plain data, testable without a GPU.
pub fn instances(molecule: &Molecule, style: AtomStyle) -> (Vec<SphereInstance>, Vec<CylinderInstance>) {
    let bohr = BOHR_PER_ANGSTROM as f32;
    let spheres = match style {
        AtomStyle::Hidden => Vec::new(),
        _ => molecule
            .atoms
            .iter()
            .map(|a| {
                let e = a.element();
                let mut radius = match style {
                    AtomStyle::SpaceFilling => e.vdw_radius,
                    AtomStyle::Sticks => STICK_RADIUS_ANG,
                    _ => e.vdw_radius * BALL_FRACTION,
                } * bohr;
                let mut color = linear_color(e.color);
                if a.ghost {
                    radius *= 0.5;
                    color = [0.35, 0.35, 0.35, 1.0];
                }
                SphereInstance { center: a.position.as_vec3().to_array(), radius, color }
            })
            .collect(),
    };
    let cylinders = match style {
        AtomStyle::BallAndStick | AtomStyle::Sticks => molecule
            .bonds
            .iter()
            .flat_map(|b| {
                let (a, c) = (&molecule.atoms[b.a as usize], &molecule.atoms[b.b as usize]);
                let (pa, pc) = (a.position.as_vec3(), c.position.as_vec3());
                let mid = 0.5 * (pa + pc);
                let half = |p: Vec3, atom, color| CylinderInstance {
                    p0: p.to_array(),
                    radius: STICK_RADIUS_ANG * bohr,
                    p1: mid.to_array(),
                    atom,
                    color,
                };
                [half(pa, b.a, linear_color(a.element().color)), half(pc, b.b, linear_color(c.element().color))]
            })
            .collect(),
        _ => Vec::new(),
    };
    (spheres, cylinders)
}

pub struct AtomsPass {
    spheres_pipeline: wgpu::RenderPipeline,
    cylinders_pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    globals: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    spheres: Option<(wgpu::Buffer, u32)>,
    cylinders: Option<(wgpu::Buffer, u32)>,
}

impl AtomsPass {
    pub fn new(ctx: &GpuContext) -> Self {
        let device = &ctx.device;
        let module = super::shader_module(device, "atoms.wgsl");
        let (layout, pipeline_layout) = super::uniform_layouts(device, "atoms");
        let pipeline = |label: &str, vs: &str, fs: &str, stride: u64, attributes: &[wgpu::VertexAttribute]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: stride,
                        step_mode: wgpu::VertexStepMode::Instance,
                        attributes,
                    })],
                },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(opaque_depth()),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &opaque_targets(),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let spheres_pipeline = pipeline(
            "sphere impostors",
            "vs_sphere",
            "fs_sphere",
            32,
            &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32, 2 => Float32x4],
        );
        let cylinders_pipeline = pipeline(
            "cylinder impostors",
            "vs_cylinder",
            "fs_cylinder",
            48,
            // Not vertex_attr_array!: the atom index sits between p1 and the colour.
            &[
                attribute(0, wgpu::VertexFormat::Float32x3, 0),
                attribute(1, wgpu::VertexFormat::Float32, 12),
                attribute(2, wgpu::VertexFormat::Float32x3, 16),
                attribute(3, wgpu::VertexFormat::Float32x4, 32),
                attribute(4, wgpu::VertexFormat::Uint32, 28),
            ],
        );
        let globals = super::uniform_buffer(device, "atoms globals", std::mem::size_of::<AtomGlobals>());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("atoms bind group"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: globals.as_entire_binding() }],
        });
        Self { spheres_pipeline, cylinders_pipeline, layout, globals, bind_group, spheres: None, cylinders: None }
    }

    /// Uploads the impostor instances of a molecule in a style.
    pub fn set_molecule(&mut self, ctx: &GpuContext, molecule: &Molecule, style: AtomStyle) {
        use wgpu::util::DeviceExt;
        let (spheres, cylinders) = instances(molecule, style);
        let upload = |label: &str, bytes: &[u8], n: usize| {
            (n > 0).then(|| {
                let buffer = ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: wgpu::BufferUsages::VERTEX,
                });
                (buffer, n as u32)
            })
        };
        self.spheres = upload("sphere instances", bytemuck::cast_slice(&spheres), spheres.len());
        self.cylinders = upload("cylinder instances", bytemuck::cast_slice(&cylinders), cylinders.len());
    }

    /// Another set of atoms drawn with this one's pipelines.
    pub fn instance(&self, ctx: &GpuContext) -> Self {
        let globals = super::uniform_buffer(&ctx.device, "atoms globals", std::mem::size_of::<AtomGlobals>());
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("atoms bind group"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: globals.as_entire_binding() }],
        });
        Self {
            spheres_pipeline: self.spheres_pipeline.clone(),
            cylinders_pipeline: self.cylinders_pipeline.clone(),
            layout: self.layout.clone(),
            globals,
            bind_group,
            spheres: None,
            cylinders: None,
        }
    }

    /// This frame's camera, in the frame of the object the atoms belong to; their pick ids name
    /// `object`.
    pub fn prepare(&self, queue: &wgpu::Queue, view: &ObjectView, object: u32) {
        let g = AtomGlobals {
            clip_from_world: view.clip_from_object.to_cols_array_2d(),
            eye: view.eye.extend(1.0).to_array(),
            light: view.light.extend(0.0).to_array(),
            up: view.up.extend(0.0).to_array(),
            pick: [PickId::atom_base(object), 0, 0, 0],
        };
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&g));
    }
}

/// A light above-left of the viewer, moving with the camera, and the camera's up vector.
pub fn headlight(eye: Vec3, target: Vec3, camera_up: Vec3) -> (Vec3, Vec3) {
    let back = (eye - target).normalize_or(Vec3::Z);
    let right = camera_up.cross(back).normalize_or(Vec3::X);
    let up = back.cross(right);
    ((back + 0.6 * up - 0.4 * right).normalize(), up)
}

impl Draw for AtomsPass {
    fn phases(&self) -> &'static [Phase] {
        &[Phase::Opaque]
    }

    fn draw(&self, _phase: Phase, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_bind_group(0, &self.bind_group, &[]);
        if let Some((buffer, n)) = &self.cylinders {
            pass.set_pipeline(&self.cylinders_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..6, 0..*n);
        }
        if let Some((buffer, n)) = &self.spheres {
            pass.set_pipeline(&self.spheres_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..6, 0..*n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Atom;
    use glam::DVec3;

    #[test]
    fn ball_and_stick_has_two_half_bonds_per_bond() {
        let atom = |z, x| Atom { z, charge: z as f64, position: DVec3::new(x, 0.0, 0.0), ghost: false };
        let m = Molecule::new(vec![atom(6, 0.0), atom(8, 2.28)]);
        assert_eq!(m.bonds.len(), 1);
        let (s, c) = instances(&m, AtomStyle::BallAndStick);
        assert_eq!((s.len(), c.len()), (2, 2));
        assert_eq!(c[0].p1, c[1].p1);
        assert!((c[0].p1[0] - 1.14).abs() < 1e-6);
        let (s2, c2) = instances(&m, AtomStyle::SpaceFilling);
        assert!(c2.is_empty() && s2[0].radius > 3.0 * s[0].radius);
        assert!(instances(&m, AtomStyle::Hidden).0.is_empty());
        let (s3, c3) = instances(&m, AtomStyle::Sticks);
        assert_eq!(c3.len(), 2);
        assert!(s3.iter().all(|s| (s.radius - c3[0].radius).abs() < 1e-6), "caps as wide as the sticks");
    }
}
