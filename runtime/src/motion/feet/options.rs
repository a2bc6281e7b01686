//! What the planting pass is asked ([`PlantOptions`], [`Anchor`]), what it must leave alone
//! ([`Kept`]) and what it reports ([`PlantStats`]).

/// Where a planted contact point is held during its span.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Anchor {
    /// Where it was, on average, over the span (the least change to the generated motion).
    #[default]
    Mean,
    /// Where it landed: its place at the span's first frame.
    Landing,
}

/// Settings of the planting pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantOptions {
    /// Shortest contact span that is planted, in seconds (shorter ones are label flicker).
    pub min_span_seconds: f64,
    /// Frames on each side of a span over which the point eases from and back to the
    /// generated motion, in seconds.
    pub blend_seconds: f64,
    /// Where a planted point is held.
    pub anchor: Anchor,
    /// A quarter of the most least-turn steps a leg gets in a frame
    /// ([`least_turn`](crate::motion::ik::least_turn)).
    pub iterations: usize,
    /// A span grows on both sides while its contact point stays within this many skeleton
    /// heights of the ground (a point on the floor does not slide, whatever the label says); 0
    /// keeps the labelled spans. The default is the height band in which SPEC section 9 counts
    /// a point as on the ground: growing further holds feet that swing low, which costs the
    /// motion more than it fixes.
    pub grow_within: f64,
    /// Where set, each contact point's band is at most this quantile (clamped to 0..=1) of its
    /// own heights over the ground in the frames whose label is at least
    /// [`CONTACT_ON`](super::spans::CONTACT_ON), and never below 0: a foot is held where it is
    /// as low as it stands, and a shuffling foot that swings within `grow_within` is not held
    /// over its swing. `None` uses `grow_within` alone. The default, 0.9, leaves a clip planted
    /// with its own labels as it is where the fixed band changed it (lab/EXPERIMENTS.md, "The
    /// ground band read from the stance").
    pub grow_stance_quantile: Option<f64>,
    /// A span grows only over frames where its contact point also moves slower than this, in
    /// skeleton heights per second along the ground: a foot that sweeps low and fast (a swing
    /// that grazes the floor, a hop's take-off) is motion the network meant, not a slide, and
    /// holding it turns the leg away from what the model made. `f64::INFINITY` grows by height
    /// alone. The default, 2.5 H/s, is well above a sliding stance (SPEC section 9 counts a
    /// slide from 0.3 H/s) and below a swinging foot.
    pub grow_below_speed: f64,
    /// Frames of a labelled span where the contact point moves at least this fast, in skeleton
    /// heights per second along the ground, are taken out of it (and growth does not take them
    /// back; the pieces ease in and out as any span does): the network is stepping the
    /// foot there, and holding it turns the leg against that step (the legs' accelerations
    /// snap). `f64::INFINITY` keeps the labelled spans whole. The default, 2.5 H/s, is the
    /// speed above which a span does not grow either (lab/EXPERIMENTS.md, "The ground band read
    /// from the stance").
    pub release_above_speed: f64,
    /// Soft reach: over the last share of a chain's length the distance it reaches eases in
    /// exponentially instead of snapping straight (a knee that straightens smoothly); 0 for a
    /// hard limit.
    pub soft_reach: f64,
    /// The farthest a held point may be from where the network put it, in skeleton heights:
    /// past this, it follows the generated point at this distance (a foot the network drags a
    /// long way is let go rather than the leg stretched after it).
    pub max_hold: f64,
    /// How much of the feet in contact's travel the root follows horizontally before the legs
    /// are turned, from 0 (the root stays where the network put it; the legs alone reach the
    /// held feet) to 1 (where planted feet slide together, the body is carried along instead,
    /// which leaves the legs' rotations as the model made them). Frames whose root a task kept
    /// are not moved. The default, 0, keeps the network's pace: a walk whose strides are
    /// shorter than its travel was slowed to under half its clip's pace by a root carried with
    /// its feet (lab/EXPERIMENTS.md, "How fast the planted samples travel").
    pub root_stance_share: f64,
    /// The root's travel with the stance is averaged over this many seconds on each side of a
    /// frame, with weights falling linearly to the edges (a root that followed every tremor of
    /// a foot would shake the whole body).
    pub stance_smoothing_seconds: f64,
}

impl Default for PlantOptions {
    fn default() -> Self {
        PlantOptions {
            min_span_seconds: 0.1,
            blend_seconds: 0.1,
            anchor: Anchor::Mean,
            iterations: 20,
            grow_within: 0.05,
            grow_stance_quantile: Some(0.9),
            grow_below_speed: 2.5,
            release_above_speed: 2.5,
            soft_reach: 0.2,
            max_hold: 0.4,
            root_stance_share: 0.0,
            stance_smoothing_seconds: 0.3,
        }
    }
}

/// What a task kept from its reference: those joints and that root travel stay untouched.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Kept {
    /// Per frame and joint, whether the joint is the reference's.
    pub joints: Vec<Vec<bool>>,
    /// Per frame, whether the root's position is the reference's.
    pub root: Vec<bool>,
}

impl Kept {
    pub(super) fn joint(&self, frame: usize, joint: usize) -> bool {
        self.joints
            .get(frame)
            .and_then(|j| j.get(joint))
            .copied()
            .unwrap_or(false)
    }

    pub(super) fn root(&self, frame: usize) -> bool {
        self.root.get(frame).copied().unwrap_or(false)
    }
}

/// What the pass did, for debugging a rig or a model (lengths in skeleton heights).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlantStats {
    /// The ground level used (canonical height, file units).
    pub ground: f64,
    /// Contact spans planted, all contact joints together.
    pub spans: usize,
    /// Frames, summed over contact joints, in which a point was held fully still.
    pub planted_frames: usize,
    /// Contact joints without a chain to turn (on the root, or sharing a chain with another).
    pub skipped_contacts: Vec<usize>,
    /// Frames in which the root was lifted so that nothing is below the ground.
    pub lifted_frames: usize,
    /// The largest lift.
    pub max_lift: f64,
    /// Planted points left more than 1e-3 H from their target (a target at the edge of or out
    /// of reach, see [`PlantOptions::soft_reach`]).
    pub unreached: usize,
    /// The farthest any point was left from its target.
    pub max_miss: f64,
    /// The mean distance of points from their targets, over every frame with a target.
    pub mean_miss: f64,
    /// The largest horizontal move of the root made so that it travels with the feet in
    /// contact ([`PlantOptions::root_stance_share`]).
    pub max_root_travel: f64,
}
