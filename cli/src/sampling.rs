//! What every generating subcommand shares: the model, seed, steps, crowd size, output files
//! and the progress bar.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use ndarray::Array2;

use sinmdm::features_file::write_features;
use sinmdm::limits::MAX_SAMPLES;
use sinmdm::motion::encode_for_model;
use sinmdm::{Feet, Generated, Method, Plan, Request, Span, Task};
use sinmdm::{Model, ModelOptions};
use sinmdm_render::{Camera, Figure};

use crate::clip_files::{
    ClipUpArg, GltfPlacement, is_gltf, metres_per_unit, named_samples, write_motion_file,
};
use crate::render::write_picture;

/// Default respaced sampling steps of the command line: the library's `sinmdm::DEFAULT_STEPS`
/// (clap needs it as text; a test checks they agree).
pub const DEFAULT_STEPS: &str = "50";

/// Respaced steps per block of `sinmdm stream` and `sinmdm eval --stream`: the library's
/// `sinmdm::DEFAULT_STREAM_STEPS` (a test checks they agree).
pub const DEFAULT_STREAM_STEPS: &str = "20";

/// Options shared by `generate`, `inbetween`, `expand`, `compose` and `harmonize`.
#[derive(Debug, Args)]
pub struct SamplingArgs {
    /// The trained model (.onnx written by sinmdm-export).
    #[arg(short, long, value_name = "MODEL.onnx")]
    pub model: PathBuf,
    /// Output file: BVH (with --count above 1, samples go to NAME_000.bvh, NAME_001.bvh, ...),
    /// or glTF (.glb, .gltf: one file with every sample as an animation, in metres and +Y up).
    /// FBX is not written: write .glb, which Blender, Godot, Unity (glTFast) and three.js open.
    #[arg(short, long, value_name = "OUT.bvh|OUT.glb")]
    pub output: PathBuf,
    /// Metres per unit of the model's clip, for glTF output (default: from the skeleton's
    /// height: metres, centimetres, or CMU units when unsure, said).
    #[arg(long, value_name = "METRES")]
    pub unit_scale: Option<f64>,
    /// Add a one-triangle mesh skinned to the root (glTF output), for importers that build
    /// skeletons only from skinned meshes (Unreal's).
    #[arg(long)]
    pub proxy_mesh: bool,
    /// The character's own .glb: the output (a .glb) is that file, meshes, skin and materials
    /// unchanged, with every sample appended as one more animation of its bones (matched by
    /// name, or as --retarget says; a rig of other proportions or rest pose is retargeted).
    #[arg(long, value_name = "CHARACTER.glb")]
    pub mesh_from: Option<PathBuf>,
    #[command(flatten)]
    pub retarget: crate::character::RetargetArg,
    /// Samples to make in one batched run (a crowd).
    #[arg(long, default_value_t = 1)]
    pub count: usize,
    /// Seed of the noise: the same model, seed and arguments give the same motion, in this
    /// program and in the Python reference.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Denoising steps: a number S of respaced steps (1..=T), or `all` for the model's full T.
    #[arg(long, default_value = DEFAULT_STEPS, value_name = "S|all")]
    pub steps: String,
    /// Threads for the network (default: every core).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Also write the raw features of every sample as JSON here.
    #[arg(long, value_name = "OUT.json")]
    pub features_json: Option<PathBuf>,
    /// Also draw what was made: an animated .gif of all samples side by side, or a .png contact
    /// sheet; parts kept from a reference are drawn in red.
    #[arg(long, value_name = "OUT.gif|OUT.png")]
    pub render: Option<PathBuf>,
    /// Do not show the progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Feet: `planted` holds each foot still while the model says it is on the ground and
    /// keeps every joint above the ground (by turning the legs; bone lengths stay exact);
    /// `raw` writes the network's motion untouched.
    #[arg(long, value_enum, default_value_t = FeetArg::Planted)]
    pub feet: FeetArg,
    #[command(flatten)]
    pub method: MethodArgs,
}

/// `--sampler` and `--eta`: the update rule of each denoising step.
#[derive(Debug, Clone, Args)]
pub struct MethodArgs {
    /// The update rule of each step: `ancestral` (the paper's DDPM sampler), `ddim`
    /// (deterministic with --eta 0) or `dpm2m` (DPM-Solver++(2M), deterministic, second order:
    /// good motion in fewer steps).
    #[arg(long, value_enum, default_value_t = SamplerArg::Ancestral)]
    pub sampler: SamplerArg,
    /// DDIM's share of the ancestral noise, 0 to 1.
    #[arg(long, default_value_t = 0.0)]
    pub eta: f64,
}

