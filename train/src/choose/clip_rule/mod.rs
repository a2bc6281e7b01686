//! The default that reads the clip: before training, what the clip's own motion says sets the
//! settings that no single value serves on every clip.
//!
//! One measure, taken before the first step, splits clips into two kinds that want opposite
//! things (lab/EXPERIMENTS.md, "A default that reads the clip"):
//! - a **calm** clip (its own intra diversity under [`CALM_INTRA_BELOW`]: a walk in one mood, a
//!   kick, a dance phrase, an idle) is covered within a few hundred steps, and the longer it
//!   trains the longer its samples replay it verbatim; how soon differs from clip to clip. Its
//!   steps are left to the step ladder ([`crate::choose::step_ladder`]), which trains short runs and
//!   keeps the one whose own samples meet the goals best; a calm clip that no short run covers
//!   trains as a varied one ([`not_calm_after_all`]).
//! - a **varied** clip (at or over it: a walk that turns and stops, a hop, a dog's run) covers
//!   more the longer it trains. It keeps the configuration's steps, and its QnA window and
//!   dropout follow its feet (the contact joints the clip's layout found):
//!   - on two feet or fewer, its samples shake more than the clip at the configuration's window:
//!     it trains a wider window ([`VARIED_WINDOW`]) that smooths them, and keeps the
//!     configuration's dropout: more damps its samples below the clip's speed
//!     (lab/EXPERIMENTS.md, "The candidates one at a time");
//!   - on [`MANY_FEET`] feet or more (a dog, a horse, a fox), its samples at a window that serves
//!     a biped keep too little of the clip (a fifth of a dog's one-second windows are never
//!     made): the legs' phases must hold over a longer span, and the network needs the width to
//!     hold four legs' phases at once. It trains the wider window [`MANY_FEET_WINDOW`] with
//!     [`MANY_FEET_CHANNELS`] channels and a little more dropout ([`MANY_FEET_DROPOUT`]: a dog
//!     that stands still between its walk and its run is not varied enough with less, and more
//!     costs a dog's walk coverage), for [`MANY_FEET_STEPS`] steps, which the wider network's
//!     steps fit in the time 17 000 of the configuration's take.
//!
//!   A varied clip's steps are meant at 30 fps. Learned at a higher rate, its window follows the
//!   frame rate and a step costs more ([`window_step_cost`]), so its steps fall to those that fit
//!   the same time ([`steps_at_window`]): 7 500 for a dog at 60 fps, whose window 7 becomes 19.
//!
//! The measure is the benchmark's intra diversity ([`sinmdm_eval::intra_diversity`]): the mean
//! distance, per frame, between two 15-frame windows of the clip's joint rotations and contact
//! labels. The rule names no clip; its threshold and the varied clip's setting were chosen on the
//! project's clips and judged on the ones each was not chosen on (`lab/scripts/leave_one_out.py`).
//!
//! A configuration asks for the rule with its `from_clip` section; each part it names may be
//! replaced by the rule, and a run saves the numbers it trained with, the section off.

use crate::chosen::{Choices, Chosen, ClipKind, Reason};
use crate::clip::ClipData;
use crate::config::{FromClip, TrainConfig};

mod batch_pairing;
mod calm;
mod reading;
mod settings;
mod window_cost;

pub use batch_pairing::{BATCH_ITEMS_MULTIPLE, paired_items};
pub use calm::{calm_most_steps, calm_warmup_steps, not_calm_after_all};
pub use reading::ClipReading;
use settings::{Choosing, steps_at_fps};
pub use window_cost::{
    FITTED_STEPS_ROUNDING, WINDOW_STEP_COST_OFFSET, steps_at_window, window_step_cost,
};

/// The clip's own intra diversity under which a clip is calm.
pub const CALM_INTRA_BELOW: f64 = 0.7;

