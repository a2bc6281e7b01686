//! The regular beat of a set of events: a dance's kinematic beats (speed minima) come at the
//! music's beats and, as often, between them; the dance's tempo and the events on its beat are
//! found as a song's are, treating each event as an onset: a Gaussian pulse of
//! [`PULSE_SECONDS`], so events a frame or two off the beat (as a dancer's are) still line up.

use sinmdm::motion::{KinematicBeats, LocalMotion, kinematic_beats};

use crate::onset::OnsetEnvelope;
use crate::{BeatsError, TrackerOptions, grid, tempo, track};

/// Standard deviation of the pulse made of each event, in seconds.
pub const PULSE_SECONDS: f64 = 0.05;

/// A regular beat found among events.
#[derive(Debug, Clone, PartialEq)]
pub struct RegularBeats {
    /// Tempo in beats per minute.
    pub bpm: f64,
    /// The events on the beat, increasing (each a frame from the events given).
    pub frames: Vec<usize>,
}

/// The tempo of `events` (frames at `frame_rate`, within `frames` frames) and the events that
/// follow it: the beat sequence of an envelope with a unit pulse at every event, each beat moved
/// to the nearest event within a quarter period (a beat with no event that near is dropped).
pub fn regular_beats(
    events: &[usize],
    frames: usize,
    frame_rate: f64,
    options: &TrackerOptions,
) -> Result<RegularBeats, BeatsError> {
    let seconds = frames as f64 / frame_rate;
    let sigma = (PULSE_SECONDS * frame_rate).max(0.5);
    let reach = (4.0 * sigma).ceil().min(frames as f64) as usize;
    let mut values = vec![0.0f32; frames];
    for &e in events.iter().filter(|&&e| e < frames) {
        for (t, v) in values
            .iter_mut()
            .enumerate()
            .take(e.saturating_add(reach).saturating_add(1).min(frames))
            .skip(e.saturating_sub(reach))
        {
            let d = (t as f64 - e as f64) / sigma;
            *v += (-0.5 * d * d).exp() as f32;
        }
    }
    let envelope = OnsetEnvelope {
        values,
        frame_rate,
        start: 0.0,
    };
    let period = tempo::estimate_period(&envelope, options)
        .map_err(|_| BeatsError::NoMotionBeats { seconds })?;
    let beats = track::beat_frames(&envelope.values, period, options.tightness);
    let snap = period / 4.0;
    let mut snapped: Vec<usize> = beats
        .iter()
        .filter_map(|&b| {
            events
                .iter()
                .copied()
                .min_by_key(|&e| e.abs_diff(b))
                .filter(|&e| (e.abs_diff(b) as f64) <= snap)
        })
        .collect();
    snapped.dedup();
    if snapped.len() < 2 {
        return Err(BeatsError::NoMotionBeats { seconds });
    }
    let times: Vec<f64> = beats.iter().map(|&b| b as f64).collect();
    let interval = if times.len() >= 2 {
        grid::fitted_interval(&times)
    } else {
        period
    };
    Ok(RegularBeats {
        bpm: 60.0 * frame_rate / interval,
        frames: snapped,
    })
}

/// A motion's kinematic beats (every speed minimum) and those on its dance's beat: the dance
/// task's reference beats.
pub fn motion_beats(motion: &LocalMotion) -> Result<(KinematicBeats, RegularBeats), BeatsError> {
    let minima = kinematic_beats(motion);
    let seconds = motion.frame_count() as f64 / motion.fps;
    if minima.frames.len() < 2 {
        return Err(BeatsError::NoMotionBeats { seconds });
    }
    let regular = regular_beats(
        &minima.frames,
        motion.frame_count(),
        motion.fps,
        &TrackerOptions::default(),
    )?;
    Ok((minima, regular))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_on_and_between_the_beats_give_the_beat() {
        // A beat every 15 frames (120 BPM at 30 fps), a frame late now and then, with an
        // extra event between some beats (no pattern of its own).
        let mut events: Vec<usize> = (0..20)
            .map(|k| 10 + 15 * k + (k % 4 == 1) as usize)
            .collect();
        events.extend([0, 3, 5, 6, 11, 13, 16].map(|k| 17 + 15 * k));
        events.sort_unstable();
        let found = regular_beats(&events, 310, 30.0, &TrackerOptions::default()).unwrap();
        assert!((found.bpm - 120.0).abs() < 2.0, "{} BPM", found.bpm);
        let on_beat = found
            .frames
            .iter()
            .filter(|&&f| (f as isize - 10).rem_euclid(15) <= 1)
            .count();
        assert!(
            on_beat as f64 >= 0.9 * found.frames.len() as f64,
            "{:?}",
            found.frames
        );
        assert!(found.frames.len() >= 18);
    }
}
