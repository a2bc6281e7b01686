//! A calm clip's part of the rule: its steps are the step ladder's, and a calm clip that no
//! rung covers trains as a varied one.

use super::{CALM_INTRA_BELOW, RuleChoice};
use crate::choose::ladder_settings::{FASTER_STEPS, LADDER_STEPS};
use crate::chosen::{Chosen, ClipKind, Reason};

/// Warm-up steps of a calm clip's cosine schedule: a third of its steps.
pub fn calm_warmup_steps(steps: u64) -> u64 {
    (steps as f64 / 3.0).round() as u64
}

/// The most steps a calm clip trains: the step ladder's most-trained rung.
pub fn calm_most_steps() -> u64 {
    LADDER_STEPS
        .into_iter()
        .chain(FASTER_STEPS)
        .max()
        .unwrap_or(0)
}

/// The rule's choice for the `calm` clip once no rung of the step ladder covered it: the clip
/// trained as a varied one ([`RuleChoice::if_not_calm`]), its reason naming the best rung, which
/// covered `most_coverage` at `at_steps` steps. `None` for a choice that holds no such fallback
/// (a varied clip's).
pub fn not_calm_after_all(
    calm: &RuleChoice,
    most_coverage: f64,
    at_steps: u64,
) -> Option<RuleChoice> {
    let mut varied = calm.if_not_calm.as_deref()?.clone();
    let reason = Reason::NotCalmAfterAll {
        intra_diversity: calm.reading.intra_diversity,
        below: CALM_INTRA_BELOW,
        most_coverage,
        at_steps,
    };
    varied.choices.kind = Chosen::new(ClipKind::Varied, reason);
    Some(varied)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choose::clip_rule::tests::{DEFAULT, reading};
    use crate::choose::clip_rule::{VARIED_WINDOW, choose};
    use crate::config::TrainConfig;

    #[test]
    fn a_calm_clip_leaves_its_steps_to_the_ladder_and_keeps_the_shape() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        let choice = choose(&config, reading(0.5));
        let out = &choice.config;
        assert!(choice.climb_ladder);
        // Until the ladder chooses, the most it may train: the faster arm's top rung.
        assert_eq!(out.training.steps, 3000);
        assert_eq!(out.training.warmup_steps, 1000);
        assert_eq!(out.model.window, config.model.window);
        assert_eq!(out.model.dropout, config.model.dropout);
        assert!(out.from_clip.is_off());
        assert!(choice.lines()[0].contains("calm: its own intra diversity 0.500 is under 0.7"));
        assert!(
            choice.lines()[1]
                .contains("short runs of 50, 75, 100, 150, 200, 250, 300, 400, 600 and 1000 steps (warm-up a third), and of 1000 and 3000 steps at learning rate 0.001 where none of those meets every goal"),
            "{:?}",
            choice.lines()
        );
        out.validate().unwrap();
        // Not asked for the steps, the rule leaves them as written and climbs nothing.
        let mut fixed = config.clone();
        fixed.from_clip.steps = false;
        assert!(!choose(&fixed, reading(0.5)).climb_ladder);
        assert_eq!(calm_warmup_steps(75), 25);
    }

    #[test]
    fn a_calm_clip_no_rung_covers_trains_as_a_varied_one() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        let calm = choose(&config, reading(0.6));
        let choice = not_calm_after_all(&calm, 80.0, 1000).expect("a calm clip's fallback");
        assert!(!choice.climb_ladder);
        assert_eq!(choice.config.training.steps, config.training.steps);
        assert_eq!(choice.config.model.window, VARIED_WINDOW);
        assert_eq!(choice.config.model.dropout, config.model.dropout);
        assert!(
            choice.lines()[0].contains("varied")
                && choice.lines()[0].contains(
                    "no short run of the step ladder covered it (at most 80.0 at 1000 steps)"
                ),
            "{:?}",
            choice.lines()
        );
    }
}
