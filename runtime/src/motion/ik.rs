//! Inverse kinematics on global joint positions, for planting feet: an analytic two-bone
//! solver that keeps the chain's bend plane, and FABRIK for longer chains (a dog's or a fox's
//! legs have three or four bones). Both keep every bone's length; the positions they return are
//! turned into rotations with [`rotation_between`], so a pose changes by rotations only.

use super::math::{self, Mat3, Vec3};
use super::rotation::{mat_from_6d, mat_to_6d};

/// Lengths of the bones of a chain of points.
pub fn bone_lengths(points: &[Vec3]) -> Vec<f64> {
    points
        .windows(2)
        .map(|w| math::norm(math::sub(w[1], w[0])))
        .collect()
}

/// The two-bone chain `root -> mid -> end` reaching for `target`: new `[mid, end]`, with the
/// root fixed, both bone lengths kept and the knee bent in the plane of the root, the target
/// and the old knee (the generated bend direction). A target out of reach gets the closest
/// reach: the chain straight towards it (too far) or folded (too near).
pub fn two_bone(root: Vec3, mid: Vec3, end: Vec3, target: Vec3) -> [Vec3; 2] {
    let lengths = [
        math::norm(math::sub(mid, root)),
        math::norm(math::sub(end, mid)),
    ];
    let fallback = math::normalize_or(math::sub(end, root), [0.0, -1.0, 0.0]);
    two_bone_bent(root, lengths, target, math::sub(mid, root), fallback)
}

/// The two-bone chain from `root` with bone `lengths` reaching for `target`, its knee bent
/// towards `bend` (only the part of `bend` across the root-target line counts): new
/// `[mid, end]`. `fallback` is the reach direction when the target sits on the root.
pub fn two_bone_bent(
    root: Vec3,
    lengths: [f64; 2],
    target: Vec3,
    bend: Vec3,
    fallback: Vec3,
) -> [Vec3; 2] {
    let [a, b] = lengths;
    let to_target = math::sub(target, root);
    let u = math::normalize_or(to_target, math::normalize_or(fallback, [0.0, -1.0, 0.0]));
    // max/min rather than clamp: with overflowing lengths the bounds may be NaN, and clamp
    // would panic on them.
    let d = math::norm(to_target).max((a - b).abs()).min(a + b);
    let across = math::sub(bend, math::scale(u, math::dot(bend, u)));
    let v = math::normalize_or(across, any_perpendicular(u));
    let cos = if a * d > 0.0 {
        ((a * a + d * d - b * b) / (2.0 * a * d)).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let new_mid = math::add(
        root,
        math::add(math::scale(u, a * cos), math::scale(v, a * sin)),
    );
    let new_end = math::add(
        new_mid,
        math::scale(
            math::normalize_or(math::sub(math::add(root, math::scale(u, d)), new_mid), u),
            b,
        ),
    );
    [new_mid, new_end]
}

/// A unit vector perpendicular to the unit vector `u`.
fn any_perpendicular(u: Vec3) -> Vec3 {
    let helper = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    math::normalize_or(math::cross(u, helper), [0.0, 0.0, 1.0])
}

/// FABRIK: the chain `points` (root first) reaching for `target` with its root fixed, in at
/// most `iterations` forward-and-backward passes, stopping once the end is within `tolerance`.
/// Bone lengths are kept; a target out of reach gets the chain straight towards it.
pub fn fabrik(points: &[Vec3], target: Vec3, iterations: usize, tolerance: f64) -> Vec<Vec3> {
    let mut p = points.to_vec();
    let n = p.len();
    if n < 2 {
        return p;
    }
    let lengths = bone_lengths(points);
    let root = p[0];
    let reach: f64 = lengths.iter().sum();
    let place = |from: Vec3, towards: Vec3, length: f64, fallback: Vec3| {
        math::add(
            from,
            math::scale(
                math::normalize_or(math::sub(towards, from), fallback),
                length,
            ),
        )
    };
    if math::norm(math::sub(target, root)) >= reach {
        let dir = math::normalize_or(math::sub(target, root), [0.0, -1.0, 0.0]);
        for i in 1..n {
            p[i] = place(p[i - 1], math::add(p[i - 1], dir), lengths[i - 1], dir);
        }
        return p;
    }
    for _ in 0..iterations {
        if math::norm(math::sub(p[n - 1], target)) <= tolerance {
            break;
        }
        // Backward: the end on the target, each joint pulled towards its child.
        p[n - 1] = target;
        for i in (0..n - 1).rev() {
            let fallback = math::normalize_or(math::sub(points[i], points[i + 1]), [0.0, 1.0, 0.0]);
            p[i] = place(p[i + 1], p[i], lengths[i], fallback);
        }
        // Forward: the root back in place, each joint pulled towards its parent.
        p[0] = root;
        for i in 1..n {
            let fallback =
                math::normalize_or(math::sub(points[i], points[i - 1]), [0.0, -1.0, 0.0]);
            p[i] = place(p[i - 1], p[i], lengths[i - 1], fallback);
        }
    }
    p
}

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
                at = math::add(at, math::mat_vec(&global, self.offsets[i - 1]));
            }
            global = math::mat_mul(&global, local);
            positions.push(at);
            globals.push(global);
        }
        let tip = math::add(at, math::mat_vec(&global, self.tip));
        (positions, globals, tip)
    }

    /// The chain's reach: its bones and the tip's lever, end to end.
    pub fn reach(&self) -> f64 {
        self.offsets.iter().map(|&o| math::norm(o)).sum::<f64>() + math::norm(self.tip)
    }
}

