//! Small fixed-size linear algebra in `f64`: 3-vectors, row-major 3x3 matrices and unit quaternions.
//!
//! Conventions used everywhere in the crate: column vectors, so a point `p` in a child's frame is
//! `R * p` in its parent's frame; matrices are row-major (`m[row][col]`); quaternions are
//! `[x, y, z, w]` (scalar last), the order of the engine's `Quaternion` and of glTF.

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A row-major 3x3 matrix (`m[row][col]`).
pub type Mat3 = [[f64; 3]; 3];
/// A unit quaternion `[x, y, z, w]` (scalar last): one order from the sampler to the engine's
/// [`super::pose::Quaternion`] and glTF files.
pub type Quat = [f64; 4];

/// The identity matrix.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `a + b`.
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s * a`.
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product `a x b`.
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`, or `fallback` when `a` is (nearly) zero.
pub fn normalize_or(a: Vec3, fallback: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 1e-12 {
        scale(a, 1.0 / n)
    } else {
        fallback
    }
}

/// Matrix product `a * b`.
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, value) in row.iter_mut().enumerate() {
            *value = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
        }
    }
    out
}

/// Matrix-vector product `m * v`.
pub fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// Transpose (the inverse of a rotation).
pub fn transpose(m: &Mat3) -> Mat3 {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// Rotation by `radians` about coordinate axis `axis` (0 = X, 1 = Y, 2 = Z), right-handed.
pub fn axis_rotation(axis: usize, radians: f64) -> Mat3 {
    let (s, c) = radians.sin_cos();
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// The unit quaternion of a rotation matrix (Shepperd's method: the largest diagonal term picks
/// the numerically stable branch). The result has `w >= 0`.
pub fn quat_from_mat(m: &Mat3) -> Quat {
    let trace = m[0][0] + m[1][1] + m[2][2];
    // Worked out scalar first, as Shepperd writes it.
    let [w, x, y, z] = if trace > 0.0 {
        let s = (trace + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
        [
            (m[2][1] - m[1][2]) / s,
            0.25 * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] > m[2][2] {
        let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            0.25 * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            0.25 * s,
        ]
    };
    let q = quat_normalize([x, y, z, w]);
    if q[3] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        q
    }
}

/// The rotation matrix of a (not necessarily unit) quaternion.
pub fn mat_from_quat(q: Quat) -> Mat3 {
    let [x, y, z, w] = quat_normalize(q);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// `q / |q|` (identity for a zero quaternion).
pub fn quat_normalize(q: Quat) -> Quat {
    // Summed scalar first, so lengths round as they always have.
    let n = (q[3] * q[3] + q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
    if n > 1e-12 {
        [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
    } else {
        [0.0, 0.0, 0.0, 1.0]
    }
}

/// Spherical linear interpolation from `a` (at `t = 0`) to `b` (at `t = 1`) along the shorter arc.
pub fn slerp(a: Quat, b: Quat, t: f64) -> Quat {
    let mut cos = a[3] * b[3] + a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let b = if cos < 0.0 {
        cos = -cos;
        [-b[0], -b[1], -b[2], -b[3]]
    } else {
        b
    };
    let (wa, wb) = if cos > 0.9995 {
        (1.0 - t, t)
    } else {
        let angle = cos.acos();
        let sin = angle.sin();
        (((1.0 - t) * angle).sin() / sin, (t * angle).sin() / sin)
    };
    quat_normalize([
        wa * a[0] + wb * b[0],
        wa * a[1] + wb * b[1],
        wa * a[2] + wb * b[2],
        wa * a[3] + wb * b[3],
    ])
}

/// Largest absolute element-wise difference of two matrices.
pub fn mat_max_abs_diff(a: &Mat3, b: &Mat3) -> f64 {
    let mut worst: f64 = 0.0;
    for r in 0..3 {
        for c in 0..3 {
            worst = worst.max((a[r][c] - b[r][c]).abs());
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn axis_rotations_turn_basis_vectors_right_handed() {
        // +90 degrees about X takes +Y to +Z; about Y takes +Z to +X; about Z takes +X to +Y.
        let close = |a: Vec3, b: Vec3| norm(sub(a, b)) < 1e-12;
        assert!(close(
            mat_vec(&axis_rotation(0, FRAC_PI_2), [0.0, 1.0, 0.0]),
            [0.0, 0.0, 1.0]
        ));
        assert!(close(
            mat_vec(&axis_rotation(1, FRAC_PI_2), [0.0, 0.0, 1.0]),
            [1.0, 0.0, 0.0]
        ));
        assert!(close(
            mat_vec(&axis_rotation(2, FRAC_PI_2), [1.0, 0.0, 0.0]),
            [0.0, 1.0, 0.0]
        ));
    }

    #[test]
    fn quaternion_of_axis_rotation_is_half_angle() {
        // Rotation by theta about Z is (0, 0, sin(theta/2), cos(theta/2)).
        let theta = 1.234_f64;
        let q = quat_from_mat(&axis_rotation(2, theta));
        let expected = [0.0, 0.0, (theta / 2.0).sin(), (theta / 2.0).cos()];
        for i in 0..4 {
            assert!((q[i] - expected[i]).abs() < 1e-12, "{q:?} vs {expected:?}");
        }
    }

    #[test]
    fn quaternion_matrix_round_trip_covers_every_branch() {
        // Rotations by ~180 degrees exercise each of Shepperd's diagonal branches.
        for axis in 0..3 {
            for angle in [0.3, 3.1, -3.1, std::f64::consts::PI - 1e-6] {
                let m = mat_mul(
                    &axis_rotation(axis, angle),
                    &axis_rotation((axis + 1) % 3, 0.2),
                );
                let back = mat_from_quat(quat_from_mat(&m));
                assert!(mat_max_abs_diff(&m, &back) < 1e-12);
            }
        }
    }

    #[test]
    fn slerp_halfway_is_half_the_angle() {
        let a = quat_from_mat(&IDENTITY);
        let b = quat_from_mat(&axis_rotation(1, 1.0));
        let mid = mat_from_quat(slerp(a, b, 0.5));
        assert!(mat_max_abs_diff(&mid, &axis_rotation(1, 0.5)) < 1e-12);
    }
}