/// QnA window of a varied clip on two feet or fewer, meant at 30 fps (it follows the frame rate
/// when the configuration's window does).
pub const VARIED_WINDOW: usize = 5;
/// The feet (contact joints) from which a varied clip trains [`MANY_FEET_WINDOW`] and
/// [`MANY_FEET_CHANNELS`].
pub const MANY_FEET: usize = 3;
/// QnA window of a varied clip on [`MANY_FEET`] feet or more, meant at 30 fps: 35 frames, 1.17 s.
pub const MANY_FEET_WINDOW: usize = 7;
/// Channels of a varied clip on [`MANY_FEET`] feet or more (never fewer than the
/// configuration's).
pub const MANY_FEET_CHANNELS: usize = 96;
/// Dropout of a varied clip on [`MANY_FEET`] feet or more, at any frame rate: the
/// configuration's 0.2 leaves a dog that walks, stands and runs too little diversity, and more
/// than 0.3 costs a walking dog coverage (lab/EXPERIMENTS.md, "The default's frame
/// rate, and a dog's dropout").
pub const MANY_FEET_DROPOUT: f64 = 0.3;
/// Steps of a varied clip on [`MANY_FEET`] feet or more whose channels the rule widened (at most
/// the configuration's): the wider network's run takes the time the default's takes
/// (lab/EXPERIMENTS.md, "A wider network for four feet").
pub const MANY_FEET_STEPS: u64 = 13_000;

/// What the rule chose for one clip, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleChoice {
    /// The reading it chose from.
    pub reading: ClipReading,
    /// The configuration as the rule leaves it (`from_clip` off).
    pub config: TrainConfig,
    /// Each setting's value and why (also for a setting the configuration kept because the rule
    /// was not asked to choose it).
    pub choices: Choices,
    /// Whether the steps are left to the step ladder ([`crate::choose::step_ladder`]): a calm
    /// clip whose steps the rule was asked for. `config` then holds the ladder's most steps.
    pub climb_ladder: bool,
    /// For a clip left to the ladder, what the rule chooses should no short run cover it: the
    /// clip trained as a varied one ([`not_calm_after_all`] completes its reason). Decided
    /// here with the rest, so that the ladder only picks between choices the rule made.
    pub if_not_calm: Option<Box<RuleChoice>>,
}

impl RuleChoice {
    /// The choices in words, a line per setting ([`Choices::lines`]).
    pub fn lines(&self) -> Vec<String> {
        self.choices.lines()
    }
}

/// What the rule chooses for a new run on `data` with `config`; `None` when its `from_clip`
/// section is off (the configuration trains as written).
pub fn apply(config: &TrainConfig, data: &ClipData) -> Option<RuleChoice> {
    if config.from_clip.is_off() {
        return None;
    }
    Some(choose(config, ClipReading::of(data)))
}

/// Applies the rule of `config.from_clip` to `config` for the clip `reading` describes. The
/// settings the rule is not asked for are kept; the result has `from_clip` off.
pub fn choose(config: &TrainConfig, reading: ClipReading) -> RuleChoice {
    let intra_diversity = reading.intra_diversity;
    let below = CALM_INTRA_BELOW;
    let kind = if reading.is_calm() {
        let reason = Reason::CalmClip {
            intra_diversity,
            below,
        };
        Chosen::new(ClipKind::Calm, reason)
    } else {
        let reason = Reason::VariedClip {
            intra_diversity,
            below,
        };
        Chosen::new(ClipKind::Varied, reason)
    };
    let mut choice = choose_kind(config, reading, kind);
    // A clip left to the ladder holds the choice it trains should no short run cover it.
    if choice.climb_ladder {
        let reason = Reason::VariedClip {
            intra_diversity,
            below,
        };
        let varied = choose_kind(config, reading, Chosen::new(ClipKind::Varied, reason));
        choice.if_not_calm = Some(Box::new(varied));
    }
    choice
}

