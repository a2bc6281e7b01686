//! The planting pass, phase by phase: predicted contact spans held still on the ground, by
//! carrying the root along with the feet in contact and then by the least turning of each leg's
//! chain; the root moved up only where something would go through the floor.

use std::ops::Range;

use super::chain::{LegChain, leg_chain};
use super::options::{Kept, PlantOptions, PlantStats};
use super::solve::{Wanted, add_nonzero, smooth_upper_envelope, solve_frame};
use super::spans::{CONTACT_ON, contact_spans};
use super::stance::stance_travel;
use super::targets::{ChainTrack, chain_targets, grow_spans, split_spans};
use crate::motion::clip::LocalMotion;
use crate::motion::features::{FeatureLayout, MotionError};
use crate::motion::fk::{GlobalPose, global_pose, global_poses};
use crate::motion::ground::{Body, ground_level};
use crate::motion::math::Vec3;
use crate::motion::up::{UP, height_of, horizontal, to_canonical, to_file};

/// Coordinates below this size can be subtracted, squared and summed without overflow.
const OVERFLOW_SAFE: f64 = 1e150;

/// Holds every contact joint of `motion` (decoded in `layout`, the file's frame) still during
/// the spans its `labels` (one series per contact joint, as the features carry them) mark, on
/// or above the ground, easing in and out over [`PlantOptions::blend_seconds`]; and lifts
/// whatever would go below the ground. Only the root's position (carried along with the feet in
/// contact, [`PlantOptions::root_stance_share`], and raised where needed) and rotations of the
/// chains above contact joints ([`leg_chain`]) change, so every bone keeps its length. Joints and
/// root positions in `kept` are left exactly as they are. The ground is the layout's (from the
/// training clip), or this motion's own ([`ground_level`]) for a model file without one.
pub fn plant_feet(
    layout: &FeatureLayout,
    motion: &LocalMotion,
    labels: &[Vec<f32>],
    kept: &Kept,
    options: &PlantOptions,
) -> Result<(LocalMotion, PlantStats), MotionError> {
    let frames = motion.frame_count();
    if labels.len() != layout.contact_joints.len() || labels.iter().any(|l| l.len() != frames) {
        return Err(MotionError::ContactLabels {
            contacts: layout.contact_joints.len(),
            frames,
        });
    }
    let canonical = to_canonical(motion, layout.up);
    let mut planting = Planting::new(layout, &canonical, kept, options);
    if !planting.is_tame() {
        // A rig so large that differences or squared lengths of its positions could overflow (a
        // broken model file's offsets) is left as it is.
        return Ok((motion.clone(), planting.stats));
    }
    // 1. One leg chain per contact joint.
    let chains = planting.leg_chains();
    // 2. Contact spans, on the generated motion: the labelled ones less the frames where the
    //    foot steps fast, grown over low, slow frames.
    let spans = planting.contact_spans(&chains, labels);
    // 3. The root carried along with the feet in contact.
    if options.root_stance_share > 0.0 {
        planting.carry_root_with_stance(&chains, &spans);
    }
    // 4. Where each contact point should be, frame by frame.
    let targets = planting.targets(&chains, &spans);
    // 5. The legs turned to reach them, the root lifted where anything is still below ground.
    let solved = planting.solve(&chains, &targets);
    // 6. Whatever a task kept restored bit for bit, and back to the file's frame.
    let planted = restore_kept(motion, &canonical, solved, kept, layout);
    Ok((planted, planting.stats))
}

/// The pass's working state: the generated motion in the canonical frame (its root moved with
/// the stance once that phase has run), its global poses, and what has been done so far.
struct Planting<'a> {
    layout: &'a FeatureLayout,
    kept: &'a Kept,
    options: &'a PlantOptions,
    frames: usize,
    /// The skeleton's height (never 0).
    height: f64,
    /// The joint that carries the motion ([`FeatureLayout::carrier`]): what the pass moves
    /// when it moves the root. Containers above it stay where the file put them.
    carrier: usize,
    /// The points that must stay above the ground: all but the containers above the carrier.
    body: Body,
    motion: LocalMotion,
    poses: Vec<GlobalPose>,
    stats: PlantStats,
}

