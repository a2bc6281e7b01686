//! The `sinmdm` command line (feature `cli`): argument parsing and printing; the work is done by
//! the library.

mod inspect;

use clap::{Parser, Subcommand};

/// sinmdm: learn a character's motion from one clip and generate new motion from it.
#[derive(Debug, Parser)]
#[command(name = "sinmdm", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe a BVH clip as the model sees it, and optionally check the representation by an
    /// encode/decode round trip.
    #[command(after_help = inspect::EXAMPLES)]
    Inspect(inspect::InspectArgs),
}

/// Runs the command line; returns the process exit status.
pub fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Inspect(args) => inspect::run(&args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
