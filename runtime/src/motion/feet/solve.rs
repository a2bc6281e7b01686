//! Solving one frame: each leg's chain turned by [`least_turn`] so that its contact point
//! reaches its target (softly near full extension), and the smooth lift that keeps a solved
//! motion above the ground.

use super::chain::LegChain;
use crate::motion::clip::LocalMotion;
use crate::motion::fk::{GlobalPose, global_pose};
use crate::motion::ik::{TurnChain, least_turn};
use crate::motion::math::{self, Mat3, Vec3};
use crate::motion::skeleton::Skeleton;

use super::options::PlantOptions;

/// One chain's goal in one frame.
pub(super) struct Wanted<'a> {
    /// The chain to turn.
    pub(super) chain: &'a LegChain,
    /// Where its contact point should be.
    pub(super) target: Vec3,
}

/// Damping of the least-turn solver, in shares of the chain's reach: it keeps a nearly straight
/// leg from swinging about where no turn moves the foot along the leg.
const LEAST_TURN_DAMPING: f64 = 0.05;

/// Least-turn steps per [`PlantOptions::iterations`]: each is a small first-order turn.
const LEAST_TURN_STEPS_PER_ITERATION: usize = 4;

/// Frame `f` of `original`, with the carrier joint's translation moved by `shift` (in its
/// parent's frame) and each chain turned so that its contact point reaches its target, written
/// into `out`; returns its global pose.
pub(super) fn solve_frame(
    original: &LocalMotion,
    out: &mut LocalMotion,
    (f, carrier, shift): (usize, usize, Vec3),
    wanted: &[Wanted<'_>],
    options: &PlantOptions,
) -> GlobalPose {
    let joints = original.skeleton.len();
    let range = f * joints..(f + 1) * joints;
    out.rotations[range.clone()].copy_from_slice(&original.rotations[range.clone()]);
    out.translations[range.clone()].copy_from_slice(&original.translations[range]);
    add_nonzero(&mut out.translations[f * joints + carrier], shift);
    if wanted.is_empty() && shift.iter().all(|&v| v == 0.0) {
        return global_pose(out, f);
    }
    let pose = global_pose(out, f);
    for w in wanted {
        turn_least(&pose, out, f, w, options);
    }
    global_pose(out, f)
}

/// The global rotation of the joint above a chain's top (the identity above the root).
fn above_chain(pose: &GlobalPose, skeleton: &Skeleton, chain: &LegChain) -> Mat3 {
    skeleton.joints[chain.joints[0]]
        .parent
        .map_or(math::IDENTITY, |p| pose.rotations[p])
}

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
        tip: (pose.rotations[effector].transpose()
            * (pose.contact_point(chain.contact) - pose.joints[effector])),
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

/// `goal` moved along its line from `top` so that the chain's extension changes by the soft
/// difference between the goal's distance and the generated contact point's (`current`): a
/// goal at the generated point is left there, and near full extension the reach eases in
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
    let offset = goal - top;
    let d = offset.norm();
    let d0 = (current - top).norm();
    if d <= 0.0 {
        return goal;
    }
    let wanted = (d0 + eased(d) - eased(d0)).min(d.max(d0));
    top + (offset * (wanted / d))
}

/// An envelope at least `values` everywhere that rises and falls over `radius` frames: a
/// running maximum, then a running mean, both over `2 radius + 1` frames (each mean covers a
/// window that contains the frame's own maximum, so it is never below the frame's value).
pub(super) fn smooth_upper_envelope(values: &[f64], radius: usize) -> Vec<f64> {
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

/// Adds `by` to `to` where a component of `by` is not zero, leaving the others' bits as they
/// are (a `-0.0` stays `-0.0`, so a pass that moves nothing writes the input back exactly).
pub(super) fn add_nonzero(to: &mut Vec3, by: Vec3) {
    for (t, d) in to.0.iter_mut().zip(by.0) {
        if d != 0.0 {
            *t += d;
        }
    }
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

    #[test]
    fn a_soft_goal_is_left_alone_inside_the_chain_and_eased_at_its_end() {
        let top = [0.0, 1.0, 0.0];
        // Well inside the reach: the goal itself.
        let goal = [0.1, 0.5, 0.0];
        let kept = soften(Vec3(top), Vec3([0.0, 0.4, 0.0]), Vec3(goal), 1.0, 0.2);
        assert!((kept - Vec3(goal)).norm() < 1e-12, "{kept:?}");
        // Past the reach: pulled back towards the top, along its line, never past the reach.
        let far = [0.0, -0.5, 0.0];
        let eased = soften(Vec3(top), Vec3([0.0, 0.4, 0.0]), Vec3(far), 1.0, 0.2);
        let d = (eased - Vec3(top)).norm();
        assert!(d < 1.0 && d > 0.8, "{d}");
        assert!(eased[0].abs() < 1e-12 && eased[2].abs() < 1e-12);
    }
}
