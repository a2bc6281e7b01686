//! Training configuration, read from YAML with every key checked.

use std::path::Path;

use serde::{Deserialize, Serialize};
use sinmdm::network::{FIXED_RECEPTIVE_HALF_WIDTH, QNA_BLOCKS};

use crate::error::TrainError;

mod resume;
mod schedule;
mod validate;

pub use schedule::LrSchedule;

/// A whole training configuration (`configs/*.yaml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainConfig {
    /// The denoiser's shape.
    pub model: ModelConfig,
    /// The diffusion process.
    pub diffusion: DiffusionConfig,
    /// The optimisation.
    pub training: TrainingConfig,
    /// How the clip becomes features.
    pub data: DataConfig,
    /// Which settings the rule that reads the clip chooses (`choose::clip_rule`); absent:
    /// none, every number trains as written. A run saves the numbers chosen, with this off.
    #[serde(default, skip_serializing_if = "FromClip::is_off")]
    pub from_clip: FromClip,
}

/// The QnA-UNet's shape (SPEC §3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelConfig {
    /// Channels C of every block (a multiple of 32, for GroupNorm(32)).
    pub channels: usize,
    /// Attention heads H of the QnA blocks (must divide `channels`).
    pub heads: usize,
    /// QnA window k in frames (odd).
    pub window: usize,
    /// Dropout probability inside the residual blocks, in [0, 1).
    pub dropout: f64,
    /// Whether `window` is the window at [`WINDOW_REFERENCE_FPS`], widened for a clip trained
    /// at a higher frame rate ([`ModelConfig::at_fps`]) so that the receptive field keeps its
    /// span in seconds. A run saves the window it resolved to, with this off.
    #[serde(default, skip_serializing_if = "is_false")]
    pub window_follows_fps: bool,
}

/// The frame rate at which a window that follows the frame rate is meant.
pub const WINDOW_REFERENCE_FPS: f64 = 30.0;

fn is_false(b: &bool) -> bool {
    !*b
}

/// The diffusion process (SPEC §4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiffusionConfig {
    /// Number of diffusion steps T of the cosine schedule.
    pub steps: usize,
}

/// The optimisation (SPEC §4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingConfig {
    /// Optimiser steps.
    pub steps: u64,
    /// Copies of the clip per step.
    pub batch_size: usize,
    /// AdamW learning rate at step 0.
    pub learning_rate: f64,
    /// Factor applied to the learning rate after every step (the `exponential` schedule).
    pub lr_decay: f64,
    /// How the learning rate moves over the run; absent means `exponential` (by `lr_decay`).
    #[serde(default, skip_serializing_if = "LrSchedule::is_exponential")]
    pub lr_schedule: LrSchedule,
    /// Steps of linear warm-up at the start of the `cosine` schedule.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub warmup_steps: u64,
    /// Decay of an exponential moving average of the weights, kept beside the trained ones and
    /// exported instead of them; absent or `null` keeps no average.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ema_decay: Option<f64>,
    /// AdamW weight decay.
    pub weight_decay: f64,
    /// Smallest temporal resampling factor of the clip per step.
    pub resample_min: f64,
    /// Largest temporal resampling factor of the clip per step.
    pub resample_max: f64,
    /// Seed of the weights, timesteps, noise, resampling and dropout.
    pub seed: u64,
    /// Steps between checkpoints (the last step is always saved).
    pub checkpoint_every: u64,
    /// Frames a step sees in all, in place of `batch_size` copies of the clip: a clip of F
    /// frames gets round(frames_per_step / F) batch items (at least 1, at most `batch_size`),
    /// each the whole stretched clip, or a random window of `frames_per_step` frames of one
    /// that is longer. A step then costs about the same whatever the clip's length, and
    /// GroupNorm's statistics are those of the whole clip, as when sampling. Absent or `null`:
    /// `batch_size` items of the whole clip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames_per_step: Option<usize>,
}

/// What every step's batch is made of, for one clip ([`TrainingConfig::batch_shape`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct BatchShape {
    /// Batch items (each with its own timestep and noise).
    pub items: usize,
    /// Frames of the stretched clip each item sees: a random window, or the whole clip when
    /// `None` or longer than the clip.
    pub window: Option<usize>,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl TrainingConfig {
    /// The batch of every step for a clip of `clip_frames` frames (at the training frame
    /// rate, before stretching).
    pub fn batch_shape(&self, clip_frames: usize) -> BatchShape {
        match self.frames_per_step {
            Some(budget) => BatchShape {
                items: ((budget as f64 / clip_frames.max(1) as f64).round() as usize)
                    .clamp(1, self.batch_size.max(1)),
                window: Some(budget),
            },
            None => BatchShape {
                items: self.batch_size,
                window: None,
            },
        }
    }
}

