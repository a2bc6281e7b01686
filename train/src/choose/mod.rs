//! The policy: what a new run trains, read from its clip, and why.
//!
//! - [`clip_rule`]: the settings one reading of the clip decides (steps, window, dropout,
//!   channels, batch);
//! - [`step_ladder`]: a calm clip's steps, chosen by the samples of short runs;
//! - [`budget`]: the steps a time budget (`sinmdm-train --minutes`) buys on this machine.
//!
//! [`start_run`] is the way in: it reads the clip, applies the rule, climbs the ladder where the
//! rule leaves the steps to it, and starts the run ([`crate::run::Trainer::start_chosen`]) with
//! the final configuration and the [`crate::chosen::Choices`] record.

pub mod budget;
pub mod clip_rule;
pub mod ladder_settings;
pub mod step_ladder;

pub use step_ladder::start_run;
