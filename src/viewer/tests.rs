//! Unit tests of the viewer's encoding and scene logic (no sockets, no browser).

use super::proto::{self, EXT_FLOAT32, EXT_UINT32};
use super::scene::{self, GeomView, SceneLayout, Shape};
use super::{Recorder, SceneTree, initial_tree, page};
use crate::sim::{Scene, Sim};
use mujoco_rs::prelude::*;
use rmpv::Value;

fn decode(bytes: &[u8]) -> Value {
    let mut slice = bytes;
    let v = rmpv::decode::read_value(&mut slice).expect("valid msgpack");
    assert!(slice.is_empty(), "exactly one value per message");
    v
}

/// Field `key` of a msgpack map with string keys (panics on a non-string key).
fn get<'a>(v: &'a Value, key: &str) -> Option<&'a Value> {
    let Value::Map(fields) = v else {
        panic!("not a map: {v}")
    };
    fields.iter().find_map(|(k, val)| {
        let k = k.as_str().expect("map keys are strings");
        (k == key).then_some(val)
    })
}

fn field<'a>(v: &'a Value, path: &[&str]) -> &'a Value {
    path.iter().fold(v, |v, k| {
        get(v, k).unwrap_or_else(|| panic!("missing field {k} in {v}"))
    })
}

fn no_nil(v: &Value) {
    match v {
        Value::Nil => panic!("nil values must never be encoded"),
        Value::Map(m) => m.iter().for_each(|(k, v)| {
            no_nil(k);
            no_nil(v)
        }),
        Value::Array(a) => a.iter().for_each(no_nil),
        _ => {}
    }
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

#[test]
fn set_transform_is_a_named_map_with_16_column_major_f64() {
    let m = proto::mat_from_pos_quat([1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0]);
    let v = decode(&proto::encode(&proto::set_transform("/a/b", &m)));
    no_nil(&v);
    assert_eq!(field(&v, &["type"]).as_str(), Some("set_transform"));
    assert_eq!(field(&v, &["path"]).as_str(), Some("/a/b"));
    let arr = field(&v, &["matrix"]).as_array().unwrap();
    assert_eq!(arr.len(), 16);
    assert!(arr.iter().all(|x| matches!(x, Value::F64(_))), "float64 entries");
    // Translation in slots 12..15 (column-major).
    assert_eq!(floats(field(&v, &["matrix"]))[12..15], [1.0, 2.0, 3.0]);
}

#[test]
fn matrices_are_column_major() {
    // 90° about Z: x -> y. Row-major R = [[0,-1,0],[1,0,0],[0,0,1]].
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let m = proto::mat_from_pos_quat([0.5, 0.0, 0.0], [h, 0.0, 0.0, h]);
    let expect = [
        0.0, 1.0, 0.0, 0.0, // first column = R·x = (0, 1, 0)
        -1.0, 0.0, 0.0, 0.0, // second column = R·y = (-1, 0, 0)
        0.0, 0.0, 1.0, 0.0, //
        0.5, 0.0, 0.0, 1.0,
    ];
    for (a, b) in m.iter().zip(expect) {
        assert!((a - b).abs() < 1e-12, "{m:?}");
    }
    // MuJoCo's row-major xmat gives the same matrix.
    let xmat = [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let m2 = proto::mat_from_pos_xmat([0.5, 0.0, 0.0], xmat);
    for (a, b) in m2.iter().zip(expect) {
        assert!((a - b).abs() < 1e-12, "{m2:?}");
    }
    // Product order: (T · R) applies R first.
    let t = proto::mat_from_pos_quat([1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]);
    let r = proto::mat_from_pos_quat([0.0; 3], [h, 0.0, 0.0, h]);
    let tr = proto::mat_mul(&t, &r);
    assert_eq!(tr[12], 1.0);
    assert!((tr[1] - 1.0).abs() < 1e-12);
    // Rx(+90°) sends three's Y axis (cylinders) to Z.
    let rx = proto::mat_rot_x90();
    assert_eq!(&rx[4..7], &[0.0, 0.0, 1.0]);
}

#[test]
fn typed_arrays_use_the_msgpack_lite_ext_codes() {
    let v = decode(&proto::encode(&proto::f32_ext(&[1.0, -2.5])));
    let Value::Ext(tag, bytes) = v else { panic!() };
    assert_eq!(tag, 0x17);
    assert_eq!(tag, EXT_FLOAT32);
    assert_eq!(bytes, [1.0f32.to_le_bytes(), (-2.5f32).to_le_bytes()].concat());
    let v = decode(&proto::encode(&proto::u32_ext(&[7, 65536])));
    let Value::Ext(tag, bytes) = v else { panic!() };
    assert_eq!(tag, 0x16);
    assert_eq!(tag, EXT_UINT32);
    assert_eq!(bytes, [7u32.to_le_bytes(), 65536u32.to_le_bytes()].concat());
}

#[test]
fn other_commands_have_named_fields() {
    let v = decode(&proto::encode(&proto::delete("/x")));
    assert_eq!(field(&v, &["type"]).as_str(), Some("delete"));
    assert_eq!(field(&v, &["path"]).as_str(), Some("/x"));
    let v = decode(&proto::encode(&proto::set_property(
        "/Grid",
        "visible",
        Value::Boolean(false),
    )));
    assert_eq!(field(&v, &["property"]).as_str(), Some("visible"));
    assert_eq!(field(&v, &["value"]).as_bool(), Some(false));
    let v = decode(&proto::encode(&proto::capture_image()));
    assert_eq!(field(&v, &["type"]).as_str(), Some("capture_image"));
    assert_eq!(proto::normalize_path("//a///b/"), "/a/b");
    assert_eq!(proto::normalize_path(""), "/");
    assert_eq!(proto::color_hex([1.0, 0.5, 0.0]), 0xff8000);
}

fn view(shape: Shape) -> GeomView {
    GeomView {
        geom: 3,
        body: 1,
        path: "/mujoco/b/g".into(),
        shape,
        rgba: [1.0, 0.0, 0.0, 0.5],
        matrix: proto::IDENTITY,
    }
}

/// Decodes a geom's `set_object` and returns (message, the single geometry, the material).
fn object_parts(g: &GeomView) -> (Value, Value, Value) {
    let v = decode(&proto::encode(&proto::set_object(&g.path, scene::geom_object(g))));
    no_nil(&v);
    assert_eq!(field(&v, &["type"]).as_str(), Some("set_object"));
    let obj = field(&v, &["object"]);
    assert_eq!(field(obj, &["metadata", "type"]).as_str(), Some("Object"));
    let geometry = field(obj, &["geometries"]).as_array().unwrap()[0].clone();
    let material = field(obj, &["materials"]).as_array().unwrap()[0].clone();
    assert_eq!(field(obj, &["object", "type"]).as_str(), Some("Mesh"));
    assert_eq!(field(obj, &["object", "geometry"]), field(&geometry, &["uuid"]));
    assert_eq!(field(obj, &["object", "material"]), field(&material, &["uuid"]));
    assert_eq!(field(obj, &["object", "matrix"]).as_array().unwrap().len(), 16);
    (v, geometry, material)
}

#[test]
fn each_mujoco_geom_type_maps_to_a_three_geometry() {
    let size = [0.1, 0.2, 0.3];
    let cases = [
        (MjtGeomBase::mjGEOM_BOX, "BoxGeometry"),
        (MjtGeomBase::mjGEOM_SPHERE, "SphereGeometry"),
        (MjtGeomBase::mjGEOM_ELLIPSOID, "SphereGeometry"),
        (MjtGeomBase::mjGEOM_CYLINDER, "CylinderGeometry"),
        (MjtGeomBase::mjGEOM_PLANE, "PlaneGeometry"),
        (MjtGeomBase::mjGEOM_CAPSULE, "BufferGeometry"),
    ];
    for (ty, three) in cases {
        let (shape, fix) = scene::shape_for(ty, size).unwrap();
        let mut g = view(shape);
        g.matrix = fix;
        let (_, geometry, material) = object_parts(&g);
        assert_eq!(field(&geometry, &["type"]).as_str(), Some(three), "{ty:?}");
        assert_eq!(field(&material, &["color"]).as_u64(), Some(0xff0000));
        assert_eq!(field(&material, &["opacity"]).as_f64(), Some(0.5));
        assert_eq!(field(&material, &["transparent"]).as_bool(), Some(true));
        match ty {
            MjtGeomBase::mjGEOM_BOX => {
                // Full extents; three's height is the Y extent.
                assert_eq!(field(&geometry, &["width"]).as_f64(), Some(0.2));
                assert_eq!(field(&geometry, &["height"]).as_f64(), Some(0.4));
                assert_eq!(field(&geometry, &["depth"]).as_f64(), Some(0.6));
            }
            MjtGeomBase::mjGEOM_SPHERE => assert_eq!(field(&geometry, &["radius"]).as_f64(), Some(0.1)),
            MjtGeomBase::mjGEOM_ELLIPSOID => {
                assert_eq!(field(&geometry, &["radius"]).as_f64(), Some(1.0));
                assert_eq!((fix[0], fix[5], fix[10]), (0.1, 0.2, 0.3));
            }
            MjtGeomBase::mjGEOM_CYLINDER => {
                assert_eq!(field(&geometry, &["radiusTop"]).as_f64(), Some(0.1));
                assert_eq!(field(&geometry, &["height"]).as_f64(), Some(0.4));
                assert_eq!(fix, proto::mat_rot_x90());
            }
            MjtGeomBase::mjGEOM_PLANE => {
                assert_eq!(field(&geometry, &["width"]).as_f64(), Some(0.2));
                assert_eq!(field(&geometry, &["height"]).as_f64(), Some(0.4));
            }
            MjtGeomBase::mjGEOM_CAPSULE => {
                let pos = field(&geometry, &["data", "attributes", "position"]);
                let Value::Ext(tag, bytes) = field(pos, &["array"]) else {
                    panic!()
                };
                assert_eq!(*tag, EXT_FLOAT32);
                assert_eq!(bytes.len() % 12, 0);
                let Value::Ext(tag, _) = field(&geometry, &["data", "index", "array"]) else {
                    panic!()
                };
                assert_eq!(*tag, EXT_UINT32);
            }
            _ => unreachable!(),
        }
    }
    // An infinite plane gets a finite size; height fields and SDFs are not drawn.
    let (shape, _) = scene::shape_for(MjtGeomBase::mjGEOM_PLANE, [0.0, 0.0, 1.0]).unwrap();
    assert_eq!(
        shape,
        Shape::Plane {
            width: scene::INFINITE_PLANE,
            height: scene::INFINITE_PLANE
        }
    );
    assert!(scene::shape_for(MjtGeomBase::mjGEOM_HFIELD, size).is_none());
    assert!(scene::shape_for(MjtGeomBase::mjGEOM_SDF, size).is_none());
}

#[test]
fn capsule_mesh_spans_the_capsule_and_faces_outwards() {
    let (r, h) = (0.05, 0.2);
    let (v, f) = scene::capsule_mesh(r, h, 16, 6);
    let zs: Vec<f32> = v.chunks(3).map(|p| p[2]).collect();
    let max = zs.iter().cloned().fold(f32::MIN, f32::max);
    let min = zs.iter().cloned().fold(f32::MAX, f32::min);
    assert!((max - (h + r) as f32).abs() < 1e-6 && (min + (h + r) as f32).abs() < 1e-6);
    for p in v.chunks(3) {
        let radial = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let axial = (p[2].abs() - h as f32).max(0.0);
        assert!(((radial * radial + axial * axial).sqrt() - r as f32).abs() < 1e-5);
    }
    assert_eq!(f.len() % 3, 0);
    assert!(f.iter().all(|&i| (i as usize) < v.len() / 3));
    // Outward normals: for every non-degenerate triangle, the normal points away from the axis.
    let p = |i: u32| {
        let i = i as usize * 3;
        [v[i] as f64, v[i + 1] as f64, v[i + 2] as f64]
    };
    for t in f.chunks(3) {
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len < 1e-12 {
            continue;
        }
        let centre = [
            (a[0] + b[0] + c[0]) / 3.0,
            (a[1] + b[1] + c[1]) / 3.0,
            (a[2] + b[2] + c[2]) / 3.0,
        ];
        let axis_z = centre[2].clamp(-h, h);
        let out = [centre[0], centre[1], centre[2] - axis_z];
        assert!(
            n[0] * out[0] + n[1] * out[1] + n[2] * out[2] > 0.0,
            "inward face {t:?}"
        );
    }
}

#[test]
fn color_rule_geom_rgba_overrides_material_unless_default() {
    let scene = Scene::load().unwrap();
    let m = &scene.model;
    let geom = |name: &str| m.name_to_id(MjtObjBase::mjOBJ_GEOM, name).unwrap();
    // The scene's objects carry their colour as geom rgba (no material): geom colour.
    assert_eq!(scene::geom_rgba(m, geom("obj/cube")), [0.95, 0.35, 0.15, 1.0]);
    assert_eq!(
        scene::geom_rgba(m, geom("obj/bowl/floor")),
        [0.25, 0.65, 0.55, 1.0]
    );
    // The pads have their own rgba and no material: geom colour.
    assert_eq!(
        scene::geom_rgba(m, geom("gripper/right_pad1")),
        [0.55, 0.55, 0.55, 1.0]
    );
    // A geom with a material and a non-default rgba keeps its own rgba (MuJoCo's rule).
    let mut spec = mujoco_rs::wrappers::mj_editing::MjSpec::from_xml_string(
        r#"<mujoco><asset><material name="m" rgba="0 0 1 1"/></asset><worldbody>
           <geom name="own" type="sphere" size="0.1" material="m" rgba="1 0 0 1"/>
           <geom name="mat" type="sphere" size="0.1" material="m"/>
           <geom name="plain" type="sphere" size="0.1"/>
           <geom name="hidden" type="sphere" size="0.1" rgba="1 1 1 0"/>
           <geom name="collision" type="sphere" size="0.1" group="3"/>
           <body name="b"><geom name="hf" type="box" size="0.1 0.1 0.1"/></body>
           </worldbody></mujoco>"#,
    )
    .unwrap();
    let m2 = spec.compile().unwrap();
    let id = |name: &str| m2.name_to_id(MjtObjBase::mjOBJ_GEOM, name).unwrap();
    assert_eq!(scene::geom_rgba(&m2, id("own")), [1.0, 0.0, 0.0, 1.0]);
    assert_eq!(scene::geom_rgba(&m2, id("mat")), [0.0, 0.0, 1.0, 1.0]);
    assert_eq!(scene::geom_rgba(&m2, id("plain")), [0.5, 0.5, 0.5, 1.0]);
    let layout = SceneLayout::new(&m2);
    let paths: Vec<&str> = layout.geoms.iter().map(|g| g.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "/mujoco/world/own",
            "/mujoco/world/mat",
            "/mujoco/world/plain",
            "/mujoco/b/hf"
        ],
        "transparent and group-3 geoms are skipped"
    );
}

#[test]
fn the_task_scene_draws_visual_geoms_only_from_compiled_meshes() {
    let scene = Scene::load().unwrap();
    let m = &scene.model;
    let layout = SceneLayout::new(m);
    assert!(layout.skipped.is_empty());
    let groups = m.geom_group();
    assert!(layout.geoms.iter().all(|g| (0..=2).contains(&groups[g.geom])));
    let meshes = layout
        .geoms
        .iter()
        .filter(|g| matches!(g.shape, Shape::Mesh { .. }))
        .count();
    assert!(meshes >= 20, "UR5e + 2F-85 visual meshes: {meshes}");
    for g in &layout.geoms {
        if let Shape::Mesh { vertices, faces } = &g.shape {
            assert_eq!(vertices.len() % 3, 0);
            assert!(
                faces.iter().all(|&i| (i as usize) < vertices.len() / 3),
                "{}",
                g.path
            );
        }
    }
    for name in [
        "/mujoco/obj_cube/obj_cube",
        "/mujoco/obj_bowl/obj_bowl_floor",
        "/mujoco/world/floor",
    ] {
        assert!(layout.geoms.iter().any(|g| g.path == name), "{name}");
    }
    // Paths are unique.
    let mut paths: Vec<&str> = layout.geoms.iter().map(|g| g.path.as_str()).collect();
    paths.sort();
    let n = paths.len();
    paths.dedup();
    assert_eq!(paths.len(), n);
    // The whole scene snapshot stays a few MB.
    let bytes = initial_tree(&layout).snapshot_bytes();
    assert!(bytes < 12 << 20, "{bytes}");
}

#[test]
fn scene_tree_replaces_deletes_subtrees_and_keeps_the_latest() {
    let b = |s: &str| tungstenite::Bytes::from(s.to_owned());
    let mut t = SceneTree::new();
    t.set_object("/a", b("obj1"));
    t.set_property("/a/<object>", "color", b("red"));
    t.set_transform("/a", b("T1"));
    t.set_transform("/a", b("T2"));
    t.set_property("/a/<object>", "color", b("blue"));
    t.set_object("/a/b", b("child"));
    t.set_object("/ab", b("sibling"));
    // Latest wins per path and per property: no history.
    assert_eq!(t.transform("/a").unwrap(), &b("T2"));
    assert_eq!(t.property("/a/<object>", "color").unwrap(), &b("blue"));
    let snap: Vec<_> = t.snapshot();
    assert_eq!(
        snap,
        vec![b("obj1"), b("T2"), b("blue"), b("child"), b("sibling")]
    );
    // Replacing the object keeps the transform and children but drops the old object's props.
    t.set_object("//a/", b("obj2"));
    assert_eq!(t.object("/a").unwrap(), &b("obj2"));
    assert_eq!(t.transform("/a").unwrap(), &b("T2"));
    assert!(t.property("/a/<object>", "color").is_none());
    assert!(t.contains("/a/b"));
    // Delete removes the subtree only (not "/ab", which merely shares a prefix).
    t.delete("/a");
    assert!(!t.contains("/a") && !t.contains("/a/b"));
    assert!(t.contains("/ab"));
    // Thousands of pose updates keep the size constant.
    for i in 0..10_000 {
        t.set_transform("/ab", b(&format!("T{i}")));
    }
    assert_eq!(t.snapshot().len(), 2);
    t.set_animation(b("anim"));
    assert_eq!(t.snapshot().last().unwrap(), &b("anim"));
    t.delete("/");
    assert_eq!(t.len(), 0);
}

fn bundle_or_skip() -> Option<tungstenite::Bytes> {
    match page::load_bundle() {
        Ok(b) => Some(b),
        Err(p) => {
            assert!(std::env::var_os("CI").is_none(), "{}", page::bundle_help(&p));
            eprintln!("SKIPPED: {}", page::bundle_help(&p));
            None
        }
    }
}

#[test]
fn recorder_subsamples_moving_bodies_into_one_animation() {
    let scene = Scene::load().unwrap();
    let mut sim = Sim::new(&scene);
    let mut rec = Recorder::new(&scene.model);
    let mut q = crate::sim::HOME_Q;
    q[0] += 0.6;
    sim.set_arm_ctrl(&q);
    rec.frame(sim.data(), sim.time());
    for _ in 0..500 {
        sim.step();
        rec.frame(sim.data(), sim.time());
    }
    // 1 s at 30 fps: 31 samples (0, 1/30, …, 1.0), the last one the final state.
    assert!((30..=32).contains(&rec.len()), "{}", rec.len());
    let cmds = rec.commands();
    let anim = decode(cmds.last().unwrap());
    assert_eq!(field(&anim, &["type"]).as_str(), Some("set_animation"));
    assert_eq!(field(&anim, &["options", "loopMode"]).as_u64(), Some(2200));
    let anims = field(&anim, &["animations"]).as_array().unwrap();
    let paths: Vec<&str> = anims
        .iter()
        .map(|a| field(a, &["path"]).as_str().unwrap())
        .collect();
    assert!(paths.contains(&"/mujoco/ur5e_shoulder_link"));
    // The world, the fixed base, the mocap bowl and the resting cube do not move: no tracks.
    for still in ["/mujoco/world", "/mujoco/ur5e_base", "/mujoco/bowl"] {
        assert!(!paths.contains(&still), "{still}");
    }
    let clip = field(&anims[0], &["clip"]);
    assert_eq!(field(clip, &["fps"]).as_f64(), Some(30.0));
    let tracks = field(clip, &["tracks"]).as_array().unwrap();
    assert_eq!(field(&tracks[0], &["name"]).as_str(), Some(".position"));
    assert_eq!(field(&tracks[1], &["type"]).as_str(), Some("quaternion"));
    let Value::Ext(tag, times) = field(&tracks[1], &["times"]) else {
        panic!()
    };
    assert_eq!(*tag, EXT_FLOAT32);
    let Value::Ext(_, values) = field(&tracks[1], &["values"]) else {
        panic!()
    };
    assert_eq!(values.len(), times.len() * 4);
    // Times are in frames (the clip's fps scales them): the last one is ~30.
    let last = f32::from_le_bytes(times[times.len() - 4..].try_into().unwrap());
    assert!((last - 30.0).abs() < 0.2, "{last}");
    // Every body has an initial transform before the animation.
    let transforms = cmds
        .iter()
        .map(|c| decode(c))
        .filter(|v| field(v, &["type"]).as_str() == Some("set_transform"))
        .count();
    assert!(transforms >= 20);
}

#[test]
fn standalone_html_inlines_everything() {
    let Some(bundle) = bundle_or_skip() else { return };
    let cmds = vec![
        proto::encode(&proto::set_property("/Grid", "visible", Value::Boolean(false))),
        proto::encode(&proto::delete("/x")),
    ];
    let html = page::standalone_html(&bundle, &cmds, Some(&serde_json::json!({"duration": 1.0})));
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(!html.contains("src=\"/main.min.js\""), "no external script");
    assert!(!html.contains("MACROTREE:"), "all placeholders filled");
    assert!(html.contains("macrotree.replay(["));
    assert!(html.contains("MeshCat"));
    // Only the script elements we open and close.
    assert_eq!(html.matches("<script").count(), html.matches("</script>").count());
    assert_eq!(html.matches("</script>").count(), 3);
    use base64::Engine as _;
    let b64 = base64::engine::general_purpose::STANDARD.encode(&cmds[1]);
    assert!(html.contains(&b64));
}

#[test]
fn the_fast_pose_encoder_matches_the_generic_one() {
    let m = proto::mat_from_pos_xmat([0.1, -2.0, 3e-9], [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    for path in [
        "/a",
        "/mujoco/ur5e_shoulder_link",
        &format!("/{}", "x".repeat(40)),
        &format!("/{}", "y".repeat(300)),
    ] {
        assert_eq!(
            proto::encode_set_transform(path, &m),
            proto::encode(&proto::set_transform(path, &m)),
            "{path}"
        );
    }
}

/// Names that would change a page if they were pasted into its markup unescaped.
const HOSTILE: [&str; 6] = [
    "<!--<script>",
    "</script><script>window.__pwned = 1</script>",
    "</SCRIPT ><img src=x onerror=\"window.__pwned = 2\">",
    "a\u{2028}b\u{2029}c -->",
    "&lt;b&gt; & <b>bold</b> ]]>",
    "'\"`${x}\\",
];

/// Issue 13, item 9: tree and event names in a replay are data, never markup.
#[test]
fn hostile_names_cannot_change_the_replay_markup() {
    let nodes: Vec<_> = HOSTILE
        .iter()
        .enumerate()
        .map(|(i, name)| serde_json::json!({ "path": format!("root/{i}"), "name": name, "kind": name }))
        .collect();
    let meta = serde_json::json!({ "tree": nodes, "timeline": [{ "t": 0.0, "events": HOSTILE }] });
    // Code is inlined too: a bundle holding these sequences must not break out either.
    let bundle = b"var s = '</Script><!--<script>'; // </script>";
    let cmds = vec![proto::encode(&proto::delete("/x"))];
    let html = page::standalone_html(bundle, &cmds, Some(&meta));
    let lower = html.to_ascii_lowercase();
    // Inside a script element only `</script` ends it, and `<script` matters only after `<!--`.
    assert_eq!(
        lower.matches("</script").count(),
        3,
        "only our script elements close"
    );
    assert!(
        !html.contains("<!--"),
        "nothing enters the parser's escaped states"
    );
    assert_eq!(html.matches("<script>\n").count(), 3);
    for c in ['\u{2028}', '\u{2029}'] {
        assert!(!html.contains(c), "raw line separators are escaped");
    }
    // The embedded metadata still reads back as the same JSON value.
    let start = html.find("macrotree.replay(").unwrap();
    let args = &html[start..];
    let meta_start = args.find("], ").unwrap() + 3;
    let meta_end = args.find(");\n</script>").unwrap();
    let back: serde_json::Value = serde_json::from_str(&args[meta_start..meta_end]).unwrap();
    assert_eq!(back, meta);
    assert_eq!(page::script_json(&meta).find(['<', '>', '&']), None);
}
