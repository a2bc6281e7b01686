//! The rule's choice of each setting the clip's kind decides (steps, window, dropout,
//! channels), and the steps of a varied clip learned above 30 fps.

use super::calm::{calm_most_steps, calm_warmup_steps};
use super::{
    ClipReading, MANY_FEET_CHANNELS, MANY_FEET_DROPOUT, MANY_FEET_STEPS, MANY_FEET_WINDOW,
    VARIED_WINDOW, steps_at_window, window_step_cost,
};
use crate::choose::ladder_settings::{
    CHECK_SAMPLES, FASTER_LEARNING_RATE, FASTER_STEPS, LADDER_STEPS, goals,
};
use crate::chosen::{Chosen, FieldNeed, Reason};
use crate::config::TrainConfig;

/// What each setting is chosen from: the configuration, the clip's reading and kind.
#[derive(Clone, Copy)]
pub(super) struct Choosing<'a> {
    /// The configuration as written.
    pub(super) config: &'a TrainConfig,
    /// The clip's reading.
    pub(super) reading: ClipReading,
    /// Whether the clip is calm.
    pub(super) calm: bool,
    /// Whether a varied clip on many feet trains the wider network.
    pub(super) widen: bool,
}

impl Choosing<'_> {
    /// The steps (meant at 30 fps); sets `out`'s steps where the rule chooses them.
    pub(super) fn steps(&self, out: &mut TrainConfig, asked: bool) -> Chosen<u64> {
        let Self {
            config,
            calm,
            widen,
            ..
        } = *self;
        let configured = config.training.steps;
        match (asked, calm) {
            (false, _) => Chosen::new(configured, Reason::NotAsked),
            (true, true) => {
                let steps = calm_most_steps();
                out.training.steps = steps;
                out.training.warmup_steps = calm_warmup_steps(steps);
                let reason = Reason::LadderWillChoose {
                    rungs: LADDER_STEPS.to_vec(),
                    faster: FASTER_STEPS.to_vec(),
                    faster_learning_rate: FASTER_LEARNING_RATE,
                    samples: CHECK_SAMPLES,
                    coverage: goals::COVERAGE,
                    replay_seconds: goals::REPLAY_SECONDS,
                    jitter_ratio: goals::JITTER_RATIO,
                };
                Chosen::new(steps, reason)
            }
            (true, false) if widen && configured > MANY_FEET_STEPS => {
                out.training.steps = MANY_FEET_STEPS;
                let reason = Reason::WiderNetworkSteps {
                    channels: MANY_FEET_CHANNELS,
                    configured_steps: configured,
                    configured_channels: config.model.channels,
                };
                Chosen::new(MANY_FEET_STEPS, reason)
            }
            (true, false) => Chosen::new(configured, Reason::VariedTrainsLonger),
        }
    }

    /// The window; sets `out.model.window` where the rule widens it.
    pub(super) fn window(&self, out: &mut TrainConfig, asked: bool) -> Chosen<usize> {
        let Self {
            config,
            reading,
            calm,
            ..
        } = *self;
        let configured = config.model.window;
        match (asked, calm) {
            (false, _) => Chosen::new(configured, Reason::NotAsked),
            (true, true) => Chosen::new(configured, Reason::CalmKeeps),
            (true, false) => {
                let (wanted, need) = if reading.has_many_feet() {
                    let need = FieldNeed::ManyFeet { feet: reading.feet };
                    (MANY_FEET_WINDOW, need)
                } else {
                    (VARIED_WINDOW, FieldNeed::Smoothing)
                };
                let at_30 = config.model.window_follows_fps;
                // The widest of the wanted windows that the clip is long enough for; never
                // narrower than the configuration's.
                let field = |window: usize| {
                    let mut model = config.model.clone();
                    model.window = window;
                    model.at_fps(reading.fps).receptive_field()
                };
                let wanted = wanted.max(configured);
                let fallback = VARIED_WINDOW.max(configured);
                match [wanted, fallback]
                    .into_iter()
                    .find(|&w| field(w) <= reading.frames)
                {
                    Some(window) if window == wanted => {
                        out.model.window = window;
                        Chosen::new(window, Reason::WiderField { at_30, need })
                    }
                    Some(window) => {
                        out.model.window = window;
                        let reason = Reason::NarrowerField {
                            at_30,
                            frames: reading.frames,
                            wanted,
                            need,
                        };
                        Chosen::new(window, reason)
                    }
                    None => {
                        let reason = Reason::ClipShorterThanField {
                            frames: reading.frames,
                            field: field(fallback),
                        };
                        Chosen::new(configured, reason)
                    }
                }
            }
        }
    }

    /// The dropout; sets `out.model.dropout` where the rule raises it.
    pub(super) fn dropout(&self, out: &mut TrainConfig, asked: bool) -> Chosen<f64> {
        let Self {
            config,
            reading,
            calm,
            ..
        } = *self;
        let configured = config.model.dropout;
        match (asked, calm) {
            (false, _) => Chosen::new(configured, Reason::NotAsked),
            (true, true) => Chosen::new(configured, Reason::CalmKeeps),
            (true, false) if reading.has_many_feet() => {
                out.model.dropout = MANY_FEET_DROPOUT;
                let reason = Reason::ManyFeet { feet: reading.feet };
                Chosen::new(MANY_FEET_DROPOUT, reason)
            }
            (true, false) => Chosen::new(configured, Reason::FewFeet { feet: reading.feet }),
        }
    }

    /// The channels; sets `out.model.channels` where the rule widens the network.
    pub(super) fn channels(&self, out: &mut TrainConfig, asked: bool) -> Chosen<usize> {
        let Self {
            config,
            reading,
            calm,
            widen,
        } = *self;
        let configured = config.model.channels;
        match (asked, calm) {
            (false, _) => Chosen::new(configured, Reason::NotAsked),
            (true, true) => Chosen::new(configured, Reason::CalmKeeps),
            (true, false) if widen => {
                out.model.channels = MANY_FEET_CHANNELS;
                let reason = Reason::ManyFeet { feet: reading.feet };
                Chosen::new(MANY_FEET_CHANNELS, reason)
            }
            (true, false) if reading.has_many_feet() => {
                let reason = Reason::ChannelsStayAsConfigured {
                    wide: MANY_FEET_CHANNELS,
                    heads: config.model.heads,
                };
                Chosen::new(configured, reason)
            }
            (true, false) => {
                let reason = Reason::FewFeet { feet: reading.feet };
                Chosen::new(configured, reason)
            }
        }
    }
}

/// The steps of a varied clip learned above 30 fps, whose window follows the frame rate and
/// whose steps cost more: `None` where `meant` (the steps meant at 30 fps) still fit; else it
/// lowers `out`'s steps to those that fit the time of `meant`.
pub(super) fn steps_at_fps(
    out: &mut TrainConfig,
    reading: ClipReading,
    meant: &Chosen<u64>,
) -> Option<Chosen<u64>> {
    let at_30 = out.model.window;
    let trained = out.model.at_fps(reading.fps).window;
    let steps = steps_at_window(out.training.steps, at_30, trained);
    if steps < out.training.steps {
        let reason = Reason::StepsAtFps {
            fps: reading.fps,
            window: trained,
            window_at_30: at_30,
            cost_ratio: window_step_cost(trained) / window_step_cost(at_30),
            meant: Box::new(meant.clone()),
        };
        out.training.steps = steps;
        out.training.warmup_steps = out.training.warmup_steps.min(steps / 10);
        return Some(Chosen::new(steps, reason));
    }
    None
}
