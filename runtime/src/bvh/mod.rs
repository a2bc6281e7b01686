//! BVH files in and out (feature `bvh`).

mod error;
mod limits;
mod read;
mod stream_write;
mod write;

pub use error::{BvhError, BvhErrorKind};
pub use limits::{
    BVH_LIMIT, MAX_BVH_BYTES, MAX_BVH_JOINTS, MAX_BVH_LINE_WORDS, MAX_BVH_NAME_BYTES,
};
pub use read::{parse_bvh, read_bvh};
pub use stream_write::BvhStreamWriter;
pub use write::{to_bvh_string, write_bvh};
