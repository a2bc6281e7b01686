//! Inverse kinematics on global joint positions, for planting feet: an analytic two-bone
//! solver that keeps the chain's bend plane, and FABRIK for longer chains (a dog's or a fox's
//! legs have three or four bones). Both keep every bone's length; the positions they return are
//! turned into rotations with [`rotation_between`], so a pose changes by rotations only.

use super::math::{self, Mat3, Vec3};

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
