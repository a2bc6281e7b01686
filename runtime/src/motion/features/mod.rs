//! The per-frame feature vector the model learns, and the way back to a motion.
//!
//! Columns, in this order (each group may be empty):
//! 1. root: for the motion root's position channels, the two ground-plane axes as per-frame
//!    displacement (frame 0 copies frame 1) and the up axis as absolute height;
//! 2. rotations: the 6D rotation of every joint that has rotation channels, in joint order;
//! 3. positions: the non-root position channels that vary over the clip (absolute values);
//! 4. contacts: one 0/1 label per contact joint.
//!
//! Position channels that never change are static skeleton data ([`FeatureLayout::rest_translations`]),
//! and the root's first position is kept as [`RootFeatures::start_position`], so decoding
//! integrates the displacements back to world positions.
//!
//! Features live in the canonical Y-up frame ([`super::up`]): `encode` turns the clip into it
//! with the clip's detected (or given) up axis, recorded as [`FeatureLayout::up`], and `decode`
//! turns the motion back into the file's frame. So a Z-up clip and its Y-up twin have the same
//! features, and the root's axes below are canonical axes (Y = up).

/// Features of one motion, laid out `[F, N]`: one row per feature column (see
/// [`FeatureLayout::columns`]), one column per frame. Batches add a leading sample axis,
/// `[B, F, N]`, the layout of the network's `x_t` and `x0`.
pub type FeatureMatrix = ndarray::Array2<f32>;

mod decode;
mod encode;
mod error;
mod fill;
pub mod heading;
mod layout;
mod reference;

pub use decode::{RootStart, decode, decode_from, root_track};
pub use encode::{EncodeOptions, EncodedClip, encode, encode_for, encode_motion};
pub use error::MotionError;
pub use heading::{Heading, RootLayout};
pub use layout::{Column, ColumnKind, FeatureLayout, HEADING_ROOT_KINDS, RootFeatures};
pub use reference::{ClipForModel, encode_for_model};
