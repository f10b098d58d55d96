//! The cell's collision model: what the collision checker copies instead of the whole model.
//!
//! It has the same bodies, joints, sites, cameras and geoms as the cell's model, in the same
//! order, so every id and address a [`super::Scene`] holds stays valid in it. What only shows is
//! left out: every geom that cannot collide (contype = conaffinity = 0, the Menagerie meshes of
//! the visual class) becomes a small sphere without a mesh, no geom or site keeps a material, and
//! the meshes, materials and textures nothing collidable uses are not compiled. A collidable
//! mesh keeps only the vertices of its convex hull, in its own frame: MuJoCo collides a mesh as
//! its convex hull, so the geom collides as before, without the faces (and their bounding-volume
//! tree) that only drawing and ray casting need.
//!
//! The meshes make up most of the cell's compiled model (about 44 MB; this one is well under
//! 1 MB), and each collision checker (one per planning thread or environment) edits its own copy.
//! A checker on this model reports the same pairs as on the whole model, at distances equal to
//! rounding (the hull is recentred, so the geom's pose is written in another frame); tested in
//! `collision_tests.rs`.
//!
//! Compiling it takes about 21 M instructions (about 9 % of what a warm `macrotree run` of the
//! flagship does outside `mj_step`), so it is kept in the model cache beside the model it derives
//! from (`super::cache::derived_key`).

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_editing::{MjSpec, MjsMesh};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

use super::cell_spec::{cell_spec, spec_err};
use super::error::SimError;

/// Radius of the sphere that stands in for a geom that cannot collide, metres (it only gives its
/// body a mass and inertia MuJoCo's compiler accepts; nothing collides with it).
const STAND_IN_RADIUS: f64 = 0.01;

/// The code that derives the collision model from the cell's model, hashed into its cache key.
const SOURCES: [&str; 2] = [include_str!("collision_model.rs"), include_str!("cell_spec.rs")];

/// Where a collision model is cached: the model cache's folder and the key of the cell's model
/// it derives from.
pub(crate) struct CacheSlot {
    /// The model cache's folder.
    pub dir: PathBuf,
    /// The cache key of the cell's model.
    pub key: String,
}

/// What a collision model is compiled from, and the model once compiled (lazily: a process that
/// never plans never compiles it).
pub(crate) struct CollisionModel {
    /// The cell's MJCF and the two Menagerie files, as the cell's model was compiled from.
    xml: String,
    ur5e: PathBuf,
    gripper: PathBuf,
    /// Where it is cached, if the cell's model is.
    cache: Option<CacheSlot>,
    compiled: OnceLock<Result<Arc<MjModel>, String>>,
}

impl CollisionModel {
    /// The collision model of the cell `xml` with the UR5e in `ur5e` and the 2F-85 in `gripper`,
    /// read from `cache` or compiled on first use.
    pub(crate) fn new(xml: &str, ur5e: &Path, gripper: &Path, cache: Option<CacheSlot>) -> Self {
        Self {
            xml: xml.to_string(),
            ur5e: ur5e.to_path_buf(),
            gripper: gripper.to_path_buf(),
            cache,
            compiled: OnceLock::new(),
        }
    }

    /// The model, shared; read from the cache or compiled by the first caller from the cell's
    /// compiled `whole` model (its meshes' convex hulls), then cached.
    ///
    /// # Errors
    /// The compile failed ([`SimError::Scene`], the same every call).
    pub(crate) fn get(&self, whole: &MjModel) -> Result<Arc<MjModel>, SimError> {
        self.compiled
            .get_or_init(|| {
                self.load_or_compile(whole)
                    .map(Arc::new)
                    .map_err(|e| e.to_string())
            })
            .clone()
            .map_err(SimError::Scene)
    }

    fn load_or_compile(&self, whole: &MjModel) -> Result<MjModel, SimError> {
        let compile = || compile_collision_model(&self.xml, &self.ur5e, &self.gripper, whole);
        let Some(slot) = &self.cache else {
            return compile();
        };
        let key = super::cache::derived_key(&slot.key, "collision model", &SOURCES);
        if let Some(model) = super::cache::load(&slot.dir, &key) {
            tracing::debug!(%key, "model cache: collision model hit");
            return Ok(model);
        }
        let model = compile()?;
        match super::cache::store(&slot.dir, &key, &model) {
            Ok(path) => tracing::debug!(path = %path.display(), "model cache: collision model stored"),
            Err(e) => tracing::debug!(error = %e, "model cache: collision model not stored"),
        }
        Ok(model)
    }
}