/// How the clip becomes features (SPEC §2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataConfig {
    /// Frame rate the clip is resampled to; `null` keeps the clip's own.
    pub fps: Option<f64>,
    /// Contact joints by name; `null` picks them automatically.
    pub contact_joints: Option<Vec<String>>,
    /// Contact speed threshold in skeleton heights per second.
    pub contact_speed: f64,
    /// The floor on each feature's standard deviation, as a share of the mean one
    /// (`sinmdm::motion::STD_FLOOR_SHARE` in the shipped configurations). Absent: the old
    /// floor `STD_FLOOR_SHARE_BEFORE`, as configurations written before it read.
    #[serde(default = "std_floor_before")]
    pub std_floor: f64,
    /// The clip's up axis (`x`, `y`, `z`, `-x`, `-y`, `-z`); absent or `null` reads it from the
    /// motion.
    #[serde(default)]
    pub up: Option<sinmdm::motion::UpAxis>,
    /// The animation of a glTF or FBX clip to learn, by name or index; absent reads the first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<String>,
    /// How the root is described: `world` (ground displacement in world axes and a world
    /// rotation, as SinMDM), `heading` (speeds and turn in the character's facing frame, what
    /// steering needs; SPEC section 2) or `auto` (heading where the clip has a facing pair and
    /// a travelling root, world otherwise; a run's saved configuration holds what was chosen).
    /// Absent: `world`, as configurations written before the heading root read.
    #[serde(default, skip_serializing_if = "is_world")]
    pub root_layout: sinmdm::motion::RootLayout,
    /// Whether a `.gltf` clip's buffer files may be read outside its folder
    /// (`--allow-outside-folder`): a permission of this run, not a setting of the model, so it
    /// is never written to or read from a configuration file.
    #[serde(skip)]
    pub allow_outside_folder: bool,
}

fn std_floor_before() -> f64 {
    f64::from(sinmdm::motion::STD_FLOOR_SHARE_BEFORE)
}

fn is_world(layout: &sinmdm::motion::RootLayout) -> bool {
    *layout == sinmdm::motion::RootLayout::World
}

/// Which settings the rule that reads the clip (`choose::clip_rule`) may choose: the
/// configuration's `from_clip` section. A part left false trains the configuration's own number.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FromClip {
    /// `training.steps` and `training.warmup_steps`.
    #[serde(default)]
    pub steps: bool,
    /// `model.window`.
    #[serde(default)]
    pub window: bool,
    /// `model.dropout`.
    #[serde(default)]
    pub dropout: bool,
    /// `model.channels`.
    #[serde(default)]
    pub channels: bool,
    /// `training.frames_per_step` (so that a step's items come in pairs).
    #[serde(default)]
    pub batch: bool,
}

impl FromClip {
    /// Whether the rule chooses nothing.
    pub fn is_off(&self) -> bool {
        !(self.steps || self.window || self.dropout || self.channels || self.batch)
    }
}

impl TrainConfig {
    /// The configuration as trained on a clip at `fps` ([`ModelConfig::at_fps`]).
    pub fn at_fps(&self, fps: f64) -> TrainConfig {
        TrainConfig {
            model: self.model.at_fps(fps),
            ..self.clone()
        }
    }

    /// Reads and checks a YAML file.
    pub fn load(path: &Path) -> Result<TrainConfig, TrainError> {
        let text =
            sinmdm::files::read_text_file(path, "a training configuration").map_err(|source| {
                TrainError::Io {
                    what: "read the config",
                    path: path.to_path_buf(),
                    reason: source,
                }
            })?;
        let config = Self::parse(&text).map_err(|message| TrainError::Config {
            path: path.to_path_buf(),
            message,
        })?;
        Ok(config)
    }

    /// Parses and checks YAML text; the error names the key and line.
    pub fn parse(text: &str) -> Result<TrainConfig, String> {
        let config: TrainConfig = serde_yaml::from_str(text).map_err(|e| e.to_string())?;
        config.validate()?;
        Ok(config)
    }
}

