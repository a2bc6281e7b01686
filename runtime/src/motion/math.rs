//! Small fixed-size linear algebra in `f64`: 3-vectors, row-major 3x3 matrices and unit quaternions.
//!
//! Conventions used everywhere in the crate: column vectors, so a point `p` in a child's frame is
//! `R * p` in its parent's frame; matrices are row-major (`m[row][col]`); quaternions are
//! `[x, y, z, w]` (scalar last), the order of the engine's `Quaternion` and of glTF.

use std::ops::{Add, AddAssign, Index, IndexMut, Mul, Neg, Sub, SubAssign};

use serde::{Deserialize, Serialize};

/// A 3-vector, with the arithmetic of one: `a + b`, `a - b`, `-a`, `a * s`, [`Vec3::dot`],
/// [`Vec3::cross`], [`Vec3::norm`]. `v[i]` is component `i`; it is stored (and serialized) as
/// `[x, y, z]`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(transparent)]
#[repr(transparent)]
pub struct Vec3(pub [f64; 3]);

impl Vec3 {
    /// The zero vector.
    pub const ZERO: Vec3 = Vec3([0.0; 3]);

    /// The vector `(x, y, z)`.
    pub const fn new(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3([x, y, z])
    }

    /// The vector whose component `i` is `f(i)`.
    pub fn from_fn(f: impl FnMut(usize) -> f64) -> Vec3 {
        Vec3(std::array::from_fn(f))
    }

    /// The unit vector along coordinate axis `axis` (0 = X, 1 = Y, 2 = Z), times `length`.
    pub fn along(axis: usize, length: f64) -> Vec3 {
        Vec3::from_fn(|i| if i == axis { length } else { 0.0 })
    }

    /// The components as an array.
    pub const fn to_array(self) -> [f64; 3] {
        self.0
    }

    /// Dot product.
    pub fn dot(self, other: Vec3) -> f64 {
        self.0[0] * other.0[0] + self.0[1] * other.0[1] + self.0[2] * other.0[2]
    }

    /// Cross product `self x other`.
    pub fn cross(self, other: Vec3) -> Vec3 {
        let (a, b) = (self.0, other.0);
        Vec3([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ])
    }

    /// Euclidean length.
    pub fn norm(self) -> f64 {
        self.dot(self).sqrt()
    }

    /// `self / |self|`, or `fallback` when `self` is (nearly) zero.
    pub fn normalize_or(self, fallback: Vec3) -> Vec3 {
        let n = self.norm();
        if n > 1e-12 {
            self * (1.0 / n)
        } else {
            fallback
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    /// Each component through `f`, as an array (such as `v.map(|c| c as f32)`).
    pub fn map<T>(self, f: impl FnMut(f64) -> T) -> [T; 3] {
        self.0.map(f)
    }

    /// The components, x first.
    pub fn iter(&self) -> std::slice::Iter<'_, f64> {
        self.0.iter()
    }
}

impl IntoIterator for Vec3 {
    type Item = f64;
    type IntoIter = std::array::IntoIter<f64, 3>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.into_iter()
    }
}

impl<'a> IntoIterator for &'a Vec3 {
    type Item = &'a f64;
    type IntoIter = std::slice::Iter<'a, f64>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl From<[f64; 3]> for Vec3 {
    fn from(v: [f64; 3]) -> Vec3 {
        Vec3(v)
    }
}

impl From<Vec3> for [f64; 3] {
    fn from(v: Vec3) -> [f64; 3] {
        v.0
    }
}

impl Index<usize> for Vec3 {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}

impl IndexMut<usize> for Vec3 {
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    fn add(self, b: Vec3) -> Vec3 {
        Vec3([self.0[0] + b.0[0], self.0[1] + b.0[1], self.0[2] + b.0[2]])
    }
}

impl Sub for Vec3 {
    type Output = Vec3;
    fn sub(self, b: Vec3) -> Vec3 {
        Vec3([self.0[0] - b.0[0], self.0[1] - b.0[1], self.0[2] - b.0[2]])
    }
}

impl Neg for Vec3 {
    type Output = Vec3;
    fn neg(self) -> Vec3 {
        Vec3([-self.0[0], -self.0[1], -self.0[2]])
    }
}

impl Mul<f64> for Vec3 {
    type Output = Vec3;
    fn mul(self, s: f64) -> Vec3 {
        Vec3([self.0[0] * s, self.0[1] * s, self.0[2] * s])
    }
}

impl AddAssign for Vec3 {
    fn add_assign(&mut self, b: Vec3) {
        *self = *self + b;
    }
}

