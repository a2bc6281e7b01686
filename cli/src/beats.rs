//! `sinmdm beats`: the tempo and beats of a piece of music (or of a motion clip), to check them
//! by ear with a click track before dancing to them.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use serde::Serialize;

use sinmdm::files::write_atomically;
use sinmdm_beats::{Beats, grid};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm beats song.wav                         # tempo, confidence and every beat time
  sinmdm beats song.wav --click out/click.wav   # hear them: the song with a click on each beat
  sinmdm beats song.wav --json out/beats.json
  sinmdm beats --motion dance.bvh               # the kinematic beats of a dance clip

Trackers find the tempo far more often than the phase (on the beat or half a beat off): when the
clicks fall between the beats, give them yourself to `sinmdm dance` with --beats FILE or
--bpm N --offset T.";

/// Arguments of `sinmdm beats`.
#[derive(Debug, Args)]
pub struct BeatsArgs {
    /// The music: WAV (MP3, OGG and FLAC in builds with the `compressed` feature).
    #[arg(value_name = "SONG.wav", required_unless_present = "motion")]
    song: Option<PathBuf>,
    /// A motion clip instead of music: print its kinematic beats (the joints' mean speed's
    /// minima) and its dance tempo.
    #[arg(long, value_name = "CLIP", conflicts_with = "song")]
    motion: Option<PathBuf>,
    /// The animation of a glTF or FBX clip given with --motion, by name or index.
    #[arg(long, value_name = "NAME|INDEX")]
    clip_anim: Option<String>,
    /// Write the song with a click on every beat here (16-bit mono WAV).
    #[arg(long, value_name = "OUT.wav", requires = "song")]
    click: Option<PathBuf>,
    /// Also write tempo and beats as JSON here.
    #[arg(long, value_name = "OUT.json")]
    json: Option<PathBuf>,
}

/// What `--json` writes.
#[derive(Debug, Serialize)]
struct BeatsReport {
    source: String,
    bpm: f64,
    confidence: f64,
    /// Beat times in seconds.
    times: Vec<f64>,
    /// For a motion clip: the beat frames at the clip's rate (the speed minima on the dance's
    /// beat).
    #[serde(skip_serializing_if = "Option::is_none")]
    frames: Option<Vec<usize>>,
    /// For a motion clip: every speed minimum, frames.
    #[serde(skip_serializing_if = "Option::is_none")]
    minima: Option<Vec<usize>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    fps: Option<f64>,
}

pub(crate) fn run(args: &BeatsArgs) -> Result<()> {
    if let Some(path) = &args.click {
        crate::sampling::check_writable(std::slice::from_ref(path))?;
    }
    let report = match (&args.song, &args.motion) {
        (Some(song), _) => song_beats(song, args.click.as_deref())?,
        (None, Some(clip)) => motion_beats(clip, args)?,
        (None, None) => bail!("give a song (SONG.wav) or a motion clip (--motion CLIP)"),
    };
    println!(
        "{}: {:.2} BPM, {} beats, confidence {:.2}",
        report.source,
        report.bpm,
        report.times.len(),
        report.confidence
    );
    let times: Vec<String> = report.times.iter().map(|t| format!("{t:.3}")).collect();
    println!("beats (s): {}", times.join(" "));
    if let Some(frames) = &report.frames {
        let frames: Vec<String> = frames.iter().map(|f| f.to_string()).collect();
        println!("beat frames: {}", frames.join(" "));
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&report)?;
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn song_beats(song: &Path, click: Option<&Path>) -> Result<BeatsReport> {
    let audio = sinmdm_beats::read_audio(song)?;
    let beats: Beats = sinmdm_beats::track_beats(&audio)
        .with_context(|| format!("finding the beats of {}", song.display()))?;
    if let Some(path) = click {
        sinmdm_beats::click::write_click_track(path, &audio, &beats.times)?;
        println!(
            "wrote {} (the song with a click on each beat)",
            path.display()
        );
    }
    Ok(BeatsReport {
        source: song.display().to_string(),
        bpm: beats.bpm,
        confidence: beats.confidence,
        times: beats.times,
        frames: None,
        minima: None,
        fps: None,
    })
}

fn motion_beats(clip: &Path, args: &BeatsArgs) -> Result<BeatsReport> {
    let motion = crate::clip_files::read_motion_file(clip, args.clip_anim.as_deref())?.to_local();
    let fps = motion.fps;
    let (minima, regular) = sinmdm_beats::pulses::motion_beats(&motion)
        .with_context(|| format!("{}: no dance beat", clip.display()))?;
    println!(
        "{} speed minima; on the dance's beat: {} (frames at {fps} fps)",
        minima.frames.len(),
        regular.frames.len()
    );
    let times: Vec<f64> = regular.frames.iter().map(|&f| f as f64 / fps).collect();
    Ok(BeatsReport {
        source: clip.display().to_string(),
        bpm: regular.bpm,
        confidence: regular.frames.len() as f64 / minima.frames.len().max(1) as f64,
        times,
        frames: Some(regular.frames),
        minima: Some(minima.frames),
        fps: Some(fps),
    })
}

/// Beat times given by a person: a file, or a tempo and offset over `seconds`.
pub(crate) fn given_beats(
    file: Option<&Path>,
    bpm: Option<f64>,
    offset: f64,
    seconds: f64,
) -> Result<Option<Vec<f64>>> {
    match (file, bpm) {
        (Some(path), _) => Ok(Some(grid::read_beat_file(path)?)),
        (None, Some(bpm)) => Ok(Some(grid::beat_grid(bpm, offset, seconds)?)),
        (None, None) => Ok(None),
    }
}
