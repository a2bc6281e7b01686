//! `sinmdm dance`: a dance as long as a piece of music, the reference's poses at its own beats
//! landing on the music's beats (the task is `sinmdm::Task::Dance`); and the options that
//! `sinmdm eval --dance` shares with it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use ndarray::Array2;
use serde::Serialize;

use crate::clip_files::ClipUpArg;
use crate::sampling::{
    SamplingArgs, check_writable, reference_features, run_task, seconds_to_frames,
};
use sinmdm::files::write_atomically;
use sinmdm::limits::MAX_SAMPLE_FRAMES;
use sinmdm::motion::{LocalMotion, decode, kinematic_beats};
use sinmdm::tasks::{
    BeatLevel, DANCE_HOLD, DANCE_RAMP, DanceBeats, KeyOrder, Placement, Task, place_keyframes,
};
use sinmdm_eval::{BeatScores, beat_scores, mean_beat_scores};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm dance -m onnx-models/human_dance_rokoko.onnx --reference tests/data/bvh/human_dance_rokoko_jesse.bvh \\
      --music tests/data/audio/loop_amen_full.wav -o out/dance.bvh
  sinmdm dance -m dance.onnx --reference dance.bvh --bpm 126 --offset 0.2 --seconds 20 -o out/d.glb
  sinmdm dance -m dance.onnx --reference dance.bvh --beats beats.txt --count 4 --order reference -o out/d.bvh
  sinmdm dance -m dance.onnx --reference dance.bvh --music song.wav --beats-out out/used.json -o out/d.bvh

The reference's poses at its kinematic beats (`sinmdm beats --motion`) are placed on the music's
beats, a window of 2 x hold + 1 frames each (weight 1 at the beat, falling linearly over the ramp),
and everything between them is generated. When the
tracker's beats are off the beat, give them with --beats FILE or --bpm N --offset T.";

/// Which music beats carry keyframes (`--level`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LevelArg {
    /// The level that brings the music's tempo closest to the reference's.
    Auto,
    /// Every beat.
    Every,
    /// Every other beat.
    EveryOther,
    /// Every beat and half-way between.
    Half,
}

impl From<LevelArg> for BeatLevel {
    fn from(l: LevelArg) -> BeatLevel {
        match l {
            LevelArg::Auto => BeatLevel::Auto,
            LevelArg::Every => BeatLevel::Every,
            LevelArg::EveryOther => BeatLevel::EveryOther,
            LevelArg::Half => BeatLevel::Half,
        }
    }
}

/// The keyframes' order (`--order`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OrderArg {
    /// A new order each pass over the reference's beats, drawn from the seed.
    Shuffled,
    /// The reference's own order, over and over.
    Reference,
}

/// What the root does inside the keyframe windows (`--root`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RootArg {
    /// Travel and height from the reference.
    Kept,
    /// Travel and height generated (the body's pose is kept).
    Free,
}

/// The music and the placement of a dance: shared by `sinmdm dance` and `sinmdm eval --dance`.
#[derive(Debug, Clone, Args)]
pub struct DanceOptions {
    /// The music: its beats are found by the tracker (`sinmdm beats`). WAV (MP3, OGG, FLAC in
    /// builds with the `compressed` feature).
    #[arg(long, value_name = "SONG.wav", conflicts_with_all = ["beats", "bpm"])]
    pub music: Option<PathBuf>,
    /// The music's beats in seconds, one per line (or a CSV whose first column they are).
    #[arg(long, value_name = "FILE", conflicts_with = "bpm")]
    pub beats: Option<PathBuf>,
    /// The music's tempo in beats per minute (with --offset for the first beat).
    #[arg(long, value_name = "N")]
    pub bpm: Option<f64>,
    /// Time of the first beat in seconds, with --bpm.
    #[arg(long, value_name = "T", default_value_t = 0.0, requires = "bpm")]
    pub offset: f64,
    /// Half-width of each keyframe window, in frames.
    #[arg(long, default_value_t = DANCE_HOLD)]
    pub hold: usize,
    /// Soft border on the kept side of each window, in frames (at most hold + 1; the default,
    /// hold + 1, makes each window a triangle whose weight is 1 at the beat only).
    #[arg(long, default_value_t = DANCE_RAMP)]
    pub ramp: usize,
    /// Order of the keyframes.
    #[arg(long, value_enum, default_value_t = OrderArg::Shuffled)]
    pub order: OrderArg,
    /// Which music beats carry keyframes.
    #[arg(long, value_enum, default_value_t = LevelArg::Auto)]
    pub level: LevelArg,
    /// The root's travel and height inside the windows.
    #[arg(long, value_enum, default_value_t = RootArg::Kept)]
    pub root: RootArg,
    /// Write the beats used (the music's and the reference's, frames and seconds) and the
    /// keyframes as JSON here.
    #[arg(long, value_name = "OUT.json")]
    pub beats_out: Option<PathBuf>,
}

