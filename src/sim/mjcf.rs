//! The scene's objects as MJCF text, inserted into the cell (`assets/scene.xml`) before it is
//! compiled with MjSpec. Every name starts with [`OBJECT_PREFIX`], so user names cannot collide
//! with the robot's.
//!
//! | object | MuJoCo |
//! |---|---|
//! | block `b` | body `obj/b` with a free joint `obj/b/joint` and a box geom `obj/b` |
//! | container `c` | mocap body `obj/c`: box geoms `obj/c/floor`, `obj/c/wall_px`, `_nx`, `_py`, `_ny`; site `obj/c/target` at the floor's top centre |
//! | obstacle `o` | mocap body `obj/o` with a box geom `obj/o` |
//!
//! Containers and obstacles are mocap bodies: a layout moves them through `mocap_pos`/`mocap_quat`
//! without recompiling, and they never move by physics. A body's origin is the centre of the
//! object's base, at the object's height `z:` above the table (a shelf board, a raised bin).
//!
//! A block's contact parameters are the ones measured for the reference cube: `priority="2"`
//! makes them win over the 2F-85 pads (priority 1), so the unmodified Menagerie pads hold it with
//! the block's sliding friction, torsional friction 0.01 (condim 4 resists pivoting between the
//! pads) and the stiff solref/solimp the pads use.

use std::fmt::Write as _;

use crate::scene::{CONTAINER_FLOOR, CONTAINER_WALL, OBJECT_PREFIX, ObjectSpec, SceneSpec, Shape};

/// A number as MJCF text: rounded to 1e-9 (so `0.15 / 2 + 0.01` is written `0.085`), no
/// trailing zeros.
fn n(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

fn rgba(o: &ObjectSpec) -> String {
    let [r, g, b, a] = o.color.rgba;
    format!("{} {} {} {}", n(r), n(g), n(b), n(a))
}

fn boxgeom(out: &mut String, name: &str, half: [f64; 3], pos: [f64; 3], rgba: &str) {
    let _ = writeln!(
        out,
        r#"      <geom name="{name}" type="box" size="{} {} {}" pos="{} {} {}" rgba="{rgba}"/>"#,
        n(half[0]),
        n(half[1]),
        n(half[2]),
        n(pos[0]),
        n(pos[1]),
        n(pos[2])
    );
}

/// The MJCF bodies of every object of `scene`, in scene order, at their fixed pose (or the
/// origin; layouts place them before an episode starts).
pub fn objects_mjcf(scene: &SceneSpec) -> String {
    let mut out = String::new();
    for o in &scene.objects {
        let name = format!("{OBJECT_PREFIX}{}", o.name);
        let pose = o.pose.unwrap_or_default();
        let color = rgba(o);
        match &o.shape {
            Shape::Block { half, mass, friction } => {
                let _ = writeln!(
                    out,
                    r#"    <body name="{name}" pos="{} {} {}">
      <freejoint name="{name}/joint"/>
      <geom name="{name}" type="box" size="{h} {h} {h}" mass="{}" rgba="{color}"
            friction="{} 0.01 0.0001" condim="4" priority="2" solimp="0.95 0.99 0.001" solref="0.004 1"/>
    </body>"#,
                    n(pose.x),
                    n(pose.y),
                    n(*half),
                    n(*mass),
                    n(*friction),
                    h = n(*half),
                );
            }
            Shape::Container {
                inner_half,
                wall_height,
            } => {
                let [ix, iy] = *inner_half;
                let (t, f, h) = (CONTAINER_WALL, CONTAINER_FLOOR, *wall_height);
                let _ = writeln!(
                    out,
                    r#"    <body name="{name}" mocap="true" pos="{} {} {}">"#,
                    n(pose.x),
                    n(pose.y),
                    n(o.z)
                );
                boxgeom(
                    &mut out,
                    &format!("{name}/floor"),
                    [ix + t, iy + t, f / 2.0],
                    [0.0, 0.0, f / 2.0],
                    &color,
                );
                let wx = [t / 2.0, iy + t, h / 2.0];
                let wy = [ix, t / 2.0, h / 2.0];
                boxgeom(
                    &mut out,
                    &format!("{name}/wall_px"),
                    wx,
                    [ix + t / 2.0, 0.0, h / 2.0],
                    &color,
                );
                boxgeom(
                    &mut out,
                    &format!("{name}/wall_nx"),
                    wx,
                    [-(ix + t / 2.0), 0.0, h / 2.0],
                    &color,
                );
                boxgeom(
                    &mut out,
                    &format!("{name}/wall_py"),
                    wy,
                    [0.0, iy + t / 2.0, h / 2.0],
                    &color,
                );
                boxgeom(
                    &mut out,
                    &format!("{name}/wall_ny"),
                    wy,
                    [0.0, -(iy + t / 2.0), h / 2.0],
                    &color,
                );
                let _ = writeln!(
                    out,
                    r#"      <site name="{name}/target" pos="0 0 {}" size="0.01" rgba="0.1 0.9 0.1 0.7"/>
    </body>"#,
                    n(f)
                );
            }
            Shape::Obstacle { half } => {
                let _ = writeln!(
                    out,
                    r#"    <body name="{name}" mocap="true" pos="{} {} {}">"#,
                    n(pose.x),
                    n(pose.y),
                    n(o.z)
                );
                boxgeom(&mut out, &name, *half, [0.0, 0.0, half[2]], &color);
                let _ = writeln!(out, "    </body>");
            }
        }
    }
    out
}

/// The cell XML with `scene`'s objects inserted into its worldbody.
pub fn cell_mjcf(cell_xml: &str, scene: &SceneSpec) -> String {
    let at = cell_xml.rfind("  </worldbody>").unwrap_or(cell_xml.len());
    let mut xml = String::with_capacity(cell_xml.len() + 4096);
    xml.push_str(&cell_xml[..at]);
    xml.push_str(&objects_mjcf(scene));
    xml.push_str(&cell_xml[at..]);
    xml
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cube_bowl_scene_builds_the_reference_tray_and_cube() {
        let xml = objects_mjcf(&SceneSpec::builtin());
        assert!(
            xml.contains(r#"<geom name="obj/cube" type="box" size="0.022 0.022 0.022" mass="0.05""#),
            "{xml}"
        );
        assert!(
            xml.contains(r#"name="obj/bowl/floor" type="box" size="0.085 0.085 0.005" pos="0 0 0.005""#),
            "{xml}"
        );
        assert!(
            xml.contains(r#"name="obj/bowl/wall_px" type="box" size="0.005 0.085 0.03" pos="0.08 0 0.03""#),
            "{xml}"
        );
        assert!(
            xml.contains(r#"name="obj/bowl/wall_ny" type="box" size="0.075 0.005 0.03" pos="0 -0.08 0.03""#),
            "{xml}"
        );
    }
}
