//! Inverse kinematics by rotations, for planting feet: [`least_turn`] turns every joint of a
//! chain (a human's two-bone leg, a dog's or a fox's three- or four-bone one, the foot included)
//! as little as it can, in the model's own 6D representation, so that the chain's tip reaches a
//! target. Only rotations change, so every bone keeps its length.

use super::math::{Mat3, Vec3};
use super::rotation::{mat_from_6d, mat_to_6d};

/// A chain of joints described by rotations, for [`least_turn`]: its top joint's position and
/// the global rotation above it, each joint's local rotation, each joint's offset from the one
/// above it, and the tip (the contact point) in the last joint's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnChain {
    /// Where the top joint is (it stays there).
    pub top: Vec3,
    /// The global rotation of the joint above the chain.
    pub above: Mat3,
    /// Local rotation of each joint of the chain, top first.
    pub locals: Vec<Mat3>,
    /// `offsets[i]`: where joint `i + 1` sits in the frame of joint `i` (one fewer than joints).
    pub offsets: Vec<Vec3>,
    /// The tip in the frame of the last joint.
    pub tip: Vec3,
}

impl TurnChain {
    /// Joint positions, global rotations and the tip's position, with `locals`.
    pub fn forward(&self, locals: &[Mat3]) -> (Vec<Vec3>, Vec<Mat3>, Vec3) {
        let mut positions = Vec::with_capacity(locals.len());
        let mut globals = Vec::with_capacity(locals.len());
        let mut at = self.top;
        let mut global = self.above;
        for (i, local) in locals.iter().enumerate() {
            if i > 0 {
                at += global * self.offsets[i - 1];
            }
            global = global * local;
            positions.push(at);
            globals.push(global);
        }
        let tip = at + (global * self.tip);
        (positions, globals, tip)
    }

    /// The chain's reach: its bones and the tip's lever, end to end.
    pub fn reach(&self) -> f64 {
        self.offsets.iter().map(|&o| o.norm()).sum::<f64>() + self.tip.norm()
    }
}

/// The rotation by `angle` radians about the unit vector `axis` (Rodrigues' formula).
pub fn rotation_about(axis: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let k = Mat3([
        [0.0, -axis[2], axis[1]],
        [axis[2], 0.0, -axis[0]],
        [-axis[1], axis[0], 0.0],
    ]);
    let k2 = k * k;
    Mat3::from_fn(|i, j| f64::from(u8::from(i == j)) + s * k[i][j] + (1.0 - c) * k2[i][j])
}

/// Solves the symmetric positive definite 3 x 3 system `a x = b` (Cramer's rule); zeros when
/// it is singular.
fn solve3(a: &Mat3, b: Vec3) -> Vec3 {
    let det = a.determinant();
    if det.abs() <= f64::MIN_POSITIVE || !det.is_finite() {
        return Vec3::ZERO;
    }
    let column = |i: usize| -> Mat3 { Mat3::from_fn(|r, c| if c == i { b[r] } else { a[r][c] }) };
    Vec3::from_fn(|i| {
        let m = column(i);
        m.determinant() / det
    })
}

/// The largest turn of one joint in one iteration of [`least_turn`], in radians.
const MAX_TURN_PER_ITERATION: f64 = 0.2;

