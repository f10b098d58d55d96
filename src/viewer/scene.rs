//! MuJoCo model → MeshCat scene: one `set_object` per visual geom at
//! `/mujoco/<body>/<geom>`, body world poses as `set_transform` on `/mujoco/<body>`.
//!
//! Body groups are flat siblings under `/mujoco` (world poses never nest). A geom's local pose
//! (`geom_pos`/`geom_quat`) and its primitive fix-up (cylinder axis, ellipsoid scale) go into the
//! object's own `matrix`, so one message per geom is enough.

use mujoco_rs::prelude::*;
use rmpv::Value;
use tungstenite::Bytes;

use super::proto::{self, Mat4, map, s};

/// Root of everything this crate draws.
pub const ROOT: &str = "/mujoco";

/// MuJoCo's default geom rgba: a geom whose rgba differs from it overrides its material.
pub const DEFAULT_RGBA: [f32; 4] = [0.5, 0.5, 0.5, 1.0];

/// Geom groups shown by default (Menagerie puts collision geoms in group 3).
pub const VISIBLE_GROUPS: std::ops::RangeInclusive<i32> = 0..=2;

/// Side length used for an infinite MuJoCo plane (size 0), metres.
pub const INFINITE_PLANE: f64 = 10.0;

/// The primitive a geom is drawn with (sizes in metres, three.js conventions).
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// `BoxGeometry`: full extents along x, y, z.
    Box {
        /// Extent along x, metres.
        width: f64,
        /// Extent along y, metres.
        height: f64,
        /// Extent along z, metres.
        depth: f64,
    },
    /// `SphereGeometry` (also the unit sphere of an ellipsoid).
    Sphere {
        /// Radius, metres.
        radius: f64,
    },
    /// `CylinderGeometry` along three's Y axis (rotated onto Z by the object matrix).
    Cylinder {
        /// Radius, metres.
        radius: f64,
        /// Full length, metres.
        height: f64,
    },
    /// A capsule along Z, generated as an indexed `BufferGeometry` (three r132 has no
    /// `CapsuleGeometry`).
    Capsule {
        /// Radius, metres.
        radius: f64,
        /// Half the length of the cylindrical part, metres.
        half_length: f64,
    },
    /// `PlaneGeometry` in the XY plane, normal +Z.
    Plane {
        /// Extent along x, metres.
        width: f64,
        /// Extent along y, metres.
        height: f64,
    },
    /// A triangle mesh: compiled MuJoCo vertices (x, y, z flat) and faces (3 indices each).
    Mesh {
        /// Vertex coordinates, x, y, z per vertex, metres.
        vertices: Vec<f32>,
        /// Vertex indices, three per triangle.
        faces: Vec<u32>,
    },
}

/// One drawable geom of the model.
#[derive(Debug, Clone)]
pub struct GeomView {
    /// Geom id in the model.
    pub geom: usize,
    /// Body id the geom belongs to.
    pub body: usize,
    /// Scene path of the geom (`/mujoco/<body>/<geom>`).
    pub path: String,
    /// What is drawn.
    pub shape: Shape,
    /// Colour and opacity (0..1).
    pub rgba: [f32; 4],
    /// Object matrix relative to the body: geom pose × primitive fix-up, column-major.
    pub matrix: Mat4,
}

/// The drawable part of a model: paths of bodies and their visual geoms.
#[derive(Debug, Clone)]
pub struct SceneLayout {
    /// Scene path of every body (`/mujoco/<name>`), indexed by body id.
    pub body_paths: Vec<String>,
    /// Whether a body carries at least one drawn geom (only those get transforms).
    pub body_drawn: Vec<bool>,
    /// The drawn geoms, in geom order.
    pub geoms: Vec<GeomView>,
    /// Geoms not drawn because their type is unsupported (height fields, SDFs).
    pub skipped: Vec<usize>,
}

