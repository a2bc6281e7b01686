//! Bevy plugin for sinmdm: characters whose motion is generated, endlessly, by a model trained on
//! one clip.
//!
//! [`spawn_character`] makes an entity per joint (with its [`Transform`], parented as the
//! skeleton is) under a character entity that holds a [`MotionCharacter`]. Every frame,
//! [`SinmdmPlugin`]'s system advances each character's clock by the frame's time, writes the
//! pose due (interpolated between the model's frames) into the joints' transforms before
//! Bevy propagates them, and, when fewer than [`CharacterOptions::ahead_frames`] frames are
//! ready, asks the character's [`sinmdm::Stream`] for the next chunk on Bevy's
//! [`AsyncComputeTaskPool`](bevy_tasks::AsyncComputeTaskPool), so frames do not wait on the
//! network. A [`Steering`] component on the character steers a heading-relative model.
//!
//! Poses are placed in Bevy's frame (+Y up, metres) by [`EngineFrame`]: the model's up axis
//! comes from its file, its unit is guessed from the figure's height unless given.
//!
//! Many characters of one model can share a [`MotionCrowd`] ([`spawn_crowd`],
//! [`spawn_crowd_character`]): one request on the compute pool makes the next chunk of every
//! character that needs one, their blocks through the network together.
//!
//! With the `animation-clip` feature, [`bake`] turns generated poses into an
//! `AnimationClip` that Bevy's animation graph can blend with authored clips.

pub mod character;
pub mod crowd;
pub mod frame;
mod playback;
pub mod steering;

#[cfg(feature = "animation-clip")]
pub mod bake;

use bevy_app::{AnimationSystems, App, Plugin, PostUpdate};
use bevy_ecs::prelude::*;
use bevy_time::Time;
use bevy_transform::TransformSystems;
use bevy_transform::components::Transform;

pub use character::{
    CharacterOptions, MotionCharacter, MotionModel, spawn_character, spawn_skeleton,
};
pub use crowd::{CrowdCharacter, CrowdOptions, MotionCrowd, spawn_crowd, spawn_crowd_character};
pub use frame::EngineFrame;
pub use steering::Steering;

/// The plugin: drives every [`MotionCharacter`] in [`PostUpdate`], in [`SinmdmSystems::Drive`],
/// after Bevy's animation systems (so a stream's pose wins over a clip playing on the same
/// joints) and before transform propagation.
pub struct SinmdmPlugin;

/// The plugin's system sets, for ordering a game's own systems around them.
#[derive(SystemSet, Debug, Clone, PartialEq, Eq, Hash)]
pub enum SinmdmSystems {
    /// Poses written into the joints' transforms.
    Drive,
}

impl Plugin for SinmdmPlugin {
    fn build(&self, app: &mut App) {
        app.configure_sets(
            PostUpdate,
            SinmdmSystems::Drive
                .after(AnimationSystems)
                .before(TransformSystems::Propagate),
        )
        .add_systems(
            PostUpdate,
            (drive_characters, crowd::drive_crowds).in_set(SinmdmSystems::Drive),
        );
    }
}

/// Advances every character by the frame's time and writes its pose: first every character's
/// clock and requests (so the compute pool works on all of them at once), then the poses.
fn drive_characters(
    time: Res<Time>,
    mut characters: Query<(&mut MotionCharacter, Option<&Steering>)>,
    mut transforms: Query<&mut Transform, Without<MotionCharacter>>,
) {
    let seconds = time.delta_secs_f64();
    for (mut character, steering) in &mut characters {
        character.advance(seconds, steering);
    }
    for (mut character, steering) in &mut characters {
        character.show(steering, &mut transforms);
    }
}
