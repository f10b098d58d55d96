//! The seeded layout sampler: scenario `k` of sweep seed `S` is a pure function of `(S, k)`.
//! [`draw`] is the one place a scene's scenario is drawn: `macrotree sweep`, `run --scenario K
//! --sweep-seed S` and `env::Reset::Scenario` all call it.
//!
//! Each scenario draws from its own ChaCha8 stream: the generator is seeded with
//! `ChaCha8Rng::seed_from_u64(S)` and switched to stream `k` (`set_stream(k)`), so a scenario
//! never depends on how many scenarios came before it, on the number of jobs or on the shard.
//! Uniform floats are built from the top 53 bits of a `u64` draw (`lo + (hi − lo)·u`,
//! `u ∈ [0, 1)`), which is the same on every platform.
//!
//! From the stream, in this order: the episode seed (one `u64`, used for fault timing and
//! magnitude), then cube x, y, yaw, bowl x, y; the pair is rejected and redrawn (cube and bowl
//! again) until the centres are at least [`Region::min_separation`] apart.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{RngCore, SeedableRng};
use serde::Serialize;

use crate::scene::{Placement, PlacementError, Sampler, sample_placement};
use crate::sim::{Layout, Scene};

/// The task region the sampler draws from. Metres and degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Region {
    /// Range of the cube and bowl centre x, metres (inclusive).
    pub x: [f64; 2],
    /// Range of the cube and bowl centre y, metres (inclusive).
    pub y: [f64; 2],
    /// Range of the cube yaw, degrees (`[lo, hi)`).
    pub yaw_deg: [f64; 2],
    /// Smallest distance between the cube and bowl centres, metres.
    pub min_separation: f64,
}

impl Region {
    /// The documented task region: x ∈ [0.30, 0.60] m, y ∈ [−0.30, 0.30] m, yaw ∈ [−45°, 45°),
    /// centres ≥ 0.16 m apart.
    pub const TASK: Region = Region {
        x: [0.30, 0.60],
        y: [-0.30, 0.30],
        yaw_deg: [-45.0, 45.0],
        min_separation: 0.16,
    };

    /// `layout` lies in this region (both centres in the rectangle, yaw in range, far enough apart).
    pub fn contains(&self, l: &ScenarioLayout) -> bool {
        let in_rect =
            |p: [f64; 2]| (self.x[0]..=self.x[1]).contains(&p[0]) && (self.y[0]..=self.y[1]).contains(&p[1]);
        in_rect([l.cube[0], l.cube[1]])
            && in_rect(l.bowl)
            && (self.yaw_deg[0]..self.yaw_deg[1]).contains(&l.cube[2])
            && l.separation() >= self.min_separation
    }
}

/// A sampled layout, exactly as `macrotree run --cube X,Y,YAW --bowl X,Y` spells it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ScenarioLayout {
    /// Cube centre x, y (metres) and yaw (degrees).
    pub cube: [f64; 3],
    /// Bowl centre x, y (metres).
    pub bowl: [f64; 2],
}

impl ScenarioLayout {
    /// Distance between the cube and bowl centres, metres.
    pub fn separation(&self) -> f64 {
        (self.cube[0] - self.bowl[0]).hypot(self.cube[1] - self.bowl[1])
    }

    /// The simulator layout, converted exactly as `macrotree run` converts its arguments
    /// (yaw with `f64::to_radians`), so a printed reproduction command is bit-exact.
    pub fn to_layout(&self) -> Layout {
        Layout {
            cube_xy: [self.cube[0], self.cube[1]],
            cube_yaw: self.cube[2].to_radians(),
            bowl_xy: self.bowl,
        }
    }
}

/// Scenario `index` of sweep seed `sweep_seed` on a scene, as [`draw`] draws it: the episode
/// seed and every object's starting pose. The one scenario type of sweeps, `run --scenario K
/// --sweep-seed S` and the step-wise environment's `Reset::Scenario`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scenario {
    /// The sweep seed `S`.
    pub sweep_seed: u64,
    /// The scenario index `k`.
    pub index: u64,
    /// The episode seed (fault timing and magnitude), drawn from the scenario's stream.
    pub seed: u64,
    /// Every object's starting pose, scene order (x, y in metres, yaw in radians).
    pub placement: Placement,
    /// The tutorial's cube/bowl layout, for a `sampler: tutorial` scene (metres and degrees).
    pub layout: Option<ScenarioLayout>,
}

/// The task-region sampler's draw for scenario `index` of sweep seed `sweep_seed`
/// ([`Region::TASK`]): the episode seed and where the cube and the bowl start (metres and
/// degrees).
pub fn sample_layout(sweep_seed: u64, index: u64) -> (u64, ScenarioLayout) {
    sample_layout_in(&Region::TASK, sweep_seed, index)
}

/// The sampler's draw for scenario `index` of sweep seed `sweep_seed` in `region`: the episode
/// seed and where the cube and the bowl start (metres and degrees).
///
/// # Panics
/// If no layout is found after a million draws (the region cannot hold two centres
/// `min_separation` apart).
pub fn sample_layout_in(region: &Region, sweep_seed: u64, index: u64) -> (u64, ScenarioLayout) {
    let mut rng = ChaCha8Rng::seed_from_u64(sweep_seed);
    rng.set_stream(index);
    let seed = rng.next_u64();
    for _ in 0..1_000_000 {
        let mut draw = |r: [f64; 2]| r[0] + (r[1] - r[0]) * unit(&mut rng);
        let cube = [draw(region.x), draw(region.y), draw(region.yaw_deg)];
        let bowl = [draw(region.x), draw(region.y)];
        let layout = ScenarioLayout { cube, bowl };
        if layout.separation() >= region.min_separation && cube[2] < region.yaw_deg[1] {
            return (seed, layout);
        }
    }
    panic!(
        "the region {region:?} cannot hold a cube and a bowl {} m apart",
        region.min_separation
    )
}

/// Scenario `index` of sweep seed `sweep_seed` on `scene`. A scene with `sampler: tutorial`
/// (the built-in `cube_bowl`) draws its cube and bowl with the documented task-region sampler
/// ([`sample_layout`]); every other scene draws its own randomization
/// ([`crate::scene::sample_placement`]).
///
/// # Errors
/// When the scene's randomization cannot place its objects.
pub fn draw(scene: &Scene, sweep_seed: u64, index: u64) -> Result<Scenario, PlacementError> {
    let (seed, placement, layout) = if scene.spec.sampler == Sampler::Tutorial {
        let (seed, layout) = sample_layout(sweep_seed, index);
        (
            seed,
            scene.placement_from_layout(&layout.to_layout()),
            Some(layout),
        )
    } else {
        let (seed, placement) = sample_placement(&scene.spec, sweep_seed, index)?;
        (seed, placement, None)
    };
    Ok(Scenario {
        sweep_seed,
        index,
        seed,
        placement,
        layout,
    })
}

/// A uniform float in [0, 1) from the top 53 bits of a draw.
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scenario_depends_only_on_seed_and_index() {
        assert_eq!(sample_layout(7, 3), sample_layout(7, 3));
        assert_ne!(sample_layout(7, 3).1, sample_layout(7, 4).1);
        assert_ne!(sample_layout(7, 3).1, sample_layout(8, 3).1);
    }
}
