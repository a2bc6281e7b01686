//! The rule's line for each setting the clip's kind decides (steps, window, dropout, channels),
//! and the steps line of a varied clip learned above 30 fps.

use super::calm::{calm_most_steps, calm_warmup_steps, ladder_list};
use super::{
    ClipReading, MANY_FEET_CHANNELS, MANY_FEET_DROPOUT, MANY_FEET_STEPS, MANY_FEET_WINDOW,
    VARIED_WINDOW, steps_at_window, window_step_cost,
};
use crate::config::TrainConfig;

/// What each setting's line is chosen from: the configuration, the clip's reading and kind.
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
    /// What a line says of a setting from_clip does not ask for.
    pub(super) kept: &'a str,
}

impl Choosing<'_> {
    /// What the steps line says after its label; sets `out`'s steps where the rule chooses them.
    pub(super) fn steps_said(&self, out: &mut TrainConfig, asked: bool) -> String {
        let Self {
            config,
            calm,
            widen,
            kept,
            ..
        } = *self;
        match (asked, calm) {
            (false, _) => format!("{} ({kept})", config.training.steps),
            (true, true) => {
                let steps = calm_most_steps();
                out.training.steps = steps;
                out.training.warmup_steps = calm_warmup_steps(steps);
                format!(
                    "chosen by the step ladder when training starts: short runs of {} steps (warm-up a third), each sampled {} times and scored, and the one that meets coverage >= {}, replay <= {} s (or the clip's own backwards score), jitter within {}x of the clip's either way and moves like the clip (still frames, speeds) with the widest margin (where none meets them all, the one that moves most like the clip, then misses the rest by least in all) trains the model (a calm clip is covered within a few hundred steps, and replays the longer it trains)",
                    ladder_list(),
                    crate::ladder_settings::CHECK_SAMPLES,
                    crate::ladder_settings::goals::COVERAGE,
                    crate::ladder_settings::goals::REPLAY_SECONDS,
                    crate::ladder_settings::goals::JITTER_RATIO,
                )
            }
            (true, false) if widen && config.training.steps > MANY_FEET_STEPS => {
                out.training.steps = MANY_FEET_STEPS;
                format!(
                    "{MANY_FEET_STEPS}: the {MANY_FEET_CHANNELS} channels below cost more a step, and this many fit the time {} steps of {} channels take",
                    config.training.steps, config.model.channels
                )
            }
            (true, false) => format!(
                "{} (the configuration's): a varied clip covers more the longer it trains",
                config.training.steps
            ),
        }
    }

    /// The window line; sets `out.model.window` where the rule widens it.
    pub(super) fn window_line(&self, out: &mut TrainConfig, asked: bool) -> String {
        let Self {
            config,
            reading,
            calm,
            kept,
            ..
        } = *self;
        match (asked, calm) {
            (false, _) => format!("window          {} ({kept})", config.model.window),
            (true, true) => format!(
                "window          {} (the configuration's): the rule widens only a varied clip's",
                config.model.window
            ),
            (true, false) => {
                let (wanted, why) = if reading.has_many_feet() {
                    (
                        MANY_FEET_WINDOW,
                        format!(
                            "on {} feet, a varied clip needs a wider field to keep its legs in step",
                            reading.feet
                        ),
                    )
                } else {
                    (
                        VARIED_WINDOW,
                        "a wider field smooths a varied clip's samples".to_string(),
                    )
                };
                let at_30 = if config.model.window_follows_fps {
                    " at 30 fps"
                } else {
                    ""
                };
                // The widest of the wanted windows that the clip is long enough for; never narrower
                // than the configuration's.
                let field = |window: usize| {
                    let mut model = config.model.clone();
                    model.window = window;
                    model.at_fps(reading.fps).receptive_field()
                };
                let wanted = wanted.max(config.model.window);
                let fallback = VARIED_WINDOW.max(config.model.window);
                match [wanted, fallback]
                    .into_iter()
                    .find(|&w| field(w) <= reading.frames)
                {
                    Some(window) if window == wanted => {
                        out.model.window = window;
                        format!("window          {window}{at_30}: {why}")
                    }
                    Some(window) => {
                        out.model.window = window;
                        format!(
                            "window          {window}{at_30}: the clip's {} frames are too few for window {wanted} ({why})",
                            reading.frames
                        )
                    }
                    None => format!(
                        "window          {} (the configuration's): the clip's {} frames are fewer than the {} a wider window sees",
                        config.model.window,
                        reading.frames,
                        field(fallback)
                    ),
                }
            }
        }
    }

    /// The dropout line; sets `out.model.dropout` where the rule raises it.
    pub(super) fn dropout_line(&self, out: &mut TrainConfig, asked: bool) -> String {
        let Self {
            config,
            reading,
            calm,
            kept,
            ..
        } = *self;
        match (asked, calm) {
            (false, _) => format!("dropout         {} ({kept})", config.model.dropout),
            (true, true) => format!(
                "dropout         {} (the configuration's): the rule raises only a varied clip's on three feet or more",
                config.model.dropout
            ),
            (true, false) if reading.has_many_feet() => {
                out.model.dropout = MANY_FEET_DROPOUT;
                format!(
                    "dropout         {MANY_FEET_DROPOUT}: on {} feet, keeps a varied clip's samples varied (more costs it coverage)",
                    reading.feet
                )
            }
            (true, false) => format!(
                "dropout         {} (the configuration's): more damps a varied clip's samples on two feet (their median speed falls below the clip's)",
                config.model.dropout
            ),
        }
    }

    /// The channels line; sets `out.model.channels` where the rule widens the network.
    pub(super) fn channels_line(&self, out: &mut TrainConfig, asked: bool) -> String {
        let Self {
            config,
            reading,
            calm,
            widen,
            kept,
            ..
        } = *self;
        match (asked, calm) {
            (false, _) => format!("channels        {} ({kept})", config.model.channels),
            (true, true) => format!(
                "channels        {} (the configuration's): the rule widens only a varied clip's network",
                config.model.channels
            ),
            (true, false) if widen => {
                out.model.channels = MANY_FEET_CHANNELS;
                format!(
                    "channels        {MANY_FEET_CHANNELS}: on {} feet, the network needs the width to hold every leg's phase at once",
                    reading.feet
                )
            }
            (true, false) if reading.has_many_feet() => format!(
                "channels        {} (the configuration's): at least {MANY_FEET_CHANNELS}, or {} heads do not divide {MANY_FEET_CHANNELS}",
                config.model.channels, config.model.heads
            ),
            (true, false) => format!(
                "channels        {} (the configuration's): on {} feet, the configuration's width serves",
                config.model.channels, reading.feet
            ),
        }
    }
}

/// The steps line of a varied clip learned above 30 fps, whose window follows the frame rate and
/// whose steps cost more: `None` where its steps still fit; else it lowers `out`'s steps to those
/// that fit the time of the steps meant at 30 fps.
pub(super) fn steps_at_fps_line(
    out: &mut TrainConfig,
    reading: ClipReading,
    steps_said: &str,
) -> Option<String> {
    let at_30 = out.model.window;
    let trained = out.model.at_fps(reading.fps).window;
    let steps = steps_at_window(out.training.steps, at_30, trained);
    if steps < out.training.steps {
        let line = format!(
            "steps           {steps}: at {} fps the window is {trained}, whose steps cost {:.2}x those of window {at_30}, so this many fit the time of the steps meant at 30 fps, {steps_said}",
            reading.fps,
            window_step_cost(trained) / window_step_cost(at_30),
        );
        out.training.steps = steps;
        out.training.warmup_steps = out.training.warmup_steps.min(steps / 10);
        return Some(line);
    }
    None
}