impl DanceOptions {
    /// Whether any music was given (`sinmdm eval` dances only then).
    pub fn has_music(&self) -> bool {
        self.music.is_some() || self.beats.is_some() || self.bpm.is_some()
    }

    /// The music's beat times in seconds and its length (the audio's, or `None` for a file or
    /// a tempo, which have no length of their own).
    fn music_beats(&self, default_seconds: f64) -> Result<(Vec<f64>, Option<f64>)> {
        if let Some(path) = &self.music {
            let audio = sinmdm_beats::read_audio(path)?;
            let beats = sinmdm_beats::track_beats(&audio)
                .with_context(|| format!("finding the beats of {}", path.display()))?;
            eprintln!(
                "{}: {:.1} BPM, {} beats, confidence {:.2} (off the beat? give --bpm N --offset T)",
                path.display(),
                beats.bpm,
                beats.times.len(),
                beats.confidence
            );
            return Ok((beats.times, Some(audio.seconds())));
        }
        match crate::beats::given_beats(
            self.beats.as_deref(),
            self.bpm,
            self.offset,
            default_seconds,
        )? {
            Some(times) => Ok((times, None)),
            None => bail!("give the music: --music SONG.wav, --beats FILE or --bpm N"),
        }
    }
}

/// A dance task ready to run, and what was chosen for it.
pub struct Dance {
    /// Raw reference features in the model's layout.
    reference: Array2<f32>,
    /// Both sides' beats (the reference's on its dance beat, the music's in output frames), the
    /// output's length and the placement settings.
    beats: DanceBeats,
    /// Whether the root's travel in the windows comes from the reference.
    root: bool,
    /// Where its keyframes go.
    pub placement: Placement,
    /// Frames per second of the model (and of every frame number here).
    pub fps: f64,
}

/// Builds the dance of `reference` (raw features in the model's layout) on the music of
/// `options`: `frames` given, or the music's length, or `fallback_frames`.
pub fn build_dance(
    layout: &sinmdm::FeatureLayout,
    reference: Array2<f32>,
    options: &DanceOptions,
    frames: Option<usize>,
    fallback_frames: usize,
    seed: u64,
) -> Result<Dance> {
    let fps = layout.fps;
    let check = |frames: usize| -> Result<usize> {
        if !(1..=MAX_SAMPLE_FRAMES).contains(&frames) {
            bail!(
                "a dance of {frames} frames is not possible: give 1 to {MAX_SAMPLE_FRAMES} frames (--seconds)"
            );
        }
        Ok(frames)
    };
    // A length given is checked before the music's beats are laid over it.
    let given = frames.map(check).transpose()?;
    let fallback_seconds = given.unwrap_or(fallback_frames) as f64 / fps;
    let (times, music_seconds) = options.music_beats(fallback_seconds)?;
    let frames =
        check(given.unwrap_or_else(|| {
            music_seconds.map_or(fallback_frames, |s| (s * fps).round() as usize)
        }))?;
    let mut music_beats: Vec<usize> = times
        .iter()
        .map(|t| (t * fps).round() as usize)
        .filter(|&f| f < frames)
        .collect();
    music_beats.dedup();
    let motion = decode(layout, reference.view()).context("decoding the reference")?;
    let reference_beats = sinmdm_beats::pulses::motion_beats(&motion)
        .context("finding the reference's beats")?
        .1
        .frames;
    let beats = DanceBeats {
        reference_beats,
        target_beats: music_beats,
        frames,
        hold: options.hold,
        ramp: options.ramp,
        order: match options.order {
            OrderArg::Reference => KeyOrder::Reference,
            OrderArg::Shuffled => KeyOrder::Shuffled,
        },
        level: options.level.into(),
    };
    let placement = place_keyframes(reference.ncols(), &beats, seed).context(
        "placing the dance's keyframes (if the tracker took the music's tempo twice or half as \
         fast, give it with --bpm N --offset T or --beats FILE)",
    )?;
    Ok(Dance {
        reference,
        beats,
        root: options.root == RootArg::Kept,
        placement,
        fps,
    })
}

/// What `--beats-out` writes.
#[derive(Debug, Serialize)]
struct BeatsOut<'a> {
    fps: f64,
    frames: usize,
    level: &'static str,
    tempo_ratio: f64,
    hold: usize,
    ramp: usize,
    /// The music's beats, frames of the output (all of them, before the level).
    music_beats: &'a [usize],
    /// The reference's kinematic beats, frames.
    reference_beats: &'a [usize],
    /// Each keyframe: (output frame, reference frame).
    keyframes: Vec<(usize, usize)>,
    /// The music beats used (the keyframes' output frames), seconds.
    used_beat_seconds: Vec<f64>,
}

