//! The step ladder's settings: its rungs, how a rung is checked and the goals it is held to
//! ([`super::step_ladder`] climbs it; [`super::clip_rule`] describes it before training).

/// The steps of each rung, fewest first.
pub const LADDER_STEPS: [u64; 10] = [50, 75, 100, 150, 200, 250, 300, 400, 600, 1000];
/// The steps of the rungs trained at [`FASTER_LEARNING_RATE`], climbed only when no rung of
/// [`LADDER_STEPS`] meets every goal and the configuration's rate is slower: calm clips still damped at the top rung move more with
/// training that goes further, and a faster rate goes there in a third of the time
/// (lab/EXPERIMENTS.md, "A faster arm of the step ladder").
pub const FASTER_STEPS: [u64; 2] = [1000, 3000];
/// The learning rate of the [`FASTER_STEPS`] rungs.
pub const FASTER_LEARNING_RATE: f64 = 1e-3;
/// Samples a rung is scored on (the benchmark's count).
pub const CHECK_SAMPLES: usize = 20;
/// Seed of a rung's samples (the benchmark's tables use seed 0, so the check and the tables
/// score different samples).
pub const CHECK_SEED: u64 = 1;
/// The goals a calm clip's samples are held to: the adaptive default's (coverage, replay, jitter
/// at most 1.5x the clip's), and one it does not set, jitter at least the clip's divided by 1.5.
/// Without that mirror bound the ladder would choose the least-trained rung whenever every rung
/// covers the clip, and those samples are smoother than the clip (lab/EXPERIMENTS.md, "The step
/// ladder").
pub mod goals {
    /// Least coverage, in percent of the clip's windows.
    pub const COVERAGE: f64 = 95.0;
    /// Longest mean verbatim run, in seconds.
    pub const REPLAY_SECONDS: f64 = 1.0;
    /// Most jitter, as a multiple of the clip's own.
    pub const JITTER_RATIO: f64 = 1.5;
    /// Least jitter, as a multiple of the clip's own: the mirror of [`JITTER_RATIO`].
    pub const LEAST_JITTER_RATIO: f64 = 1.0 / JITTER_RATIO;
    /// Coverage points that count as one goal's worth of margin.
    pub const COVERAGE_UNIT: f64 = 5.0;
    /// Replay seconds that count as one goal's worth of margin.
    pub const REPLAY_UNIT: f64 = 0.5;
    /// Jitter (times the clip's) over [`JITTER_RATIO`] that counts as one goal's worth of margin.
    pub const JITTER_UNIT: f64 = 0.5;
    /// Jitter (times the clip's) under [`LEAST_JITTER_RATIO`] that counts as one goal's worth of
    /// margin: the mirror of [`JITTER_UNIT`], from 1 / 1.5 down to 1 / (1.5 + 0.5).
    pub const LEAST_JITTER_UNIT: f64 = LEAST_JITTER_RATIO - 1.0 / (JITTER_RATIO + JITTER_UNIT);
    /// A speed ratio off by this factor (above 1.25x or below 0.8x the clip's) counts as one
    /// goal's worth of margin.
    pub const SPEED_RATIO_UNIT: f64 = 1.25;
    /// Nearly still share (0..=1) over the clip's + 5 points that counts as one goal's worth.
    pub const STILL_SHARE_UNIT: f64 = 0.05;
    /// Speed distance over its bound that counts as one goal's worth.
    pub const SPEED_DISTANCE_UNIT: f64 = 0.1;
    /// Acceleration distance over its bound that counts as one goal's worth.
    pub const ACCELERATION_DISTANCE_UNIT: f64 = 0.25;
}
