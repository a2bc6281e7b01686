//! The planting pass: predicted contact spans held still on the ground, by carrying the root
//! along with the feet in contact and then by rotations of each leg's chain; the root moved up
//! or down only where no leg can reach or something would go through the floor.

use std::ops::Range;

use super::chain::{LegChain, leg_chain};
use super::ground::ground_level;
use super::spans::{contact_spans, span_weights};
use super::stance::stance_travel;
use crate::motion::clip::LocalMotion;
use crate::motion::features::{FeatureLayout, MotionError};
use crate::motion::fk::{GlobalPose, global_pose, global_poses};
use crate::motion::ik::{TurnChain, fabrik, least_turn, rotation_between, two_bone, two_bone_bent};
use crate::motion::math::{self, Mat3, Vec3};
use crate::motion::skeleton::Skeleton;
use crate::motion::up::{UP, height_of, horizontal, to_canonical, to_file};

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
    /// Iterations of the iterative solvers: FABRIK's passes ([`LegSolver::Positions`], chains of
    /// three or more bones), or a quarter of the least-turn steps ([`LegSolver::LeastTurn`]).
    pub iterations: usize,
    /// Whether the root may move up or down so that a leg reaches its target.
    pub reach_with_root: bool,
    /// A span grows on both sides while its contact point stays within this many skeleton
    /// heights of the ground (a point on the floor does not slide, whatever the label says); 0
    /// keeps the labelled spans. The default is the height band in which SPEC section 9 counts
    /// a point as on the ground: growing further holds feet that swing low, which costs the
    /// motion more than it fixes.
    pub grow_within: f64,
    /// A span grows only over frames where its contact point also moves slower than this, in
    /// skeleton heights per second along the ground: a foot that sweeps low and fast (a swing
    /// that grazes the floor, a hop's take-off) is motion the network meant, not a slide, and
    /// holding it turns the leg away from what the model made. `f64::INFINITY` grows by height
    /// alone. The default, 2.5 H/s, is well above a sliding stance (SPEC section 9 counts a
    /// slide from 0.3 H/s) and below a swinging foot.
    pub grow_below_speed: f64,
    /// Soft reach: over the last share of a chain's length the distance it reaches eases in
    /// exponentially instead of snapping straight (a knee that straightens smoothly); 0 for a
    /// hard limit.
    pub soft_reach: f64,
    /// The farthest a held point may be from where the network put it, in skeleton heights:
    /// past this, it follows the generated point at this distance (a foot the network drags a
    /// long way is let go rather than the leg stretched after it).
    pub max_hold: f64,
    /// Whether the root travels horizontally with the feet in contact before the legs are
    /// turned: where planted feet slide together, the body is carried along instead, which
    /// leaves the legs' rotations (what the model made) as they are. Frames whose root a task
    /// kept are not moved.
    pub root_follows_stance: bool,
    /// The root's travel with the stance is averaged over this many seconds on each side of a
    /// frame, with weights falling linearly to the edges (a root that followed every tremor of
    /// a foot would shake the whole body).
    pub stance_smoothing_seconds: f64,
    /// How a leg's chain is turned to put its contact point on the target.
    pub solver: LegSolver,
}

/// How planting turns a leg's chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegSolver {
    /// The least turning of every joint of the chain, the foot included (damped least squares on
    /// the rotations): what the network made changes as little as the target allows.
    #[default]
    LeastTurn,
    /// Positions first: analytic two-bone IK with the generated bend direction for a leg, FABRIK
    /// for longer chains; the effector (the foot) keeps its global rotation.
    Positions,
}

