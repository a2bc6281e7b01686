//! A rung's scores: how its samples met the goals, which rung the main run trains, and the
//! `check.json` file that keeps a finished rung's scores in its folder.

use std::path::Path;

use serde::{Deserialize, Serialize};

use sinmdm_eval::KinematicScores;

use crate::choose::ladder_settings::goals;
use crate::error::TrainError;

/// The scores file of a finished rung.
const CHECK_FILE: &str = "check.json";

/// How a rung's samples scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RungCheck {
    /// The rung's optimiser steps.
    pub steps: u64,
    /// Its learning rate where it is not the configuration's (a rung of the faster arm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub learning_rate: Option<f64>,
    /// Coverage of the clip's windows, percent.
    pub coverage: f64,
    /// Global diversity.
    pub global_diversity: f64,
    /// Mean over the samples of their longest verbatim copy of the clip, seconds.
    pub replay_seconds: f64,
    /// The samples' jitter as a multiple of the clip's (raw feet).
    pub jitter_ratio: f64,
    /// What the clip played backwards scores on the replay measure, seconds: motion that is no
    /// copy, so a replay no longer than it meets the replay goal however long it is.
    #[serde(default)]
    pub replay_floor_seconds: f64,
    /// How the samples (raw feet) move against the clip: stillness, speeds, accelerations.
    #[serde(default)]
    pub kinematics: KinematicScores,
    /// The clip's own share of nearly still frames.
    #[serde(default)]
    pub clip_still_share: f64,
    /// Seconds the rung trained.
    pub train_seconds: f64,
    /// Seconds its samples took to make and score.
    pub check_seconds: f64,
    /// What the rung was made from
    /// ([`Ladder::rung_fingerprint`](super::Ladder::rung_fingerprint)): a rung scored for
    /// another clip, configuration, check or trainer version is trained again, not reused.
    #[serde(default)]
    pub made_from: String,
}

impl RungCheck {
    /// Each goal's margin (coverage, replay, most jitter, least jitter), in units of about one
    /// goal's worth ([`goals`]): positive where met, negative where missed.
    pub fn margins(&self) -> [f64; 4] {
        [
            (self.coverage - goals::COVERAGE) / goals::COVERAGE_UNIT,
            (self.replay_goal() - self.replay_seconds) / goals::REPLAY_UNIT,
            (goals::JITTER_RATIO - self.jitter_ratio) / goals::JITTER_UNIT,
            (self.jitter_ratio - goals::LEAST_JITTER_RATIO) / goals::LEAST_JITTER_UNIT,
        ]
    }

    /// The longest mean verbatim run that meets the replay goal: [`goals::REPLAY_SECONDS`], or
    /// the clip's backwards score where that is longer (a replay no longer than motion that is
    /// no copy is no evidence of copying).
    pub fn replay_goal(&self) -> f64 {
        goals::REPLAY_SECONDS.max(self.replay_floor_seconds)
    }

    /// Each kinematic goal's margin (nearly still share, speed p25, p50 and p90, speed and
    /// acceleration distance; `sinmdm_eval::kinematics::goals`), in units of about one goal's
    /// worth: positive where met, negative where missed.
    pub fn kinematic_margins(&self) -> [f64; 6] {
        use sinmdm_eval::kinematics::goals as moves;
        let k = &self.kinematics;
        let ratio = |r: f64| {
            let r = r.max(f64::MIN_POSITIVE);
            (r / moves::LEAST_SPEED_RATIO)
                .ln()
                .min((moves::MOST_SPEED_RATIO / r).ln())
                / goals::SPEED_RATIO_UNIT.ln()
        };
        [
            (self.clip_still_share + moves::STILL_SHARE_MARGIN - k.still_share)
                / goals::STILL_SHARE_UNIT,
            ratio(k.speed_ratios[0]),
            ratio(k.speed_ratios[1]),
            ratio(k.speed_ratios[2]),
            (moves::SPEED_DISTANCE - k.speed_distance) / goals::SPEED_DISTANCE_UNIT,
            (moves::ACCELERATION_DISTANCE - k.acceleration_distance)
                / goals::ACCELERATION_DISTANCE_UNIT,
        ]
    }

