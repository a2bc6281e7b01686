//! Retargeting: motion learned on one rig put onto a character with other proportions, other
//! rest orientations or other bone names. A bone map pairs the character's bones with the
//! model's joints ([`bone_map`], [`conventions`]); each paired bone then turns in the world as
//! its joint does, from a rest in which both point the same way ([`align`]).

pub mod align;
pub mod bone_map;
pub mod conventions;

pub use bone_map::{AutoMap, BoneMap, Rig};
pub use conventions::{Convention, Recognised, Role, Side, plain_name, recognise};

/// How the character's bones are matched to the model's joints.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum BoneMatch {
    /// By name (with or without a namespace); a character whose rest differs is retargeted.
    #[default]
    Names,
    /// By the naming conventions both rigs follow (`--retarget auto`).
    Auto,
    /// By a map the user wrote (`--retarget MAP.yaml`).
    Map(BoneMap, std::path::PathBuf),
}