/// The rotation by `angle` radians about the unit vector `axis` (Rodrigues' formula).
pub fn rotation_about(axis: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let k: Mat3 = [
        [0.0, -axis[2], axis[1]],
        [axis[2], 0.0, -axis[0]],
        [-axis[1], axis[0], 0.0],
    ];
    let k2 = math::mat_mul(&k, &k);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| f64::from(u8::from(i == j)) + s * k[i][j] + (1.0 - c) * k2[i][j])
    })
}

/// Solves the symmetric positive definite 3 x 3 system `a x = b` (Cramer's rule); zeros when
/// it is singular.
fn solve3(a: &Mat3, b: Vec3) -> Vec3 {
    let det = math::dot(a[0], math::cross(a[1], a[2]));
    if det.abs() <= f64::MIN_POSITIVE || !det.is_finite() {
        return [0.0; 3];
    }
    let column = |i: usize| -> Mat3 {
        std::array::from_fn(|r| std::array::from_fn(|c| if c == i { b[r] } else { a[r][c] }))
    };
    std::array::from_fn(|i| {
        let m = column(i);
        math::dot(m[0], math::cross(m[1], m[2])) / det
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
        let error = math::sub(target, tip);
        if math::norm(error) <= tolerance || !math::norm(error).is_finite() {
            break;
        }
        // The tip moves by w x r for a turn w (world axis) at a joint r away: J = -[r]x. A turn
        // d (in the joint's frame) changes the 6D value (the local rotation's first two rows,
        // L0 and L1) by |L0 x d|^2 + |L1 x d|^2 = d^T (I + L2 L2^T) d, to first order: in the
        // world frame, W = I + u u^T with u = G L2. The least weighted change is
        // w = W^-1 J^T y with (J W^-1 J^T + damping^2 I) y = e; W^-1 = I - u u^T / 2 and
        // J W^-1 J^T = |r|^2 I - r r^T - v v^T / 2 with v = r x u.
        let levers: Vec<Vec3> = positions.iter().map(|&p| math::sub(tip, p)).collect();
        let axes: Vec<Vec3> = globals
            .iter()
            .zip(&locals)
            .map(|(g, l)| math::mat_vec(g, l[2]))
            .collect();
        let jjt: Mat3 = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let diagonal = f64::from(u8::from(i == j));
                levers
                    .iter()
                    .zip(&axes)
                    .fold(diagonal * damping * damping, |sum, (r, u)| {
                        let v = math::cross(*r, *u);
                        sum + diagonal * math::dot(*r, *r) - r[i] * r[j] - 0.5 * v[i] * v[j]
                    })
            })
        });
        let y = solve3(&jjt, error);
        for (i, (r, u)) in levers.iter().zip(&axes).enumerate() {
            let jty = math::cross(*r, y);
            let turn = math::sub(jty, math::scale(*u, 0.5 * math::dot(*u, jty)));
            let angle = math::norm(turn);
            if angle <= 0.0 || !angle.is_finite() {
                continue;
            }
            let world = rotation_about(
                math::scale(turn, 1.0 / angle),
                angle.min(MAX_TURN_PER_ITERATION),
            );
            // The same turn in the joint's own frame: G' = W G = G (G^T W G).
            let g = &globals[i];
            let in_joint = math::mat_mul(&math::transpose(g), &math::mat_mul(&world, g));
            // Products of products drift from a rotation, and the drift feeds on itself
            // through the globals: back to the nearest rotation after every turn.
            locals[i] = mat_from_6d(&mat_to_6d(&math::mat_mul(&locals[i], &in_joint)));
        }
    }
    locals
}

