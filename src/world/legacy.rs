//! The compatibility layer for the first trees' names `cube` and `bowl`: the one place that says
//! which objects they stand for ([`crate::scene::SceneSpec::legacy_cube`],
//! [`crate::scene::SceneSpec::legacy_bowl`]: the block called `cube`, else the scene's only block;
//! the container called `bowl`, else its only container). Everything that reads "the cube" or
//! "the bowl" — the `cube_*` conditions, the `cube`/`bowl` targets, the reference tutorial's
//! checks, the reports' `cube_final`/`bowl_target`, the faults — resolves them here, and then
//! reads the general object state of [`World::objects`].

use crate::failure::Failure;
use nalgebra::Vector3;

use super::World;
use crate::scene::CONTAINER_FLOOR;

impl World {
    /// The block the legacy name `cube` stands for, if the scene has one.
    pub fn cube(&self) -> Option<usize> {
        self.scene.legacy_cube()
    }

    /// The container the legacy name `bowl` stands for, if the scene has one.
    pub fn bowl(&self) -> Option<usize> {
        self.scene.legacy_bowl()
    }

    /// [`World::cube`], or why the scene has none (for condition and action failures).
    pub fn require_cube(&self) -> Result<usize, Failure> {
        self.cube().ok_or_else(|| {
            Failure::other(format!(
                "scene `{}` has no cube: `cube` stands for the block called `cube`, else the scene's only block",
                self.scene.name
            ))
        })
    }

    /// [`World::bowl`], or why the scene has none (for condition and action failures).
    pub fn require_bowl(&self) -> Result<usize, Failure> {
        self.bowl().ok_or_else(|| {
            Failure::other(format!(
                "scene `{}` has no bowl: `bowl` stands for the container called `bowl`, else the scene's only container",
                self.scene.name
            ))
        })
    }

    /// The bowl target: the centre of the bowl floor's top surface, world frame, metres (`None`
    /// when the scene has no bowl).
    pub fn bowl_target(&self) -> Option<Vector3<f64>> {
        self.bowl().map(|b| {
            let p = self.objects[b].pos;
            Vector3::new(p.x, p.y, p.z + CONTAINER_FLOOR)
        })
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use crate::scene::SceneSpec;
    use crate::world::tests_support::resting;

    #[test]
    fn the_legacy_names_resolve_to_the_only_block_and_container() {
        let w = resting();
        assert_eq!((w.cube(), w.bowl()), (Some(0), Some(1)));
        let t = w.bowl_target().unwrap();
        assert_eq!([t.x, t.y, t.z], [0.45, 0.08, 0.01]);
    }

    #[test]
    fn a_scene_without_a_bowl_has_no_bowl_target() {
        let mut w = resting();
        w.scene = Arc::new(
            SceneSpec::from_str(
                "objects:\n  a: {block: {size: 0.04}, pose: [0.45, -0.1]}\n  b: {block: {size: 0.04}, pose: [0.45, 0.1]}\n",
                "two.yaml",
            )
            .unwrap(),
        );
        assert_eq!((w.cube(), w.bowl(), w.bowl_target()), (None, None, None));
        assert!(w.require_cube().unwrap_err().message.contains("only block"));
        assert!(w.require_bowl().unwrap_err().message.contains("only container"));
    }
}
