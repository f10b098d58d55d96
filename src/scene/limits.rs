//! What a scene file may set: the ranges of an object's size, mass, friction and placement,
//! each declared once. The scene's JSON Schema, the reader's checks and their messages read
//! these constants; a test holds every schema description to the numbers declared here.

use crate::yaml::Bounds;

/// A block's edge, metres (the 2F-85 opens 0.085 m).
pub const BLOCK_EDGE: Bounds = Bounds::new(0.02, 0.07);
/// A block's mass, kg.
pub const BLOCK_MASS: Bounds = Bounds::new(0.005, 0.5);
/// A block's sliding friction coefficient (below 0.5 the 2F-85's pads cannot hold a block
/// through a fast carry).
pub const BLOCK_FRICTION: Bounds = Bounds::new(0.5, 2.0);
/// Each side of a container's free space inside the walls, metres.
pub const CONTAINER_INNER: Bounds = Bounds::new(0.06, 0.40);
/// A container's rim above the table, metres.
pub const WALL_HEIGHT: Bounds = Bounds::new(0.02, 0.12);
/// An obstacle's size along x and along y, metres.
pub const OBSTACLE_SIDE: Bounds = Bounds::new(0.01, 0.5);
/// An obstacle's height, metres (a post or a fixture).
pub const OBSTACLE_HEIGHT: Bounds = Bounds::new(0.01, 1.0);
/// The base of a container or an obstacle above the table (`z:`), metres.
pub const BASE_HEIGHT: Bounds = Bounds::new(0.0, 0.6);
/// A random placement's smallest gap to every other object's footprint, metres.
pub const CLEARANCE: Bounds = Bounds::new(0.0, 0.5);