impl ModelConfig {
    /// The shape trained on a clip at `fps`: with [`ModelConfig::window_follows_fps`], the
    /// window that keeps the receptive field's span in seconds what it is at 30 fps (never
    /// narrower than `window`): the receptive half-width grows by `fps / 30` and the QnA windows,
    /// the only part of it that can, take up the difference, rounded. Window 3 (23 frames,
    /// 0.77 s) stays 3 at 30 fps and below, and becomes 11 at 60 fps (47 frames, 0.78 s) and 25
    /// at 120.
    pub fn at_fps(&self, fps: f64) -> ModelConfig {
        if !self.window_follows_fps {
            return self.clone();
        }
        let scale = if fps.is_finite() {
            (fps / WINDOW_REFERENCE_FPS).max(1.0)
        } else {
            1.0
        };
        let wanted = self.receptive_half_width() as f64 * scale;
        let half = ((wanted - FIXED_RECEPTIVE_HALF_WIDTH as f64) / QNA_BLOCKS as f64).round();
        let half = (half as usize).max(self.window / 2);
        ModelConfig {
            window: 2 * half + 1,
            window_follows_fps: false,
            ..self.clone()
        }
    }

    /// Frames on each side of a frame that can change its prediction (the network contract's
    /// [`receptive_half_width`](sinmdm::network::receptive_half_width)).
    pub fn receptive_half_width(&self) -> usize {
        sinmdm::network::receptive_half_width(self.window)
    }

