//! The ground level of a motion: where its contact points rest.

use crate::motion::fk::GlobalPose;
use crate::motion::up::height_of;

/// The ground is this percentile of the per-frame lowest contact point (SPEC section 9): low
/// enough to be the floor, robust to a few frames of a foot through it.
pub const GROUND_PERCENTILE: f64 = 5.0;

/// The height of a canonical-frame pose's lowest point (every joint and End Site).
pub fn lowest_point(pose: &GlobalPose) -> f64 {
    pose.points().map(height_of).fold(f64::INFINITY, f64::min)
}

/// The ground level of canonical-frame `poses`: the [`GROUND_PERCENTILE`]th percentile of each
/// frame's lowest contact point of `contact_joints`, or of its lowest point of all when there
/// are no contact joints. 0 for no frames.
pub fn ground_level(contact_joints: &[usize], poses: &[GlobalPose]) -> f64 {
    let mut lowest: Vec<f64> = poses
        .iter()
        .map(|pose| {
            if contact_joints.is_empty() {
                lowest_point(pose)
            } else {
                contact_joints
                    .iter()
                    .map(|&j| height_of(pose.contact_point(j)))
                    .fold(f64::INFINITY, f64::min)
            }
        })
        .collect();
    lowest.sort_by(f64::total_cmp);
    percentile(&lowest, GROUND_PERCENTILE)
}

/// The `p`-th percentile of sorted values, linearly interpolated (numpy's default); 0 for none.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = p / 100.0 * (sorted.len() - 1) as f64;
    let (lo, hi) = (rank.floor() as usize, rank.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (rank - lo as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_matches_numpy_linear() {
        // numpy.percentile([1, 2, 3, 4, 10], 5) = 1.2
        assert!((percentile(&[1.0, 2.0, 3.0, 4.0, 10.0], 5.0) - 1.2).abs() < 1e-12);
        assert_eq!(percentile(&[7.0], 5.0), 7.0);
        assert_eq!(percentile(&[], 5.0), 0.0);
    }
}