/// `--sampler`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplerArg {
    /// Ancestral DDPM.
    Ancestral,
    /// DDIM (with --eta).
    Ddim,
    /// DPM-Solver++(2M).
    Dpm2m,
}

impl MethodArgs {
    /// The method asked for.
    pub fn method(&self) -> Result<Method> {
        if self.sampler != SamplerArg::Ddim && self.eta != 0.0 {
            bail!("--eta applies to --sampler ddim only");
        }
        let method = match self.sampler {
            SamplerArg::Ancestral => Method::Ancestral,
            SamplerArg::Ddim => Method::Ddim { eta: self.eta },
            SamplerArg::Dpm2m => Method::DpmSolver2M,
        };
        if let Some(problem) = method.problem() {
            bail!("--eta: {problem}");
        }
        Ok(method)
    }
}

/// `--feet`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FeetArg {
    /// Feet held still during contact, nothing below the ground.
    Planted,
    /// The network's motion untouched.
    Raw,
}

impl From<FeetArg> for Feet {
    fn from(arg: FeetArg) -> Feet {
        match arg {
            FeetArg::Planted => Feet::Planted,
            FeetArg::Raw => Feet::Raw,
        }
    }
}

impl SamplingArgs {
    /// `None` for all steps.
    pub fn steps(&self) -> Result<Option<usize>> {
        parse_steps(&self.steps)
    }

    /// Opens the model with the requested threads.
    pub fn open_model(&self) -> Result<Model> {
        if self.threads == Some(0) {
            bail!("--threads must be at least 1");
        }
        Ok(Model::open(
            &self.model,
            &ModelOptions {
                threads: self.threads,
            },
        )?)
    }

    /// The file of sample `index` of `count` (a glTF file holds them all).
    pub fn output_path(&self, index: usize, count: usize) -> PathBuf {
        if count == 1 || is_gltf(&self.output) {
            return self.output.clone();
        }
        let stem = self
            .output
            .file_stem()
            .map_or("sample".into(), |s| s.to_string_lossy().into_owned());
        let ext = self
            .output
            .extension()
            .map_or("bvh".into(), |e| e.to_string_lossy().into_owned());
        self.output
            .with_file_name(format!("{stem}_{index:03}.{ext}"))
    }
}

/// Where a run's motions go, decided and checked before any sampling.
enum MotionOutput<'a> {
    /// One BVH file per sample.
    Bvh,
    /// One glTF file with every sample as an animation, at `metres` per unit of the model's clip.
    Gltf { metres: f64 },
    /// The character's own GLB (`--mesh-from`) with the samples appended.
    Character(&'a Path),
}

impl SamplingArgs {
    /// The output `-o`, `--mesh-from`, `--unit-scale` and `--proxy-mesh` ask for, checked
    /// together; `skeleton_height` (file units) gives a glTF file's unit when none is given.
    fn motion_output(&self, skeleton_height: f64) -> Result<MotionOutput<'_>> {
        if let Some(character) = &self.mesh_from {
            anyhow::ensure!(
                self.output
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("glb")),
                "--mesh-from writes the character's file with the new animations: -o must be a .glb"
            );
            anyhow::ensure!(
                self.unit_scale.is_none() && !self.proxy_mesh,
                "--mesh-from takes the character's units and meshes; leave out --unit-scale and --proxy-mesh"
            );
            return Ok(MotionOutput::Character(character));
        }
        if is_gltf(&self.output) {
            let metres = metres_per_unit(skeleton_height, self.unit_scale)?;
            return Ok(MotionOutput::Gltf { metres });
        }
        crate::clip_files::check_output(&self.output)?;
        anyhow::ensure!(
            self.unit_scale.is_none() && !self.proxy_mesh,
            "--unit-scale and --proxy-mesh are for glTF output; BVH keeps the clip's units and has no meshes"
        );
        Ok(MotionOutput::Bvh)
    }
}

/// `--steps`: a number of respaced steps, or `all` (`None`) for the model's full T.
pub fn parse_steps(text: &str) -> Result<Option<usize>> {
    if text.eq_ignore_ascii_case("all") {
        return Ok(None);
    }
    match text.parse::<usize>() {
        Ok(s) => Ok(Some(s)),
        Err(_) => bail!("--steps must be a whole number of steps or 'all', got '{text}'"),
    }
}

