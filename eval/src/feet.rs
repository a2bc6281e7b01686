//! Feet and smoothness metrics (SPEC section 9), for any skeleton: how often contact points
//! skate, how deep anything goes below the ground, and how jerky the joints are. Computed on
//! canonical-frame forward kinematics at the model's frame rate, relative to the skeleton height
//! H, for the samples and for the clip itself (the level a model should reach).

use serde::{Deserialize, Serialize};
use sinmdm::motion::feet::ground_level;
use sinmdm::motion::ground::Body;
use sinmdm::motion::math::Vec3;
use sinmdm::motion::up::{height_of, horizontal, to_canonical};
use sinmdm::motion::{FeatureLayout, GlobalPose, LocalMotion, global_poses};

/// A contact point is on the ground while it is lower than this share of H above the ground.
pub const GROUND_BAND: f64 = 0.05;
/// ... and skates while its ground-plane speed is above this many H per second.
pub const SKATING_SPEED: f64 = 0.3;
/// A joint more than this share of H below the ground counts as through the floor.
pub const PENETRATION_TOLERANCE: f64 = 0.01;
/// Frames of the centred moving average of a contact point's speed.
pub const SPEED_WINDOW: usize = 5;

/// The feet and smoothness figures of one motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FeetScores {
    /// Share (0..=1) of frame pairs in which some contact point skates.
    pub skating_ratio: f64,
    /// Deepest point below the ground over all frames, joints and End Sites, in H (0 if none).
    pub max_penetration: f64,
    /// Share (0..=1) of frames in which some point is more than 0.01 H below the ground.
    pub penetrating_frames: f64,
    /// Mean joint acceleration `|p[i+1] - 2 p[i] + p[i-1]| f^2 / H`, in H per second squared.
    pub jitter: f64,
}

/// What the feet metrics measure against: the model's layout and the clip's ground level.
#[derive(Debug, Clone)]
pub struct FeetReference {
    layout: FeatureLayout,
    body: Body,
    ground: f64,
}

impl FeetReference {
    /// The reference of a model's layout, with the ground read from the clip's motion (the
    /// 5th percentile of each frame's lowest contact point; the lowest point of all when the
    /// layout has no contact joints).
    pub fn new(layout: &FeatureLayout, clip: &LocalMotion) -> FeetReference {
        let poses = canonical_poses(layout, clip);
        let body = layout.body();
        FeetReference {
            layout: layout.clone(),
            ground: ground_level(&layout.contact_joints, &body, &poses),
            body,
        }
    }

    /// The ground level, a height in the canonical frame (file units).
    pub fn ground(&self) -> f64 {
        self.ground
    }

    /// The figures of `motion` (decoded in the reference's layout).
    pub fn scores(&self, motion: &LocalMotion) -> FeetScores {
        let poses = canonical_poses(&self.layout, motion);
        let h = self.layout.skeleton_height.max(f64::MIN_POSITIVE);
        let fps = self.layout.fps;
        FeetScores {
            skating_ratio: self.skating_ratio(&poses, h, fps),
            max_penetration: poses
                .iter()
                .flat_map(|p| self.body.points(p))
                .map(|p| (self.ground - height_of(p)).max(0.0) / h)
                .fold(0.0, f64::max),
            penetrating_frames: share(poses.len(), |i| {
                self.body
                    .points(&poses[i])
                    .any(|p| height_of(p) < self.ground - PENETRATION_TOLERANCE * h)
            }),
            jitter: jitter(&poses, h, fps),
        }
    }

    fn skating_ratio(&self, poses: &[GlobalPose], h: f64, fps: f64) -> f64 {
        let pairs = poses.len().saturating_sub(1);
        let mut skating = vec![false; pairs];
        for &joint in &self.layout.contact_joints {
            let points: Vec<Vec3> = poses.iter().map(|p| p.contact_point(joint)).collect();
            let speed: Vec<f64> = points
                .windows(2)
                .map(|w| horizontal(w[1] - w[0]).norm() * fps)
                .collect();
            let on_ground = |i: usize| height_of(points[i]) - self.ground < GROUND_BAND * h;
            for i in 0..pairs {
                let half = SPEED_WINDOW / 2;
                let window = i.saturating_sub(half)..(i + half + 1).min(pairs);
                let average = speed[window.clone()].iter().sum::<f64>() / window.len() as f64;
                if on_ground(i)
                    && on_ground(i + 1)
                    && speed[i] > SKATING_SPEED * h
                    && average > SKATING_SPEED * h
                {
                    skating[i] = true;
                }
            }
        }
        share(pairs, |i| skating[i])
    }
}