impl<'a> Planting<'a> {
    fn new(
        layout: &'a FeatureLayout,
        canonical: &LocalMotion,
        kept: &'a Kept,
        options: &'a PlantOptions,
    ) -> Planting<'a> {
        let poses = global_poses(canonical);
        let body = layout.body();
        let ground = layout
            .ground
            .unwrap_or_else(|| ground_level(&layout.contact_joints, &body, &poses));
        Planting {
            layout,
            kept,
            options,
            frames: canonical.frame_count(),
            height: layout.skeleton_height.max(f64::MIN_POSITIVE),
            carrier: layout.carrier(),
            body,
            motion: canonical.clone(),
            poses,
            stats: PlantStats {
                ground,
                ..PlantStats::default()
            },
        }
    }

    /// Whether every coordinate is small enough to compute with.
    fn is_tame(&self) -> bool {
        let tame = |v: f64| v.abs() < OVERFLOW_SAFE;
        tame(self.stats.ground)
            && self
                .poses
                .iter()
                .all(|pose| pose.points().all(|p| p.iter().all(|&v| tame(v))))
    }

    /// Whether a task kept the root (its position, or the carrier joint) at frame `f`.
    fn root_kept(&self, f: usize) -> bool {
        self.kept.root(f) || self.kept.joint(f, self.carrier)
    }

    /// A move of the carrier by `world` (canonical frame) at frame `f`, in its parent's frame:
    /// the carrier's translation is local to the container above it, which may be turned.
    fn in_carrier_frame(&self, f: usize, world: Vec3) -> Vec3 {
        match self.motion.skeleton.joints[self.carrier].parent {
            Some(p) => self.poses[f].rotations[p].transpose() * world,
            None => world,
        }
    }

    /// One chain per contact joint; a chain that shares joints with an earlier one is skipped
    /// (and reported).
    fn leg_chains(&mut self) -> Vec<Option<LegChain>> {
        let layout = self.layout;
        let mut chains: Vec<Option<LegChain>> = Vec::new();
        for &contact in &layout.contact_joints {
            let chain =
                leg_chain(&layout.skeleton, &layout.rest_translations, contact).filter(|c| {
                    !chains
                        .iter()
                        .flatten()
                        .any(|o| o.joints.iter().any(|j| c.joints.contains(j)))
                });
            if chain.is_none() {
                self.stats.skipped_contacts.push(contact);
            }
            chains.push(chain);
        }
        chains
    }

    /// A chain's contact point, frame by frame, in the current poses.
    fn contact_points(&self, chain: &LegChain) -> Vec<Vec3> {
        self.poses
            .iter()
            .map(|p| p.contact_point(chain.contact))
            .collect()
    }

    /// Each chain's contact spans: those its labels mark (at least
    /// [`PlantOptions::min_span_seconds`]), less the frames where the point moves at least
    /// [`PlantOptions::release_above_speed`] (the step to the next frame; the last frame's from
    /// the one before), then grown on both sides over frames where the point is within its band
    /// of the ground ([`Planting::grow_band`]) and slower than both
    /// [`PlantOptions::grow_below_speed`] and the release speed (growth never takes back a
    /// released frame).
    fn contact_spans(
        &self,
        chains: &[Option<LegChain>],
        labels: &[Vec<f32>],
    ) -> Vec<Vec<Range<usize>>> {
        let (fps, frames, height) = (self.layout.fps, self.frames, self.height);
        let options = self.options;
        let min_frames = (options.min_span_seconds * fps).round().max(1.0) as usize;
        chains
            .iter()
            .zip(labels)
            .map(|(chain, labels)| {
                let Some(chain) = chain else {
                    return Vec::new();
                };
                let points = self.contact_points(chain);
                let speed = |f: usize| {
                    let next = if f + 1 < frames {
                        f + 1
                    } else {
                        f.saturating_sub(1)
                    };
                    horizontal(points[next] - points[f]).norm() * fps / height
                };
                let band = self.grow_band(&points, labels);
                let grow_below = options.grow_below_speed.min(options.release_above_speed);
                let low = |f: usize| {
                    height_of(points[f]) - self.stats.ground < band && speed(f) < grow_below
                };
                let labelled = split_spans(contact_spans(labels, min_frames), min_frames, |f| {
                    speed(f) >= options.release_above_speed
                });
                grow_spans(labelled, frames, low)
            })
            .collect()
    }

    /// How far over the ground a contact point may be for its spans to grow over it:
    /// [`PlantOptions::grow_within`] skeleton heights, or less where
    /// [`PlantOptions::grow_stance_quantile`] reads a lower band from the point's own heights
    /// in the frames whose label is at least [`CONTACT_ON`] (never below 0: a foot that stands
    /// under the ground grows only over frames still further under it).
    fn grow_band(&self, points: &[Vec3], labels: &[f32]) -> f64 {
        let fixed = self.options.grow_within * self.height;
        let Some(q) = self.options.grow_stance_quantile else {
            return fixed;
        };
        let mut stance: Vec<f64> = points
            .iter()
            .zip(labels)
            .filter(|(_, l)| **l >= CONTACT_ON)
            .map(|(p, _)| height_of(*p) - self.stats.ground)
            .collect();
        if stance.is_empty() {
            return fixed;
        }
        stance.sort_by(f64::total_cmp);
        let at = ((stance.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
        fixed.min(stance[at].max(0.0))
    }

    /// The root moved horizontally with the feet in contact ([`stance_travel`], times
    /// [`PlantOptions::root_stance_share`]), except where a task kept it; the poses follow.
    fn carry_root_with_stance(&mut self, chains: &[Option<LegChain>], spans: &[Vec<Range<usize>>]) {
        let (mut points, mut weights) = (Vec::new(), Vec::new());
        for (chain, spans) in chains.iter().zip(spans) {
            let Some(chain) = chain else { continue };
            points.push(self.contact_points(chain));
            weights.push(
                (0..self.frames)
                    .map(|f| {
                        let inside = spans.iter().any(|s| s.contains(&f));
                        let kept = chain.joints.iter().any(|&j| self.kept.joint(f, j));
                        if inside && !kept { 1.0 } else { 0.0 }
                    })
                    .collect::<Vec<f64>>(),
            );
        }
        let kept_root: Vec<bool> = (0..self.frames).map(|f| self.root_kept(f)).collect();
        let radius = (self.options.stance_smoothing_seconds * self.layout.fps)
            .round()
            .max(0.0) as usize;
        let travel = stance_travel(&points, &weights, &kept_root, radius);
        let joints = self.motion.skeleton.len();
        let share = self.options.root_stance_share.clamp(0.0, 1.0);
        for (f, t) in travel.iter().enumerate() {
            let t = *t * share;
            let step = self.in_carrier_frame(f, t);
            add_nonzero(
                &mut self.motion.translations[f * joints + self.carrier],
                step,
            );
            self.stats.max_root_travel = self.stats.max_root_travel.max(t.norm() / self.height);
        }
        self.poses = global_poses(&self.motion);
    }

    /// The frames over which a point eases between the generated path and its anchor.
    fn blend_frames(&self) -> usize {
        (self.options.blend_seconds * self.layout.fps)
            .round()
            .max(0.0) as usize
    }

    /// Per chain and frame, where its contact point should be ([`chain_targets`]).
    fn targets(
        &mut self,
        chains: &[Option<LegChain>],
        spans: &[Vec<Range<usize>>],
    ) -> Vec<Vec<Option<Vec3>>> {
        let shape = (self.stats.ground, self.height, self.blend_frames());
        chains
            .iter()
            .zip(spans)
            .map(|(chain, spans)| {
                let Some(chain) = chain else {
                    return vec![None; self.frames];
                };
                let points = self.contact_points(chain);
                self.stats.spans += spans.len();
                let track = ChainTrack {
                    chain,
                    points: &points,
                    spans,
                };
                let (targets, planted) = chain_targets(&track, self.kept, self.options, shape);
                self.stats.planted_frames += planted;
                targets
            })
            .collect()
    }

    /// The motion with every chain turned towards its targets and the root lifted so that
    /// nothing is below the ground: a first pass finds how far below the ground each solved
    /// frame still goes, a lift that rises and falls smoothly and covers every frame's need is
    /// applied, and whatever that leaves below is lifted frame by frame. Fills in the stats.
    fn solve(&mut self, chains: &[Option<LegChain>], targets: &[Vec<Option<Vec3>>]) -> LocalMotion {
        let frame_targets = |f: usize| -> Vec<Wanted<'_>> {
            chains
                .iter()
                .zip(targets)
                .filter_map(|(c, t)| {
                    Some(Wanted {
                        chain: c.as_ref()?,
                        target: t[f]?,
                    })
                })
                .collect()
        };
        let ground = self.stats.ground;
        let lifts: Vec<Vec3> = (0..self.frames)
            .map(|f| {
                let mut world = Vec3([0.0; 3]);
                world[UP] = 1.0;
                self.in_carrier_frame(f, world)
            })
            .collect();
        let up = |f: usize, by: f64| lifts[f] * by;
        let carrier = self.carrier;
        let mut out = self.motion.clone();
        let mut deficit = vec![0.0; self.frames];
        for (f, need) in deficit.iter_mut().enumerate() {
            if self.root_kept(f) {
                continue;
            }
            let solved = solve_frame(
                &self.motion,
                &mut out,
                (f, carrier, up(f, 0.0)),
                &frame_targets(f),
                self.options,
            );
            *need = (ground - self.body.lowest_point(&solved)).max(0.0);
        }
        let lift = smooth_upper_envelope(&deficit, self.blend_frames());
        let (mut miss_sum, mut miss_count) = (0.0, 0usize);
        for (f, &smooth_lift) in lift.iter().enumerate() {
            let free = !self.root_kept(f);
            let shift = if free { smooth_lift } else { 0.0 };
            let wanted = frame_targets(f);
            let mut solved = solve_frame(
                &self.motion,
                &mut out,
                (f, carrier, up(f, shift)),
                &wanted,
                self.options,
            );
            let mut total_lift = shift;
            let rest = ground - self.body.lowest_point(&solved);
            if rest > 0.0 && free {
                // What the smooth lift and the legs could not fix: lift the root the rest.
                add_nonzero(
                    &mut out.translations[f * out.skeleton.len() + carrier],
                    up(f, rest),
                );
                total_lift += rest;
                solved = global_pose(&out, f);
            }
            if total_lift > 0.0 {
                self.stats.lifted_frames += 1;
                self.stats.max_lift = self.stats.max_lift.max(total_lift / self.height);
            }
            for w in &wanted {
                let miss = (solved.contact_point(w.chain.contact) - w.target).norm() / self.height;
                if miss > 1e-3 {
                    self.stats.unreached += 1;
                }
                self.stats.max_miss = self.stats.max_miss.max(miss);
                miss_sum += miss;
                miss_count += 1;
            }
        }
        self.stats.mean_miss = miss_sum / miss_count.max(1) as f64;
        out
    }
}

/// `solved` (canonical frame) with every joint a task kept set back to the input's, turned back
/// into the file's frame; values the pass left untouched are taken from the input itself, so a
/// kept joint is exact even in a file frame that the canonical round trip would round.
fn restore_kept(
    motion: &LocalMotion,
    canonical: &LocalMotion,
    mut solved: LocalMotion,
    kept: &Kept,
    layout: &FeatureLayout,
) -> LocalMotion {
    let joints = solved.skeleton.len();
    let frames = solved.frame_count();
    for f in 0..frames {
        for j in 0..joints {
            if kept.joint(f, j) {
                solved.rotations[f * joints + j] = canonical.rotations[f * joints + j];
                solved.translations[f * joints + j] = canonical.translations[f * joints + j];
            }
        }
    }
    let mut planted = to_file(&solved, layout.up);
    for k in 0..frames * joints {
        if solved.rotations[k] == canonical.rotations[k]
            && solved.translations[k] == canonical.translations[k]
        {
            planted.rotations[k] = motion.rotations[k];
            planted.translations[k] = motion.translations[k];
        }
    }
    planted
}
