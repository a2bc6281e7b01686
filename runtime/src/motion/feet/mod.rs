//! Planted feet: a pass over decoded motion that holds each contact point still while the
//! model's own contact labels say it is on the ground, and keeps everything above the ground,
//! by turning the joints of each leg (bone lengths stay exact). Usable on its own
//! ([`plant_feet`]) and applied by default to the motion and poses of a
//! [`Generated`](crate::Generated) batch ([`Feet`]).
//!
//! - [`spans`]: contact spans from labels (hysteresis, shortest span) and blend weights;
//! - [`chain`]: which joints above a contact joint may turn;
//! - [`options`]: what the pass is asked, must keep, and reports;
//! - [`plant`]: the pass itself, phase by phase ([`plant_feet`]);
//! - `stance`: the root's horizontal travel with the feet in contact, before the legs turn;
//! - `targets`: where each contact point should be, frame by frame;
//! - `solve`: each frame's legs turned by [`least_turn`](crate::motion::ik::least_turn), and
//!   the lift that keeps the motion above the ground.

pub mod chain;
pub mod options;
pub mod plant;
mod solve;
pub mod spans;
mod stance;
mod targets;

pub use crate::motion::ground::{GROUND_PERCENTILE, ground_level};
pub use chain::{LegChain, leg_chain};
pub use options::{Anchor, Kept, PlantOptions, PlantStats};
pub use plant::plant_feet;
pub use spans::{CONTACT_OFF, CONTACT_ON, contact_spans};

/// What happens to the feet of generated motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Feet {
    /// Contact points held still during their predicted contact spans and nothing below the
    /// ground ([`plant_feet`] with default [`PlantOptions`]). The default.
    #[default]
    Planted,
    /// The network's motion untouched.
    Raw,
}
