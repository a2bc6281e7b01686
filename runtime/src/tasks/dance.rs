//! Dance: keyframes of a reference dance placed on the beats of a piece of music, everything
//! between them generated (SPEC section 5's in-betweening, with the spans chosen from beats).
//!
//! The reference's beats are its kinematic beats (`motion::kinematic_beats`), the music's are
//! frames of the output (a beat tracker, a file, or a tempo: the runtime takes plain frames).
//! Around each used music beat a window of `2 * hold + 1` frames of the reference, centred on one
//! of its beats, is kept (soft borders of `ramp` frames on the kept side); the window's centre is
//! kept exactly, so the chosen reference pose lands on the beat.
//!
//! The beat level (every beat, every other one, or half beats) is chosen so that the music's
//! beat interval over the reference's stays within [`DANCE_TEMPO_RANGE`], the stretch the default
//! training showed the model; outside it the task is refused. Windows never overlap: the hold is
//! shrunk so the closest two beats' windows keep a free frame between them (beats a frame apart
//! get windows of one frame each, touching), which [`Placement::hold`] reports.

use std::fmt;

use super::TaskError;
use crate::diffusion::noise;

/// The tempo ratios (music beat interval over reference beat interval) the task accepts: the
/// range over which the default training stretches the clip in time (`resample_min`,
/// `resample_max` of configs/default.yaml).
pub const DANCE_TEMPO_RANGE: (f64, f64) = (0.75, 1.25);
/// Default half-width of a keyframe window, in frames.
pub const DANCE_HOLD: usize = 12;
/// Default soft border of a keyframe window, in frames: the whole half-window (`DANCE_HOLD + 1`),
/// so each window's weight rises linearly to 1 at its beat and falls back (a triangle).
pub const DANCE_RAMP: usize = 13;
/// Noise stream of the shuffled keyframe order (SPEC section 7's counter-based words).
pub const DANCE_ORDER_STREAM: u64 = 3_000_000;

/// Which of the music's beats carry keyframes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BeatLevel {
    /// The level whose tempo ratio is closest to 1 (in log).
    Auto,
    /// Every beat.
    Every,
    /// Every other beat, from the first.
    EveryOther,
    /// Every beat and the frame half-way to the next.
    Half,
}

impl BeatLevel {
    /// The level's name as the command line writes it.
    pub fn name(self) -> &'static str {
        match self {
            BeatLevel::Auto => "auto",
            BeatLevel::Every => "every",
            BeatLevel::EveryOther => "every-other",
            BeatLevel::Half => "half",
        }
    }

    /// The music's beats at this level (not [`BeatLevel::Auto`]).
    fn apply(self, beats: &[usize]) -> Vec<usize> {
        match self {
            BeatLevel::Auto | BeatLevel::Every => beats.to_vec(),
            BeatLevel::EveryOther => beats.iter().step_by(2).copied().collect(),
            BeatLevel::Half => {
                let mut out = Vec::with_capacity(2 * beats.len());
                for pair in beats.windows(2) {
                    out.push(pair[0]);
                    let mid = (pair[0] + pair[1]) / 2;
                    if mid > pair[0] {
                        out.push(mid);
                    }
                }
                out.extend(beats.last());
                out
            }
        }
    }
}

impl fmt::Display for BeatLevel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The order in which the reference's beat windows follow each other on the music's beats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KeyOrder {
    /// Each pass over the reference's usable beats in an order drawn from the seed (the
    /// default: a new sequence of the reference's moves for every seed).
    #[default]
    Shuffled,
    /// The reference's own order, starting again from its first usable beat at the end.
    Reference,
}

impl KeyOrder {
    /// The order's name as the command line writes it.
    pub fn name(self) -> &'static str {
        match self {
            KeyOrder::Reference => "reference",
            KeyOrder::Shuffled => "shuffled",
        }
    }
}

/// What a dance asks for, besides the reference's features.
#[derive(Debug, Clone, PartialEq)]
pub struct DanceBeats {
    /// Beat frames of the reference (its kinematic beats), increasing.
    pub reference_beats: Vec<usize>,
    /// Beat frames of the output (the music's beats at the model's frame rate), increasing.
    pub target_beats: Vec<usize>,
    /// Frames of the output.
    pub frames: usize,
    /// Half-width of each keyframe window, in frames.
    pub hold: usize,
    /// Soft border on the kept side of each window, in frames (at most `hold + 1`, so the
    /// window's centre is kept exactly).
    pub ramp: usize,
    /// Order of the keyframes.
    pub order: KeyOrder,
    /// Which music beats carry keyframes.
    pub level: BeatLevel,
}

/// One keyframe: the reference frame whose window is centred on an output frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Keyframe {
    /// The output frame (a music beat at the chosen level).
    pub target: usize,
    /// The reference frame (one of its beats) placed there.
    pub reference: usize,
}