/// Compiles the collision model of the cell `xml` (see the module docs), taking the collidable
/// meshes' convex hulls from `whole`, the cell's model compiled from the same files.
///
/// # Errors
/// The cell cannot be composed or compiled, or a mesh has no convex hull in `whole`.
pub fn compile_collision_model(
    xml: &str,
    ur5e: &Path,
    gripper: &Path,
    whole: &MjModel,
) -> Result<MjModel, SimError> {
    let mut spec = cell_spec(xml, ur5e, gripper)?;
    let mut meshes_used = HashSet::new();
    for geom in spec.geom_iter_mut() {
        geom.set_material("");
        if geom.contype() == 0 && geom.conaffinity() == 0 {
            geom.set_meshname("");
            geom.set_type(MjtGeomBase::mjGEOM_SPHERE);
            geom.with_size([STAND_IN_RADIUS, 0.0, 0.0]);
        } else if !geom.meshname().is_empty() {
            meshes_used.insert(geom.meshname().to_string());
        }
    }
    for site in spec.site_iter_mut() {
        site.set_material("");
    }
    delete_all(&mut spec, |s| first_unused_mesh(s, &meshes_used))?;
    for mesh in spec.mesh_iter_mut() {
        let hull = hull_vertices(whole, mesh.name())?;
        mesh.set_file("");
        mesh.set_userface(&[]);
        mesh.set_usernormal(&[]);
        mesh.set_usertexcoord(&[]);
        mesh.set_uservert(&hull);
        mesh.with_scale([1.0; 3]);
        mesh.with_refpos([0.0; 3]);
        mesh.with_refquat([1.0, 0.0, 0.0, 0.0]);
    }
    delete_all(&mut spec, |s| s.material_iter_mut().next())?;
    delete_all(&mut spec, |s| s.texture_iter_mut().next())?;
    spec.compile()
        .map_err(|e| spec_err("compiling the cell's collision model", e))
}

/// The vertices of the convex hull of `whole`'s mesh `name`, in the mesh's file frame (scaled,
/// before the compiler recentred it), flattened (x, y, z per vertex, metres).
fn hull_vertices(whole: &MjModel, name: &str) -> Result<Vec<f32>, SimError> {
    let no_hull = || {
        SimError::Scene(format!(
            "the cell's collision model: mesh `{name}` has no convex hull"
        ))
    };
    let id = whole
        .name_to_id(MjtObjBase::mjOBJ_MESH, name)
        .ok_or_else(no_hull)?;
    let adr = usize::try_from(whole.mesh_graphadr()[id]).map_err(|_| no_hull())?;
    let graph = whole.mesh_graph();
    // MuJoCo's hull graph: numvert, numface, vert_edgeadr[numvert], vert_globalid[numvert], ….
    let numvert = usize::try_from(graph[adr]).map_err(|_| no_hull())?;
    let ids = graph
        .get(adr + 2 + numvert..adr + 2 + 2 * numvert)
        .ok_or_else(no_hull)?;
    let first = whole.mesh_vertadr()[id] as usize;
    let (p, q) = (whole.mesh_pos()[id], whole.mesh_quat()[id]);
    let frame = Isometry3::from_parts(
        Translation3::new(p[0], p[1], p[2]),
        UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3])),
    );
    let mut out = Vec::with_capacity(3 * numvert);
    for &v in ids {
        let [x, y, z] = whole.mesh_vert()[first + usize::try_from(v).map_err(|_| no_hull())?];
        let at = frame * Point3::new(f64::from(x), f64::from(y), f64::from(z));
        out.extend([at.x as f32, at.y as f32, at.z as f32]);
    }
    Ok(out)
}

/// The first mesh of `spec` no collidable geom names, if any.
fn first_unused_mesh<'a>(spec: &'a mut MjSpec, used: &HashSet<String>) -> Option<&'a mut MjsMesh> {
    spec.mesh_iter_mut().find(|m| !used.contains(m.name()))
}

/// Deletes the element `next` finds until it finds none (each deletion ends the iteration that
/// found it, so no handle outlives its element); at most [`MAX_DELETED`] elements.
fn delete_all<T: SpecObject>(
    spec: &mut MjSpec,
    mut next: impl FnMut(&mut MjSpec) -> Option<&mut T>,
) -> Result<(), SimError> {
    for _ in 0..MAX_DELETED {
        let Some(element) = next(spec) else {
            return Ok(());
        };
        // SAFETY: the element is deleted once, and its handle (borrowed from `spec` for this
        // statement only) is not used again: the next round looks elements up afresh.
        unsafe { element.delete() }.map_err(|e| spec_err("leaving out what only shows", e))?;
    }
    Err(SimError::Scene(format!(
        "the cell's collision model: more than {MAX_DELETED} meshes, materials or textures to leave out"
    )))
}

/// The most elements of one kind [`delete_all`] deletes (the cell has a few dozen meshes).
const MAX_DELETED: usize = 10_000;
