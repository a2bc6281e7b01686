//! glTF 2.0 (`.glb` and `.gltf`): skinned skeletons with animations, read as clips and written
//! from motions.

mod accessor;
mod animate;
pub mod container;
mod drive;
mod nodes;
mod read;
mod replant;
mod skin;
mod splice;
mod tracks;
mod write;

pub use drive::Retargeted;
pub use read::{GltfClip, list_animations, read_gltf, read_gltf_with_access};
pub use splice::{SpliceReport, character_bones, splice_into_character, splice_retargeted};
pub use write::{GltfWriteOptions, gltf_document, write_gltf};

/// The key under a node's `extras` where this crate keeps what glTF has no place for: the
/// joint's BVH channel list and its End Site, so BVH -> glTF -> BVH gives the same skeleton.
pub const EXTRAS_KEY: &str = "sinmdm";
