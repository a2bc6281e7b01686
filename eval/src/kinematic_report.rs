//! The kinematic fidelity report of a batch of samples ([`crate::kinematics`]): the clip's
//! figures beside the raw and the planted samples', and its Markdown table.

use serde::{Deserialize, Serialize};
use sinmdm::motion::LocalMotion;
use sinmdm::motion::up::UpAxis;

use crate::kinematics::{ClipKinematics, KinematicScores, Kinematics, goals};
use crate::turning::{ClipTurning, TurnScores, turn_rates};

/// The kinematic fidelity of a batch of samples, as the network made them and as written
/// (feet planted), beside the clip's own figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KinematicReport {
    /// The clip's figures.
    pub clip: ClipKinematics,
    /// The samples as the network made them.
    pub raw: KinematicScores,
    /// The samples with their feet planted (the default output).
    pub planted: KinematicScores,
    /// How fast the whole body turns: the clip, then the raw and the planted samples.
    #[serde(default)]
    pub turning: TurningReport,
}

/// How fast the root's heading turns in the clip and in the samples ([`crate::turning`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TurningReport {
    /// The clip's turn rates.
    pub clip: ClipTurning,
    /// The samples as the network made them.
    pub raw: TurnScores,
    /// The samples with their feet planted.
    pub planted: TurnScores,
}

impl KinematicReport {
    /// The report of `raw` and `planted` samples against `clip`, all of a skeleton `height`
    /// tall whose file points `up`.
    pub fn new(
        clip: &LocalMotion,
        raw: &[LocalMotion],
        planted: &[LocalMotion],
        height: f64,
        up: UpAxis,
    ) -> KinematicReport {
        let clip_kinematics = Kinematics::of_motion(clip, height);
        let clip_figures = ClipKinematics::new(&clip_kinematics);
        let scores = |motions: &[LocalMotion]| {
            clip_figures.score(&clip_kinematics, &Kinematics::of_motions(motions, height))
        };
        let clip_turning = ClipTurning::new(&turn_rates(clip, up));
        let turns = |motions: &[LocalMotion]| {
            let pooled: Vec<f64> = motions.iter().flat_map(|m| turn_rates(m, up)).collect();
            clip_turning.score(&pooled)
        };
        KinematicReport {
            raw: scores(raw),
            planted: scores(planted),
            turning: TurningReport {
                raw: turns(raw),
                planted: turns(planted),
                clip: clip_turning,
            },
            clip: clip_figures,
        }
    }

    /// The figures as a Markdown table: clip, raw samples, planted samples, and the goals.
    pub fn markdown_table(&self) -> String {
        let (c, r, p) = (&self.clip, &self.raw, &self.planted);
        let mut out = String::from(
            "| how it moves | clip | samples, raw | samples, feet planted | goal |\n|---|---|---|---|---|\n",
        );
        out.push_str(&format!(
            "| nearly still frames (%) | {:.1} | {:.1} | {:.1} | <= {:.1} |\n",
            100.0 * c.still_share,
            100.0 * r.still_share,
            100.0 * p.still_share,
            100.0 * (c.still_share + goals::STILL_SHARE_MARGIN)
        ));
        for (i, name) in ["p25", "p50", "p90"].iter().enumerate() {
            out.push_str(&format!(
                "| speed {name} (H/s; samples: x the clip's) | {:.3} | {:.2}x | {:.2}x | {}-{}x |\n",
                c.speed_percentiles[i],
                r.speed_ratios[i],
                p.speed_ratios[i],
                goals::LEAST_SPEED_RATIO,
                goals::MOST_SPEED_RATIO
            ));
        }
        out.push_str(&format!(
            "| speed distance (x clip's mean {:.3} H/s) | 0 | {:.3} | {:.3} | <= {} |\n",
            c.mean_speed,
            r.speed_distance,
            p.speed_distance,
            goals::SPEED_DISTANCE
        ));
        out.push_str(&format!(
            "| acceleration distance (x clip's mean {:.2} H/s²) | 0 | {:.3} | {:.3} | <= {} |\n",
            c.mean_acceleration,
            r.acceleration_distance,
            p.acceleration_distance,
            goals::ACCELERATION_DISTANCE
        ));
        let t = &self.turning;
        out.push_str(&format!(
            "| root turn rate p99 (degrees/s; the clip's most {:.0}) | {:.0} | {:.0} | {:.0} | (reported) |\n",
            t.clip.most, t.clip.fast, t.raw.fast, t.planted.fast
        ));
        out.push_str(&format!(
            "| frames turning faster than the clip's most (%) | 0 | {:.1} | {:.1} | (reported) |\n",
            100.0 * t.raw.faster_than_clip,
            100.0 * t.planted.faster_than_clip
        ));
        out
    }
}
