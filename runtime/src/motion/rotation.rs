//! Rotation conversions: per-joint Euler orders <-> matrix <-> 6D.
//!
//! A BVH joint whose channels list rotations in the order `A B C` has the local rotation
//! `R = R_A(a) * R_B(b) * R_C(c)` (intrinsic: the first listed axis is outermost). Every joint keeps
//! its own order; joints with fewer than three rotation channels rotate about only those axes.

use super::math::{self, Mat3, Vec3};
use super::skeleton::Axis;

/// The rotation matrix of Euler angles (radians) applied in `order`, outermost first.
pub fn euler_to_mat(order: &[Axis], radians: &[f64]) -> Mat3 {
    order
        .iter()
        .zip(radians)
        .fold(math::IDENTITY, |acc, (axis, &angle)| {
            acc * math::axis_rotation(axis.index(), angle)
        })
}

/// Euler angles (radians) in `order` that reproduce `m`.
///
/// `order` holds one to three distinct axes. With three axes the result is exact (in gimbal lock
/// the last angle is set to zero). With fewer axes the missing ones are appended to complete a
/// Tait-Bryan order and their angles dropped, which is exact whenever `m` is a rotation about the
/// listed axes only.
pub fn mat_to_euler(order: &[Axis], m: &Mat3) -> Vec<f64> {
    let mut full: Vec<usize> = order.iter().map(|a| a.index()).collect();
    for axis in 0..3 {
        if !full.contains(&axis) {
            full.push(axis);
        }
    }
    let angles = tait_bryan_angles([full[0], full[1], full[2]], m);
    angles[..order.len()].to_vec()
}

/// Decomposes `m = R_i(a) R_j(b) R_k(c)` for distinct axes (i, j, k).
fn tait_bryan_angles([i, j, k]: [usize; 3], m: &Mat3) -> [f64; 3] {
    // An even permutation of (X, Y, Z) has sign +1, an odd one -1.
    let sign = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let sin_b = (sign * m[i][k]).clamp(-1.0, 1.0);
    let b = sin_b.asin();
    let cos_b = (m[i][i] * m[i][i] + m[i][j] * m[i][j]).sqrt();
    if cos_b > 1e-9 {
        let a = (-sign * m[j][k]).atan2(m[k][k]);
        let c = (-sign * m[i][j]).atan2(m[i][i]);
        [a, b, c]
    } else {
        // Gimbal lock: only a +/- c is determined; put it all in a.
        let a = (sign * m[k][j]).atan2(m[j][j]);
        [a, b, 0.0]
    }
}

/// The 6D representation: the first two rows of the matrix, `[R00 R01 R02 R10 R11 R12]`.
pub fn mat_to_6d(m: &Mat3) -> [f64; 6] {
    [m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2]]
}

/// The rotation nearest to a (possibly perturbed) 6D value, by Gram-Schmidt:
/// `a = normalize(r0)`, `c = normalize(a x r1)`, `b = c x a`, rows `a, b, c`.
pub fn mat_from_6d(v: &[f64]) -> Mat3 {
    let r0 = Vec3::new(v[0], v[1], v[2]);
    let r1 = Vec3::new(v[3], v[4], v[5]);
    let a = r0.normalize_or(Vec3::new(1.0, 0.0, 0.0));
    // A degenerate second row (parallel to the first, or zero) falls back to any perpendicular.
    let fallback = if a[0].abs() < 0.9 {
        a.cross(Vec3::new(1.0, 0.0, 0.0))
            .normalize_or(Vec3::new(0.0, 0.0, 1.0))
    } else {
        a.cross(Vec3::new(0.0, 1.0, 0.0))
            .normalize_or(Vec3::new(0.0, 0.0, 1.0))
    };
    let c = a.cross(r1).normalize_or(fallback);
    let b = c.cross(a);
    Mat3([a.0, b.0, c.0])
}