/// Where a dance's keyframes go: the chosen level, its tempo ratio, the hold after shrinking,
/// and every keyframe.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// The beat level used.
    pub level: BeatLevel,
    /// Music beat interval over reference beat interval at that level (medians).
    pub ratio: f64,
    /// The window half-width used (the asked hold, shrunk so windows keep a free frame
    /// between them).
    pub hold: usize,
    /// The soft border used.
    pub ramp: usize,
    /// The keyframes, in output order.
    pub keys: Vec<Keyframe>,
}

fn median_interval(beats: &[usize]) -> Option<f64> {
    let mut gaps: Vec<usize> = beats.windows(2).map(|w| w[1] - w[0]).collect();
    if gaps.is_empty() {
        return None;
    }
    gaps.sort_unstable();
    Some(gaps[gaps.len() / 2] as f64)
}

fn check_beats(beats: &[usize], frames: usize, what: &str) -> Result<(), TaskError> {
    if beats.len() < 2 {
        return Err(TaskError::Dance(format!(
            "{what} need at least two beats to have a tempo, got {}",
            beats.len()
        )));
    }
    if let Some(pair) = beats.windows(2).find(|w| w[1] <= w[0]) {
        return Err(TaskError::Dance(format!(
            "{what} must increase: frame {} comes after frame {}",
            pair[1], pair[0]
        )));
    }
    if let Some(&last) = beats.last()
        && last >= frames
    {
        return Err(TaskError::Dance(format!(
            "{what} reach frame {last}, past the {frames} frames they belong to"
        )));
    }
    Ok(())
}

/// Chooses the beat level, the hold and the keyframes of a dance on a reference of
/// `reference_frames` frames; `seed` draws the shuffled order.
pub fn place_keyframes(
    reference_frames: usize,
    dance: &DanceBeats,
    seed: u64,
) -> Result<Placement, TaskError> {
    check_beats(
        &dance.reference_beats,
        reference_frames,
        "the reference's beats",
    )?;
    check_beats(&dance.target_beats, dance.frames, "the music's beats")?;
    let reference_interval =
        median_interval(&dance.reference_beats).expect("two beats or more, checked");
    let ratio_of =
        |beats: &[usize]| median_interval(beats).map_or(f64::NAN, |i| i / reference_interval);
    let candidates: Vec<BeatLevel> = match dance.level {
        BeatLevel::Auto => vec![BeatLevel::Every, BeatLevel::EveryOther, BeatLevel::Half],
        fixed => vec![fixed],
    };
    let (level, beats, ratio) = candidates
        .into_iter()
        .map(|level| {
            let beats = level.apply(&dance.target_beats);
            let ratio = ratio_of(&beats);
            (level, beats, ratio)
        })
        .filter(|(_, beats, ratio)| beats.len() >= 2 && ratio.is_finite())
        .min_by(|a, b| a.2.ln().abs().total_cmp(&b.2.ln().abs()))
        .ok_or_else(|| {
            TaskError::Dance(format!(
                "the music's beats at level {} leave fewer than two beats",
                dance.level
            ))
        })?;
    let (low, high) = DANCE_TEMPO_RANGE;
    if !(low..=high).contains(&ratio) {
        let tried = if dance.level == BeatLevel::Auto {
            "no level (every beat, every other one, half beats) comes closer"
        } else {
            "another level may fit"
        };
        return Err(TaskError::Dance(format!(
            "the music's beats ({level} level, every {:.1} frames) are {ratio:.2}x the reference's \
             (every {reference_interval:.1} frames), outside the {low}-{high}x the model learned; \
             {tried}",
            ratio * reference_interval
        )));
    }
    let closest = beats
        .windows(2)
        .map(|w| w[1] - w[0])
        .min()
        .expect("two beats or more");
    // Two windows of 2 h + 1 frames centred `closest` apart keep a free frame between them
    // when 2 h + 2 <= closest.
    let hold = dance.hold.min(closest.saturating_sub(2) / 2);
    let ramp = dance.ramp.min(hold + 1);
    let usable: Vec<usize> = dance
        .reference_beats
        .iter()
        .copied()
        .filter(|&r| r >= hold && r + hold < reference_frames)
        .collect();
    if usable.is_empty() {
        return Err(TaskError::Dance(format!(
            "no beat of the reference has {hold} frames on both sides inside its {reference_frames} frames"
        )));
    }
    let order = keyframe_order(usable.len(), beats.len(), dance.order, seed);
    let keys = beats
        .iter()
        .zip(order)
        .map(|(&target, k)| Keyframe {
            target,
            reference: usable[k],
        })
        .collect();
    Ok(Placement {
        level,
        ratio,
        hold,
        ramp,
        keys,
    })
}

