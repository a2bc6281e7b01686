//! The heading-relative root: the root's travel and rotation described in the character's own
//! facing frame, as character controllers describe it, so a walk that heads north and the same
//! walk turned east are the same features.
//!
//! The rule (SPEC section 2, "Heading-relative root"):
//! - **facing**: the horizontal axis across a left/right pair of joints (the hips, or the
//!   shoulders when no hip pair is found), turned a quarter turn about up: `forward = (left -
//!   right) x up`, projected on the ground. Its angle about up (0 facing +Z, a quarter turn
//!   facing +X) is unwrapped over the clip and smoothed by a Gaussian of
//!   [`HEADING_SMOOTHING_SECONDS`], so the sway of a stride stays in the body's rotation and
//!   the facing follows the course;
//! - **root columns**, per frame `f` (frame 0 copies frame 1): the ground displacement
//!   `p(f) - p(f-1)` in the facing frame of frame `f` (forward along the facing, leftward
//!   across it), the turn `heading(f) - heading(f-1)` in radians, and the height;
//! - **the root joint's rotation** is taken relative to the facing frame:
//!   `R_rel = yaw(heading)^T R`.
//!
//! Decoding integrates the turn from [`Heading::start`] and the displacement from the root's
//! start position, so encoding and decoding are exact inverses up to the features' `f32`.

use serde::{Deserialize, Serialize};

use crate::motion::fk::GlobalPose;
use crate::motion::math::{Mat3, Vec3, axis_rotation};
use crate::motion::skeleton::Skeleton;
use crate::motion::smooth::gaussian_smooth;
use crate::motion::up::{GROUND_PLANE, UP};

/// The facing's smoothing: a Gaussian of this many seconds (sigma). A stride is about half a
/// second, so the hips' sway about the course is smoothed out and a turn is not.
pub const HEADING_SMOOTHING_SECONDS: f64 = 0.2;

/// Which root description a model's features use, or (as a request) which to choose.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RootLayout {
    /// As SinMDM: ground displacement in world axes, height, and the root's world rotation.
    /// The default of a request that names none (a configuration written before the heading
    /// layout existed).
    #[default]
    World,
    /// Forward and leftward speed in the facing frame, turn rate, height, and the root's
    /// rotation relative to the facing frame.
    Heading,
    /// A request only (configurations, encode options), chosen from the clip: [`Heading`]
    /// for locomotion that has what it needs (a root that travels at least
    /// [`HEADING_MIN_TRAVEL`] and a facing pair), [`World`] otherwise, saying why. Encoded
    /// features are always one of the two.
    ///
    /// [`Heading`]: RootLayout::Heading
    /// [`World`]: RootLayout::World
    Auto,
}

impl std::fmt::Display for RootLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RootLayout::World => "world",
            RootLayout::Heading => "heading",
            RootLayout::Auto => "auto",
        })
    }
}

impl std::str::FromStr for RootLayout {
    type Err = String;
    fn from_str(s: &str) -> Result<RootLayout, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "world" => Ok(RootLayout::World),
            "heading" => Ok(RootLayout::Heading),
            "auto" => Ok(RootLayout::Auto),
            other => Err(format!(
                "unknown root layout '{other}': use 'world', 'heading' or 'auto'"
            )),
        }
    }
}

/// How the left and right joints of the facing pair were told apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SideEvidence {
    /// Their names (`Left`/`Right`, or one letter `L`/`R` where the names differ).
    Names,
    /// The clip's travel: the side that makes the clip walk forward is the left.
    Travel,
    /// Neither names nor travel tell: the order is the skeleton's, and "forward" may be the
    /// character's back.
    Unresolved,
}

/// The facts of a heading-relative root a model file carries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Heading {
    /// The joint on the character's left of the facing pair.
    pub left: usize,
    /// The joint on its right.
    pub right: usize,
    /// How left and right were told apart.
    pub sides: SideEvidence,
    /// The facing's smoothing, a Gaussian sigma in seconds.
    pub smoothing: f64,
    /// The facing at frame 0, radians about up from +Z toward +X (canonical frame): where
    /// decoding starts integrating the turn.
    pub start: f64,
}

