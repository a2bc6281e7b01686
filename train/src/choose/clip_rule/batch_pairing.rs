//! A varied clip's batch items in pairs: the even count of copies of the clip a step that
//! keeps both cores busy.

use super::ClipReading;
use crate::chosen::{Batch, Chosen, Reason};
use crate::config::TrainConfig;

/// A varied clip that would train an odd count of copies of the clip a step, 3 or more, trains
/// an even one: a multiple of this. The trainer shares a step's items among the cores, item by
/// item, so an odd count leaves one of the two cores of the 10-minute goal's machine idle for
/// part of every step (lab/EXPERIMENTS.md, "Items in pairs"). A single copy is left alone:
/// pairing it would double a step's frames.
pub const BATCH_ITEMS_MULTIPLE: usize = 2;

/// The rule's batch; it sets `out.training.frames_per_step` where it pairs the items.
pub(super) fn batch(
    config: &TrainConfig,
    out: &mut TrainConfig,
    reading: ClipReading,
    asked: bool,
    calm: bool,
) -> Chosen<Batch> {
    let frames = reading.frames;
    let items = config.training.batch_shape(frames).items;
    let budget = config.training.frames_per_step;
    let theirs = Batch {
        items,
        frames,
        budget,
    };
    let Some(budget) = budget else {
        return Chosen::new(theirs, Reason::NoFrameBudget);
    };
    if !asked {
        return Chosen::new(theirs, Reason::NotAsked);
    }
    if calm {
        return Chosen::new(theirs, Reason::CalmKeeps);
    }
    match paired_items(items, frames, budget, config.training.batch_size) {
        Some(paired) => {
            out.training.frames_per_step = Some(paired * frames);
            let batch = Batch {
                items: paired,
                ..theirs
            };
            let reason = Reason::PairedItems {
                configured_items: items,
            };
            Chosen::new(batch, reason)
        }
        None if frames > budget => Chosen::new(theirs, Reason::WindowsOfLongerClip),
        None if items == 1 => Chosen::new(theirs, Reason::SingleCopy),
        None => Chosen::new(
            theirs,
            Reason::EvenItems {
                multiple: BATCH_ITEMS_MULTIPLE,
            },
        ),
    }
}

/// The items a varied clip of `frames` frames trains in a step, a multiple of
/// [`BATCH_ITEMS_MULTIPLE`], in place of the `items` a budget of `budget` frames a step gives it
/// (at most `most_items`): of the two multiples next to `items`, the one whose frames come
/// nearest the budget (the smaller on a tie). `None` where `items` is already a multiple or a
/// single copy, where the clip is longer than the budget (each item is then a window of it), or
/// where no multiple fits.
pub fn paired_items(
    items: usize,
    frames: usize,
    budget: usize,
    most_items: usize,
) -> Option<usize> {
    let unit = BATCH_ITEMS_MULTIPLE;
    if frames == 0 || frames > budget || items < unit || items.is_multiple_of(unit) {
        return None;
    }
    let lower = items - items % unit;
    let upper = lower + unit;
    [lower, upper]
        .into_iter()
        .filter(|&n| n <= most_items)
        .min_by_key(|&n| (n * frames).abs_diff(budget))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choose::clip_rule::tests::{DEFAULT, reading};
    use crate::choose::clip_rule::{choose, not_calm_after_all};

    #[test]
    fn paired_items_take_the_even_count_whose_frames_come_nearest_the_budget() {
        // (clip frames, batch_size, items in pairs or None), for 1 024 frames a step; worked
        // out by hand from round(1024 / frames): 409 -> 3 (2 x 409 = 818 is 206 short of the
        // budget, 4 x 409 = 1 636 is 612 over), 297 -> 3 (594 is 430 short, 1 188 is 164
        // over), 213 -> 5 (852 is 172 short, 1 278 is 254 over).
        let cases = [
            (409, 8, Some(2)),
            (297, 8, Some(4)),
            (213, 8, Some(4)),
            (341, 8, Some(4)), // 3: 682 is 342 short, 1 364 only 340 over
            (779, 8, None),    // 1: a single copy is left alone
            (527, 8, None),    // 2 already
            (180, 8, None),    // 6 already
            (1054, 8, None),   // longer than the budget: one window of it
            (100, 8, None),    // 10, held to batch_size 8
            (100, 7, Some(6)), // 10, held to 7; 8 is over batch_size
            (300, 3, Some(2)), // 3, held to 3; 4 is over batch_size
        ];
        let mut config = TrainConfig::parse(DEFAULT).unwrap().training;
        config.frames_per_step = Some(1024);
        for (frames, most, want) in cases {
            config.batch_size = most;
            let items = config.batch_shape(frames).items;
            assert_eq!(
                paired_items(items, frames, 1024, most),
                want,
                "{frames} frames"
            );
        }
    }

    #[test]
    fn a_varied_clip_trains_its_items_in_pairs_and_a_calm_one_as_configured() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        let budget = config.training.frames_per_step.unwrap();
        let mut dog = reading(0.8);
        dog.frames = 409;
        dog.feet = 4;
        let choice = choose(&config, dog);
        assert_eq!(choice.config.training.frames_per_step, Some(818));
        assert_eq!(choice.config.training.batch_shape(409).items, 2);
        assert_eq!(
            config.training.batch_shape(409).items,
            3,
            "what it replaces"
        );
        let line = choice
            .lines()
            .into_iter()
            .find(|l| l.starts_with("batch"))
            .unwrap();
        assert!(
            line.contains("2 items") && line.contains("would make 3"),
            "{line}"
        );
        // Calm, or not asked for the batch, or already in pairs: the configuration's budget.
        let mut calm = dog;
        calm.intra_diversity = 0.5;
        assert_eq!(
            choose(&config, calm).config.training.frames_per_step,
            Some(budget)
        );
        // A calm clip that no rung covered trains as a varied one, in pairs.
        let after_all = not_calm_after_all(&choose(&config, calm), 80.0, 1000).unwrap();
        assert_eq!(after_all.config.training.frames_per_step, Some(818));
        let mut fixed = config.clone();
        fixed.from_clip.batch = false;
        assert_eq!(
            choose(&fixed, dog).config.training.frames_per_step,
            Some(budget)
        );
        let mut even = dog;
        even.frames = 527;
        assert_eq!(
            choose(&config, even).config.training.frames_per_step,
            Some(budget)
        );
        // Each line says why its count stands: 2 copies of 527 frames are already a pair, 1 of
        // 818 a single copy, and a clip of 1 054 frames trains one window of it a step.
        let batch_line_of = |frames: usize| {
            let clip = ClipReading { frames, ..dog };
            let choice = choose(&config, clip);
            assert_eq!(choice.config.training.frames_per_step, Some(budget));
            choice
                .lines()
                .into_iter()
                .find(|l| l.starts_with("batch"))
                .unwrap()
        };
        let line = batch_line_of(527);
        assert!(
            line.starts_with("batch           2 items") && line.contains("a multiple of 2"),
            "{line}"
        );
        let line = batch_line_of(818);
        assert!(
            line.starts_with("batch           1 item of") && line.contains("a single copy"),
            "{line}"
        );
        let line = batch_line_of(1054);
        assert!(
            line.starts_with("batch           1 item of") && line.contains("a random window"),
            "{line}"
        );
    }
}
