//! What the rule that reads the clip chose for a run, and why: a typed record.
//!
//! [`crate::choose`] writes it and [`crate::run`] keeps and prints it, so it sits below both and
//! imports neither. Its text is made in one place, [`Choices::lines`] ([`text`]).

mod text;

/// A setting's value, and why it has it.
#[derive(Debug, Clone, PartialEq)]
pub struct Chosen<T> {
    /// The value the run trains.
    pub value: T,
    /// Why.
    pub reason: Reason,
}

impl<T> Chosen<T> {
    /// `value`, for `reason`.
    pub fn new(value: T, reason: Reason) -> Chosen<T> {
        Chosen { value, reason }
    }

    /// Whether the rule was asked for this setting (it may still have kept the configuration's).
    pub fn asked(&self) -> bool {
        self.reason != Reason::NotAsked
    }
}

/// The two kinds of clip the rule tells apart by the clip's own intra diversity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClipKind {
    /// Under the threshold: covered within a few hundred steps; its steps are the ladder's.
    Calm,
    /// At or over it: covers more the longer it trains.
    Varied,
}

/// Why a clip's frames are batched as they are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Batch {
    /// Items (copies or windows of the clip) a step.
    pub items: usize,
    /// The clip's frames.
    pub frames: usize,
    /// The configuration's budget of frames a step, if it sets one.
    pub budget: Option<usize>,
}

/// What a wider QnA window is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldNeed {
    /// Legs in step: a varied clip on this many feet (three or more).
    ManyFeet {
        /// The clip's feet.
        feet: usize,
    },
    /// Smoother samples: a varied clip on two feet or fewer.
    Smoothing,
}

/// Why a setting has its value. The rule's own numbers (thresholds, goals) travel in the
/// variants, so that the text needs nothing from the rule.
#[derive(Debug, Clone, PartialEq)]
pub enum Reason {
    /// The configuration's: its `from_clip` section does not ask the rule for this setting.
    NotAsked,
    /// The configuration's, kept for a calm clip: the rule changes the window, dropout, channels
    /// and batch of a varied clip only.
    CalmKeeps,
    /// A varied clip on this many feet (three or more): the many-feet setting (more dropout, a
    /// wider network).
    ManyFeet {
        /// The clip's feet.
        feet: usize,
    },
    /// The configuration's, kept for a varied clip on this many feet (two or fewer): more
    /// dropout damps its samples, and the configuration's width serves.
    FewFeet {
        /// The clip's feet.
        feet: usize,
    },

    /// The clip is calm: its own intra diversity is under `below`.
    CalmClip {
        /// The clip's own intra diversity.
        intra_diversity: f64,
        /// The threshold.
        below: f64,
    },
    /// The clip is varied: its own intra diversity is at least `below`.
    VariedClip {
        /// The clip's own intra diversity.
        intra_diversity: f64,
        /// The threshold.
        below: f64,
    },
    /// The clip read as calm, but no short run of the step ladder covered it, so it trains as a
    /// varied one.
    NotCalmAfterAll {
        /// The clip's own intra diversity.
        intra_diversity: f64,
        /// The threshold.
        below: f64,
        /// The best coverage a rung reached.
        most_coverage: f64,
        /// That rung's steps.
        at_steps: u64,
    },