/// The rotation about up by `heading` radians (takes +Z to the facing).
pub fn yaw(heading: f64) -> Mat3 {
    axis_rotation(UP, heading)
}

/// The facing of a left-to-right axis: `(left - right) x up` on the ground, as an angle; `None`
/// when the axis is (nearly) vertical.
fn facing_of(across: Vec3) -> Option<f64> {
    let [x, z] = GROUND_PLANE.map(|a| across[a]);
    // (x, _, z) x up = (-z, 0, x): the facing's ground components.
    let (fx, fz) = (-z, x);
    (fx.hypot(fz) > 1e-9 * (1.0 + across.norm())).then(|| fx.atan2(fz))
}

/// The facing per frame of `poses` (canonical frame), unwrapped and smoothed by `sigma_frames`.
pub fn facing_angles(
    poses: &[GlobalPose],
    left: usize,
    right: usize,
    sigma_frames: f64,
) -> Vec<f64> {
    let mut angles = Vec::with_capacity(poses.len());
    let mut last: Option<f64> = None;
    for pose in poses {
        let raw = facing_of(pose.joints[left] - pose.joints[right]);
        let angle = match (raw, last) {
            (Some(a), Some(prev)) => prev + wrap(a - prev),
            (Some(a), None) => a,
            // A vertical hip axis says nothing: the facing holds.
            (None, Some(prev)) => prev,
            (None, None) => 0.0,
        };
        angles.push(angle);
        last = Some(angle);
    }
    gaussian_smooth(&angles, sigma_frames)
}

/// `angle` wrapped into `(-pi, pi]`.
pub fn wrap(angle: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let a = angle - tau * (angle / tau).round();
    if a <= -std::f64::consts::PI {
        a + tau
    } else {
        a
    }
}

/// The least travel, in skeleton heights per second, at which [`RootLayout::Auto`] takes a clip
/// for locomotion and gives it the heading-relative root: the median of the root's ground
/// distance over 1-second windows. Walks, hops and dog walks travel 0.25-1.0 heights per
/// second by that measure and a dog's run 6; a kick 0.13, the Rokoko dance 0.10, the fox's
/// survey and in-place cycles 0. A clip that hardly travels has nothing to steer, and on the
/// dance the heading root's samples were 3 % less diverse (docs/STEERING.md).
pub const HEADING_MIN_TRAVEL: f64 = 0.15;

/// The median ground distance the joint `root` covers in 1-second windows (windows starting a
/// quarter second apart), in `height`s per second; 0 for a clip shorter than a second.
pub fn median_travel(poses: &[GlobalPose], root: usize, fps: f64, height: f64) -> f64 {
    let window = fps.round().max(1.0) as usize;
    let step = (window / 4).max(1);
    let mut distances: Vec<f64> = (0..poses.len().saturating_sub(window))
        .step_by(step)
        .map(|f| {
            let mut d = poses[f + window].joints[root] - poses[f].joints[root];
            d[UP] = 0.0;
            d.norm() / height
        })
        .collect();
    if distances.is_empty() {
        return 0.0;
    }
    distances.sort_by(f64::total_cmp);
    distances[distances.len() / 2] * fps / window as f64
}