impl Dance {
    /// The task to run (a copy: the caller's request owns it).
    pub fn task(&self) -> Task {
        Task::Dance {
            reference: self.reference.clone(),
            beats: self.beats.clone(),
            root: self.root,
        }
    }

    /// Says what was chosen.
    pub fn describe(&self) {
        let p = &self.placement;
        let beats = &self.beats;
        if p.hold < beats.hold {
            eprintln!(
                "dance: windows of {} frames each side instead of {}: the closest beats at this level are {} frames apart",
                p.hold,
                beats.hold,
                p.keys
                    .windows(2)
                    .map(|w| w[1].target - w[0].target)
                    .min()
                    .unwrap_or(0)
            );
        }
        eprintln!(
            "dance: {} frames ({:.1} s), {} keyframes on {} beats (tempo {:.2}x the reference's), hold {} ramp {}",
            beats.frames,
            beats.frames as f64 / self.fps,
            p.keys.len(),
            p.level,
            p.ratio,
            p.hold,
            p.ramp
        );
    }

    /// The music beats used, seconds.
    pub fn used_beat_seconds(&self) -> Vec<f64> {
        self.placement
            .keys
            .iter()
            .map(|k| k.target as f64 / self.fps)
            .collect()
    }

    /// Writes the beats used as JSON.
    pub fn write_beats(&self, path: &Path) -> Result<()> {
        let p = &self.placement;
        let out = BeatsOut {
            fps: self.fps,
            frames: self.beats.frames,
            level: p.level.name(),
            tempo_ratio: p.ratio,
            hold: p.hold,
            ramp: p.ramp,
            music_beats: &self.beats.target_beats,
            reference_beats: &self.beats.reference_beats,
            keyframes: p.keys.iter().map(|k| (k.target, k.reference)).collect(),
            used_beat_seconds: self.used_beat_seconds(),
        };
        write_atomically(path, serde_json::to_string_pretty(&out)?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
    }

    /// Beat scores of each motion against the beats used.
    pub fn scores(&self, motions: &[LocalMotion], seed: u64) -> Vec<BeatScores> {
        let music = self.used_beat_seconds();
        motions
            .iter()
            .map(|m| {
                let beats: Vec<f64> = kinematic_beats(m)
                    .frames
                    .iter()
                    .map(|&f| f as f64 / m.fps)
                    .collect();
                beat_scores(&beats, &music, m.frame_count() as f64 / m.fps, seed)
            })
            .collect()
    }
}

/// Prints the mean beat scores.
pub fn print_scores(scores: &[BeatScores]) {
    let s = mean_beat_scores(scores);
    println!(
        "beats: hit rate {:.2} (random phase {:.2}), Beat Align Score {:.3} (random phase {:.3}) over {} sample(s)",
        s.hit_rate,
        s.hit_rate_control,
        s.bas,
        s.bas_control,
        scores.len()
    );
}

/// Arguments of `sinmdm dance`.
#[derive(Debug, Args)]
pub struct DanceArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    /// The dance clip the model learned (its poses at its beats become the keyframes).
    #[arg(long, value_name = "CLIP.bvh|CLIP.glb")]
    reference: PathBuf,
    #[command(flatten)]
    up: ClipUpArg,
    #[command(flatten)]
    dance: DanceOptions,
    /// Length in seconds (default: the music's, or twice the clip with --beats or --bpm).
    #[arg(long)]
    seconds: Option<f64>,
}

pub(crate) fn run(args: &DanceArgs) -> Result<()> {
    if let Some(path) = &args.dance.beats_out {
        check_writable(std::slice::from_ref(path))?;
    }
    let mut model = args.sampling.open_model()?;
    let layout = model.metadata().layout.clone();
    let frames = args
        .seconds
        .map(|s| seconds_to_frames(s, layout.fps))
        .transpose()?;
    let reference = reference_features(&model, &args.reference, &args.up)?;
    let fallback = 2 * reference.ncols();
    let dance = build_dance(
        &layout,
        reference,
        &args.dance,
        frames,
        fallback,
        args.sampling.seed,
    )?;
    dance.describe();
    if let Some(path) = &args.dance.beats_out {
        dance.write_beats(path)?;
        eprintln!("wrote {}", path.display());
    }
    let generated = run_task(&args.sampling, &mut model, dance.task())?;
    let motions = (0..generated.count())
        .map(|i| generated.motion(i))
        .collect::<Result<Vec<_>, _>>()?;
    print_scores(&dance.scores(&motions, args.sampling.seed));
    Ok(())
}