impl Default for PlantOptions {
    fn default() -> Self {
        PlantOptions {
            min_span_seconds: 0.1,
            blend_seconds: 0.1,
            anchor: Anchor::Mean,
            iterations: 20,
            reach_with_root: false,
            grow_within: 0.05,
            grow_below_speed: 2.5,
            soft_reach: 0.2,
            max_hold: 0.4,
            root_follows_stance: true,
            stance_smoothing_seconds: 0.3,
            solver: LegSolver::LeastTurn,
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
    fn joint(&self, frame: usize, joint: usize) -> bool {
        self.joints
            .get(frame)
            .and_then(|j| j.get(joint))
            .copied()
            .unwrap_or(false)
    }

    fn root(&self, frame: usize) -> bool {
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
    /// Frames in which the root moved vertically because no leg could reach its target.
    pub reach_frames: usize,
    /// The largest such move.
    pub max_reach_shift: f64,
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
    /// contact ([`PlantOptions::root_follows_stance`]).
    pub max_root_travel: f64,
}

/// Coordinates below this size can be subtracted, squared and summed without overflow.
const OVERFLOW_SAFE: f64 = 1e150;

/// Holds every contact joint of `motion` (decoded in `layout`, the file's frame) still during
/// the spans its `labels` (one series per contact joint, as the features carry them) mark, on
/// or above the ground, easing in and out over [`PlantOptions::blend_seconds`]; and lifts
/// whatever would go below the ground. Only the root's position (carried along with the feet in
/// contact, [`PlantOptions::root_follows_stance`], and raised where needed) and rotations of the
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
    let mut original = canonical.clone();
    let mut poses = global_poses(&original);
    let ground = layout
        .ground
        .unwrap_or_else(|| ground_level(&layout.contact_joints, &poses));
    let height = layout.skeleton_height.max(f64::MIN_POSITIVE);
    let mut stats = PlantStats {
        ground,
        ..PlantStats::default()
    };
    // A rig whose positions are so large that differences or squared lengths of them could
    // overflow (a broken model file's offsets) is left as it is.
    let tame = |v: f64| v.abs() < OVERFLOW_SAFE;
    if !tame(ground)
        || !poses
            .iter()
            .all(|pose| pose.points().all(|p| p.iter().all(|&v| tame(v))))
    {
        return Ok((motion.clone(), stats));
    }

    // One chain per contact joint; a chain that shares joints with an earlier one is skipped.
    let mut chains: Vec<Option<LegChain>> = Vec::new();
    for &contact in &layout.contact_joints {
        let chain = leg_chain(&layout.skeleton, &layout.rest_translations, contact).filter(|c| {
            !chains
                .iter()
                .flatten()
                .any(|o| o.joints.iter().any(|j| c.joints.contains(j)))
        });
        if chain.is_none() {
            stats.skipped_contacts.push(contact);
        }
        chains.push(chain);
    }

    // Per contact joint and frame: the point it should be at, or None to leave it.
    let min_frames = (options.min_span_seconds * layout.fps).round().max(1.0) as usize;
    let blend = (options.blend_seconds * layout.fps).round().max(0.0) as usize;
    let contact_points = |poses: &[GlobalPose], chain: &LegChain| -> Vec<Vec3> {
        poses
            .iter()
            .map(|p| p.contact_point(chain.contact))
            .collect()
    };
    // Spans are found on the generated motion, before the root travels with the stance.
    let chain_spans: Vec<Vec<Range<usize>>> = chains
        .iter()
        .enumerate()
        .map(|(k, chain)| {
            let Some(chain) = chain else {
                return Vec::new();
            };
            let points = contact_points(&poses, chain);
            let speed = |f: usize| {
                let next = if f + 1 < frames {
                    f + 1
                } else {
                    f.saturating_sub(1)
                };
                math::norm(horizontal(math::sub(points[next], points[f]))) * layout.fps / height
            };
            let low = |f: usize| {
                height_of(points[f]) - ground < options.grow_within * height
                    && speed(f) < options.grow_below_speed
            };
            grow_spans(contact_spans(&labels[k], min_frames), frames, low)
        })
        .collect();
    let top = top_joint(&original);
    if options.root_follows_stance {
        let (mut points, mut weights) = (Vec::new(), Vec::new());
        for (chain, spans) in chains.iter().zip(&chain_spans) {
            let Some(chain) = chain else { continue };
            points.push(contact_points(&poses, chain));
            weights.push(
                (0..frames)
                    .map(|f| {
                        let inside = spans.iter().any(|s| s.contains(&f));
                        let kept = chain.joints.iter().any(|&j| kept.joint(f, j));
                        if inside && !kept { 1.0 } else { 0.0 }
                    })
                    .collect::<Vec<f64>>(),
            );
        }
        let kept_root: Vec<bool> = (0..frames)
            .map(|f| kept.root(f) || kept.joint(f, top))
            .collect();
        let radius = (options.stance_smoothing_seconds * layout.fps)
            .round()
            .max(0.0) as usize;
        let travel = stance_travel(&points, &weights, &kept_root, radius);
        let joints = original.skeleton.len();
        for (f, t) in travel.iter().enumerate() {
            let root = &mut original.translations[f * joints + top];
            *root = math::add(*root, *t);
            stats.max_root_travel = stats.max_root_travel.max(math::norm(*t) / height);
        }
        poses = global_poses(&original);
    }
    let mut targets: Vec<Vec<Option<Vec3>>> = Vec::with_capacity(chains.len());
    for (chain, spans) in chains.iter().zip(chain_spans) {
        let Some(chain) = chain else {
            targets.push(vec![None; frames]);
            continue;
        };
        let points = contact_points(&poses, chain);
        stats.spans += spans.len();
        let anchors: Vec<Vec3> = spans
            .iter()
            .map(|s| anchor(&points, s.clone(), options.anchor, ground))
            .collect();
        let weights = span_weights(&spans, frames, blend);
        let per_frame = (0..frames)
            .map(|f| {
                if chain.joints.iter().any(|&j| kept.joint(f, j)) {
                    return None;
                }
                let mut target = points[f];
                if let Some((span, w)) = weights[f] {
                    // Inside, the anchor; on the borders, the generated path carrying a share
                    // `w` of the anchor's offset from the span's nearest end (a fixed offset
                    // that fades, so the point never chases a foot that swings away).
                    let s = &spans[span];
                    let edge = if f < s.start { s.start } else { s.end - 1 };
                    let offset = math::sub(anchors[span], points[edge]);
                    let pull = if s.contains(&f) {
                        math::sub(anchors[span], points[f])
                    } else {
                        math::scale(offset, w)
                    };
                    let length = math::norm(pull);
                    let most = options.max_hold * height;
                    target = math::add(
                        points[f],
                        math::scale(pull, if length > most { most / length } else { 1.0 }),
                    );
                    if w >= 1.0 {
                        stats.planted_frames += 1;
                    }
                } else if height_of(points[f]) >= ground {
                    return None;
                }
                target[UP] = target[UP].max(ground);
                Some(target)
            })
            .collect();
        targets.push(per_frame);
    }

    // Each two-bone chain's bend direction, in the frame of the joint above the chain and
    // averaged over nearby frames by how bent the knee is: a nearly straight knee has no
    // direction of its own, and taking it frame by frame would swing the knee about.
    let bend_window = (options.blend_seconds * layout.fps).round() as usize;
    let bends: Vec<Vec<Vec3>> = chains
        .iter()
        .map(|chain| match chain {
            Some(c) if c.bones() == 2 && options.solver == LegSolver::Positions => {
                smoothed_bends(&poses, &layout.skeleton, c, bend_window)
            }
            _ => Vec::new(),
        })
        .collect();
    let mut out = original.clone();
    let frame_targets = |f: usize| -> Vec<Wanted<'_>> {
        chains
            .iter()
            .zip(&targets)
            .zip(&bends)
            .filter_map(|((c, t), b)| {
                Some(Wanted {
                    chain: c.as_ref()?,
                    target: t[f]?,
                    bend: b.get(f).copied(),
                })
            })
            .collect()
    };
    // First pass: reach, then how far below the ground the solved frame still goes.
    let mut reach = vec![0.0; frames];
    let mut deficit = vec![0.0; frames];
    for f in 0..frames {
        if kept.root(f) || kept.joint(f, top) {
            continue;
        }
        let wanted = frame_targets(f);
        if options.reach_with_root {
            reach[f] = reach_shift(&poses[f], &wanted);
        }
        let solved = solve_frame(&original, &mut out, f, top, reach[f], &wanted, options);
        deficit[f] = (ground - lowest(&solved)).max(0.0);
    }
    let (mut miss_sum, mut miss_count) = (0.0, 0usize);
    // A lift that rises and falls smoothly and is never less than what a frame needs.
    let lift = smooth_upper_envelope(&deficit, blend);
    for f in 0..frames {
        let shift = if kept.root(f) || kept.joint(f, top) {
            0.0
        } else {
            reach[f] + lift[f]
        };
        let wanted = frame_targets(f);
        let mut solved = solve_frame(&original, &mut out, f, top, shift, &wanted, options);
        let mut total_lift = lift[f];
        let rest = ground - lowest(&solved);
        if rest > 0.0 && !(kept.root(f) || kept.joint(f, top)) {
            // What the smooth lift and the legs could not fix: lift the root the rest.
            out.translations[f * out.skeleton.len() + top][UP] += rest;
            total_lift += rest;
            solved = global_pose(&out, f);
        }
        if reach[f] != 0.0 {
            stats.reach_frames += 1;
            stats.max_reach_shift = stats.max_reach_shift.max(reach[f].abs() / height);
        }
        if total_lift > 0.0 {
            stats.lifted_frames += 1;
            stats.max_lift = stats.max_lift.max(total_lift / height);
        }
        for w in &wanted {
            let miss =
                math::norm(math::sub(solved.contact_point(w.chain.contact), w.target)) / height;
            if miss > 1e-3 {
                stats.unreached += 1;
            }
            stats.max_miss = stats.max_miss.max(miss);
            miss_sum += miss;
            miss_count += 1;
        }
    }
    stats.mean_miss = miss_sum / miss_count.max(1) as f64;
    // Whatever a task kept is the input's, bit for bit.
    let joints = out.skeleton.len();
    for f in 0..frames {
        for j in 0..joints {
            if kept.joint(f, j) {
                out.rotations[f * joints + j] = canonical.rotations[f * joints + j];
                out.translations[f * joints + j] = canonical.translations[f * joints + j];
            }
        }
    }
    let mut planted = to_file(&out, layout.up);
    // Untouched values are restored from the input itself, so a kept joint is exact even in a
    // file frame that the canonical round trip would round.
    for f in 0..frames {
        for j in 0..joints {
            let k = f * joints + j;
            if out.rotations[k] == canonical.rotations[k]
                && out.translations[k] == canonical.translations[k]
            {
                planted.rotations[k] = motion.rotations[k];
                planted.translations[k] = motion.translations[k];
            }
        }
    }
    Ok((planted, stats))
}

/// Spans grown on both sides over the frames where `low` holds, merged where they meet.
fn grow_spans(
    spans: Vec<Range<usize>>,
    frames: usize,
    low: impl Fn(usize) -> bool,
) -> Vec<Range<usize>> {
    let mut grown: Vec<Range<usize>> = Vec::with_capacity(spans.len());
    for mut span in spans {
        while span.start > 0 && low(span.start - 1) {
            span.start -= 1;
        }
        while span.end < frames && low(span.end) {
            span.end += 1;
        }
        match grown.last_mut() {
            Some(last) if last.end >= span.start => last.end = last.end.max(span.end),
            _ => grown.push(span),
        }
    }
    grown
}

/// How far (in thigh lengths) a knee must stick out of its hip-ankle line before its own bend
/// direction outweighs the smoothed one.
const BEND_FLOOR: f64 = 0.05;

/// One chain's goal in one frame.
struct Wanted<'a> {
    chain: &'a LegChain,
    /// Where its contact point should be.
    target: Vec3,
    /// The knee's bend direction in the frame above the chain (two-bone chains).
    bend: Option<Vec3>,
}