/// A frame position given as frames (`120`) or seconds (`4s`, `1.5s`).
pub fn parse_position(text: &str, fps: f64) -> Result<usize> {
    let text = text.trim();
    if let Some(seconds) = text.strip_suffix('s') {
        let s: f64 = seconds
            .parse()
            .with_context(|| format!("'{text}' is not a number of seconds"))?;
        if !(s.is_finite() && s >= 0.0) {
            bail!("'{text}': seconds must be 0 or more");
        }
        Ok((s * fps).round() as usize)
    } else {
        text.parse::<usize>().with_context(|| {
            format!("'{text}' is not a frame number (use a whole number, or seconds as '2.5s')")
        })
    }
}

/// Every span of a repeated `START:END` flag, in order.
pub fn parse_spans(texts: &[String], fps: f64, frames: usize) -> Result<Vec<Span>> {
    texts.iter().map(|s| parse_span(s, fps, frames)).collect()
}

/// A span `START:END` (END exclusive, empty = `frames`), each part frames or seconds.
pub fn parse_span(text: &str, fps: f64, frames: usize) -> Result<Span> {
    let (a, b) = text
        .split_once(':')
        .with_context(|| format!("span '{text}' must look like START:END, e.g. 0:60 or 0s:2s"))?;
    let start = if a.trim().is_empty() {
        0
    } else {
        parse_position(a, fps).with_context(|| format!("in span '{text}'"))?
    };
    let end = if b.trim().is_empty() {
        frames
    } else {
        parse_position(b, fps).with_context(|| format!("in span '{text}'"))?
    };
    Ok(Span::new(start, end))
}

/// Reads a clip (BVH, glTF or FBX) of the model's skeleton as raw features in the model's layout
/// ([`encode_for_model`]), saying so when the clip was turned into the model's up convention.
/// A clip in which nothing moves is refused, naming the animation read: a still reference has
/// nothing for a task to keep or a score to compare (a Mixamo download's `Take 001`).
pub fn reference_features(model: &Model, clip: &Path, read: &ClipUpArg) -> Result<Array2<f32>> {
    let (channels, source) =
        crate::clip_files::read_motion_file_and_source(clip, read.clip_anim.as_deref())?;
    if !sinmdm_formats::clip_moves(&channels) {
        let what = source.animation.map_or("the clip".to_string(), |a| {
            format!("animation {}", a.describe())
        });
        bail!(
            "{}: nothing moves in {what} (no channel varies by more than {}); a reference must move{}",
            clip.display(),
            sinmdm_formats::STILL_TOLERANCE,
            if source.animations.len() > 1 {
                ": pick another animation with --clip-anim NAME|INDEX"
            } else {
                ""
            }
        );
    }
    let layout = &model.metadata().layout;
    let encoded = encode_for_model(&channels, layout, read.up).with_context(|| {
        format!(
            "{}: cannot use it with model {}",
            clip.display(),
            model.path().display()
        )
    })?;
    if encoded.turned {
        eprintln!(
            "{}: up axis {}, the model's is {}: turned the clip into the model's convention",
            clip.display(),
            encoded.clip_up,
            layout.up
        );
    }
    Ok(encoded.features)
}

/// A progress bar over sampling steps (hidden with `quiet`; indicatif hides it off a terminal).
pub fn progress_bar(quiet: bool, steps: usize, message: String) -> indicatif::ProgressBar {
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(steps as u64)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:30} {pos}/{len} steps, {per_sec}, ETA {eta} ({msg})",
        )
        .expect("valid template"),
    );
    bar.set_message(message);
    bar
}

/// `--seconds S` as frames at `fps` (rounded); S must be a positive number.
pub fn seconds_to_frames(seconds: f64, fps: f64) -> Result<usize> {
    if !(seconds.is_finite() && seconds > 0.0) {
        bail!("--seconds must be a positive number, got {seconds}");
    }
    Ok((seconds * fps).round() as usize)
}

