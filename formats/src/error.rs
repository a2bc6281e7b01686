//! Errors of the format readers and writers: each names the file and the part of it at fault.

use std::fmt;
use std::path::PathBuf;

/// The part of a glTF file a problem is in.
#[derive(Debug, Clone, PartialEq)]
pub enum Part {
    /// The GLB container (header and chunks).
    Container,
    /// The JSON document as a whole.
    Json,
    /// `buffers[i]`.
    Buffer(usize),
    /// `bufferViews[i]`.
    BufferView(usize),
    /// `accessors[i]`.
    Accessor(usize),
    /// `nodes[i]`, with its name when it has one.
    Node(usize, Option<String>),
    /// `skins[i]`.
    Skin(usize),
    /// `animations[i]`, with its name when it has one.
    Animation(usize, Option<String>),
    /// `animations[a].samplers[s]`.
    Sampler(usize, usize),
    /// `animations[a].channels[c]`.
    Channel(usize, usize),
    /// The skeleton the file describes.
    Skeleton,
    /// An FBX file's data as a whole.
    Fbx,
    /// A bone map's entry for the named character bone.
    MapEntry(String),
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let named =
            |f: &mut fmt::Formatter<'_>, what: &str, i: usize, name: &Option<String>| match name {
                Some(n) => write!(f, "{what} {i} ('{n}')"),
                None => write!(f, "{what} {i}"),
            };
        match self {
            Part::Container => f.write_str("GLB container"),
            Part::Json => f.write_str("JSON"),
            Part::Buffer(i) => write!(f, "buffer {i}"),
            Part::BufferView(i) => write!(f, "bufferView {i}"),
            Part::Accessor(i) => write!(f, "accessor {i}"),
            Part::Node(i, name) => named(f, "node", *i, name),
            Part::Skin(i) => write!(f, "skin {i}"),
            Part::Animation(i, name) => named(f, "animation", *i, name),
            Part::Sampler(a, s) => write!(f, "animation {a}, sampler {s}"),
            Part::Channel(a, c) => write!(f, "animation {a}, channel {c}"),
            Part::Skeleton => f.write_str("skeleton"),
            Part::Fbx => f.write_str("FBX data"),
            Part::MapEntry(name) => write!(f, "bone '{name}'"),
        }
    }
}

/// Why a motion file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// The file could not be read or written. The reason is said in the message and not
    /// chained as a source, so a printer of causes (`{:#}`) says it once.
    #[error("{}: {reason}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's reason, or the limit the file broke.
        reason: std::io::Error,
    },
    /// The file's extension names no format this reads or writes.
    #[error("{}: {message}", path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is supported instead.
        message: String,
    },
    /// A BVH file could not be read.
    #[error(transparent)]
    Bvh(#[from] sinmdm::bvh::BvhError),
    /// A part of the file is malformed or holds something the reader cannot use.
    #[error("{}: {part}: {message}", path.display())]
    Bad {
        /// The file.
        path: PathBuf,
        /// Where in it.
        part: Part,
        /// What is wrong.
        message: String,
    },
    /// What was asked cannot be written (no motion, motions of different skeletons).
    #[error("{}: {message}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl FormatError {
    /// A [`FormatError::Bad`] about `part` of `path`.
    pub fn bad(path: &std::path::Path, part: Part, message: String) -> FormatError {
        FormatError::Bad {
            path: path.to_path_buf(),
            part,
            message,
        }
    }
}