/// The colour of a geom by MuJoCo's rule: the geom's own rgba when it differs from the default
/// (0.5, 0.5, 0.5, 1) or when it has no material, else the material's rgba.
pub fn geom_rgba(model: &MjModel, geom: usize) -> [f32; 4] {
    let own = model.geom_rgba()[geom];
    let matid = model.geom_matid()[geom];
    if matid >= 0 && own == DEFAULT_RGBA {
        model.mat_rgba()[matid as usize]
    } else {
        own
    }
}

/// A path segment from a MuJoCo name: `/` and whitespace become `_`; unnamed objects get
/// `<fallback><id>`.
fn segment(name: Option<&str>, fallback: &str, id: usize) -> String {
    match name {
        Some(n) if !n.is_empty() => n
            .chars()
            .map(|c| if c == '/' || c.is_whitespace() { '_' } else { c })
            .collect(),
        _ => format!("{fallback}{id}"),
    }
}

/// Makes `name` unique within `taken` by appending `_<n>`.
fn unique(name: String, taken: &mut std::collections::HashSet<String>) -> String {
    if taken.insert(name.clone()) {
        return name;
    }
    let mut n = 2;
    loop {
        let candidate = format!("{name}_{n}");
        if taken.insert(candidate.clone()) {
            return candidate;
        }
        n += 1;
    }
}

/// The drawn shape and its fix-up matrix for geom type `ty` with MuJoCo `size`, or `None` for
/// types that are not drawn.
pub fn shape_for(ty: MjtGeomBase, size: [f64; 3]) -> Option<(Shape, Mat4)> {
    let fixed = |shape| Some((shape, proto::IDENTITY));
    match ty {
        MjtGeomBase::mjGEOM_PLANE => {
            let side = |half: f64| if half > 0.0 { 2.0 * half } else { INFINITE_PLANE };
            fixed(Shape::Plane {
                width: side(size[0]),
                height: side(size[1]),
            })
        }
        MjtGeomBase::mjGEOM_SPHERE => fixed(Shape::Sphere { radius: size[0] }),
        MjtGeomBase::mjGEOM_CAPSULE => fixed(Shape::Capsule {
            radius: size[0],
            half_length: size[1],
        }),
        MjtGeomBase::mjGEOM_ELLIPSOID => Some((
            Shape::Sphere { radius: 1.0 },
            proto::mat_scale(size[0], size[1], size[2]),
        )),
        MjtGeomBase::mjGEOM_CYLINDER => Some((
            Shape::Cylinder {
                radius: size[0],
                height: 2.0 * size[1],
            },
            proto::mat_rot_x90(),
        )),
        MjtGeomBase::mjGEOM_BOX => fixed(Shape::Box {
            width: 2.0 * size[0],
            height: 2.0 * size[1],
            depth: 2.0 * size[2],
        }),
        _ => None,
    }
}

/// The compiled vertices and faces of mesh `mesh` (MuJoCo has already re-centred, re-oriented
/// and scaled them, so they match `geom_pos`/`geom_quat`).
pub fn mesh_shape(model: &MjModel, mesh: usize) -> Shape {
    let vadr = model.mesh_vertadr()[mesh] as usize;
    let vnum = model.mesh_vertnum()[mesh] as usize;
    let fadr = model.mesh_faceadr()[mesh] as usize;
    let fnum = model.mesh_facenum()[mesh] as usize;
    let vertices = model.mesh_vert()[vadr..vadr + vnum]
        .iter()
        .flat_map(|v| v.iter().copied())
        .collect();
    let faces = model.mesh_face()[fadr..fadr + fnum]
        .iter()
        .flat_map(|f| f.iter().map(|&i| i as u32))
        .collect();
    Shape::Mesh { vertices, faces }
}

impl SceneLayout {
    /// Walks the model: names bodies and geoms, keeps visual geoms (groups 0–2, alpha > 0).
    pub fn new(model: &MjModel) -> Self {
        Self::with_groups(model, VISIBLE_GROUPS)
    }

