//! A new run, from its configuration to its trainer, in one pass: the clip read once, the rule
//! that reads it applied once, the steps set by a time budget or the step ladder, and the
//! trainer started with the final configuration and the record of what was chosen.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use burn::tensor::Device;

use crate::choose::budget;
use crate::choose::clip_rule;
use crate::choose::step_ladder::{self, Ladder, LadderClip, RungCheck};
use crate::chosen::{Chosen, Reason};
use crate::clip::ClipData;
use crate::config::TrainConfig;
use crate::error::TrainError;
use crate::run::Trainer;

/// Who sets a new run's steps.
#[derive(Debug, Clone, Copy)]
pub enum StepsFrom<'a> {
    /// The configuration, or the rule that reads the clip where it is asked for them; for a calm
    /// clip the rule leaves them to this ladder.
    Rule(&'a Ladder),
    /// As many as fit in this many minutes on this machine, from a timing probe of the network
    /// that trains (the rule's, where it is asked for one); the rule is not asked for steps.
    Minutes(f64),
}

/// Starts a new run of `config` on `clip` in the folder `run` (which must hold no run), its
/// steps from `steps`. A calm clip's ladder climbs in [`step_ladder::folder`]`(run)` and
/// `on_rung` hears each rung's scores; `None` when the stop flag was raised during the climb
/// (the same call starts again and keeps the finished rungs).
pub fn start_run(
    clip: &Path,
    mut config: TrainConfig,
    run: &Path,
    device: Device,
    steps: StepsFrom<'_>,
    stop: &AtomicBool,
    on_rung: &mut dyn FnMut(&RungCheck),
) -> Result<Option<Trainer>, TrainError> {
    let began = Instant::now();
    Trainer::check_new_run(run)?;
    if let StepsFrom::Minutes(_) = steps {
        config.from_clip.steps = false;
    }
    let data = ClipData::load(clip, &config.data)?;
    let choice = clip_rule::apply(&config, &data);
    let (config, choices) = match steps {
        StepsFrom::Minutes(minutes) => {
            let (mut config, mut choices) = match choice {
                Some(choice) => (choice.config, Some(choice.choices)),
                None => (config, None),
            };
            let fitted = budget::fit(clip, &data, &config, device.clone(), minutes, began)?;
            config.training.steps = fitted.steps;
            config.training.warmup_steps = fitted.warmup;
            if let Some(choices) = &mut choices {
                let reason = Reason::TimeBudget {
                    minutes,
                    seconds_per_step: fitted.seconds_per_step,
                    warmup: fitted.warmup,
                };
                choices.steps = Chosen::new(fitted.steps, reason);
            }
            (config, choices)
        }
        StepsFrom::Rule(ladder) => match choice {
            None => (config, None),
            Some(choice) => {
                let on_clip = LadderClip {
                    path: clip,
                    sha256: &data.facts.sha256,
                };
                let folder = step_ladder::folder(run);
                match ladder.settle(on_clip, choice, &folder, &device, stop, on_rung)? {
                    Some(settled) => (settled.config, Some(settled.choices)),
                    None => return Ok(None),
                }
            }
        },
    };
    Trainer::start_chosen(clip, data, config, choices, run, device).map(Some)
}