/// The rule's choice for a clip of the kind `kind` says.
fn choose_kind(config: &TrainConfig, reading: ClipReading, kind: Chosen<ClipKind>) -> RuleChoice {
    let calm = kind.value == ClipKind::Calm;
    let asked = config.from_clip;
    let mut out = config.clone();
    out.from_clip = FromClip::default();
    // A varied clip on many feet trains a wider network, if asked and if the heads divide it.
    let widen = !calm
        && reading.has_many_feet()
        && asked.channels
        && config.model.channels < MANY_FEET_CHANNELS
        && MANY_FEET_CHANNELS.is_multiple_of(config.model.heads);
    let choosing = Choosing {
        config,
        reading,
        calm,
        widen,
    };
    let meant = choosing.steps(&mut out, asked.steps);
    let window = choosing.window(&mut out, asked.window);
    let dropout = choosing.dropout(&mut out, asked.dropout);
    let channels = choosing.channels(&mut out, asked.channels);
    // The steps above are meant at 30 fps. At a higher rate the window follows the frame rate,
    // a step costs more, and a varied clip's steps fall to fit the same time.
    let steps = if asked.steps && !calm {
        steps_at_fps(&mut out, reading, &meant).unwrap_or(meant)
    } else {
        meant
    };
    let batch = batch_pairing::batch(config, &mut out, reading, asked.batch, calm);
    RuleChoice {
        reading,
        config: out,
        choices: Choices {
            kind,
            steps,
            window,
            dropout,
            channels,
            batch,
            rungs: Vec::new(),
        },
        climb_ladder: calm && asked.steps,
        if_not_calm: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) const DEFAULT: &str = include_str!("../../../../configs/default.yaml");
    const TINY: &str = include_str!("../../../../configs/tiny.yaml");

    pub(super) fn reading(intra_diversity: f64) -> ClipReading {
        ClipReading {
            frames: 300,
            fps: 30.0,
            intra_diversity,
            feet: 2,
        }
    }

    #[test]
    fn the_default_asks_the_rule_for_steps_window_and_dropout() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        let all = FromClip {
            steps: true,
            window: true,
            dropout: true,
            channels: true,
            batch: true,
        };
        assert_eq!(config.from_clip, all);
        // A configuration without the section trains its numbers as written.
        assert!(TrainConfig::parse(TINY).unwrap().from_clip.is_off());
    }

    #[test]
    fn a_varied_clip_keeps_the_steps_and_widens_the_window() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        // The threshold itself counts as varied.
        for intra in [CALM_INTRA_BELOW, 0.9] {
            let choice = choose(&config, reading(intra));
            let out = &choice.config;
            assert_eq!(out.training.steps, config.training.steps);
            assert_eq!(out.training.warmup_steps, config.training.warmup_steps);
            assert_eq!(out.model.window, VARIED_WINDOW);
            assert_eq!(out.model.dropout, config.model.dropout, "two feet");
            assert_eq!(out.model.channels, config.model.channels, "two feet");
            assert!(
                out.model.window_follows_fps,
                "the window still follows the frame rate"
            );
            assert!(choice.lines()[0].contains("varied"), "{:?}", choice.lines());
            assert!(!choice.climb_ladder);
            out.validate().unwrap();
        }
        // A wider window of the configuration's own is never narrowed.
        let mut wide = config.clone();
        wide.model.window = 7;
        assert_eq!(choose(&wide, reading(0.9)).config.model.window, 7);
    }

    #[test]
    fn a_varied_clip_on_many_feet_trains_a_wider_network_for_fewer_steps() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        let dog = ClipReading {
            feet: 4,
            ..reading(0.8)
        };
        let choice = choose(&config, dog);
        let out = &choice.config;
        assert_eq!(out.model.window, MANY_FEET_WINDOW);
        assert_eq!(out.model.channels, MANY_FEET_CHANNELS);
        assert_eq!(out.model.dropout, MANY_FEET_DROPOUT);
        assert!(
            config.model.dropout < MANY_FEET_DROPOUT,
            "more than the configuration's"
        );
        assert_eq!(out.training.steps, MANY_FEET_STEPS);
        assert!(MANY_FEET_STEPS < config.training.steps);
        assert_eq!(out.training.warmup_steps, config.training.warmup_steps);
        assert!(
            choice.lines()[1].contains(&format!(
                "{MANY_FEET_STEPS}: the {MANY_FEET_CHANNELS} channels below cost more a step"
            )) && choice.lines()[2].contains("on 4 feet")
                && choice.lines()[3].starts_with("dropout         0.3: on 4 feet")
                && choice.lines()[4].starts_with("channels        96: on 4 feet"),
            "{:?}",
            choice.lines()
        );
        out.validate().unwrap();
        // A configuration already as wide, or with fewer steps, keeps its numbers; heads that do
        // not divide the wider width keep the configuration's width and steps.
        let mut wide = config.clone();
        wide.model.channels = 128;
        let kept = choose(&wide, dog).config;
        assert_eq!((kept.model.channels, kept.training.steps), (128, 17_000));
        let mut short = config.clone();
        short.training.steps = 5_000;
        assert_eq!(choose(&short, dog).config.training.steps, 5_000);
        let mut odd_heads = config.clone();
        odd_heads.model.heads = 64;
        odd_heads.validate().unwrap();
        let kept = choose(&odd_heads, dog);
        assert_eq!(
            (kept.config.model.channels, kept.config.training.steps),
            (64, 17_000)
        );
        assert!(
            kept.lines()[4].contains("64 heads do not divide 96"),
            "{:?}",
            kept.lines()
        );
        // Two feet, or three: the boundary.
        let biped = ClipReading { feet: 2, ..dog };
        assert_eq!(choose(&config, biped).config.model.window, VARIED_WINDOW);
        let three = ClipReading { feet: 3, ..dog };
        assert_eq!(choose(&config, three).config.model.window, MANY_FEET_WINDOW);
        // A calm clip on four feet (the fox) is left to the ladder, with the configuration's
        // window.
        let fox = ClipReading {
            feet: 4,
            ..reading(0.2)
        };
        let calm = choose(&config, fox);
        assert!(calm.climb_ladder);
        assert_eq!(calm.config.model.window, config.model.window);
        // Window 7 sees 35 frames at 30 fps: a shorter clip gets window 5 (29 frames), and one
        // shorter still the configuration's.
        let short = ClipReading { frames: 34, ..dog };
        let choice = choose(&config, short);
        assert_eq!(choice.config.model.window, VARIED_WINDOW);
        assert!(
            choice.lines()[2].contains("too few for window 7"),
            "{:?}",
            choice.lines()
        );
        let shorter = ClipReading { frames: 28, ..dog };
        assert_eq!(
            choose(&config, shorter).config.model.window,
            config.model.window
        );
    }

    #[test]
    fn the_parts_not_asked_for_keep_the_configuration_numbers() {
        let mut config = TrainConfig::parse(DEFAULT).unwrap();
        config.from_clip.window = false;
        config.from_clip.dropout = false;
        config.from_clip.channels = false;
        let varied = choose(&config, reading(0.9));
        assert_eq!(varied.config.model.window, config.model.window);
        assert_eq!(varied.config.model.dropout, config.model.dropout);
        // Not asked for the channels or the dropout, a dog keeps the configuration's width, steps
        // and dropout.
        let dog = choose(
            &config,
            ClipReading {
                feet: 4,
                ..reading(0.9)
            },
        );
        assert_eq!(dog.config.model.channels, config.model.channels);
        assert_eq!(dog.config.training.steps, config.training.steps);
        assert_eq!(dog.config.model.dropout, config.model.dropout);
        assert!(
            varied
                .lines()
                .iter()
                .any(|l| l.starts_with("window") && l.contains("from_clip does not ask for it")),
            "{:?}",
            varied.lines()
        );
        config.from_clip.steps = false;
        let calm = choose(&config, reading(0.2));
        assert_eq!(calm.config.training.steps, config.training.steps);
    }

    #[test]
    fn a_clip_shorter_than_the_wider_field_keeps_its_window() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        // Window 5 sees 29 frames at 30 fps.
        let short = ClipReading {
            frames: 28,
            ..reading(0.9)
        };
        let choice = choose(&config, short);
        assert_eq!(choice.config.model.window, config.model.window);
        assert!(
            choice
                .lines()
                .iter()
                .any(|l| l.contains("fewer than the 29")),
            "{:?}",
            choice.lines()
        );
        let just = ClipReading {
            frames: 29,
            ..reading(0.9)
        };
        assert_eq!(choose(&config, just).config.model.window, VARIED_WINDOW);
    }
}