/// The chain's local rotations turned as little as possible so that its tip reaches `target`:
/// each step is the least change of the rotations' 6D values (the model's own representation,
/// to first order) that moves the tip to the target, by damped least squares over the turns of
/// every joint; at most `iterations` steps, stopping once the tip is within `tolerance`. Bone lengths cannot change (only rotations do); a target out of reach gets the
/// tip as near as the damping lets it, without NaN. `damping` is a length (a share of the reach
/// keeps a nearly straight chain from flailing).
pub fn least_turn(
    chain: &TurnChain,
    target: Vec3,
    iterations: usize,
    tolerance: f64,
    damping: f64,
) -> Vec<Mat3> {
    let mut locals = chain.locals.clone();
    for _ in 0..iterations {
        let (positions, globals, tip) = chain.forward(&locals);
        let error = target - tip;
        if error.norm() <= tolerance || !error.norm().is_finite() {
            break;
        }
        // The tip moves by w x r for a turn w (world axis) at a joint r away: J = -[r]x. A turn
        // d (in the joint's frame) changes the 6D value (the local rotation's first two rows,
        // L0 and L1) by |L0 x d|^2 + |L1 x d|^2 = d^T (I + L2 L2^T) d, to first order: in the
        // world frame, W = I + u u^T with u = G L2. The least weighted change is
        // w = W^-1 J^T y with (J W^-1 J^T + damping^2 I) y = e; W^-1 = I - u u^T / 2 and
        // J W^-1 J^T = |r|^2 I - r r^T - v v^T / 2 with v = r x u.
        let levers: Vec<Vec3> = positions.iter().map(|&p| tip - p).collect();
        let axes: Vec<Vec3> = globals
            .iter()
            .zip(&locals)
            .map(|(g, l)| g * l.row(2))
            .collect();
        let jjt = Mat3::from_fn(|i, j| {
            let diagonal = f64::from(u8::from(i == j));
            levers
                .iter()
                .zip(&axes)
                .fold(diagonal * damping * damping, |sum, (r, u)| {
                    let v = r.cross(*u);
                    sum + diagonal * r.dot(*r) - r[i] * r[j] - 0.5 * v[i] * v[j]
                })
        });
        let y = solve3(&jjt, error);
        for (i, (r, u)) in levers.iter().zip(&axes).enumerate() {
            let jty = r.cross(y);
            let turn = jty - (*u * (0.5 * u.dot(jty)));
            let angle = turn.norm();
            if angle <= 0.0 || !angle.is_finite() {
                continue;
            }
            let world = rotation_about(turn * (1.0 / angle), angle.min(MAX_TURN_PER_ITERATION));
            // The same turn in the joint's own frame: G' = W G = G (G^T W G).
            let g = &globals[i];
            let in_joint = g.transpose() * (world * g);
            // Products of products drift from a rotation, and the drift feeds on itself
            // through the globals: back to the nearest rotation after every turn.
            locals[i] = mat_from_6d(&mat_to_6d(&(locals[i] * in_joint)));
        }
    }
    locals
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::math;

    fn distance(a: Vec3, b: Vec3) -> f64 {
        (a - b).norm()
    }

    /// A dog's hind leg as rotations: hip, knee, hock, paw, each bent a little about its own
    /// axes, and a toe tip below the paw.
    fn hind_leg() -> TurnChain {
        let turn = |x: f64, y: f64, z: f64| {
            math::axis_rotation(0, x) * (math::axis_rotation(1, y) * math::axis_rotation(2, z))
        };
        TurnChain {
            top: Vec3([0.1, 1.0, -0.2]),
            above: turn(0.1, 0.3, -0.05),
            locals: vec![
                turn(0.4, 0.05, 0.1),
                turn(-0.9, 0.0, 0.05),
                turn(0.7, -0.1, 0.0),
                turn(-0.2, 0.0, 0.1),
            ],
            offsets: vec![
                Vec3([0.0, -0.3, 0.05]),
                Vec3([0.0, -0.3, -0.05]),
                Vec3([0.0, -0.25, 0.02]),
            ],
            tip: Vec3([0.03, -0.1, 0.08]),
        }
    }

    /// The summed squared change of the 6D values of two sets of local rotations.
    fn six_d_change(a: &[Mat3], b: &[Mat3]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| {
                let (x, y) = (mat_to_6d(x), mat_to_6d(y));
                x.iter().zip(&y).map(|(p, q)| (p - q).powi(2)).sum::<f64>()
            })
            .sum()
    }

    fn is_rotation(m: &Mat3) -> bool {
        let mmt = m * m.transpose();
        math::mat_max_abs_diff(&mmt, &math::IDENTITY) < 1e-12
            && (m.determinant() - 1.0).abs() < 1e-12
    }

    #[test]
    fn least_turn_brings_a_four_bone_leg_to_its_target_keeping_lengths() {
        let leg = hind_leg();
        let (_, _, tip) = leg.forward(&leg.locals);
        let target = tip + Vec3([0.08, 0.05, -0.06]);
        let reach = leg.reach();
        let locals = least_turn(&leg, target, 80, 1e-9, 0.05 * reach);
        let (positions, _, reached) = leg.forward(&locals);
        assert!(distance(reached, target) < 1e-6, "{reached:?}");
        assert!(locals.iter().all(is_rotation));
        // Only rotations changed: every bone and the tip's lever keep their lengths.
        for (w, offset) in positions.windows(2).zip(&leg.offsets) {
            assert!((distance(w[0], w[1]) - offset.norm()).abs() < 1e-12);
        }
        assert!((distance(reached, positions[3]) - leg.tip.norm()).abs() < 1e-12);
        assert_eq!(positions[0], leg.top);
    }

    #[test]
    fn least_turn_changes_the_rotations_less_than_any_nearby_answer() {
        let leg = hind_leg();
        let (_, _, tip) = leg.forward(&leg.locals);
        let reach = leg.reach();
        let mut seed = 7u64;
        let mut uniform = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for offset in [[0.05, 0.0, 0.0], [0.0, 0.04, -0.03], [-0.03, -0.02, 0.06]] {
            let target = tip + Vec3(offset);
            let least = least_turn(&leg, target, 200, 1e-12, 1e-3 * reach);
            let cost = six_d_change(&leg.locals, &least);
            // Other exact answers near it: start from the least turn's, turned a little at
            // random, and reach the target again from there. None changes the leg less, but
            // for what a sequence of first-order steps leaves (well under 1 %).
            for _ in 0..40 {
                let start: Vec<Mat3> = least
                    .iter()
                    .map(|l| {
                        let axis = Vec3::new(uniform(), uniform(), uniform())
                            .normalize_or(Vec3::new(1.0, 0.0, 0.0));
                        l * rotation_about(axis, 0.05 * uniform())
                    })
                    .collect();
                let nearby = TurnChain {
                    locals: start,
                    ..leg.clone()
                };
                let other = least_turn(&nearby, target, 200, 1e-12, 1e-3 * reach);
                let (_, _, reached) = leg.forward(&other);
                assert!(distance(reached, target) < 1e-9);
                let other_cost = six_d_change(&leg.locals, &other);
                assert!(
                    cost <= other_cost * 1.01,
                    "{offset:?}: {cost} against {other_cost}"
                );
            }
        }
    }

    #[test]
    fn least_turn_stretches_towards_a_target_out_of_reach_without_nan() {
        let leg = hind_leg();
        let reach = leg.reach();
        let far = leg.top + Vec3([0.3, -2.0 * reach, 0.1]);
        let locals = least_turn(&leg, far, 80, 1e-9, 0.05 * reach);
        assert!(locals.iter().all(Mat3::is_finite));
        assert!(locals.iter().all(is_rotation));
        let (_, _, tip) = leg.forward(&locals);
        // Nearly straight towards it: within a few per cent of the closest reach.
        let closest = distance(far, leg.top) - reach;
        assert!(distance(tip, far) < closest + 0.03 * reach, "{tip:?}");
        // A target on the top itself, or NaN, changes nothing into NaN.
        for target in [leg.top, Vec3([f64::NAN, 0.0, 0.0])] {
            let locals = least_turn(&leg, target, 80, 1e-9, 0.05 * reach);
            assert!(locals.iter().all(Mat3::is_finite));
        }
    }
}