    /// The smallest margin of every goal, the kinematic ones included: how far the rung is from
    /// missing a goal (negative: how far it misses the goal it misses most).
    pub fn worst_margin(&self) -> f64 {
        self.margins()
            .into_iter()
            .chain(self.kinematic_margins())
            .fold(f64::INFINITY, f64::min)
    }

    /// The kinematic goals' shortfalls summed (0 where the samples move like the clip), in the
    /// margins' units.
    pub fn kinematic_shortfall(&self) -> f64 {
        self.kinematic_margins()
            .into_iter()
            .map(|m| (-m).max(0.0))
            .sum()
    }

    /// The other goals' shortfalls summed (0 where every one is met), in the margins' units: how
    /// far the rung misses the goals it misses, all of them.
    pub fn shortfall(&self) -> f64 {
        self.margins().into_iter().map(|m| (-m).max(0.0)).sum()
    }

    /// Whether the samples cover the clip.
    pub fn covers(&self) -> bool {
        self.coverage >= goals::COVERAGE
    }

    /// Whether the samples meet every goal.
    pub fn meets_goals(&self) -> bool {
        self.worst_margin() >= 0.0
    }

    /// One line of the ladder's table.
    pub fn line(&self) -> String {
        format!(
            "{:>4} steps{}: coverage {:.1}, replay {:.2} s, jitter {:.2}x the clip's, global diversity {:.3}, still {:.0}% (clip {:.0}%), speed p25/p50/p90 {:.2}/{:.2}/{:.2}x, distances {:.2}/{:.2}{} ({:.0} s + {:.0} s check)",
            self.steps,
            self.learning_rate
                .map_or(String::new(), |r| format!(" at learning rate {r}")),
            self.coverage,
            self.replay_seconds,
            self.jitter_ratio,
            self.global_diversity,
            100.0 * self.kinematics.still_share,
            100.0 * self.clip_still_share,
            self.kinematics.speed_ratios[0],
            self.kinematics.speed_ratios[1],
            self.kinematics.speed_ratios[2],
            self.kinematics.speed_distance,
            self.kinematics.acceleration_distance,
            if self.meets_goals() {
                ", every goal met"
            } else {
                ""
            },
            self.train_seconds,
            self.check_seconds
        )
    }
}

/// Which rung the main run trains: of those that meet every goal, the one whose worst margin
/// is widest. Where none does, moving like the clip comes first: the rung whose kinematic
/// shortfalls sum least ([`RungCheck::kinematic_shortfall`]), so that a frozen or shaking rung
/// is never taken for a moving one; then the one whose other shortfalls sum least
/// ([`RungCheck::shortfall`]), so that a rung a hair under one goal beats one that misses another
/// by far. Fewer steps on a tie. `None` when no rung covers the clip (it is not calm after
/// all); where one does, the rung chosen may still be one under coverage, when the covering
/// rungs move less like the clip or miss the other goals by more.
pub fn choose(rungs: &[RungCheck]) -> Option<&RungCheck> {
    if !rungs.iter().any(RungCheck::covers) {
        return None;
    }
    rungs.iter().min_by(|a, b| {
        a.kinematic_shortfall()
            .total_cmp(&b.kinematic_shortfall())
            .then(a.shortfall().total_cmp(&b.shortfall()))
            .then(b.worst_margin().total_cmp(&a.worst_margin()))
            .then(a.steps.cmp(&b.steps))
    })
}

/// Writes a finished rung's scores into its folder `dir` (whole, or not at all).
pub(super) fn write_check(dir: &Path, check: &RungCheck) -> Result<(), TrainError> {
    let json = serde_json::to_string_pretty(check).expect("scores serialise");
    sinmdm::files::write_atomically(&dir.join(CHECK_FILE), json.as_bytes()).map_err(|source| {
        TrainError::Io {
            what: "write a rung's scores",
            path: dir.join(CHECK_FILE),
            reason: source,
        }
    })
}