    /// Steps the step ladder chooses when training starts (the value is its most).
    LadderWillChoose {
        /// The rungs' steps.
        rungs: Vec<u64>,
        /// The steps of the rungs at a faster learning rate, climbed where no other rung
        /// meets every goal.
        faster: Vec<u64>,
        /// Their learning rate.
        faster_learning_rate: f64,
        /// Samples a rung is scored on.
        samples: usize,
        /// The coverage goal.
        coverage: f64,
        /// The replay goal, in seconds.
        replay_seconds: f64,
        /// The jitter goal, as a factor of the clip's either way.
        jitter_ratio: f64,
    },
    /// The rung of the step ladder the run trains.
    LadderRung {
        /// Its warm-up steps.
        warmup: u64,
        /// Whether it meets every goal (else it misses them by least, moving like the clip first).
        meets_goals: bool,
        /// Its learning rate where it is not the configuration's.
        learning_rate: Option<f64>,
    },
    /// A varied clip's steps: the configuration's, since it covers more the longer it trains.
    VariedTrainsLonger,
    /// The steps that fit a time budget (`sinmdm-train --minutes`), from a timing probe of the
    /// network the rule chose.
    TimeBudget {
        /// The budget, in minutes.
        minutes: f64,
        /// Seconds one step took in the probe.
        seconds_per_step: f64,
        /// Its warm-up steps (at most a tenth of the steps).
        warmup: u64,
    },
    /// A wider network's steps: as many as fit the time the configuration's take.
    WiderNetworkSteps {
        /// The wider network's channels.
        channels: usize,
        /// The configuration's steps.
        configured_steps: u64,
        /// The configuration's channels.
        configured_channels: usize,
    },
    /// A varied clip learned above 30 fps: its window follows the rate, a step costs more, and
    /// its steps fall to fit the time of those meant at 30 fps.
    StepsAtFps {
        /// The rate it learns at.
        fps: f64,
        /// The window at that rate.
        window: usize,
        /// The window meant at 30 fps.
        window_at_30: usize,
        /// A step's cost at `window` over one at `window_at_30`.
        cost_ratio: f64,
        /// The steps meant at 30 fps, and why.
        meant: Box<Chosen<u64>>,
    },

    /// A varied clip's wider window.
    WiderField {
        /// Whether the window is meant at 30 fps (it follows the frame rate).
        at_30: bool,
        /// What it is for.
        need: FieldNeed,
    },
    /// A varied clip too short for the window it wants gets a narrower wide one.
    NarrowerField {
        /// Whether the window is meant at 30 fps.
        at_30: bool,
        /// The clip's frames.
        frames: usize,
        /// The window it wanted.
        wanted: usize,
        /// What that was for.
        need: FieldNeed,
    },
    /// A varied clip shorter than any wider window's field keeps the configuration's window.
    ClipShorterThanField {
        /// The clip's frames.
        frames: usize,
        /// The frames the narrowest wider window sees.
        field: usize,
    },

    /// A varied clip on many feet keeps the configuration's width: it is already as wide, or
    /// its heads do not divide the wider width.
    ChannelsStayAsConfigured {
        /// The wider width.
        wide: usize,
        /// The configuration's heads.
        heads: usize,
    },

    /// The configuration sets no frames a step: its batch of whole copies.
    NoFrameBudget,
    /// A varied clip's odd item count raised or lowered to an even one, which the cores share.
    PairedItems {
        /// The items the configuration's budget makes.
        configured_items: usize,
    },
    /// Each item is a random window of a clip longer than the budget.
    WindowsOfLongerClip,
    /// A single copy is left alone (a second would double a step's frames).
    SingleCopy,
    /// The items are already a multiple of this, which the cores share evenly.
    EvenItems {
        /// The multiple.
        multiple: usize,
    },
}

/// What the rule that reads the clip chose for a run, a [`Chosen`] per setting, and the step
/// ladder's rungs where it climbed one.
#[derive(Debug, Clone, PartialEq)]
pub struct Choices {
    /// Calm or varied.
    pub kind: Chosen<ClipKind>,
    /// Training steps (meant at 30 fps unless [`Reason::StepsAtFps`]).
    pub steps: Chosen<u64>,
    /// QnA window (meant at 30 fps where it follows the frame rate).
    pub window: Chosen<usize>,
    /// Dropout.
    pub dropout: Chosen<f64>,
    /// Channels.
    pub channels: Chosen<usize>,
    /// Items a step.
    pub batch: Chosen<Batch>,
    /// The step ladder's rungs, a line each as it scored them; empty where it did not climb.
    pub rungs: Vec<String>,
}

impl Choices {
    /// Whether the rule chose the QnA window (so a hint of a wider one would second-guess it).
    pub fn window_from_clip(&self) -> bool {
        self.window.asked()
    }
}
