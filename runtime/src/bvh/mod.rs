//! BVH files in and out (feature `bvh`).

mod error;
mod read;
mod stream_write;
mod write;

pub use error::{BvhError, BvhErrorKind};
pub use read::{parse_bvh, read_bvh};
pub use stream_write::BvhStreamWriter;
pub use write::{to_bvh_string, write_bvh};
