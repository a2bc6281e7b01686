//! `sinmdm` installed outside the checkout (as `cargo install --path cli` leaves it): it finds
//! onnxruntime next to itself or through the system loader, `sinmdm doctor` says which, and
//! with none it names every place it looked.
#![cfg(target_os = "linux")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// `sinmdm ARGS` from the copy in `bin`, run in `work` with the loader's variables cleared
/// (`LD_LIBRARY_PATH` set to `system` when given).
fn installed(bin: &Path, work: &Path, system: Option<&Path>, args: &[&str]) -> Output {
    let mut command = Command::new(bin.join("sinmdm"));
    command
        .args(args)
        .current_dir(work)
        .env_remove("ORT_DYLIB_PATH")
        .env_remove("LD_LIBRARY_PATH");
    if let Some(folder) = system {
        command.env("LD_LIBRARY_PATH", folder);
    }
    command.output().expect("run the installed sinmdm")
}

fn text(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

#[test]
fn an_installed_sinmdm_finds_onnxruntime_beside_it_or_on_the_system_path() {
    let library = sinmdm::init_onnxruntime()
        .expect("run scripts/setup.sh first")
        .path
        .clone();
    let root = std::env::temp_dir().join(format!("sinmdm-installed-{}", std::process::id()));
    let (bin, work, system) = (root.join("bin"), root.join("work"), root.join("lib"));
    for folder in [&bin, &work, &system] {
        std::fs::create_dir_all(folder).unwrap();
    }
    std::fs::copy(env!("CARGO_BIN_EXE_sinmdm"), bin.join("sinmdm")).unwrap();
    let model = repo_file("tests/data/models/walk_tiny.onnx");
    let glb = work.join("walk.glb");
    let generate = [
        "generate",
        "-m",
        model.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ];

    // None anywhere: every place of the search is named, in order, by `doctor` and by a command
    // that needs it. (A machine with an onnxruntime of its own on the loader's path cannot show
    // this; there the check says so and goes on.)
    let doctor = installed(&bin, &work, None, &["doctor"]);
    let said = text(&doctor);
    if doctor.status.success()
        && said.contains("the search's place: the system loader's search path")
    {
        eprintln!(
            "this machine's loader finds an onnxruntime of its own; not checked: none anywhere"
        );
    } else {
        nowhere(&bin, &work, &said, &generate, &glb);
    }
    // On the system loader's path.
    std::fs::copy(&library, system.join("libonnxruntime.so")).unwrap();
    let doctor = installed(&bin, &work, Some(&system), &["doctor"]);
    assert!(doctor.status.success(), "{}", text(&doctor));
    let said = text(&doctor);
    assert!(
        said.contains(&format!(
            "onnxruntime  {} from",
            sinmdm::ONNXRUNTIME_VERSION
        )) && said.contains("the search's place: the system loader's search path"),
        "{said}"
    );

    // Next to the binary, as a game or an install ships it: found first, and it generates.
    std::fs::copy(&library, bin.join(library.file_name().unwrap())).unwrap();
    let doctor = installed(&bin, &work, Some(&system), &["doctor"]);
    assert!(
        text(&doctor).contains("the search's place: next to the executable"),
        "{}",
        text(&doctor)
    );
    let run = installed(&bin, &work, None, &generate);
    assert!(run.status.success(), "{}", text(&run));
    let written = std::fs::read(&glb).unwrap();
    assert_eq!(&written[..4], b"glTF");
    std::fs::remove_dir_all(&root).unwrap();
}

/// With no onnxruntime to be found, `doctor` (which said `said`) fails naming every place in
/// order, and `generate` fails the same way and writes nothing.
fn nowhere(bin: &Path, work: &Path, said: &str, generate: &[&str], glb: &Path) {
    assert!(said.contains("error: onnxruntime was not found"), "{said}");
    let places = [
        "ORT_DYLIB_PATH: not set",
        &format!(
            "next to the executable: no libonnxruntime.so in {}",
            bin.display()
        ),
        "the system loader's search path",
        "a developer checkout's .venv: none",
    ];
    let at: Vec<usize> = places
        .iter()
        .map(|p| {
            said.find(p)
                .unwrap_or_else(|| panic!("'{p}' not in: {said}"))
        })
        .collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "out of order: {said}");
    assert!(said.contains("missing  generate"), "{said}");
    let run = installed(bin, work, None, generate);
    assert!(!run.status.success());
    assert!(
        text(&run).contains("a developer checkout's .venv: none"),
        "{}",
        text(&run)
    );
    assert!(!glb.exists());
}