/// The global rotation of the joint above a chain's top (the identity above the root).
fn above_chain(pose: &GlobalPose, skeleton: &Skeleton, chain: &LegChain) -> Mat3 {
    skeleton.joints[chain.joints[0]]
        .parent
        .map_or(math::IDENTITY, |p| pose.rotations[p])
}

/// Per frame, a two-bone chain's bend direction (the knee's offset across the line from the
/// chain's top to its effector) in the frame above the chain, summed over `radius` frames on
/// each side with each frame weighted by how far its knee sticks out, then normalised.
fn smoothed_bends(
    poses: &[GlobalPose],
    skeleton: &Skeleton,
    chain: &LegChain,
    radius: usize,
) -> Vec<Vec3> {
    let [top, mid, end] = [chain.joints[0], chain.joints[1], chain.joints[2]];
    let local: Vec<Vec3> = poses
        .iter()
        .map(|pose| {
            let line = math::normalize_or(math::sub(pose.joints[end], pose.joints[top]), [0.0; 3]);
            let knee = math::sub(pose.joints[mid], pose.joints[top]);
            let across = math::sub(knee, math::scale(line, math::dot(knee, line)));
            math::mat_vec(
                &math::transpose(&above_chain(pose, skeleton, chain)),
                across,
            )
        })
        .collect();
    let n = local.len();
    (0..n)
        .map(|f| {
            let window = f.saturating_sub(radius)..(f + radius + 1).min(n);
            let sum = local[window].iter().fold([0.0; 3], |a, &v| math::add(a, v));
            math::normalize_or(sum, math::normalize_or(local[f], [0.0; 3]))
        })
        .collect()
}