/// Checks that every output file can be written, before any work is done.
pub fn check_writable(paths: &[PathBuf]) -> Result<()> {
    for path in paths {
        if path.is_dir() {
            bail!("output '{}' is a folder; give a file name", path.display());
        }
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create output folder '{}'", dir.display()))?;
        let probe = dir.join(format!(".sinmdm-probe-{}", std::process::id()));
        std::fs::write(&probe, b"")
            .with_context(|| format!("cannot write in output folder '{}'", dir.display()))?;
        let _ = std::fs::remove_file(&probe);
    }
    Ok(())
}

/// Runs a task with the shared options: checks the request and the outputs, samples with a
/// progress bar, and writes the motions (BVH files, one glTF file, or the character's GLB with
/// them appended), the features JSON and the picture, each atomically.
pub fn run_task(args: &SamplingArgs, model: &mut Model, task: Task) -> Result<Generated> {
    if !(1..=MAX_SAMPLES).contains(&args.count) {
        bail!(
            "--count must be between 1 and {MAX_SAMPLES}, got {}",
            args.count
        );
    }
    let request = Request {
        task,
        count: args.count,
        seed: args.seed,
        steps: args.steps()?,
        feet: args.feet.into(),
        method: args.method.method()?,
    };
    let plan = sinmdm::plan(model.metadata(), &request)?;
    for warning in plan.warnings() {
        eprintln!("warning: {warning}");
    }
    let mut outputs: Vec<PathBuf> = (0..plan.count())
        .map(|i| args.output_path(i, plan.count()))
        .collect();
    outputs.dedup();
    let destination = args.motion_output(model.metadata().layout.skeleton_height)?;
    let bones = args.retarget.bone_match()?;
    outputs.extend(args.features_json.iter().cloned());
    outputs.extend(args.render.iter().cloned());
    check_writable(&outputs)?;

    let generated = run_with_progress(model, &plan, args.quiet)?;
    let motions = (0..generated.count())
        .map(|i| {
            generated
                .motion(i)
                .with_context(|| format!("sample {i} could not be decoded"))
        })
        .collect::<Result<Vec<_>>>()?;
    let layout = generated.layout();
    match destination {
        MotionOutput::Character(character) => {
            crate::character::put_on_character(
                character,
                &args.output,
                &named_samples(&motions),
                layout.up,
                &bones,
            )?;
        }
        MotionOutput::Gltf { metres } => {
            let placement = GltfPlacement {
                up: layout.up,
                metres,
                proxy_mesh: args.proxy_mesh,
            };
            write_motion_file(&args.output, &motions, None, placement)?;
            eprintln!(
                "wrote {} ({} animation{})",
                args.output.display(),
                motions.len(),
                if motions.len() == 1 { "" } else { "s" }
            );
        }
        MotionOutput::Bvh => {
            for (i, motion) in motions.iter().enumerate() {
                let path = args.output_path(i, motions.len());
                let one = std::slice::from_ref(motion);
                write_motion_file(&path, one, None, GltfPlacement::NONE)?;
                eprintln!("wrote {}", path.display());
            }
        }
    }
    if let Some(path) = &args.features_json {
        write_features(path, generated.layout(), generated.features.view())?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.render {
        let layout = generated.layout();
        let kept = plan.kept_joints();
        let mut figures = Vec::new();
        for i in 0..generated.count() {
            let mut figure = Figure::new(
                &generated.motion(i)?,
                layout.up,
                format!("sample {i}"),
                layout.contact_speed_threshold,
            );
            figure.kept = kept.clone();
            figures.push(figure);
        }
        write_picture(path, &figures, Camera::Follow, 320, 8)?;
    }
    Ok(generated)
}

/// Runs a checked plan on the model with a progress bar over its steps.
pub fn run_with_progress(model: &mut Model, plan: &Plan, quiet: bool) -> Result<Generated> {
    let bar = progress_bar(
        quiet,
        plan.steps(),
        format!("{} x {} frames", plan.count(), plan.frames()),
    );
    let generated = plan.run(model, &mut |done, _| {
        bar.set_position(done as u64);
        ControlFlow::Continue(())
    })?;
    bar.finish_and_clear();
    Ok(generated)
}

#[cfg(test)]
mod default_steps_tests {
    #[test]
    fn the_command_line_default_is_the_library_default() {
        assert_eq!(
            super::DEFAULT_STEPS.parse::<usize>(),
            Ok(sinmdm::DEFAULT_STEPS)
        );
        assert_eq!(
            super::DEFAULT_STREAM_STEPS.parse::<usize>(),
            Ok(sinmdm::DEFAULT_STREAM_STEPS)
        );
    }
}