/// The facing pair of `skeleton`: two joints whose chains mirror each other (the same depth,
/// subtrees of the same size, bones of lengths within 10 %), apart on the ground at frame 0 by
/// at least 2 % of the character's height, and meeting at the motion root `root` or below it.
/// The pair that meets nearest the root wins (the hips before the shoulders), then the pair
/// nearest their meeting joint (a hip before a knee), then the widest.
pub fn facing_pair(
    skeleton: &Skeleton,
    root: usize,
    first: &GlobalPose,
    height: f64,
) -> Option<(usize, usize)> {
    let joints = skeleton.len();
    let ancestors = |j: usize| {
        let mut chain = vec![j];
        let mut k = j;
        while let Some(p) = skeleton.joints[k].parent {
            chain.push(p);
            k = p;
        }
        chain
    };
    let chains: Vec<Vec<usize>> = (0..joints).map(ancestors).collect();
    let depth = |j: usize| chains[j].len() - 1;
    let subtree: Vec<usize> = (0..joints)
        .map(|j| chains.iter().filter(|c| c[1..].contains(&j)).count())
        .collect();
    let mut best: Option<((usize, usize, f64), usize, usize)> = None;
    for a in 0..joints {
        for b in a + 1..joints {
            if depth(a) != depth(b) || subtree[a] != subtree[b] {
                continue;
            }
            // The joint where the two chains meet, which must be the root or below it.
            let Some(&meet) = chains[a].iter().find(|j| chains[b].contains(j)) else {
                continue;
            };
            if meet == a || meet == b || !chains[meet].contains(&root) {
                continue;
            }
            let (la, lb) = (
                skeleton.joints[a].offset.norm(),
                skeleton.joints[b].offset.norm(),
            );
            if la.max(lb) <= 1e-9 * height || (la - lb).abs() > 0.1 * la.max(lb) {
                continue;
            }
            let across = first.joints[a] - first.joints[b];
            let spread = GROUND_PLANE
                .map(|g| across[g] * across[g])
                .iter()
                .sum::<f64>()
                .sqrt();
            if spread < 0.02 * height {
                continue;
            }
            let rank = (depth(meet), depth(a), spread);
            let better = match &best {
                None => true,
                Some((r, _, _)) => {
                    (rank.0, rank.1) < (r.0, r.1)
                        || ((rank.0, rank.1) == (r.0, r.1) && rank.2 > r.2)
                }
            };
            if better {
                best = Some((rank, a, b));
            }
        }
    }
    best.map(|(_, a, b)| (a, b))
}

/// Which of two joints is on the left, by their names: `Some(true)` if `a` is, `Some(false)` if
/// `b` is, `None` if the names do not say.
pub fn left_by_name(a: &str, b: &str) -> Option<bool> {
    let (a, b) = (a.to_lowercase(), b.to_lowercase());
    let side = |name: &str| match (name.contains("left"), name.contains("right")) {
        (true, false) => Some(true),
        (false, true) => Some(false),
        _ => None,
    };
    if let (Some(sa), Some(sb)) = (side(&a), side(&b))
        && sa != sb
    {
        return Some(sa);
    }
    // One letter apart: l against r.
    let (ca, cb): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    if ca.len() != cb.len() {
        return None;
    }
    let differing: Vec<(char, char)> = ca
        .iter()
        .zip(&cb)
        .filter(|(x, y)| x != y)
        .map(|(x, y)| (*x, *y))
        .collect();
    match differing.as_slice() {
        [('l', 'r')] => Some(true),
        [('r', 'l')] => Some(false),
        _ => None,
    }
}

/// The root's columns under the heading layout for ground positions `positions` (canonical,
/// per frame) and facing `headings`: rows forward, leftward, turn (radians per frame), height.
pub fn root_columns(positions: &[Vec3], headings: &[f64]) -> [Vec<f64>; 4] {
    let frames = positions.len();
    let mut out = [
        vec![0.0; frames],
        vec![0.0; frames],
        vec![0.0; frames],
        vec![0.0; frames],
    ];
    for f in 0..frames {
        out[3][f] = positions[f][UP];
        if frames < 2 {
            continue;
        }
        let g = f.max(1);
        let mut step = positions[g] - positions[g - 1];
        step[UP] = 0.0;
        let local = yaw(headings[g]).transpose() * step;
        out[0][f] = local[2];
        out[1][f] = local[0];
        out[2][f] = headings[g] - headings[g - 1];
    }
    out
}

