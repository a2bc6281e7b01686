//! The record's words: a line per setting, as `sinmdm-train` prints them at the start of a run
//! and `--dry-run` before one.

use super::{Batch, Choices, Chosen, ClipKind, FieldNeed, Reason};

/// What a line says of a setting `from_clip` does not ask for.
const NOT_ASKED: &str = "the configuration's; from_clip does not ask for it";

impl Choices {
    /// A line per setting, label first, then the step ladder's rungs where it climbed one.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = vec![
            format!("clip            {}", kind_text(&self.kind)),
            format!("steps           {}", steps_text(&self.steps)),
            format!("window          {}", window_text(&self.window)),
            format!("dropout         {}", dropout_text(&self.dropout)),
            format!("channels        {}", channels_text(&self.channels)),
            format!("batch           {}", batch_text(&self.batch)),
        ];
        if !self.rungs.is_empty() {
            lines.push("step ladder (each rung's samples, scored):".into());
            lines.extend(self.rungs.iter().map(|r| format!("  {r}")));
        }
        lines
    }
}

/// The reason no variant of a setting's own is expected to carry.
fn unexpected(reason: &Reason) -> String {
    format!("({reason:?})")
}

fn kind_text(kind: &Chosen<ClipKind>) -> String {
    match &kind.reason {
        Reason::CalmClip {
            intra_diversity,
            below,
        } => format!("calm: its own intra diversity {intra_diversity:.3} is under {below}"),
        Reason::VariedClip {
            intra_diversity,
            below,
        } => format!("varied: its own intra diversity {intra_diversity:.3} is at least {below}"),
        Reason::NotCalmAfterAll {
            intra_diversity,
            below,
            most_coverage,
            at_steps,
        } => format!(
            "varied: its own intra diversity {intra_diversity:.3} is under {below}, but no short run of the step ladder covered it (at most {most_coverage:.1} at {at_steps} steps)"
        ),
        other => unexpected(other),
    }
}

/// The steps and why, without the label (a steps line learned above 30 fps quotes the steps
/// meant at 30 fps this way).
fn steps_text(steps: &Chosen<u64>) -> String {
    let value = steps.value;
    match &steps.reason {
        Reason::NotAsked => format!("{value} ({NOT_ASKED})"),
        Reason::LadderWillChoose {
            rungs,
            faster,
            faster_learning_rate,
            samples,
            coverage,
            replay_seconds,
            jitter_ratio,
        } => format!(
            "chosen by the step ladder when training starts: short runs of {} steps (warm-up a third), and of {} steps at learning rate {faster_learning_rate} where none of those meets every goal, each sampled {samples} times and scored, and the one that meets coverage >= {coverage}, replay <= {replay_seconds} s (or the clip's own backwards score), jitter within {jitter_ratio}x of the clip's either way and moves like the clip (still frames, speeds) with the widest margin (where none meets them all, the one that moves most like the clip, then misses the rest by least in all) trains the model (a calm clip is covered within a few hundred steps, and replays the longer it trains)",
            in_words(rungs),
            in_words(faster)
        ),
        Reason::LadderRung {
            warmup,
            meets_goals,
            learning_rate,
        } => {
            let why = if *meets_goals {
                "the rung of the step ladder that meets every goal with the widest margin"
            } else {
                "no rung of the step ladder meets every goal; this one moves most like the clip, then misses the rest by least in all"
            };
            let rate = learning_rate.map_or(String::new(), |r| format!(", learning rate {r}"));
            format!("{value} (warm-up {warmup}{rate}): {why}")
        }
        Reason::TimeBudget {
            minutes,
            seconds_per_step,
            warmup,
        } => format!(
            "{value} (warm-up {warmup}): as many as fit --minutes {minutes} here (one step {seconds_per_step:.4} s in a timing probe)"
        ),
        Reason::VariedTrainsLonger => {
            format!("{value} (the configuration's): a varied clip covers more the longer it trains")
        }
        Reason::WiderNetworkSteps {
            channels,
            configured_steps,
            configured_channels,
        } => format!(
            "{value}: the {channels} channels below cost more a step, and this many fit the time {configured_steps} steps of {configured_channels} channels take"
        ),
        Reason::StepsAtFps {
            fps,
            window,
            window_at_30,
            cost_ratio,
            meant,
        } => format!(
            "{value}: at {fps} fps the window is {window}, whose steps cost {cost_ratio:.2}x those of window {window_at_30}, so this many fit the time of the steps meant at 30 fps, {}",
            steps_text(meant)
        ),
        other => unexpected(other),
    }
}

