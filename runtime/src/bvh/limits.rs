//! What a BVH file may hold: its size, joints, names and hierarchy lines, each a named limit
//! the reader checks as it goes, so a file from a stranger cannot make it allocate past them.

use crate::files::FileLimit;

/// The largest BVH file read (1 GiB): far beyond a long capture, and a bound on what a file can
/// make the reader allocate.
pub const MAX_BVH_BYTES: u64 = 1 << 30;
/// The most joints a BVH file may have: the most a model's skeleton may have. It bounds the
/// nesting depth too (the parser keeps open joints on a stack, not the call stack, so a chain
/// of this many joints is read).
pub const MAX_BVH_JOINTS: usize = crate::limits::MAX_JOINTS;
/// The most words a line of the hierarchy may hold: a keyword and six channels, or a joint name
/// of up to [`MAX_BVH_NAME_BYTES`], take far fewer.
pub const MAX_BVH_LINE_WORDS: usize = 256;
/// The longest joint name, in bytes: the longest a model's skeleton may have.
pub const MAX_BVH_NAME_BYTES: usize = crate::limits::MAX_NAME_BYTES;
/// The size limit of BVH files, for [`crate::files::read_regular_file`].
pub const BVH_LIMIT: FileLimit = FileLimit {
    bytes: MAX_BVH_BYTES,
    name: "MAX_BVH_BYTES",
    what: "a BVH file",
};