    /// The receptive field in frames (23 for window 3).
    pub fn receptive_field(&self) -> usize {
        sinmdm::network::receptive_field(self.window)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TINY: &str = include_str!("../../../configs/tiny.yaml");

    #[test]
    fn shipped_configs_parse() {
        for text in [
            TINY,
            include_str!("../../../configs/cpu.yaml"),
            include_str!("../../../configs/paper.yaml"),
            include_str!("../../../configs/default.yaml"),
        ] {
            // Each floors the feature spreads at the runtime's share, so the number lives once.
            let config = TrainConfig::parse(text).unwrap();
            assert_eq!(
                config.data.std_floor as f32,
                sinmdm::motion::STD_FLOOR_SHARE
            );
        }
        let paper = TrainConfig::parse(include_str!("../../../configs/paper.yaml")).unwrap();
        assert_eq!(paper.model.channels, 256);
        assert_eq!(paper.training.batch_size, 64);
        assert_eq!(paper.training.steps, 60_000);
        assert_eq!(paper.model.receptive_field(), 23);
    }

    #[test]
    fn frames_per_step_sets_items_and_window_from_the_clip_length() {
        let default = TrainConfig::parse(include_str!("../../../configs/default.yaml")).unwrap();
        let t = &default.training;
        assert_eq!(t.frames_per_step, Some(1024));
        // 1024 / 249 = 4.1; 1024 / 302 = 3.4; 1024 / 527 = 1.9; 1024 / 1054 = 0.97 is one item,
        // and a clip longer than 1024 frames gets one window of 1024; a short one never more
        // than batch_size items.
        let shape = |frames| {
            let s = t.batch_shape(frames);
            (s.items, s.window)
        };
        assert_eq!(shape(249), (4, Some(1024)));
        assert_eq!(shape(302), (3, Some(1024)));
        assert_eq!(shape(527), (2, Some(1024)));
        assert_eq!(shape(1054), (1, Some(1024)));
        assert_eq!(shape(5000), (1, Some(1024)));
        assert_eq!(shape(60), (8, Some(1024)));
        // Without it: batch_size items of the whole clip.
        let mut fixed = t.clone();
        fixed.frames_per_step = None;
        assert_eq!(
            fixed.batch_shape(1054),
            BatchShape {
                items: 8,
                window: None
            }
        );
    }

    #[test]
    fn frames_per_step_covers_the_receptive_field_and_lost_knobs_are_refused() {
        let text = include_str!("../../../configs/default.yaml");
        // The knobs that lost their experiments are gone, and a config that still sets one is
        // told so by name.
        for knob in [
            "window_frames: 256",
            "foot_contact_weight: 1.0",
            "acceleration_weight: 0.5",
            "acceleration_below_timestep: 250",
        ] {
            let old = text.replace(
                "  frames_per_step: 1024",
                &format!("  frames_per_step: 1024\n  {knob}"),
            );
            let err = TrainConfig::parse(&old).unwrap_err();
            let name = knob.split(':').next().unwrap();
            assert!(err.contains(&format!("unknown field `{name}`")), "{err}");
        }
        let tiny = text.replace("  frames_per_step: 1024", "  frames_per_step: 10");
        let err = TrainConfig::parse(&tiny).unwrap_err();
        assert!(
            err.contains("training.frames_per_step must be at least"),
            "{err}"
        );
    }

    #[test]
    fn schedule_and_average_settings_are_checked() {
        let cases = [
            ("ema_decay: 0.999", "ema_decay: 1.0", "training.ema_decay"),
            (
                "warmup_steps: 500",
                "warmup_steps: 30000",
                "training.warmup_steps",
            ),
            (
                "lr_schedule: cosine",
                "lr_schedule: exponential",
                "cosine only",
            ),
            (
                "lr_schedule: cosine",
                "lr_schedule: linear",
                "unknown variant `linear`",
            ),
        ];
        let default = include_str!("../../../configs/default.yaml");
        for (from, to, expected) in cases {
            assert!(default.contains(from), "default.yaml lacks `{from}`");
            let err = TrainConfig::parse(&default.replacen(from, to, 1)).unwrap_err();
            assert!(err.contains(expected), "{to}: {err}");
        }
    }

    #[test]
    fn unknown_key_is_named_with_its_line() {
        let text = TINY.replacen("channels:", "chanels:", 1);
        let err = TrainConfig::parse(&text).unwrap_err();
        assert!(err.contains("unknown field `chanels`"), "{err}");
        assert!(err.contains("line"), "{err}");
    }

    #[test]
    fn bad_sizes_are_named() {
        let cases = [
            ("batch_size: 4", "batch_size: 0", "training.batch_size"),
            ("channels: 32", "channels: 0", "model.channels"),
            ("channels: 32", "channels: 40", "32 GroupNorm groups"),
            (
                "learning_rate: 2.0e-3",
                "learning_rate: -1.0",
                "training.learning_rate",
            ),
            ("window: 3", "window: 4", "window (4) must be odd"),
            ("heads: 4", "heads: 3", "multiple of heads (3)"),
        ];
        for (from, to, expected) in cases {
            assert!(TINY.contains(from), "tiny.yaml lacks `{from}`");
            let err = TrainConfig::parse(&TINY.replacen(from, to, 1)).unwrap_err();
            assert!(err.contains(expected), "{to}: {err}");
        }
        // A negative size is not even a number of the right type: serde names the field.
        let err =
            TrainConfig::parse(&TINY.replacen("batch_size: 4", "batch_size: -4", 1)).unwrap_err();
        assert!(err.contains("batch_size"), "{err}");
    }

    #[test]
    fn a_window_that_follows_the_frame_rate_widens_with_it() {
        let default = TrainConfig::parse(include_str!("../../../configs/default.yaml")).unwrap();
        assert!(default.model.window_follows_fps);
        assert_eq!(default.model.window, 3);
        let window = |fps| default.at_fps(fps).model.window;
        // Receptive half-width 11 frames at 30 fps; 8 of them come from the convolutions and
        // 3 x (k - 1) / 2 from the QnA windows. At f fps it should be 11 f / 30, so
        // (k - 1) / 2 = round((11 f / 30 - 8) / 3), never below 1.
        for (fps, expected) in [
            (24.0, 3),
            (30.0, 3),
            (33.0, 3),   // (12.1 - 8) / 3 = 1.37 -> 1
            (35.0, 5),   // (12.83 - 8) / 3 = 1.61 -> 2
            (40.0, 5),   // (14.67 - 8) / 3 = 2.22 -> 2
            (60.0, 11),  // (22 - 8) / 3 = 4.67 -> 5
            (90.0, 17),  // (33 - 8) / 3 = 8.33 -> 8
            (120.0, 25), // (44 - 8) / 3 = 12
        ] {
            assert_eq!(window(fps), expected, "{fps} fps");
        }
        // Receptive field 23 frames at 30 fps (0.77 s); 47 at 60 fps (0.78 s).
        assert_eq!(default.at_fps(60.0).model.receptive_field(), 47);
        assert_eq!(window(f64::NAN), 3);
        // Resolved, the flag is off, so the saved config trains the same shape at any rate.
        let resolved = default.at_fps(60.0);
        assert!(!resolved.model.window_follows_fps);
        assert_eq!(resolved.at_fps(120.0).model.window, 11);
        // A resume that asks for the default again resolves it the same way: no difference.
        assert_eq!(resolved.resume_difference(&default.at_fps(60.0)), None);
        // Off (the paper's configs): the window is the one written, at any frame rate.
        let paper = TrainConfig::parse(include_str!("../../../configs/paper.yaml")).unwrap();
        assert!(!paper.model.window_follows_fps);
        assert_eq!(paper.at_fps(120.0).model.window, 3);
        // The saved YAML records the flag only when it is on.
        let saved = serde_yaml::to_string(&resolved).unwrap();
        assert!(!saved.contains("window_follows_fps"), "{saved}");
        assert!(
            serde_yaml::to_string(&default)
                .unwrap()
                .contains("window_follows_fps: true")
        );
    }
}