/// Integrates the heading layout's root columns from `start` and `start_heading`: the position
/// and the facing of every frame.
pub fn integrate(
    forward: &[f64],
    leftward: &[f64],
    turn: &[f64],
    height: &[f64],
    start: Vec3,
    start_heading: f64,
) -> (Vec<Vec3>, Vec<f64>) {
    let frames = height.len();
    let mut positions = Vec::with_capacity(frames);
    let mut headings = Vec::with_capacity(frames);
    let (mut p, mut h) = (start, start_heading);
    for f in 0..frames {
        if f > 0 {
            h += turn[f];
            p += yaw(h) * Vec3::new(leftward[f], 0.0, forward[f]);
        }
        p[UP] = height[f];
        positions.push(p);
        headings.push(h);
    }
    (positions, headings)
}

/// Frames a character counts as moving in [`facing_against_travel`]: a ground speed of at
/// least this many heights per second (a slow walk is about 0.5).
pub const MOVING_SPEED: f64 = 0.2;

/// The angle in degrees between the facing and the direction of travel on the ground, for
/// every frame of heading-layout `features` (`[F, N]`, unnormalised) whose ground speed is at
/// least [`MOVING_SPEED`]; `None` for a model without a heading-relative root.
///
/// The root's rows are the travel in the facing frame, so the angle is read off them. The
/// travel is smoothed as the facing is (a Gaussian of [`Heading::smoothing`]): the body's
/// sideways sway within a stride is not a change of course.
pub fn facing_against_travel(
    layout: &crate::motion::FeatureLayout,
    features: ndarray::ArrayView2<'_, f32>,
) -> Option<Vec<f64>> {
    let heading = layout.root.as_ref()?.heading.as_ref()?;
    let sigma = heading.smoothing * layout.fps;
    let row = |r: usize| -> Vec<f64> {
        let values: Vec<f64> = features.row(r).iter().map(|&v| f64::from(v)).collect();
        gaussian_smooth(&values, sigma)
    };
    let (forward, leftward) = (row(0), row(1));
    let per_frame = MOVING_SPEED * layout.skeleton_height / layout.fps;
    Some(
        forward
            .iter()
            .zip(&leftward)
            .filter(|(f, l)| f.hypot(**l) >= per_frame)
            .map(|(f, l)| l.abs().atan2(*f).to_degrees())
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn facing_of_a_left_axis_along_x_is_plus_z() {
        assert_eq!(facing_of(Vec3::new(1.0, 0.0, 0.0)), Some(0.0));
        let quarter = facing_of(Vec3::new(0.0, 0.3, -1.0)).unwrap();
        assert!((quarter - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(facing_of(Vec3::new(0.0, 1.0, 0.0)), None);
        // yaw(h) takes +Z to the facing h.
        let f = yaw(quarter) * Vec3::new(0.0, 0.0, 1.0);
        assert!((f[0] - 1.0).abs() < 1e-12 && f[2].abs() < 1e-12);
    }

    #[test]
    fn sides_from_names() {
        assert_eq!(left_by_name("LeftUpLeg", "RightUpLeg"), Some(true));
        assert_eq!(left_by_name("RHipJoint", "LHipJoint"), Some(false));
        assert_eq!(
            left_by_name("b_LeftLeg01_19", "b_RightLeg01_23"),
            Some(true)
        );
        assert_eq!(left_by_name("thigh.l", "thigh.r"), Some(true));
        assert_eq!(left_by_name("leg_a", "leg_b"), None);
    }

    #[test]
    fn root_columns_integrate_back() {
        let positions: Vec<Vec3> = (0..20)
            .map(|f| {
                let t = f as f64 * 0.1;
                Vec3::new(t.sin() * 3.0, 1.0 + 0.1 * t.cos(), t * 2.0)
            })
            .collect();
        let headings: Vec<f64> = (0..20).map(|f| 0.3 + 0.05 * f as f64).collect();
        let [fwd, left, turn, height] = root_columns(&positions, &headings);
        let (back, hs) = integrate(&fwd, &left, &turn, &height, positions[0], headings[0]);
        for f in 0..20 {
            assert!((back[f] - positions[f]).norm() < 1e-12, "frame {f}");
            assert!((hs[f] - headings[f]).abs() < 1e-12);
        }
    }

    #[test]
    fn wrap_stays_in_half_open_range() {
        assert!((wrap(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap(-0.5) + 0.5).abs() < 1e-15);
    }
}