/// The point a span holds its contact point at, on or above the ground.
fn anchor(points: &[Vec3], span: Range<usize>, kind: Anchor, ground: f64) -> Vec3 {
    let mut at = match kind {
        Anchor::Landing => points[span.start],
        Anchor::Mean => {
            let n = span.len() as f64;
            let sum = points[span].iter().fold([0.0; 3], |a, &p| math::add(a, p));
            math::scale(sum, 1.0 / n)
        }
    };
    at[UP] = at[UP].max(ground);
    at
}

/// The joint without a parent (a validated skeleton has exactly one, first).
fn top_joint(motion: &LocalMotion) -> usize {
    motion
        .skeleton
        .joints
        .iter()
        .position(|j| j.parent.is_none())
        .unwrap_or(0)
}

/// The lowest height of a pose's joints and End Sites.
fn lowest(pose: &GlobalPose) -> f64 {
    pose.points().map(height_of).fold(f64::INFINITY, f64::min)
}

/// The smallest vertical move of the root that brings every target within its chain's reach
/// (0 when all are, or when no single move serves them all).
fn reach_shift(pose: &GlobalPose, wanted: &[Wanted<'_>]) -> f64 {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for Wanted { chain, target, .. } in wanted {
        let top = pose.joints[chain.joints[0]];
        let effector_target = effector_target(pose, chain, *target);
        let reach: f64 = chain
            .joints
            .windows(2)
            .map(|w| math::norm(math::sub(pose.joints[w[1]], pose.joints[w[0]])))
            .sum::<f64>()
            * 0.999;
        let d = math::sub(effector_target, top);
        let across = math::norm(horizontal(d));
        if across >= reach {
            return 0.0;
        }
        let slack = (reach * reach - across * across).sqrt();
        lo = lo.max(d[UP] - slack);
        hi = hi.min(d[UP] + slack);
    }
    if lo > hi || (lo <= 0.0 && 0.0 <= hi) {
        0.0
    } else if lo > 0.0 {
        lo
    } else {
        hi
    }
}