impl SubAssign for Vec3 {
    fn sub_assign(&mut self, b: Vec3) {
        *self = *self - b;
    }
}

/// A row-major 3x3 matrix: `m[row][col]`, `m * v` for a column vector, `a * b` for a product.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
#[repr(transparent)]
pub struct Mat3(pub [[f64; 3]; 3]);

/// A unit quaternion `[x, y, z, w]` (scalar last): one order from the sampler to the engine's
/// [`super::pose::Quaternion`] and glTF files.
pub type Quat = [f64; 4];

/// The identity matrix.
pub const IDENTITY: Mat3 = Mat3([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

impl Mat3 {
    /// The matrix whose entry `(row, col)` is `f(row, col)`.
    pub fn from_fn(mut f: impl FnMut(usize, usize) -> f64) -> Mat3 {
        Mat3(std::array::from_fn(|r| std::array::from_fn(|c| f(r, c))))
    }

    /// The matrix with these columns.
    pub fn from_columns(x: Vec3, y: Vec3, z: Vec3) -> Mat3 {
        Mat3([[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]])
    }

    /// Row `r` as a vector.
    pub fn row(&self, r: usize) -> Vec3 {
        Vec3(self.0[r])
    }

    /// Column `c` as a vector.
    pub fn column(&self, c: usize) -> Vec3 {
        Vec3([self.0[0][c], self.0[1][c], self.0[2][c]])
    }

    /// The determinant, `row 0 . (row 1 x row 2)` (1 for a rotation).
    pub fn determinant(&self) -> f64 {
        self.row(0).dot(self.row(1).cross(self.row(2)))
    }

    /// Transpose (the inverse of a rotation).
    pub fn transpose(&self) -> Mat3 {
        Mat3::from_fn(|r, c| self.0[c][r])
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.0.iter().flatten().all(|v| v.is_finite())
    }
}

impl<'a> IntoIterator for &'a Mat3 {
    type Item = &'a [f64; 3];
    type IntoIter = std::slice::Iter<'a, [f64; 3]>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl Index<usize> for Mat3 {
    type Output = [f64; 3];
    fn index(&self, r: usize) -> &[f64; 3] {
        &self.0[r]
    }
}

impl IndexMut<usize> for Mat3 {
    fn index_mut(&mut self, r: usize) -> &mut [f64; 3] {
        &mut self.0[r]
    }
}

impl Mul for Mat3 {
    type Output = Mat3;
    fn mul(self, b: Mat3) -> Mat3 {
        let a = &self.0;
        Mat3::from_fn(|r, c| a[r][0] * b.0[0][c] + a[r][1] * b.0[1][c] + a[r][2] * b.0[2][c])
    }
}

impl Mul<Vec3> for Mat3 {
    type Output = Vec3;
    fn mul(self, v: Vec3) -> Vec3 {
        Vec3([self.row(0).dot(v), self.row(1).dot(v), self.row(2).dot(v)])
    }
}

impl Mul<&Mat3> for Mat3 {
    type Output = Mat3;
    fn mul(self, b: &Mat3) -> Mat3 {
        self * *b
    }
}

impl Mul<Mat3> for &Mat3 {
    type Output = Mat3;
    fn mul(self, b: Mat3) -> Mat3 {
        *self * b
    }
}

impl Mul<&Mat3> for &Mat3 {
    type Output = Mat3;
    fn mul(self, b: &Mat3) -> Mat3 {
        *self * *b
    }
}

impl Mul<Vec3> for &Mat3 {
    type Output = Vec3;
    fn mul(self, v: Vec3) -> Vec3 {
        *self * v
    }
}

/// Rotation by `radians` about coordinate axis `axis` (0 = X, 1 = Y, 2 = Z), right-handed.
pub fn axis_rotation(axis: usize, radians: f64) -> Mat3 {
    let (s, c) = radians.sin_cos();
    match axis {
        0 => Mat3([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]),
        1 => Mat3([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]),
        _ => Mat3([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]),
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
    Mat3([
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
    ])
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
        let close = |a: Vec3, b: Vec3| (a - b).norm() < 1e-12;
        assert!(close(
            axis_rotation(0, FRAC_PI_2) * Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0)
        ));
        assert!(close(
            axis_rotation(1, FRAC_PI_2) * Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0)
        ));
        assert!(close(
            axis_rotation(2, FRAC_PI_2) * Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0)
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
                let m = axis_rotation(axis, angle) * axis_rotation((axis + 1) % 3, 0.2);
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
