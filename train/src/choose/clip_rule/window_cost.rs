//! What a training step costs at a wider QnA window, and the steps of a varied clip at a
//! higher frame rate that fit the time its steps at 30 fps take.

/// How much of a training step does not grow with the QnA window, in window frames: a step at
/// window `k` costs about as much as `WINDOW_STEP_COST_OFFSET + k` frames of window
/// ([`window_step_cost`]), fitted to whole runs of a dog at two windows (lab/EXPERIMENTS.md,
/// "Steps at a higher frame rate").
pub const WINDOW_STEP_COST_OFFSET: f64 = 10.0;
/// The steps fitted to a wider window's cost are rounded down to a multiple of this.
pub const FITTED_STEPS_ROUNDING: u64 = 500;

/// What a training step costs at QnA window `window`, relative to the rest of the network: the
/// step grows with the window as `WINDOW_STEP_COST_OFFSET + window`.
pub fn window_step_cost(window: usize) -> f64 {
    WINDOW_STEP_COST_OFFSET + window as f64
}

/// Steps at window `trained` that take the time `steps` take at window `at_30` (the window the
/// rule chose at 30 fps), rounded down to [`FITTED_STEPS_ROUNDING`]; `steps` where the trained
/// window is no wider.
pub fn steps_at_window(steps: u64, at_30: usize, trained: usize) -> u64 {
    if trained <= at_30 {
        return steps;
    }
    let fitted = steps as f64 * window_step_cost(at_30) / window_step_cost(trained);
    let unit = FITTED_STEPS_ROUNDING;
    ((fitted / unit as f64).floor() as u64 * unit).clamp(unit, steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choose::clip_rule::tests::{DEFAULT, reading};
    use crate::choose::clip_rule::{
        ClipReading, MANY_FEET_STEPS, MANY_FEET_WINDOW, VARIED_WINDOW, calm_most_steps, choose,
    };
    use crate::config::TrainConfig;

    #[test]
    fn a_varied_clip_at_a_higher_frame_rate_trains_the_steps_that_fit_the_same_time() {
        let config = TrainConfig::parse(DEFAULT).unwrap();
        // The most steps, in whole units of the rounding, whose cost at the wider window is
        // within that of the 30 fps steps.
        let unit = FITTED_STEPS_ROUNDING;
        let fits = |steps: u64, at_30: usize, trained: usize, chosen: u64| {
            let budget = steps as f64 * window_step_cost(at_30);
            chosen.is_multiple_of(unit)
                && chosen as f64 * window_step_cost(trained) <= budget
                && (chosen + unit) as f64 * window_step_cost(trained) > budget
        };
        let default_steps = config.training.steps;
        for (feet, at_30, steps) in [
            (2, VARIED_WINDOW, default_steps),
            (4, MANY_FEET_WINDOW, MANY_FEET_STEPS),
        ] {
            let at_60 = ClipReading {
                frames: 1054,
                fps: 60.0,
                feet,
                ..reading(0.8)
            };
            let choice = choose(&config, at_60);
            let out = &choice.config;
            // The window is still the one meant at 30 fps; the run widens it at 60.
            assert_eq!(out.model.window, at_30);
            let trained = out.model.at_fps(60.0).window;
            assert_eq!(trained, if feet == 2 { 15 } else { 19 });
            assert!(
                fits(steps, at_30, trained, out.training.steps),
                "{feet} feet: {} steps",
                out.training.steps
            );
            assert!(out.training.warmup_steps <= out.training.steps / 10);
            assert!(
                choice.lines()[1].starts_with(&format!("steps           {}:", out.training.steps))
                    && choice.lines()[1].contains(&format!("at 60 fps the window is {trained}"))
                    && choice.lines()[1].contains(&format!("meant at 30 fps, {steps}")),
                "{:?}",
                choice.lines()
            );
            out.validate().unwrap();
            // At 30 fps, or with a window that does not follow the frame rate, nothing falls.
            let at_30_fps = ClipReading { fps: 30.0, ..at_60 };
            assert_eq!(choose(&config, at_30_fps).config.training.steps, steps);
            let mut fixed = config.clone();
            fixed.model.window_follows_fps = false;
            assert_eq!(choose(&fixed, at_60).config.training.steps, steps);
        }
        // A calm clip's steps are the ladder's at any rate.
        let calm = ClipReading {
            fps: 60.0,
            ..reading(0.3)
        };
        assert_eq!(
            choose(&config, calm).config.training.steps,
            calm_most_steps()
        );
        assert_eq!(steps_at_window(17_000, 5, 5), 17_000);
    }
}
