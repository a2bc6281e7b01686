//! Resuming a run: the configuration a resume asks for, with what the rule that reads the
//! clip chose standing in, and the first setting that keeps a checkpoint from continuing.

use super::{FromClip, TrainConfig};

impl TrainConfig {
    /// The configuration `self` asks a run that started as `saved` (on a clip trained at `fps`)
    /// to continue with: what the rule that reads the clip chose when the run started stands in
    /// for every part `self.from_clip` leaves to the rule, and so does the root layout `auto`
    /// chose. Compare it with `saved` by [`TrainConfig::resume_difference`].
    pub fn for_resume(&self, saved: &TrainConfig, fps: f64) -> TrainConfig {
        let mut asked = self.clone();
        let rule = asked.from_clip;
        if rule.steps {
            asked.training.steps = saved.training.steps;
            asked.training.warmup_steps = saved.training.warmup_steps;
        }
        if rule.window {
            asked.model.window = saved.model.window;
            asked.model.window_follows_fps = false;
        }
        if rule.dropout {
            asked.model.dropout = saved.model.dropout;
        }
        if rule.channels {
            asked.model.channels = saved.model.channels;
        }
        if rule.batch {
            asked.training.frames_per_step = saved.training.frames_per_step;
        }
        asked.from_clip = FromClip::default();
        let mut asked = asked.at_fps(fps);
        if asked.data.root_layout == sinmdm::motion::RootLayout::Auto {
            asked.data.root_layout = saved.data.root_layout;
        }
        asked
    }

    /// Why a checkpoint trained under `self` cannot continue under `asked`: the first setting
    /// (by its YAML key) that differs, comparing the whole configurations except
    /// `training.steps` and `training.checkpoint_every`, the only two a resume may change.
    pub fn resume_difference(&self, asked: &TrainConfig) -> Option<String> {
        let mut asked = asked.clone();
        asked.training.steps = self.training.steps;
        asked.training.checkpoint_every = self.training.checkpoint_every;
        let as_value = |c: &TrainConfig| serde_json::to_value(c).unwrap_or_default();
        first_difference(&as_value(self), &as_value(&asked), String::new()).map(|(key, a, b)| {
            format!("the checkpoint was trained with {key} = {a}, the config asks for {b}")
        })
    }
}

/// The first leaf (dotted key, saved value, asked value) where two JSON trees differ.
fn first_difference(
    a: &serde_json::Value,
    b: &serde_json::Value,
    key: String,
) -> Option<(String, String, String)> {
    use serde_json::Value;
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort();
            keys.dedup();
            keys.into_iter().find_map(|k| {
                let child = if key.is_empty() {
                    k.clone()
                } else {
                    format!("{key}.{k}")
                };
                first_difference(
                    x.get(k).unwrap_or(&Value::Null),
                    y.get(k).unwrap_or(&Value::Null),
                    child,
                )
            })
        }
        _ if a == b => None,
        _ => Some((key, a.to_string(), b.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choose::clip_rule::{MANY_FEET_CHANNELS, MANY_FEET_STEPS, MANY_FEET_WINDOW};

    /// The default, and what a new run with it on a varied clip of `frames` frames on four feet
    /// at 30 fps saved: the rule's choices, and the root layout auto chose.
    fn the_default_and_a_dog_run_it_saved(
        frames: usize,
        intra_diversity: f64,
    ) -> (TrainConfig, TrainConfig) {
        let default = TrainConfig::parse(include_str!("../../../configs/default.yaml")).unwrap();
        let dog = crate::choose::clip_rule::ClipReading {
            frames,
            fps: 30.0,
            intra_diversity,
            feet: 4,
        };
        let mut saved = crate::choose::clip_rule::choose(&default, dog)
            .config
            .at_fps(30.0);
        saved.data.root_layout = sinmdm::motion::RootLayout::Heading;
        (default, saved)
    }

    #[test]
    fn a_resume_with_the_default_keeps_what_the_rule_chose_for_a_dog() {
        // The rule's window, channels and steps.
        let (default, saved) = the_default_and_a_dog_run_it_saved(527, 0.77);
        assert_eq!(
            (
                saved.model.channels,
                saved.model.window,
                saved.training.steps
            ),
            (MANY_FEET_CHANNELS, MANY_FEET_WINDOW, MANY_FEET_STEPS)
        );
        let asked = default.for_resume(&saved, 30.0);
        assert_eq!(saved.resume_difference(&asked), None);
        // A configuration that does not leave the channels to the rule asks for 64: refused,
        // naming the setting.
        let mut fixed = default.clone();
        fixed.from_clip.channels = false;
        let message = saved
            .resume_difference(&fixed.for_resume(&saved, 30.0))
            .unwrap();
        assert!(message.contains("model.channels = 96"), "{message}");
    }

    #[test]
    fn a_resume_with_the_default_keeps_the_batch_the_rule_paired() {
        // A varied dog of 409 frames: 1 024 frames a step would make 3 copies; the rule made 2.
        let (default, saved) = the_default_and_a_dog_run_it_saved(409, 0.76);
        assert_eq!(saved.training.frames_per_step, Some(818));
        assert_eq!(
            saved.resume_difference(&default.for_resume(&saved, 30.0)),
            None
        );
        let mut fixed = default.clone();
        fixed.from_clip.batch = false;
        let message = saved
            .resume_difference(&fixed.for_resume(&saved, 30.0))
            .unwrap();
        assert!(
            message.contains("training.frames_per_step = 818"),
            "{message}"
        );
    }

    #[test]
    fn resume_compares_every_setting_but_the_step_counts() {
        let saved = TrainConfig::parse(include_str!("../../../configs/tiny.yaml")).unwrap();
        let mut asked = saved.clone();
        asked.training.steps += 100;
        asked.training.checkpoint_every += 1;
        assert_eq!(saved.resume_difference(&asked), None);
        // Any other setting, found by its YAML key.
        asked.data.contact_speed *= 2.0;
        let message = saved.resume_difference(&asked).expect("a difference");
        assert!(message.contains("data.contact_speed"), "{message}");
        let mut asked = saved.clone();
        asked.model.heads *= 2;
        let message = saved.resume_difference(&asked).expect("a difference");
        assert!(
            message.starts_with("the checkpoint was trained with model.heads = "),
            "{message}"
        );
    }
}
