//! The `sinmdm` command line: argument parsing and printing; the work is done by the libraries
//! (`sinmdm`, `sinmdm-render`, `sinmdm-eval`).

mod beats;
mod character;
mod clip_files;
mod convert;
mod dance;
mod doctor;
mod eval;
mod info;
mod inspect;
mod library;
mod render;
mod reorient;
mod sampling;
mod steer;
mod stream;
mod tasks;

use clap::{Parser, Subcommand};

/// sinmdm: learn a character's motion from one clip and generate new motion from it.
#[derive(Debug, Parser)]
#[command(name = "sinmdm", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Read a .gltf clip's buffer files even where its URIs lead outside the clip's folder
    /// (`../other/data.bin`); off so that a downloaded file cannot read others on the machine.
    #[arg(long, global = true)]
    pub allow_outside_folder: bool,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe a clip (BVH, glTF) as the model sees it, and optionally check the representation by an
    /// encode/decode round trip.
    #[command(after_help = inspect::EXAMPLES)]
    Inspect(inspect::InspectArgs),
    /// New motion from a model: one sample or a crowd, of any length.
    #[command(after_help = tasks::GENERATE_EXAMPLES)]
    Generate(tasks::GenerateArgs),
    /// Keep spans of a reference clip and generate the motion between them.
    #[command(after_help = tasks::INBETWEEN_EXAMPLES)]
    Inbetween(tasks::InbetweenArgs),
    /// Generate new motion before and/or after a reference clip.
    #[command(after_help = tasks::EXPAND_EXAMPLES)]
    Expand(tasks::ExpandArgs),
    /// Keep chosen joints (a body part) and/or the root motion of a reference, generate the rest.
    #[command(after_help = tasks::COMPOSE_EXAMPLES)]
    Compose(tasks::ComposeArgs),
    /// A dance as long as a piece of music: the reference's poses at its beats land on the
    /// music's beats, everything between them new.
    #[command(after_help = dance::EXAMPLES)]
    Dance(dance::DanceArgs),
    /// Motion that goes where it is told (a path, a circle, a figure eight, speeds and turn
    /// rates), the body in the clip's style; needs a heading-relative model.
    #[command(after_help = steer::EXAMPLES)]
    Steer(steer::SteerArgs),
    /// Style transfer: a content clip's low frequencies in the style the model learned.
    #[command(after_help = tasks::HARMONIZE_EXAMPLES)]
    Harmonize(tasks::HarmonizeArgs),
    /// The tempo and beats of a piece of music (WAV), or of a motion clip; a click track to hear
    /// them.
    #[command(after_help = beats::EXAMPLES)]
    Beats(beats::BeatsArgs),
    /// Draw clips (BVH, glTF) as stick figures: an animated GIF, or a PNG contact sheet.
    #[command(after_help = render::EXAMPLES)]
    Render(render::RenderArgs),
    /// Convert a clip between motion formats (BVH, glTF .glb/.gltf).
    #[command(after_help = convert::EXAMPLES)]
    Convert(convert::ConvertArgs),
    /// Rewrite a clip with another up axis (Z-up to Y-up, say) and/or turned about its up axis.
    #[command(after_help = reorient::EXAMPLES)]
    Reorient(reorient::ReorientArgs),
    /// Endless motion written chunk by chunk, as an engine pulls it from a stream.
    #[command(after_help = stream::EXAMPLES)]
    Stream(stream::StreamArgs),
    /// Score a model: generate samples and measure coverage and diversity against its clip.
    #[command(after_help = eval::EXAMPLES)]
    Eval(eval::EvalArgs),
    /// Print what a model file holds: network, skeleton, features, training facts.
    #[command(after_help = info::INFO_EXAMPLES)]
    Info(info::InfoArgs),
    /// Write a clip's features in a model's layout as JSON (input of the Python reference).
    #[command(after_help = info::ENCODE_EXAMPLES)]
    Encode(info::EncodeArgs),
    /// Which onnxruntime this program loads (file, release, where it was found) and what each
    /// feature still lacks.
    #[command(after_help = doctor::EXAMPLES)]
    Doctor(doctor::DoctorArgs),
    /// A motion library trained as an array job (`sinmdm-train --manifest`): status, report,
    /// batch generation.
    #[command(after_help = library::EXAMPLES)]
    Library(library::LibraryArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    clip_files::set_file_access(sinmdm_formats::FileAccess {
        allow_outside_folder: cli.allow_outside_folder,
    });
    let result = match cli.command {
        Command::Inspect(args) => inspect::run(&args),
        Command::Generate(args) => tasks::generate(&args),
        Command::Inbetween(args) => tasks::inbetween(&args),
        Command::Expand(args) => tasks::expand(&args),
        Command::Compose(args) => tasks::compose(&args),
        Command::Harmonize(args) => tasks::harmonize(&args),
        Command::Dance(args) => dance::run(&args),
        Command::Steer(args) => steer::run(&args),
        Command::Stream(args) => stream::run(&args),
        Command::Eval(args) => eval::run(&args),
        Command::Info(args) => info::info(&args),
        Command::Beats(args) => beats::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Reorient(args) => reorient::run(&args),
        Command::Convert(args) => convert::run(&args),
        Command::Encode(args) => info::encode(&args),
        Command::Library(args) => library::run(&args),
        Command::Doctor(args) => doctor::run(&args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
