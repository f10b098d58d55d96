//! Real MuJoCo: kinematics, trajectories, the collision screen and planner, the macro-action leaves, faults, episodes, multi-object tasks, sweeps through the library, the step-wise environment.
//!
//! One test binary (`cargo test --release --test physics`); one file per subject.

#[path = "../support/mod.rs"]
mod support;

mod action_noise;
mod action_roles;
mod container_packing;
mod ctrl_replay;
mod env_primitives;
mod env_replay;
mod env_residual;
mod env_step;
mod env_subtree;
mod env_vector;
mod episode_halt;
mod episode_layouts;
mod example_trees;
mod failure_kinds;
mod fault_nudge;
mod fault_recovery;
mod fault_slip;
mod goal_predicates;
mod held_out_posts;
mod model_cache;
mod motion_cells;
mod motion_collision;
mod motion_fk;
mod motion_gripper;
mod motion_ik;
mod motion_in_cell;
mod motion_screen;
mod motion_tracking;
mod motion_trajectory;
mod multi_object;
mod nodes;
mod place;
mod policy_leaf;
mod scene_layout;
mod shipped_tree_contacts;
mod side_grasp;
mod spot_targets;
mod sweep_batch;
mod sweep_layouts;