fn canonical_poses(layout: &FeatureLayout, motion: &LocalMotion) -> Vec<GlobalPose> {
    global_poses(&to_canonical(motion, layout.up))
}

/// Mean over frames `1..N-1` and joints of the second difference's length, times `f^2 / H`.
fn jitter(poses: &[GlobalPose], h: f64, fps: f64) -> f64 {
    if poses.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    let mut count = 0usize;
    for w in poses.windows(3) {
        for j in 0..w[1].joints.len() {
            let a = (w[2].joints[j] - w[1].joints[j]) + (w[0].joints[j] - w[1].joints[j]);
            sum += a.norm();
            count += 1;
        }
    }
    sum / count.max(1) as f64 * fps * fps / h
}

/// Share of `0..n` for which `test` holds (0 when `n` is 0).
fn share(n: usize, test: impl Fn(usize) -> bool) -> f64 {
    if n == 0 {
        return 0.0;
    }
    (0..n).filter(|&i| test(i)).count() as f64 / n as f64
}

/// The mean of each figure over several motions.
pub fn mean_scores(scores: &[FeetScores]) -> FeetScores {
    let n = scores.len().max(1) as f64;
    let sum = |f: fn(&FeetScores) -> f64| scores.iter().map(f).sum::<f64>() / n;
    FeetScores {
        skating_ratio: sum(|s| s.skating_ratio),
        max_penetration: sum(|s| s.max_penetration),
        penetrating_frames: sum(|s| s.penetrating_frames),
        jitter: sum(|s| s.jitter),
    }
}

/// A row of the Markdown table: name, figure, decimals.
type TableRow = (&'static str, fn(&FeetScores) -> f64, usize);

/// The feet figures of a batch of samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleFeet {
    /// The mean over the samples.
    pub mean: FeetScores,
    /// Every sample's figures.
    pub per_sample: Vec<FeetScores>,
    /// The samples' jitter over the clip's.
    pub jitter_ratio: f64,
}

/// The feet figures of a batch of samples, as the network made them and with their feet
/// planted, beside the clip's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeetReport {
    /// The clip itself: the level a model should reach.
    pub clip: FeetScores,
    /// The samples as the network made them.
    pub raw: SampleFeet,
    /// The same samples with their feet planted.
    pub planted: SampleFeet,
}

impl FeetReport {
    /// The feet figures of `raw` and `planted` samples against `clip`, all decoded motions of
    /// `layout`.
    pub fn new(
        layout: &FeatureLayout,
        clip: &LocalMotion,
        raw: &[LocalMotion],
        planted: &[LocalMotion],
    ) -> FeetReport {
        let reference = FeetReference::new(layout, clip);
        let clip = reference.scores(clip);
        let batch = |motions: &[LocalMotion]| {
            let per_sample: Vec<FeetScores> = motions.iter().map(|m| reference.scores(m)).collect();
            let mean = mean_scores(&per_sample);
            SampleFeet {
                jitter_ratio: mean.jitter / clip.jitter.max(f64::MIN_POSITIVE),
                mean,
                per_sample,
            }
        };
        FeetReport {
            raw: batch(raw),
            planted: batch(planted),
            clip,
        }
    }

    /// The figures as a Markdown table: clip, raw samples, planted samples.
    pub fn markdown_table(&self) -> String {
        let (c, r, p) = (&self.clip, &self.raw.mean, &self.planted.mean);
        let rows: [TableRow; 4] = [
            ("skating ratio (%) ↓", |s| 100.0 * s.skating_ratio, 1),
            (
                "deepest point below the ground (x H) ↓",
                |s| s.max_penetration,
                4,
            ),
            (
                "frames through the floor (%) ↓",
                |s| 100.0 * s.penetrating_frames,
                1,
            ),
            ("jitter (H/s²) ↓", |s| s.jitter, 2),
        ];
        let mut out = String::from(
            "| feet and smoothness | clip | samples, raw | samples, feet planted |\n|---|---|---|---|\n",
        );
        for (name, value, digits) in rows {
            out.push_str(&format!(
                "| {name} | {:.digits$} | {:.digits$} | {:.digits$} |\n",
                value(c),
                value(r),
                value(p)
            ));
        }
        out.push_str(&format!(
            "| jitter, samples / clip | | {:.2} | {:.2} |\n",
            self.raw.jitter_ratio, self.planted.jitter_ratio
        ));
        out
    }
}
