//! `sinmdm doctor`: which onnxruntime this program loads, and what each feature still lacks.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm doctor
  ORT_DYLIB_PATH=/opt/onnxruntime/lib/libonnxruntime.so sinmdm doctor";

/// Arguments of `sinmdm doctor`.
#[derive(Debug, Args)]
pub struct DoctorArgs {}

/// A feature and whether this install has what it needs.
struct Feature {
    what: &'static str,
    /// `Ok(where it comes from)` or `Err(what is missing and how to get it)`.
    state: std::result::Result<String, String>,
}

/// Prints the onnxruntime found (its file, release and the place of the search that gave it)
/// and each feature's state; fails when onnxruntime is not found, naming every place looked in.
pub fn run(_args: &DoctorArgs) -> Result<()> {
    let program = std::env::current_exe().ok();
    let runtime = sinmdm::init_onnxruntime();
    let report = report(program.as_deref(), &runtime);
    // A reader that stops early (`sinmdm doctor | head -2`) is not an error of this program.
    match std::io::stdout().lock().write_all(report.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => return Err(e.into()),
        _ => {}
    }
    if runtime.is_err() {
        bail!("onnxruntime was not found (the places looked in are listed above)");
    }
    Ok(())
}

fn report(
    program: Option<&Path>,
    runtime: &std::result::Result<&sinmdm::OnnxRuntime, sinmdm::RuntimeLibraryError>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "sinmdm       {} ({})",
        env!("CARGO_PKG_VERSION"),
        program.map_or("its file is unknown here".into(), |p| p
            .display()
            .to_string())
    );
    match runtime {
        Ok(rt) => {
            let version = rt.version.as_deref().unwrap_or("release unknown");
            let tested = if rt.version.as_deref() == Some(sinmdm::ONNXRUNTIME_VERSION) {
                "the release the project tests with".to_string()
            } else {
                format!("the project tests with {}", sinmdm::ONNXRUNTIME_VERSION)
            };
            let _ = writeln!(
                s,
                "onnxruntime  {version} from {} (the search's place: {}; {tested})",
                rt.path.display(),
                rt.found_in
            );
        }
        Err(e) => {
            let _ = writeln!(s, "onnxruntime  not found: {e}");
        }
    }
    for feature in features(runtime.is_ok(), program.and_then(Path::parent)) {
        let _ = match feature.state {
            Ok(from) => writeln!(s, "  ready    {}: {from}", feature.what),
            Err(missing) => writeln!(s, "  missing  {}: {missing}", feature.what),
        };
    }
    s
}

fn features(onnxruntime: bool, folder: Option<&Path>) -> Vec<Feature> {
    let needs_runtime = |what| Feature {
        what,
        state: if onnxruntime {
            Ok("onnxruntime".into())
        } else {
            Err("onnxruntime (see above)".into())
        },
    };
    let program = |what, name: &str, package: &str| Feature {
        what,
        state: find_program(name, folder)
            .map(|p| p.display().to_string())
            .ok_or(format!(
                "no {name} next to this program or on PATH: `scripts/setup.sh --train` in a \
                 checkout, or `cargo install --path {package}`"
            )),
    };
    vec![
        needs_runtime(
            "generate, inbetween, expand, compose, harmonize, dance, steer, stream, eval",
        ),
        Feature {
            what: "inspect, convert, reorient, render (GIF, PNG), beats of WAV music",
            state: Ok("built in".into()),
        },
        Feature {
            what: "MP3, OGG and FLAC music",
            state: if cfg!(feature = "compressed") {
                Ok("built in".into())
            } else {
                Err("built without the `compressed` feature: \
                     `cargo install --path cli --features compressed`"
                    .into())
            },
        },
        program("training (sinmdm-train)", "sinmdm-train", "train"),
        program(
            "export of a training run (sinmdm-export)",
            "sinmdm-export",
            "train",
        ),
    ]
}

/// `name` (with the platform's executable suffix) next to this program, else on `PATH`.
fn find_program(name: &str, folder: Option<&Path>) -> Option<PathBuf> {
    let file = format!("{name}{}", std::env::consts::EXE_SUFFIX);
    let path = std::env::var_os("PATH").unwrap_or_default();
    folder
        .map(Path::to_path_buf)
        .into_iter()
        .chain(std::env::split_paths(&path))
        .map(|dir| dir.join(&file))
        .find(|candidate| candidate.is_file())
}