/// Steps as words: "50, 75, ... and 300".
fn in_words(steps: &[u64]) -> String {
    let words: Vec<String> = steps.iter().map(u64::to_string).collect();
    match words.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        Some((last, _)) => last.clone(),
        None => String::new(),
    }
}

fn need_text(need: FieldNeed) -> String {
    match need {
        FieldNeed::ManyFeet { feet } => {
            format!("on {feet} feet, a varied clip needs a wider field to keep its legs in step")
        }
        FieldNeed::Smoothing => "a wider field smooths a varied clip's samples".into(),
    }
}

fn at_30_text(at_30: bool) -> &'static str {
    if at_30 { " at 30 fps" } else { "" }
}

fn window_text(window: &Chosen<usize>) -> String {
    let value = window.value;
    match &window.reason {
        Reason::NotAsked => format!("{value} ({NOT_ASKED})"),
        Reason::CalmKeeps => {
            format!("{value} (the configuration's): the rule widens only a varied clip's")
        }
        Reason::WiderField { at_30, need } => {
            format!("{value}{}: {}", at_30_text(*at_30), need_text(*need))
        }
        Reason::NarrowerField {
            at_30,
            frames,
            wanted,
            need,
        } => format!(
            "{value}{}: the clip's {frames} frames are too few for window {wanted} ({})",
            at_30_text(*at_30),
            need_text(*need)
        ),
        Reason::ClipShorterThanField { frames, field } => format!(
            "{value} (the configuration's): the clip's {frames} frames are fewer than the {field} a wider window sees"
        ),
        other => unexpected(other),
    }
}

fn dropout_text(dropout: &Chosen<f64>) -> String {
    let value = dropout.value;
    match &dropout.reason {
        Reason::NotAsked => format!("{value} ({NOT_ASKED})"),
        Reason::CalmKeeps => format!(
            "{value} (the configuration's): the rule raises only a varied clip's on three feet or more"
        ),
        Reason::ManyFeet { feet } => format!(
            "{value}: on {feet} feet, keeps a varied clip's samples varied (more costs it coverage)"
        ),
        Reason::FewFeet { .. } => format!(
            "{value} (the configuration's): more damps a varied clip's samples on two feet (their median speed falls below the clip's)"
        ),
        other => unexpected(other),
    }
}

fn channels_text(channels: &Chosen<usize>) -> String {
    let value = channels.value;
    match &channels.reason {
        Reason::NotAsked => format!("{value} ({NOT_ASKED})"),
        Reason::CalmKeeps => {
            format!("{value} (the configuration's): the rule widens only a varied clip's network")
        }
        Reason::ManyFeet { feet } => format!(
            "{value}: on {feet} feet, the network needs the width to hold every leg's phase at once"
        ),
        Reason::ChannelsStayAsConfigured { wide, heads } => format!(
            "{value} (the configuration's): at least {wide}, or {heads} heads do not divide {wide}"
        ),
        Reason::FewFeet { feet } => format!(
            "{value} (the configuration's): on {feet} feet, the configuration's width serves"
        ),
        other => unexpected(other),
    }
}

fn batch_text(batch: &Chosen<Batch>) -> String {
    let Batch {
        items,
        frames,
        budget,
    } = batch.value;
    // Without a budget the reason is `Reason::NoFrameBudget`, and its line says so.
    let Some(budget) = budget else {
        return format!(
            "{items} copies of the whole clip (the configuration's batch_size; it sets no frames_per_step)"
        );
    };
    let noun = if items == 1 { "item" } else { "items" };
    let theirs =
        format!("{items} {noun} of the clip's {frames} frames from {budget} frames a step");
    match &batch.reason {
        Reason::NotAsked => format!("{theirs} ({NOT_ASKED})"),
        Reason::CalmKeeps => {
            format!("{theirs} (the configuration's): the rule pairs only a varied clip's items")
        }
        Reason::PairedItems { configured_items } => format!(
            "{items} items of the clip's {frames} frames, {} frames a step: the configuration's {budget} would make {configured_items}, and a step's items are shared among the cores, so an odd count leaves one of two cores idle for part of every step",
            items * frames
        ),
        Reason::WindowsOfLongerClip => {
            format!("{theirs} (the configuration's): each item a random window of the longer clip")
        }
        Reason::SingleCopy => format!(
            "{theirs} (the configuration's): a single copy is left alone, as a second would double a step's frames"
        ),
        Reason::EvenItems { multiple } => format!(
            "{theirs} (the configuration's): a multiple of {multiple}, which the cores share evenly"
        ),
        other => unexpected(other),
    }
}
