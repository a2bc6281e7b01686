//! The policy: what a new run trains, read from its clip, and why.
//!
//! - [`clip_rule`]: the settings one reading of the clip decides (steps, window, dropout,
//!   channels, batch);
//! - [`step_ladder`]: a calm clip's steps, chosen by the samples of short runs;
//! - [`budget`]: the steps a time budget (`sinmdm-train --minutes`) buys on this machine.
//!
//! [`start_run`] ([`start`]) is the way in: it reads the clip, applies the rule, sets the steps
//! (a time budget, or the ladder where the rule leaves them to it), and starts the run
//! ([`crate::run::Trainer::start_chosen`]) with the final configuration and the
//! [`crate::chosen::Choices`] record. The trainer imports nothing from here.

pub mod budget;
pub mod clip_rule;
pub mod ladder_settings;
pub mod start;
pub mod step_ladder;

pub use start::{StepsFrom, start_run};