    /// Like [`SceneLayout::new`] with the geom groups to draw.
    pub fn with_groups(model: &MjModel, groups: std::ops::RangeInclusive<i32>) -> Self {
        let nbody = model.ffi().nbody as usize;
        let ngeom = model.ffi().ngeom as usize;
        let mut taken = std::collections::HashSet::new();
        let body_paths: Vec<String> = (0..nbody)
            .map(|b| {
                let seg = segment(model.id_to_name(MjtObjBase::mjOBJ_BODY, b), "body", b);
                format!("{ROOT}/{}", unique(seg, &mut taken))
            })
            .collect();
        let mut geom_taken: Vec<std::collections::HashSet<String>> = vec![Default::default(); nbody];
        let mut body_drawn = vec![false; nbody];
        let mut geoms = Vec::new();
        let mut skipped = Vec::new();
        for g in 0..ngeom {
            if !groups.contains(&model.geom_group()[g]) {
                continue;
            }
            let rgba = geom_rgba(model, g);
            if rgba[3] <= 0.0 {
                continue;
            }
            let ty = model.geom_type()[g];
            let (shape, fixup) = if ty == MjtGeomBase::mjGEOM_MESH {
                let mesh = model.geom_dataid()[g];
                if mesh < 0 {
                    skipped.push(g);
                    continue;
                }
                (mesh_shape(model, mesh as usize), proto::IDENTITY)
            } else {
                match shape_for(ty, model.geom_size()[g]) {
                    Some(found) => found,
                    None => {
                        skipped.push(g);
                        continue;
                    }
                }
            };
            let body = model.geom_bodyid()[g] as usize;
            // Unnamed mesh geoms (most of Menagerie's) are named after their mesh.
            let name = model.id_to_name(MjtObjBase::mjOBJ_GEOM, g).or_else(|| {
                let mesh = model.geom_dataid()[g];
                (ty == MjtGeomBase::mjGEOM_MESH && mesh >= 0)
                    .then(|| model.id_to_name(MjtObjBase::mjOBJ_MESH, mesh as usize))
                    .flatten()
            });
            let seg = segment(name, "geom", g);
            let seg = unique(seg, &mut geom_taken[body]);
            let local = proto::mat_from_pos_quat(model.geom_pos()[g], model.geom_quat()[g]);
            body_drawn[body] = true;
            geoms.push(GeomView {
                geom: g,
                body,
                path: format!("{}/{seg}", body_paths[body]),
                shape,
                rgba,
                matrix: proto::mat_mul(&local, &fixup),
            });
        }
        Self {
            body_paths,
            body_drawn,
            geoms,
            skipped,
        }
    }

    /// The `set_object` command of every drawn geom, as `(path, encoded message)`.
    pub fn object_messages(&self) -> Vec<(String, Bytes)> {
        self.geoms
            .iter()
            .map(|g| {
                let msg = proto::set_object(&g.path, geom_object(g));
                (g.path.clone(), proto::encode(&msg))
            })
            .collect()
    }
}

/// The three.js JSON (ObjectLoader format 4.5) for one geom: geometry, material and a `Mesh`.
pub fn geom_object(g: &GeomView) -> Value {
    let id = g.geom;
    let geometry_uuid = format!("mujoco-geom-{id}-geometry");
    let material_uuid = format!("mujoco-geom-{id}-material");
    let mut geometry = match &g.shape {
        Shape::Box { width, height, depth } => vec![
            ("type", s("BoxGeometry")),
            ("width", Value::F64(*width)),
            ("height", Value::F64(*height)),
            ("depth", Value::F64(*depth)),
        ],
        Shape::Sphere { radius } => vec![
            ("type", s("SphereGeometry")),
            ("radius", Value::F64(*radius)),
            ("widthSegments", Value::from(32)),
            ("heightSegments", Value::from(16)),
        ],
        Shape::Cylinder { radius, height } => vec![
            ("type", s("CylinderGeometry")),
            ("radiusTop", Value::F64(*radius)),
            ("radiusBottom", Value::F64(*radius)),
            ("height", Value::F64(*height)),
            ("radialSegments", Value::from(32)),
        ],
        Shape::Plane { width, height } => vec![
            ("type", s("PlaneGeometry")),
            ("width", Value::F64(*width)),
            ("height", Value::F64(*height)),
        ],
        Shape::Capsule { radius, half_length } => {
            let (vertices, faces) = capsule_mesh(*radius, *half_length, 24, 8);
            buffer_geometry(&vertices, &faces)
        }
        Shape::Mesh { vertices, faces } => buffer_geometry(vertices, faces),
    };
    geometry.insert(0, ("uuid", s(&geometry_uuid)));
    let [r, gr, b, a] = g.rgba;
    let material = map(vec![
        ("uuid", s(&material_uuid)),
        ("type", s("MeshPhongMaterial")),
        ("color", Value::from(proto::color_hex([r, gr, b]))),
        ("opacity", Value::F64(f64::from(a))),
        ("transparent", Value::Boolean(a < 1.0)),
        ("side", Value::from(2)),
    ]);
    map(vec![
        (
            "metadata",
            map(vec![("version", Value::F64(4.5)), ("type", s("Object"))]),
        ),
        ("geometries", Value::Array(vec![map(geometry)])),
        ("materials", Value::Array(vec![material])),
        (
            "object",
            map(vec![
                ("uuid", s(&format!("mujoco-geom-{id}-object"))),
                ("type", s("Mesh")),
                ("geometry", s(&geometry_uuid)),
                ("material", s(&material_uuid)),
                ("matrix", proto::f64_array(&g.matrix)),
            ]),
        ),
    ])
}