/// Shifts each angle (degrees) by a multiple of 360 so it lies nearest to `previous`, keeping
/// animation curves continuous instead of jumping at +/-180.
pub fn unwrap_degrees(angles: &mut [f64], previous: &[f64]) {
    for (angle, prev) in angles.iter_mut().zip(previous) {
        *angle -= 360.0 * ((*angle - prev) / 360.0).round();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::math::{Vec3, axis_rotation, mat_max_abs_diff};
    use std::f64::consts::FRAC_PI_2;

    const ORDERS: [[Axis; 3]; 6] = [
        [Axis::X, Axis::Y, Axis::Z],
        [Axis::X, Axis::Z, Axis::Y],
        [Axis::Y, Axis::X, Axis::Z],
        [Axis::Y, Axis::Z, Axis::X],
        [Axis::Z, Axis::X, Axis::Y],
        [Axis::Z, Axis::Y, Axis::X],
    ];

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).norm() < 1e-12
    }

    #[test]
    fn single_axis_euler_matches_analytic_rotation_in_every_order() {
        // A 90 degree turn on one channel, zero on the others, equals that axis rotation whatever
        // the order; +90 about X maps +Y to +Z, about Y maps +Z to +X, about Z maps +X to +Y.
        let expected = [
            ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ];
        for order in ORDERS {
            for slot in 0..3 {
                let mut angles = [0.0; 3];
                angles[slot] = FRAC_PI_2;
                let m = euler_to_mat(&order, &angles);
                let (from, to) = expected[order[slot].index()];
                assert!(close(m * Vec3(from), Vec3(to)), "{order:?} slot {slot}");
            }
        }
    }

    #[test]
    fn two_axis_euler_applies_the_first_listed_axis_last() {
        // For order Z X (R = Rz(90) Rx(90)): a point on +Y goes first to +Z (by Rx), then Rz keeps
        // it at +Z. For X Z (R = Rx(90) Rz(90)): +Y goes to -X (by Rz), then Rx keeps it at -X.
        let zx = euler_to_mat(&[Axis::Z, Axis::X], &[FRAC_PI_2, FRAC_PI_2]);
        assert!(close(zx * Vec3::new(0.0, 1.0, 0.0), Vec3([0.0, 0.0, 1.0])));
        let xz = euler_to_mat(&[Axis::X, Axis::Z], &[FRAC_PI_2, FRAC_PI_2]);
        assert!(close(xz * Vec3::new(0.0, 1.0, 0.0), Vec3([-1.0, 0.0, 0.0])));
    }

    #[test]
    fn euler_round_trip_in_all_six_orders_recovers_the_angles() {
        let angles = [0.7, -0.4, 1.9];
        for order in ORDERS {
            let m = euler_to_mat(&order, &angles);
            let back = mat_to_euler(&order, &m);
            for (a, b) in angles.iter().zip(&back) {
                assert!((a - b).abs() < 1e-12, "{order:?}: {angles:?} vs {back:?}");
            }
            // The decomposition agrees with an independent product of axis rotations.
            let naive = (axis_rotation(order[0].index(), angles[0])
                * axis_rotation(order[1].index(), angles[1]))
                * axis_rotation(order[2].index(), angles[2]);
            assert!(mat_max_abs_diff(&m, &naive) < 1e-15);
        }
    }

    #[test]
    fn euler_decomposition_survives_gimbal_lock() {
        for order in ORDERS {
            for middle in [FRAC_PI_2, -FRAC_PI_2] {
                let m = euler_to_mat(&order, &[0.3, middle, -0.5]);
                let back = euler_to_mat(&order, &mat_to_euler(&order, &m));
                assert!(mat_max_abs_diff(&m, &back) < 1e-7, "{order:?} {middle}");
            }
        }
    }

    #[test]
    fn fewer_than_three_channels_decompose_exactly() {
        let m = euler_to_mat(&[Axis::Y, Axis::X], &[0.4, -1.1]);
        let back = mat_to_euler(&[Axis::Y, Axis::X], &m);
        assert_eq!(back.len(), 2);
        assert!((back[0] - 0.4).abs() < 1e-12 && (back[1] + 1.1).abs() < 1e-12);
        let single = mat_to_euler(&[Axis::Z], &axis_rotation(2, 2.5));
        assert!((single[0] - 2.5).abs() < 1e-12);
    }

    #[test]
    fn six_d_of_a_rotation_decodes_to_the_same_rotation() {
        let m = euler_to_mat(&ORDERS[4], &[0.3, 1.2, -2.0]);
        let back = mat_from_6d(&mat_to_6d(&m));
        assert!(mat_max_abs_diff(&m, &back) < 1e-14);
    }

    #[test]
    fn gram_schmidt_on_perturbed_6d_matches_hand_orthonormalisation() {
        // r0 = (2, 0, 0) -> a = (1, 0, 0); r1 = (0.5, 3, 0) -> c = a x r1 / |.| = (0, 0, 1);
        // b = c x a = (0, 1, 0): the identity, whatever the scale and skew of the input rows.
        let m = mat_from_6d(&[2.0, 0.0, 0.0, 0.5, 3.0, 0.0]);
        assert!(mat_max_abs_diff(&m, &math::IDENTITY) < 1e-15);
        // Perturb a real rotation: the result is orthonormal with determinant +1 and close to it.
        let r = euler_to_mat(&ORDERS[0], &[0.2, -0.7, 1.3]);
        let mut v = mat_to_6d(&r);
        let noise = [0.01, -0.02, 0.015, -0.01, 0.02, 0.005];
        for (x, n) in v.iter_mut().zip(noise) {
            *x += n;
        }
        let m = mat_from_6d(&v);
        let mtm = m.transpose() * m;
        assert!(mat_max_abs_diff(&mtm, &math::IDENTITY) < 1e-12);
        let det = m.determinant();
        assert!((det - 1.0).abs() < 1e-12);
        assert!(mat_max_abs_diff(&m, &r) < 0.05);
        // The first row keeps the direction of the perturbed r0.
        let r0 = Vec3::new(v[0], v[1], v[2]).normalize_or(Vec3::new(1.0, 0.0, 0.0));
        assert!(close(Vec3(m[0]), r0));
    }

    #[test]
    fn degenerate_6d_still_gives_a_rotation() {
        for v in [[0.0; 6], [1.0, 0.0, 0.0, 2.0, 0.0, 0.0]] {
            let m = mat_from_6d(&v);
            let mtm = m.transpose() * m;
            assert!(mat_max_abs_diff(&mtm, &math::IDENTITY) < 1e-12);
        }
    }

    #[test]
    fn unwrapping_keeps_angles_near_the_previous_frame() {
        let mut angles = [-179.0, 10.0, 350.0];
        unwrap_degrees(&mut angles, &[179.0, 10.0, -5.0]);
        assert_eq!(angles, [181.0, 10.0, -10.0]);
    }
}