/// Where the effector must be for the contact point to reach `target`, the effector keeping its
/// global rotation (the contact point rides rigidly with it).
fn effector_target(pose: &GlobalPose, chain: &LegChain, target: Vec3) -> Vec3 {
    let lever = math::sub(
        pose.contact_point(chain.contact),
        pose.joints[chain.effector()],
    );
    math::sub(target, lever)
}

/// `goal` moved along its line from `top` so that the chain's extension changes by the soft
/// difference between the goal's distance and the generated effector's (`current`): a goal at
/// the generated effector is left there, and near full extension the reach eases in
/// exponentially over the last `share` of the chain's `reach` instead of snapping the knee
/// straight (soft IK).
fn soften(top: Vec3, current: Vec3, goal: Vec3, reach: f64, share: f64) -> Vec3 {
    let soft = share * reach;
    let start = reach - soft;
    let eased = |d: f64| {
        if soft <= 0.0 || d <= start {
            d
        } else {
            start + soft * (1.0 - (-(d - start) / soft).exp())
        }
    };
    let offset = math::sub(goal, top);
    let d = math::norm(offset);
    let d0 = math::norm(math::sub(current, top));
    if d <= 0.0 {
        return goal;
    }
    let wanted = (d0 + eased(d) - eased(d0)).min(d.max(d0));
    math::add(top, math::scale(offset, wanted / d))
}

