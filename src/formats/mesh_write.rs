//! Isosurface meshes to files other programs open: Wavefront OBJ (Blender, ParaView, VMD),
//! binary PLY (ParaView, MeshLab, Blender) and glTF binary `.glb` (Blender, web viewers).
//! Positions are written in ångström, normals unit length; each surface is its own object.

use std::io::{self, Write};

use crate::model::isosurface::Mesh;
use crate::model::units::BOHR_PER_ANGSTROM;

/// A named surface to write (e.g. "psi_plus", "psi_minus", "density").
pub struct NamedMesh<'a> {
    pub name: &'a str,
    pub mesh: &'a Mesh,
    /// Linear RGB, written where the format has a place for it (the mesh's per-vertex colours
    /// instead, when it has them).
    pub color: [f32; 3],
    /// A value per vertex (a surface coloured by a quantity: NaN where there is none), written
    /// beside the colour: PLY `property float value`, glTF attribute `_VALUE`.
    pub values: Option<&'a [f32]>,
}

/// sRGB bytes of a linear colour.
fn srgb(c: [f32; 3]) -> [u8; 3] {
    c.map(|c| (c.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0).round() as u8)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Ply,
    Glb,
}

impl MeshFormat {
    /// The format a file name's extension asks for.
    pub fn from_path(path: &std::path::Path) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "obj" => Some(Self::Obj),
            "ply" => Some(Self::Ply),
            "glb" => Some(Self::Glb),
            _ => None,
        }
    }
}

fn angstrom(p: glam::Vec3) -> [f32; 3] {
    (p / BOHR_PER_ANGSTROM as f32).to_array()
}

pub fn write(w: &mut impl Write, format: MeshFormat, meshes: &[NamedMesh]) -> io::Result<()> {
    match format {
        MeshFormat::Obj => write_obj(w, meshes),
        MeshFormat::Ply => write_ply(w, meshes),
        MeshFormat::Glb => write_glb(w, meshes),
    }
}

pub fn write_obj(w: &mut impl Write, meshes: &[NamedMesh]) -> io::Result<()> {
    writeln!(w, "# orbcloud isosurfaces; positions in angstrom")?;
    let mut base = 1;
    for m in meshes {
        writeln!(w, "o {}", m.name)?;
        for p in &m.mesh.positions {
            let [x, y, z] = angstrom(*p);
            writeln!(w, "v {x:.6} {y:.6} {z:.6}")?;
        }
        for n in &m.mesh.normals {
            writeln!(w, "vn {:.5} {:.5} {:.5}", n.x, n.y, n.z)?;
        }
        for t in m.mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0] + base, t[1] + base, t[2] + base];
            writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        base += m.mesh.positions.len() as u32;
    }
    Ok(())
}

/// Binary little-endian PLY; all surfaces in one file, each vertex coloured by its surface.
pub fn write_ply(w: &mut impl Write, meshes: &[NamedMesh]) -> io::Result<()> {
    let vertices: usize = meshes.iter().map(|m| m.mesh.positions.len()).sum();
    let faces: usize = meshes.iter().map(|m| m.mesh.triangle_count()).sum();
    let names: Vec<&str> = meshes.iter().map(|m| m.name).collect();
    let with_values = meshes.iter().any(|m| m.values.is_some());
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment orbcloud isosurfaces ({}); positions in angstrom\n\
         element vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n{}\
         element face {faces}\nproperty list uchar int vertex_indices\nend_header\n",
        names.join(", "),
        if with_values { "property float value\n" } else { "" }
    )?;
    for m in meshes {
        let own = srgb(m.color);
        for (i, (p, n)) in m.mesh.positions.iter().zip(&m.mesh.normals).enumerate() {
            for v in angstrom(*p).into_iter().chain(n.to_array()) {
                w.write_all(&v.to_le_bytes())?;
            }
            w.write_all(&m.mesh.colors.get(i).map_or(own, |c| srgb(*c)))?;
            if with_values {
                let value = m.values.and_then(|v| v.get(i)).copied().unwrap_or(f32::NAN);
                w.write_all(&value.to_le_bytes())?;
            }
        }
    }
    let mut base = 0i32;
    for m in meshes {
        for t in m.mesh.indices.chunks_exact(3) {
            w.write_all(&[3])?;
            for &i in t {
                w.write_all(&(i as i32 + base).to_le_bytes())?;
            }
        }
        base += m.mesh.positions.len() as i32;
    }
    Ok(())
}