/// The smallest rotation taking the direction of `from` to the direction of `to` (the identity
/// for a zero vector; a half turn about a perpendicular axis for opposite directions).
pub fn rotation_between(from: Vec3, to: Vec3) -> Mat3 {
    let (a, b) = (
        math::normalize_or(from, [0.0; 3]),
        math::normalize_or(to, [0.0; 3]),
    );
    if a == [0.0; 3] || b == [0.0; 3] {
        return math::IDENTITY;
    }
    let c = math::dot(a, b);
    if c < -1.0 + 1e-12 {
        let k = any_perpendicular(a);
        // 2 k k^T - I: a half turn about k.
        return std::array::from_fn(|i| {
            std::array::from_fn(|j| 2.0 * k[i] * k[j] - f64::from(u8::from(i == j)))
        });
    }
    let v = math::cross(a, b);
    let k = 1.0 / (1.0 + c);
    // Rodrigues' formula for the unit axis v/|v| and angle acos(c): I + [v]x + [v]x^2 / (1 + c).
    let vx: Mat3 = [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]];
    let vx2 = math::mat_mul(&vx, &vx);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| f64::from(u8::from(i == j)) + vx[i][j] + vx2[i][j] * k)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distance(a: Vec3, b: Vec3) -> f64 {
        math::norm(math::sub(a, b))
    }

    #[test]
    fn two_bone_matches_a_brute_force_search_in_the_bend_plane() {
        let root = [0.0, 1.0, 0.0];
        let mid = [0.0, 0.5, 0.1];
        let end = [0.0, 0.0, 0.0];
        let target = [0.3, 0.2, 0.25];
        let [new_mid, new_end] = two_bone(root, mid, end, target);
        let (a, b) = (distance(mid, root), distance(end, mid));
        assert!((distance(new_mid, root) - a).abs() < 1e-12);
        assert!((distance(new_end, new_mid) - b).abs() < 1e-12);
        assert!(distance(new_end, target) < 1e-12);
        // Brute force: knees on the circle of radius a in the plane of root, target and the old
        // knee, on the old knee's side; the best is the one whose shin reaches the target.
        let u = math::normalize_or(math::sub(target, root), [0.0; 3]);
        let knee = math::sub(mid, root);
        let v = math::normalize_or(
            math::sub(knee, math::scale(u, math::dot(knee, u))),
            [0.0; 3],
        );
        let best = (0..200_000)
            .map(|i| std::f64::consts::PI * i as f64 / 200_000.0)
            .map(|t| {
                math::add(
                    root,
                    math::add(math::scale(u, a * t.cos()), math::scale(v, a * t.sin())),
                )
            })
            .min_by(|p, q| {
                let e = |m: Vec3| (distance(m, target) - b).abs();
                e(*p).total_cmp(&e(*q))
            })
            .unwrap();
        assert!(distance(best, new_mid) < 1e-4 * a, "{best:?} {new_mid:?}");
    }

    #[test]
    fn an_unreachable_target_gets_the_closest_reach_without_nan() {
        let (root, mid, end) = ([0.0, 1.0, 0.0], [0.0, 0.5, 0.05], [0.0, 0.0, 0.0]);
        let far = [0.0, -5.0, 0.0];
        let [m, e] = two_bone(root, mid, end, far);
        assert!(m.iter().chain(&e).all(|v| v.is_finite()));
        assert!((distance(e, root) - distance(mid, root) - distance(end, mid)).abs() < 1e-9);
        // On the root itself: any direction, but finite and lengths kept.
        let [m, e] = two_bone(root, mid, end, root);
        assert!(m.iter().chain(&e).all(|v| v.is_finite()));
        assert!((distance(m, root) - distance(mid, root)).abs() < 1e-9);
        let p = fabrik(&[root, mid, end, [0.0, -0.3, 0.1]], far, 20, 1e-6);
        assert!(p.iter().flatten().all(|v| v.is_finite()));
        assert!(distance(p[3], far) > 1.0);
    }

    #[test]
    fn overflowing_lengths_do_not_panic() {
        // Bones of a broken rig whose lengths overflowed: any answer, but no panic.
        let lengths = [f64::INFINITY, f64::INFINITY];
        let _ = two_bone_bent(
            [0.0; 3],
            lengths,
            [1e308, 0.0, -1e308],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        );
        let _ = two_bone(
            [0.0; 3],
            [1e308, 0.0, 0.0],
            [-1e308, 0.0, 0.0],
            [0.0, 1e308, 0.0],
        );
    }

    #[test]
    fn fabrik_brings_a_four_bone_leg_to_its_target_keeping_lengths() {
        // A quadruped's hind leg: hip, knee, hock, paw, toe.
        let leg = [
            [0.0, 1.0, 0.0],
            [0.1, 0.7, 0.05],
            [-0.05, 0.4, 0.0],
            [0.0, 0.1, 0.02],
            [0.05, 0.0, 0.0],
        ];
        let target = [0.25, 0.05, 0.1];
        let solved = fabrik(&leg, target, 30, 1e-6);
        assert_eq!(solved[0], leg[0]);
        assert!(distance(solved[4], target) < 1e-4, "{:?}", solved[4]);
        for (x, y) in bone_lengths(&leg).iter().zip(bone_lengths(&solved)) {
            assert!((x - y).abs() < 1e-9, "{x} {y}");
        }
    }

    /// A dog's hind leg as rotations: hip, knee, hock, paw, each bent a little about its own
    /// axes, and a toe tip below the paw.
    fn hind_leg() -> TurnChain {
        let turn = |x: f64, y: f64, z: f64| {
            math::mat_mul(
                &math::axis_rotation(0, x),
                &math::mat_mul(&math::axis_rotation(1, y), &math::axis_rotation(2, z)),
            )
        };
        TurnChain {
            top: [0.1, 1.0, -0.2],
            above: turn(0.1, 0.3, -0.05),
            locals: vec![
                turn(0.4, 0.05, 0.1),
                turn(-0.9, 0.0, 0.05),
                turn(0.7, -0.1, 0.0),
                turn(-0.2, 0.0, 0.1),
            ],
            offsets: vec![[0.0, -0.3, 0.05], [0.0, -0.3, -0.05], [0.0, -0.25, 0.02]],
            tip: [0.03, -0.1, 0.08],
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
        let mmt = math::mat_mul(m, &math::transpose(m));
        math::mat_max_abs_diff(&mmt, &math::IDENTITY) < 1e-12
            && (math::dot(m[0], math::cross(m[1], m[2])) - 1.0).abs() < 1e-12
    }

    #[test]
    fn least_turn_brings_a_four_bone_leg_to_its_target_keeping_lengths() {
        let leg = hind_leg();
        let (_, _, tip) = leg.forward(&leg.locals);
        let target = math::add(tip, [0.08, 0.05, -0.06]);
        let reach = leg.reach();
        let locals = least_turn(&leg, target, 80, 1e-9, 0.05 * reach);
        let (positions, _, reached) = leg.forward(&locals);
        assert!(distance(reached, target) < 1e-6, "{reached:?}");
        assert!(locals.iter().all(is_rotation));
        // Only rotations changed: every bone and the tip's lever keep their lengths.
        for (w, offset) in positions.windows(2).zip(&leg.offsets) {
            assert!((distance(w[0], w[1]) - math::norm(*offset)).abs() < 1e-12);
        }
        assert!((distance(reached, positions[3]) - math::norm(leg.tip)).abs() < 1e-12);
        assert_eq!(positions[0], leg.top);
    }

    /// The position solvers' answer as rotations, the way planting applies it: each bone turned
    /// from its old direction to its new one, the last joint keeping its global rotation.
    fn positions_answer(leg: &TurnChain, target: Vec3) -> Vec<Mat3> {
        let (old, globals, tip) = leg.forward(&leg.locals);
        let n = old.len();
        let lever = math::sub(tip, old[n - 1]);
        let new = fabrik(&old, math::sub(target, lever), 200, 1e-12);
        let mut turned: Vec<Mat3> = (0..n - 1)
            .map(|i| {
                let turn =
                    rotation_between(math::sub(old[i + 1], old[i]), math::sub(new[i + 1], new[i]));
                math::mat_mul(&turn, &globals[i])
            })
            .collect();
        turned.push(globals[n - 1]);
        (0..n)
            .map(|i| {
                let above = if i == 0 { leg.above } else { turned[i - 1] };
                math::mat_mul(&math::transpose(&above), &turned[i])
            })
            .collect()
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
            let target = math::add(tip, offset);
            let least = least_turn(&leg, target, 200, 1e-12, 1e-3 * reach);
            let cost = six_d_change(&leg.locals, &least);
            // The position solvers reach the same target with more change.
            let by_positions = positions_answer(&leg, target);
            let (_, _, reached) = leg.forward(&by_positions);
            assert!(distance(reached, target) < 1e-6);
            assert!(
                cost < six_d_change(&leg.locals, &by_positions),
                "{offset:?}"
            );
            // Other exact answers near it: start from the least turn's, turned a little at
            // random, and reach the target again from there. None changes the leg less, but
            // for what a sequence of first-order steps leaves (well under 1 %).
            for _ in 0..40 {
                let start: Vec<Mat3> = least
                    .iter()
                    .map(|l| {
                        let axis =
                            math::normalize_or([uniform(), uniform(), uniform()], [1.0, 0.0, 0.0]);
                        math::mat_mul(l, &rotation_about(axis, 0.05 * uniform()))
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
        let far = math::add(leg.top, [0.3, -2.0 * reach, 0.1]);
        let locals = least_turn(&leg, far, 80, 1e-9, 0.05 * reach);
        assert!(locals.iter().flatten().flatten().all(|v| v.is_finite()));
        assert!(locals.iter().all(is_rotation));
        let (_, _, tip) = leg.forward(&locals);
        // Nearly straight towards it: within a few per cent of the closest reach.
        let closest = distance(far, leg.top) - reach;
        assert!(distance(tip, far) < closest + 0.03 * reach, "{tip:?}");
        // A target on the top itself, or NaN, changes nothing into NaN.
        for target in [leg.top, [f64::NAN, 0.0, 0.0]] {
            let locals = least_turn(&leg, target, 80, 1e-9, 0.05 * reach);
            assert!(locals.iter().flatten().flatten().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn rotation_between_turns_one_direction_into_the_other() {
        for (a, b) in [
            ([1.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
            ([0.3, -0.4, 0.5], [-0.2, 0.1, 0.9]),
            ([0.0, 0.0, 1.0], [0.0, 0.0, -3.0]),
            ([1.0, 1.0, 0.0], [1.0, 1.0, 0.0]),
        ] {
            let r = rotation_between(a, b);
            let turned = math::mat_vec(&r, math::normalize_or(a, [0.0; 3]));
            assert!(
                distance(turned, math::normalize_or(b, [0.0; 3])) < 1e-12,
                "{a:?} {b:?}"
            );
            let rrt = math::mat_mul(&r, &math::transpose(&r));
            assert!(math::mat_max_abs_diff(&rrt, &math::IDENTITY) < 1e-12);
            assert!((math::dot(r[0], math::cross(r[1], r[2])) - 1.0).abs() < 1e-12);
        }
    }
}