/// The scores a finished rung left in `dir`, if it finished, trained `steps` and was made from
/// `made_from` ([`Ladder::rung_fingerprint`](super::Ladder::rung_fingerprint)).
pub(super) fn read_check(dir: &Path, steps: u64, made_from: &str) -> Option<RungCheck> {
    let text = std::fs::read_to_string(dir.join(CHECK_FILE)).ok()?;
    serde_json::from_str::<RungCheck>(&text)
        .ok()
        .filter(|c| c.steps == steps && c.made_from == made_from)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kinematic scores of samples that move exactly like their clip.
    fn moving_like_the_clip() -> KinematicScores {
        KinematicScores {
            speed_ratios: [1.0; 3],
            ..KinematicScores::default()
        }
    }

    fn rung(steps: u64, coverage: f64, replay_seconds: f64, jitter_ratio: f64) -> RungCheck {
        RungCheck {
            steps,
            learning_rate: None,
            coverage,
            global_diversity: 1.0,
            replay_seconds,
            jitter_ratio,
            replay_floor_seconds: 0.0,
            kinematics: moving_like_the_clip(),
            clip_still_share: 0.0,
            train_seconds: 1.0,
            check_seconds: 1.0,
            made_from: String::new(),
        }
    }

    #[test]
    fn margins_are_in_units_of_one_goal() {
        let r = rung(100, 97.5, 0.75, 1.0);
        let m = r.margins();
        assert_eq!(m[..3], [0.5, 0.5, 1.0]);
        // 1.0 is 1/3 over the least jitter 2/3, whose unit is 2/3 - 1/2 = 1/6: two units.
        assert!((m[3] - 2.0).abs() < 1e-12, "{m:?}");
        assert_eq!(r.worst_margin(), 0.5);
        assert!(r.meets_goals() && r.covers());
        // Exactly on every goal meets it.
        assert!(rung(100, 95.0, 1.0, 1.5).meets_goals());
        assert!(rung(100, 95.0, 1.0, 1.0 / 1.5).meets_goals());
        let missed = rung(100, 99.0, 1.25, 1.0);
        assert_eq!(missed.worst_margin(), -0.5);
        assert!(!missed.meets_goals() && missed.covers());
        // Smoother than the clip by more than 1.5x misses the least jitter: half the clip's is
        // one unit under it.
        let smooth = rung(50, 100.0, 0.2, 0.5);
        assert!(
            (smooth.worst_margin() + 1.0).abs() < 1e-12,
            "{:?}",
            smooth.margins()
        );
    }

    #[test]
    fn kinematic_margins_are_in_units_of_one_goal() {
        let mut r = rung(100, 100.0, 0.5, 1.0);
        assert_eq!(r.kinematic_margins()[4..], [2.0, 2.0]);
        assert!(r.meets_goals());
        // A quarter of the clip's still share over its bound (clip 10 %, samples 20 %): one
        // unit short. p50 at 1.25 x 1.25 the clip's: one unit over; p25 at 0.8: just met.
        r.clip_still_share = 0.1;
        r.kinematics.still_share = 0.2;
        r.kinematics.speed_ratios = [0.8, 1.25 * 1.25, 1.0];
        let m = r.kinematic_margins();
        assert!((m[0] + 1.0).abs() < 1e-12 && m[1].abs() < 1e-12, "{m:?}");
        assert!((m[2] + 1.0).abs() < 1e-12, "{m:?}");
        assert!((r.kinematic_shortfall() - 2.0).abs() < 1e-12);
        assert!(!r.meets_goals());
    }

    #[test]
    fn moving_like_the_clip_comes_before_every_other_goal() {
        // The fox's ladder: 50 steps stand still in 69 % of the frames (its clip: none) and meet
        // the other goals; 1 000 steps move at the clip's median speed but shake (acceleration
        // distance 4.1) and jitter 4.4x. Moving more like the clip wins.
        let mut frozen = rung(50, 100.0, 1.89, 1.42);
        frozen.replay_floor_seconds = 2.0;
        frozen.kinematics = KinematicScores {
            still_share: 0.69,
            speed_ratios: [0.02, 0.06, 1.39],
            speed_distance: 0.78,
            acceleration_distance: 0.78,
            ..KinematicScores::default()
        };
        let mut shaking = rung(1000, 100.0, 2.06, 4.44);
        shaking.replay_floor_seconds = 2.0;
        shaking.kinematics = KinematicScores {
            still_share: 0.03,
            speed_ratios: [0.71, 1.01, 1.49],
            speed_distance: 0.32,
            acceleration_distance: 4.12,
            ..KinematicScores::default()
        };
        assert!(frozen.shortfall() < shaking.shortfall());
        assert!(shaking.kinematic_shortfall() < frozen.kinematic_shortfall());
        let rungs = [frozen, shaking];
        assert_eq!(choose(&rungs).map(|r| r.steps), Some(1000));
    }

    #[test]
    fn a_replay_no_longer_than_the_clip_played_backwards_meets_the_replay_goal() {
        // The fox's idle: its samples replay 1.97 s, the clip backwards scores 2.00 s.
        let mut fox = rung(50, 100.0, 1.97, 1.4);
        assert!(!fox.meets_goals());
        fox.replay_floor_seconds = 2.0;
        assert_eq!(fox.replay_goal(), 2.0);
        assert!(fox.meets_goals(), "{:?}", fox.margins());
        // Over the floor misses it by as much as over the one second would.
        fox.replay_seconds = 2.5;
        assert!(
            (fox.margins()[1] + 1.0).abs() < 1e-12,
            "{:?}",
            fox.margins()
        );
        // A floor under a second leaves the goal at one second.
        fox.replay_floor_seconds = 0.4;
        assert_eq!(fox.replay_goal(), goals::REPLAY_SECONDS);
    }

    #[test]
    fn the_widest_margin_wins_and_the_least_shortfall_where_no_rung_meets_every_goal() {
        // A kick: covered only from 200 steps, and replaying more the longer it trains.
        let kick = [
            rung(50, 80.0, 0.4, 1.0),
            rung(100, 90.0, 0.5, 1.2),
            rung(200, 96.0, 0.8, 1.4),
            rung(300, 97.5, 0.9, 1.45),
        ];
        // 200: min(0.2, 0.4, 0.2) = 0.2; 300: min(0.5, 0.2, 0.1) = 0.1.
        assert_eq!(choose(&kick).map(|r| r.steps), Some(200));
        // A hair under coverage beats a replay well over its goal.
        let edge = [rung(300, 94.97, 0.97, 1.48), rung(400, 97.3, 1.23, 1.45)];
        assert_eq!(choose(&edge).map(|r| r.steps), Some(300));
        // Every rung meets the adaptive default's goals: the least-trained is too smooth.
        let happy = [
            rung(50, 100.0, 0.20, 0.26),
            rung(150, 100.0, 0.76, 0.82),
            rung(300, 100.0, 0.91, 0.83),
        ];
        assert_eq!(choose(&happy).map(|r| r.steps), Some(150));
        // A clip that replays: the rung that replays least, when every rung covers it.
        let still = [
            rung(50, 100.0, 1.7, 1.4),
            rung(100, 100.0, 1.9, 1.3),
            rung(200, 100.0, 2.1, 1.2),
        ];
        assert_eq!(choose(&still).map(|r| r.steps), Some(50));
        // A goal no rung meets (the fox's idle, which replays whatever the steps): the rung
        // that misses only it beats one that misses it a little less and the jitter too. The
        // widest worst margin alone would take 75: min(-1.48, -1.56) against min(-1.78, 0.16).
        let fox = [
            rung(50, 100.0, 1.89, 1.42),
            rung(75, 100.0, 1.74, 2.28),
            rung(300, 100.0, 1.66, 3.61),
        ];
        assert!(fox[1].worst_margin() > fox[0].worst_margin());
        assert!(
            (fox[0].shortfall() - 1.78).abs() < 1e-9,
            "{}",
            fox[0].shortfall()
        );
        assert!(
            (fox[1].shortfall() - 3.04).abs() < 1e-9,
            "{}",
            fox[1].shortfall()
        );
        assert_eq!(choose(&fox).map(|r| r.steps), Some(50));
        // Ties go to fewer steps, in any order.
        let tie = [rung(100, 100.0, 0.5, 1.0), rung(50, 100.0, 0.5, 1.0)];
        assert_eq!(choose(&tie).map(|r| r.steps), Some(50));
        // No rung that covers the clip: none is chosen, however wide the other margins.
        let uncovered = [rung(50, 94.9, 0.1, 0.5), rung(300, 90.0, 0.1, 0.5)];
        assert_eq!(choose(&uncovered), None);
        assert_eq!(choose(&[]), None);
    }
}