/// glTF 2.0 binary: one node and mesh per surface, a lit material of its colour.
pub fn write_glb(w: &mut impl Write, meshes: &[NamedMesh]) -> io::Result<()> {
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut gltf_meshes, mut nodes, mut materials) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (n, m) in meshes.iter().enumerate() {
        let positions: Vec<[f32; 3]> = m.mesh.positions.iter().map(|p| angstrom(*p)).collect();
        let (lo, hi) = positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            (std::array::from_fn(|a| lo[a].min(p[a])), std::array::from_fn(|a| hi[a].max(p[a])))
        });
        let mut view = |bytes: &[u8], target: u32| {
            let offset = bin.len();
            bin.extend_from_slice(bytes);
            bin.resize(bin.len().next_multiple_of(4), 0);
            views.push(format!(
                r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{},"target":{target}}}"#,
                bytes.len()
            ));
            views.len() - 1
        };
        let pv = view(bytemuck::cast_slice(&positions), 34962);
        let nv = view(bytemuck::cast_slice(&m.mesh.normals), 34962);
        let iv = view(bytemuck::cast_slice(&m.mesh.indices), 34963);
        let count = positions.len();
        let a = accessors.len();
        accessors.push(format!(
            r#"{{"bufferView":{pv},"componentType":5126,"count":{count},"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#
        ));
        accessors.push(format!(r#"{{"bufferView":{nv},"componentType":5126,"count":{count},"type":"VEC3"}}"#));
        accessors.push(format!(
            r#"{{"bufferView":{iv},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            m.mesh.indices.len()
        ));
        // Per-vertex colours (linear RGB, as glTF's COLOR_0 is) and values, when the surface has
        // them.
        let mut extra = String::new();
        if m.mesh.colors.len() == count {
            let cv = view(bytemuck::cast_slice(&m.mesh.colors), 34962);
            extra += &format!(r#","COLOR_0":{}"#, accessors.len());
            accessors.push(format!(r#"{{"bufferView":{cv},"componentType":5126,"count":{count},"type":"VEC3"}}"#));
        }
        if let Some(values) = m.values.filter(|v| v.len() == count) {
            let vv = view(bytemuck::cast_slice(values), 34962);
            extra += &format!(r#","_VALUE":{}"#, accessors.len());
            accessors.push(format!(r#"{{"bufferView":{vv},"componentType":5126,"count":{count},"type":"SCALAR"}}"#));
        }
        let [r, g, b] = if m.mesh.colors.len() == count { [1.0; 3] } else { m.color };
        materials.push(format!(
            r#"{{"name":"{}","pbrMetallicRoughness":{{"baseColorFactor":[{r},{g},{b},1.0],"metallicFactor":0.0,"roughnessFactor":0.5}},"doubleSided":true}}"#,
            m.name
        ));
        gltf_meshes.push(format!(
            r#"{{"name":"{}","primitives":[{{"attributes":{{"POSITION":{a},"NORMAL":{}{extra}}},"indices":{},"material":{n}}}]}}"#,
            m.name,
            a + 1,
            a + 2
        ));
        nodes.push(format!(r#"{{"name":"{}","mesh":{n}}}"#, m.name));
    }
    let scene_nodes: Vec<String> = (0..nodes.len()).map(|n| n.to_string()).collect();
    let mut json = format!(
        r#"{{"asset":{{"version":"2.0","generator":"orbcloud"}},"scene":0,"scenes":[{{"nodes":[{}]}}],"nodes":[{}],"meshes":[{}],"materials":[{}],"accessors":[{}],"bufferViews":[{}],"buffers":[{{"byteLength":{}}}]}}"#,
        scene_nodes.join(","),
        nodes.join(","),
        gltf_meshes.join(","),
        materials.join(","),
        accessors.join(","),
        views.join(","),
        bin.len()
    )
    .into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + json.len() + 8 + bin.len();
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(total as u32).to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin)
}
