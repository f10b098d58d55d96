//! Demonstrations out of sweeps: every episode sampled at a fixed frame rate ([`record`]) and
//! written as a LeRobot v3.0 dataset ([`DatasetWriter`], feature `dataset`) — parquet data with
//! robot state, commanded action, object poses and the running leaf per frame, H.264 videos
//! per camera, and LeRobot's metadata. See docs/datasets.md for every column.

pub mod record;
#[cfg(feature = "dataset")]
pub mod stats;
#[cfg(feature = "dataset")]
pub mod table;
#[cfg(feature = "dataset")]
mod writer;

pub use record::{
    CONTROL_RATE, DEFAULT_FRAME_RATE, EpisodeRecorder, FRAME_RATES, FrameRecord, Recording, STATE_NAMES,
    parse_frame_rate,
};
#[cfg(feature = "dataset")]
pub use writer::{
    CHUNKS_SIZE, CODEBASE_VERSION, DatasetError, DatasetOptions, DatasetWriter, MARKER, ROBOT_TYPE,
    check_dir, video_key,
};