/// Indices into the usable reference beats for `count` keyframes: passes over them in order,
/// or, shuffled, each pass `p` a Fisher-Yates shuffle that for `i` from `usable - 1` down to 1
/// swaps `i` with `j = word(seed, DANCE_ORDER_STREAM, p * usable + i) mod (i + 1)`.
pub fn keyframe_order(usable: usize, count: usize, order: KeyOrder, seed: u64) -> Vec<usize> {
    let mut out = Vec::with_capacity(count);
    let mut cycle = 0u64;
    while out.len() < count {
        let mut pass: Vec<usize> = (0..usable).collect();
        if order == KeyOrder::Shuffled {
            for i in (1..usable).rev() {
                let w = noise::word(seed, DANCE_ORDER_STREAM, cycle * usable as u64 + i as u64);
                let j = (w % (i as u64 + 1)) as usize;
                pass.swap(i, j);
            }
        }
        out.extend(pass.into_iter().take(count - out.len()));
        cycle += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dance(reference: Vec<usize>, target: Vec<usize>, frames: usize) -> DanceBeats {
        DanceBeats {
            reference_beats: reference,
            target_beats: target,
            frames,
            hold: 3,
            ramp: 3,
            order: KeyOrder::Reference,
            level: BeatLevel::Auto,
        }
    }

    #[test]
    fn the_level_brings_the_tempo_ratio_nearest_one() {
        // Reference every 16 frames; music every 8 (twice as fast): every other beat.
        let d = dance(
            vec![10, 26, 42, 58],
            (0..12).map(|k| 4 + 8 * k).collect(),
            100,
        );
        let p = place_keyframes(80, &d, 0).unwrap();
        assert_eq!(p.level, BeatLevel::EveryOther);
        assert!((p.ratio - 1.0).abs() < 1e-12);
        let targets: Vec<usize> = p.keys.iter().map(|k| k.target).collect();
        assert_eq!(targets, vec![4, 20, 36, 52, 68, 84]);
        // Reference order, cycling over the beats with room for the window.
        let refs: Vec<usize> = p.keys.iter().map(|k| k.reference).collect();
        assert_eq!(refs, vec![10, 26, 42, 58, 10, 26]);
        // Music every 32 frames: half beats.
        let d = dance(vec![10, 26, 42, 58], vec![0, 32, 64, 96], 100);
        let p = place_keyframes(80, &d, 0).unwrap();
        assert_eq!(p.level, BeatLevel::Half);
        assert_eq!(
            p.keys.iter().map(|k| k.target).collect::<Vec<_>>(),
            vec![0, 16, 32, 48, 64, 80, 96]
        );
    }

    #[test]
    fn a_tempo_outside_the_trained_stretch_is_refused() {
        let mut d = dance(
            vec![10, 26, 42, 58],
            (0..8).map(|k| 4 + 11 * k).collect(),
            100,
        );
        d.level = BeatLevel::Every;
        let e = place_keyframes(80, &d, 0).unwrap_err().to_string();
        assert!(e.contains("0.69x") && e.contains("0.75-1.25"), "{e}");
        assert!(e.contains("another level may fit"), "{e}");
        d.level = BeatLevel::Auto;
        d.target_beats = vec![0, 21, 42, 63, 84];
        let e = place_keyframes(80, &d, 0).unwrap_err().to_string();
        assert!(e.contains("1.31x") && e.contains("no level"), "{e}");
    }

    #[test]
    fn windows_never_overlap_and_centres_stay_exact() {
        let mut d = dance(vec![10, 20, 30, 40], vec![5, 15, 25, 35, 45], 50);
        d.hold = 8;
        d.ramp = 20;
        let p = place_keyframes(60, &d, 0).unwrap();
        assert_eq!(p.hold, 4);
        assert_eq!(p.ramp, 5);
        for pair in p.keys.windows(2) {
            assert!(pair[0].target + p.hold < pair[1].target - p.hold - 1);
        }
    }

    #[test]
    fn a_shuffle_is_a_permutation_per_pass_and_follows_the_seed() {
        let a = keyframe_order(7, 21, KeyOrder::Shuffled, 5);
        for pass in a.chunks(7) {
            let mut sorted = pass.to_vec();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..7).collect::<Vec<_>>());
        }
        assert_eq!(a, keyframe_order(7, 21, KeyOrder::Shuffled, 5));
        assert_ne!(a, keyframe_order(7, 21, KeyOrder::Shuffled, 6));
        assert_eq!(
            keyframe_order(3, 7, KeyOrder::Reference, 5),
            vec![0, 1, 2, 0, 1, 2, 0]
        );
    }

    #[test]
    fn bad_beats_are_named() {
        let e = place_keyframes(80, &dance(vec![10], vec![1, 2], 10), 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("reference's beats") && e.contains("two"), "{e}");
        let e = place_keyframes(80, &dance(vec![10, 20], vec![5, 3], 10), 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("increase"), "{e}");
        let e = place_keyframes(80, &dance(vec![10, 20], vec![5, 30], 10), 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("frame 30"), "{e}");
    }
}