/// Frame `f` of `original`, with the top joint raised by `shift` and each chain turned so that
/// its contact point reaches its target, written into `out`; returns its global pose.
fn solve_frame(
    original: &LocalMotion,
    out: &mut LocalMotion,
    f: usize,
    top: usize,
    shift: f64,
    wanted: &[Wanted<'_>],
    options: &PlantOptions,
) -> GlobalPose {
    let joints = original.skeleton.len();
    let range = f * joints..(f + 1) * joints;
    out.rotations[range.clone()].copy_from_slice(&original.rotations[range.clone()]);
    out.translations[range.clone()].copy_from_slice(&original.translations[range]);
    out.translations[f * joints + top][UP] += shift;
    if wanted.is_empty() && shift == 0.0 {
        return global_pose(out, f);
    }
    let pose = global_pose(out, f);
    for w in wanted {
        match options.solver {
            LegSolver::LeastTurn => turn_least(&pose, out, f, w, options),
            LegSolver::Positions => place_by_positions(&pose, out, f, w, options),
        }
    }
    global_pose(out, f)
}

/// Damping of the least-turn solver, in shares of the chain's reach: it keeps a nearly straight
/// leg from swinging about where no turn moves the foot along the leg.
const LEAST_TURN_DAMPING: f64 = 0.05;

/// Least-turn steps per FABRIK iteration ([`PlantOptions::iterations`]): each is a small
/// first-order turn, where a FABRIK pass moves whole bones.
const LEAST_TURN_STEPS_PER_ITERATION: usize = 4;

/// One chain of frame `f` turned by [`least_turn`] so that its contact point reaches its target:
/// every joint of the chain, the foot included, turns as little as it can. `pose` is the
/// frame's global pose before any chain was turned (chains share no joint).
fn turn_least(
    pose: &GlobalPose,
    out: &mut LocalMotion,
    f: usize,
    wanted: &Wanted<'_>,
    options: &PlantOptions,
) {
    let chain = wanted.chain;
    let joints = out.skeleton.len();
    let effector = chain.effector();
    let turn = TurnChain {
        top: pose.joints[chain.joints[0]],
        above: above_chain(pose, &out.skeleton, chain),
        locals: chain
            .joints
            .iter()
            .map(|&j| out.rotations[f * joints + j])
            .collect(),
        offsets: chain.joints[1..]
            .iter()
            .map(|&j| out.translations[f * joints + j])
            .collect(),
        tip: math::mat_vec(
            &math::transpose(&pose.rotations[effector]),
            math::sub(pose.contact_point(chain.contact), pose.joints[effector]),
        ),
    };
    let reach = turn.reach();
    let now = pose.contact_point(chain.contact);
    let goal = soften(turn.top, now, wanted.target, reach, options.soft_reach);
    let locals = least_turn(
        &turn,
        goal,
        LEAST_TURN_STEPS_PER_ITERATION * options.iterations,
        1e-6 * reach,
        LEAST_TURN_DAMPING * reach,
    );
    for (&j, local) in chain.joints.iter().zip(locals) {
        out.rotations[f * joints + j] = local;
    }
}

/// One chain of frame `f` placed by positions: analytic two-bone IK with the generated bend
/// direction for a leg, FABRIK for longer chains, each bone then turned from its old direction
/// to its new one, the effector keeping its global rotation.
fn place_by_positions(
    pose: &GlobalPose,
    out: &mut LocalMotion,
    f: usize,
    wanted: &Wanted<'_>,
    options: &PlantOptions,
) {
    let Wanted {
        chain,
        target,
        bend,
    } = wanted;
    let joints = out.skeleton.len();
    let old: Vec<Vec3> = chain.joints.iter().map(|&j| pose.joints[j]).collect();
    let exact = effector_target(pose, chain, *target);
    let reach: f64 = crate::motion::ik::bone_lengths(&old).iter().sum();
    if math::norm(math::sub(exact, old[old.len() - 1])) <= 1e-12 * reach.max(f64::MIN_POSITIVE) {
        return;
    }
    let goal = soften(old[0], old[old.len() - 1], exact, reach, options.soft_reach);
    let new: Vec<Vec3> = if old.len() == 3 {
        let [mid, end] = match bend {
            Some(bend) => {
                // The generated knee's own direction where it is bent; the smoothed one
                // decides only for a knee that is nearly straight.
                let frame = above_chain(pose, &out.skeleton, chain);
                let line = math::normalize_or(math::sub(goal, old[0]), [0.0; 3]);
                let knee = math::sub(old[1], old[0]);
                let across = math::sub(knee, math::scale(line, math::dot(knee, line)));
                let thigh = math::norm(knee);
                let bend = math::add(
                    across,
                    math::scale(math::mat_vec(&frame, *bend), BEND_FLOOR * thigh),
                );
                two_bone_bent(
                    old[0],
                    [
                        math::norm(math::sub(old[1], old[0])),
                        math::norm(math::sub(old[2], old[1])),
                    ],
                    goal,
                    bend,
                    math::sub(old[2], old[0]),
                )
            }
            None => two_bone(old[0], old[1], old[2], goal),
        };
        vec![old[0], mid, end]
    } else {
        fabrik(&old, goal, options.iterations, 1e-6 * reach)
    };
    let globals: Vec<Mat3> = (0..old.len() - 1)
        .map(|i| {
            let turn =
                rotation_between(math::sub(old[i + 1], old[i]), math::sub(new[i + 1], new[i]));
            math::mat_mul(&turn, &pose.rotations[chain.joints[i]])
        })
        .collect();
    let first = chain.joints[0];
    let parent_global = out.skeleton.joints[first]
        .parent
        .map_or(math::IDENTITY, |p| pose.rotations[p]);
    for (i, &j) in chain.joints.iter().enumerate() {
        let above = if i == 0 {
            parent_global
        } else {
            globals[i - 1]
        };
        let global = globals.get(i).copied().unwrap_or(pose.rotations[j]);
        out.rotations[f * joints + j] = math::mat_mul(&math::transpose(&above), &global);
    }
}

/// An envelope at least `values` everywhere that rises and falls over `radius` frames: a
/// running maximum, then a running mean, both over `2 radius + 1` frames (each mean covers a
/// window that contains the frame's own maximum, so it is never below the frame's value).
fn smooth_upper_envelope(values: &[f64], radius: usize) -> Vec<f64> {
    let n = values.len();
    let window = |i: usize| i.saturating_sub(radius)..(i + radius + 1).min(n);
    let maxima: Vec<f64> = (0..n)
        .map(|i| values[window(i)].iter().copied().fold(0.0, f64::max))
        .collect();
    (0..n)
        .map(|i| {
            let w = window(i);
            let len = w.len() as f64;
            let mean = maxima[w].iter().sum::<f64>() / len;
            mean.max(values[i])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_envelope_covers_every_value_and_eases() {
        let v = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let e = smooth_upper_envelope(&v, 2);
        assert!(e.iter().zip(&v).all(|(e, v)| e >= v));
        assert_eq!(e[3], 1.0);
        // Maxima 0 1 1 1 1 1 0 0 0 0, then means over five frames.
        assert!((e[0] - 2.0 / 3.0).abs() < 1e-12 && (e[1] - 0.75).abs() < 1e-12);
        assert!((e[7] - 0.2).abs() < 1e-12);
        assert_eq!(e[9], 0.0);
    }
}
