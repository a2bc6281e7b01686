//! Rest alignment: the rotation that turns a target bone's rest directions onto its source
//! bone's, so the two point the same way before any motion is carried over.

use sinmdm::motion::math::{self, Mat3, Vec3};

/// Directions shorter than this have no direction to align.
const SHORTEST: f64 = 1e-9;

/// The smallest rotation taking the direction of `from` onto that of `to` (identity when either
/// is too short to have a direction). Twist about the bone is left as it was: the two rigs'
/// rolls differ by their authors' choice, not by the motion.
pub fn shortest_rotation(from: Vec3, to: Vec3) -> Mat3 {
    let (a, b) = (from.norm(), to.norm());
    if a < SHORTEST || b < SHORTEST {
        return math::IDENTITY;
    }
    let (u, v) = (from * (1.0 / a), to * (1.0 / b));
    let cos = u.dot(v).clamp(-1.0, 1.0);
    let axis = u.cross(v);
    let sin = axis.norm();
    if sin < 1e-12 {
        if cos > 0.0 {
            return math::IDENTITY;
        }
        // Opposite: half a turn about any axis across the bone.
        let across = if u[0].abs() < 0.9 {
            Vec3::new(1.0, 0.0, 0.0)
        } else {
            Vec3::new(0.0, 1.0, 0.0)
        };
        let k = u.cross(across).normalize_or(Vec3::new(0.0, 0.0, 1.0));
        return rotation_about(k, -1.0, 0.0);
    }
    rotation_about(axis * (1.0 / sin), cos, sin)
}

/// Rodrigues' rotation about unit axis `k` by the angle whose cosine and sine are given.
fn rotation_about(k: Vec3, cos: f64, sin: f64) -> Mat3 {
    let one = 1.0 - cos;
    Mat3::from_fn(|r, c| {
        let delta = if r == c { cos } else { 0.0 };
        let cross = match (r, c) {
            (0, 1) => -k[2],
            (0, 2) => k[1],
            (1, 0) => k[2],
            (1, 2) => -k[0],
            (2, 0) => -k[1],
            (2, 1) => k[0],
            _ => 0.0,
        };
        delta + sin * cross + one * k[r] * k[c]
    })
}

/// The rotation `R` that best turns each `from` direction onto its `to` direction (most of
/// `sum to_i . R from_i` over unit directions), by Horn's closed form: the quaternion is the
/// eigenvector of the largest eigenvalue of a 4x4 symmetric matrix. One pair is the shortest
/// rotation; several pairs fix the twist too (a hip with a spine and two legs).
pub fn fitted_rotation(pairs: &[(Vec3, Vec3)]) -> Mat3 {
    let units: Vec<(Vec3, Vec3)> = pairs
        .iter()
        .filter(|(a, b)| a.norm() >= SHORTEST && b.norm() >= SHORTEST)
        .map(|(a, b)| (*a * (1.0 / a.norm()), *b * (1.0 / b.norm())))
        .collect();
    match units.as_slice() {
        [] => return math::IDENTITY,
        [(a, b)] => return shortest_rotation(*a, *b),
        _ => {}
    }
    // S[i][k] = sum a_i b_k.
    let s = Mat3::from_fn(|i, k| units.iter().map(|(a, b)| a[i] * b[k]).sum());
    let n = [
        [
            s[0][0] + s[1][1] + s[2][2],
            s[1][2] - s[2][1],
            s[2][0] - s[0][2],
            s[0][1] - s[1][0],
        ],
        [
            s[1][2] - s[2][1],
            s[0][0] - s[1][1] - s[2][2],
            s[0][1] + s[1][0],
            s[2][0] + s[0][2],
        ],
        [
            s[2][0] - s[0][2],
            s[0][1] + s[1][0],
            -s[0][0] + s[1][1] - s[2][2],
            s[1][2] + s[2][1],
        ],
        [
            s[0][1] - s[1][0],
            s[2][0] + s[0][2],
            s[1][2] + s[2][1],
            -s[0][0] - s[1][1] + s[2][2],
        ],
    ];
    let [w, x, y, z] = largest_eigenvector(n);
    math::mat_from_quat([x, y, z, w])
}

/// The unit eigenvector of the largest eigenvalue of a symmetric 4x4 matrix (cyclic Jacobi).
fn largest_eigenvector(mut a: [[f64; 4]; 4]) -> [f64; 4] {
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..64 {
        let off: f64 = (0..4)
            .flat_map(|p| ((p + 1)..4).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..4 {
            for q in (p + 1)..4 {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in &mut a {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (row_p, row_q) = (a[p], a[q]);
                for k in 0..4 {
                    a[p][k] = c * row_p[k] - s * row_q[k];
                    a[q][k] = s * row_p[k] + c * row_q[k];
                }
                for row in &mut v {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    let best = (0..4)
        .max_by(|&i, &j| a[i][i].total_cmp(&a[j][j]))
        .unwrap_or(0);
    [v[0][best], v[1][best], v[2][best], v[3][best]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use sinmdm::motion::math::axis_rotation;

    fn angle(a: Vec3, b: Vec3) -> f64 {
        (a.dot(b) / (a.norm() * b.norm())).clamp(-1.0, 1.0).acos()
    }

    #[test]
    fn the_shortest_rotation_turns_one_direction_onto_another_about_their_normal() {
        let from = Vec3::new(0.2, 1.0, -0.3);
        for to in [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-0.2, -1.0, 0.3),
            Vec3::new(0.4, 2.0, -0.6),
            Vec3::new(0.0, -0.5, 2.0),
        ] {
            let r = shortest_rotation(from, to);
            assert!(angle(r * from, to) < 1e-9, "{to:?}");
            assert!((r.determinant() - 1.0).abs() < 1e-12);
            // The normal of the two stays where it was (no twist added).
            let normal = from.cross(to);
            if normal.norm() > 1e-9 {
                assert!((r * normal - normal).norm() < 1e-9);
            }
        }
    }

    #[test]
    fn a_fit_of_several_directions_finds_the_rotation_that_made_them() {
        let turn = axis_rotation(1, 0.7) * axis_rotation(0, -1.9) * axis_rotation(2, 0.4);
        let from = [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.1, -0.2, 0.9),
            Vec3::new(-0.1, -0.2, 0.9),
        ];
        // Lengths differ (other proportions): directions alone count.
        let pairs: Vec<(Vec3, Vec3)> = from
            .iter()
            .zip([1.3, 0.7, 2.0])
            .map(|(&f, k)| (f, (turn * f) * k))
            .collect();
        let found = fitted_rotation(&pairs);
        assert!(math::mat_max_abs_diff(&found, &turn) < 1e-9, "{found:?}");
    }
}