/// Fields of an indexed `BufferGeometry`: positions as Float32 ext, indices as Uint32 ext. The
/// viewer computes vertex normals itself.
fn buffer_geometry(vertices: &[f32], faces: &[u32]) -> Vec<(&'static str, Value)> {
    vec![
        ("type", s("BufferGeometry")),
        (
            "data",
            map(vec![
                (
                    "attributes",
                    map(vec![(
                        "position",
                        map(vec![
                            ("itemSize", Value::from(3)),
                            ("type", s("Float32Array")),
                            ("array", proto::f32_ext(vertices)),
                            ("normalized", Value::Boolean(false)),
                        ]),
                    )]),
                ),
                (
                    "index",
                    map(vec![
                        ("itemSize", Value::from(1)),
                        ("type", s("Uint32Array")),
                        ("array", proto::u32_ext(faces)),
                        ("normalized", Value::Boolean(false)),
                    ]),
                ),
            ]),
        ),
    ]
}

/// An indexed capsule along Z: `segments` around, `rings` per hemisphere. Returns flat
/// vertices (x, y, z) and triangle indices (counter-clockwise seen from outside).
pub fn capsule_mesh(radius: f64, half_length: f64, segments: usize, rings: usize) -> (Vec<f32>, Vec<u32>) {
    let segments = segments.max(3);
    let rings = rings.max(1);
    let mut vertices = Vec::new();
    // Rows from the top pole down to the bottom pole: the top hemisphere (polar angle 0..π/2 at
    // z = +half_length) then the bottom one (π/2..π at z = -half_length).
    let mut rows = Vec::new();
    for i in 0..=rings {
        rows.push((i as f64 / rings as f64 * std::f64::consts::FRAC_PI_2, half_length));
    }
    for i in 0..=rings {
        rows.push((
            std::f64::consts::FRAC_PI_2 + i as f64 / rings as f64 * std::f64::consts::FRAC_PI_2,
            -half_length,
        ));
    }
    for &(theta, z0) in &rows {
        let (st, ct) = theta.sin_cos();
        for j in 0..=segments {
            let phi = j as f64 / segments as f64 * std::f64::consts::TAU;
            let (sp, cp) = phi.sin_cos();
            vertices.extend_from_slice(&[
                (radius * st * cp) as f32,
                (radius * st * sp) as f32,
                (z0 + radius * ct) as f32,
            ]);
        }
    }
    let width = (segments + 1) as u32;
    let mut faces = Vec::new();
    for r in 0..rows.len() as u32 - 1 {
        for j in 0..segments as u32 {
            let a = r * width + j;
            let b = a + 1;
            let c = a + width;
            let d = c + 1;
            // Rows go downwards (z decreasing) and columns counter-clockwise about +Z, so
            // (a, c, b) faces outwards.
            faces.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    (vertices, faces)
}
