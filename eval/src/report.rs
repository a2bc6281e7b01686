//! What an evaluation reports: each sample's scores, their mean and spread, the clip's windows
//! the samples make, the normalised scores and their harmonic mean, and the stretches of the
//! clip few samples make.

use serde::{Deserialize, Serialize};

use crate::{COVERAGE_THRESHOLD, COVERAGE_WINDOW, LOCAL_WINDOW, mean, std_dev};

/// The metrics of one sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SampleScores {
    /// Coverage in percent.
    pub coverage: f64,
    /// Global diversity (patched nearest neighbour cost per frame).
    pub global_diversity: f64,
    /// Local diversity.
    pub local_diversity: f64,
    /// Inter diversity to the previous sample (the last one for the first).
    pub inter_diversity: f64,
    /// The sample's intra diversity (before taking the difference to the clip's).
    pub intra_diversity: f64,
}

/// Mean and population standard deviation over samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
}

impl Stat {
    pub(crate) fn of(values: &[f64]) -> Stat {
        Stat {
            mean: mean(values),
            std: std_dev(values),
        }
    }
}

/// The benchmark's table for a set of samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Coverage in percent (higher is better).
    pub coverage: Stat,
    /// Global diversity (higher is better, unless coverage drops).
    pub global_diversity: Stat,
    /// Local diversity (higher is better, unless coverage drops).
    pub local_diversity: Stat,
    /// Inter diversity (higher is better).
    pub inter_diversity: Stat,
    /// |mean intra diversity of the samples - the clip's| (lower is better).
    pub intra_diversity_diff: f64,
    /// The clip's own intra diversity.
    pub clip_intra_diversity: f64,
    /// Harmonic mean of the five normalised scores, in `[0, 1]` (higher is better).
    pub harmonic_mean: f64,
    /// Frames per sample.
    pub sample_frames: usize,
    /// Frames of the clip.
    pub clip_frames: usize,
    /// Each sample's scores.
    pub per_sample: Vec<SampleScores>,
    /// For each 30-frame window of the clip, by its first frame: the share of the samples, in
    /// percent, that make it (have a window closer than the coverage threshold). Their mean is
    /// the mean coverage; the low ones are the parts of the clip the model rarely makes.
    pub clip_window_coverage: Vec<f64>,
}

/// The five scores mapped to `[0, 1]` (see the module documentation), in table order.
pub fn normalised_scores(report: &Report) -> [f64; 5] {
    let unit = |value: f64, max: f64| (value / max).clamp(0.0, 1.0);
    let frames = report.sample_frames.max(1) as f64;
    [
        unit(report.coverage.mean, 100.0),
        unit(report.global_diversity.mean, COVERAGE_THRESHOLD),
        unit(report.local_diversity.mean, COVERAGE_THRESHOLD),
        unit(
            report.inter_diversity.mean,
            COVERAGE_THRESHOLD / frames.sqrt(),
        ),
        1.0 - unit(
            report.intra_diversity_diff,
            COVERAGE_THRESHOLD / (LOCAL_WINDOW as f64).sqrt(),
        ),
    ]
}

/// Harmonic mean of values in `[0, 1]`; 0 when any is 0.
pub fn harmonic_mean(values: &[f64]) -> f64 {
    if values.is_empty() || values.iter().any(|&v| v <= 0.0) {
        return 0.0;
    }
    values.len() as f64 / values.iter().map(|v| 1.0 / v).sum::<f64>()
}

/// A stretch of the clip that few samples make: the frames of coverage windows each made by
/// fewer than the asked share of the samples (overlapping or touching windows joined).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RarelyMade {
    /// First frame of the stretch (its first window's first frame).
    pub first_frame: usize,
    /// Last frame of the stretch (its last window's last frame).
    pub last_frame: usize,
    /// The lowest share of samples, in percent, that make one of its windows.
    pub least_share: f64,
}

impl Report {
    /// The stretches of the clip whose coverage windows are each made by fewer than `below`
    /// percent of the samples, in clip order; windows that share or touch frames join one
    /// stretch.
    pub fn rarely_made(&self, below: f64) -> Vec<RarelyMade> {
        let mut stretches: Vec<RarelyMade> = Vec::new();
        for (start, &share) in self.clip_window_coverage.iter().enumerate() {
            if share >= below {
                continue;
            }
            let last_frame = start + COVERAGE_WINDOW - 1;
            match stretches.last_mut() {
                Some(stretch) if start <= stretch.last_frame + 1 => {
                    stretch.last_frame = last_frame;
                    stretch.least_share = stretch.least_share.min(share);
                }
                _ => stretches.push(RarelyMade {
                    first_frame: start,
                    last_frame,
                    least_share: share,
                }),
            }
        }
        stretches
    }
}
